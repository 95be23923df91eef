// Loops over the channels of one NHWC pixel: 4-float vectors, then single floats for the
// channels left over. Include only from *_neon.cpp files. Same pattern as
// kernels/x86/avx2_channels.h: kernel bodies are generic lambdas written with the
// lane-generic arithmetic below (NEON has no masked loads; a bounce buffer for the
// partial vector stalls store forwarding).
#pragma once
#include <arm_neon.h>

#include <cmath>
#include <cstdint>

namespace ampi::neon {

struct Vector {
  static float32x4_t load(const float* p) { return vld1q_f32(p); }
  // ST1, not the STR that vst1q_f32 becomes: llvm-mca's Cortex-A76 (Neoverse-N1) model
  // gives a Q-form STR two vector-pipe micro-ops and ST1 one, and the vector pipes are
  // the FMAs' (bench/RESULTS-arm-model.md). The "Q" operand tells GCC the 16 bytes
  // written, so it still orders the loads and stores around it.
  static void store(float* p, float32x4_t v) {
    asm("st1 {%1.4s}, %0" : "=Q"(*reinterpret_cast<float(*)[4]>(p)) : "w"(v));
  }
  // Plain stores: a 16-byte vector is a quarter of a line, too little to stream.
  static void stream(float* p, float32x4_t v) { store(p, v); }
  static float32x4_t splat(float x) { return vdupq_n_f32(x); }
  // A load the compiler may not merge with an earlier one of the same address: each of a
  // block's accumulators starts from its own load of the bias, not from a copy of one
  // register (fmla overwrites its addend, so each copy is a vector move, and the moves
  // take the vector pipes the FMAs need while the load pipes have room).
  static float32x4_t load_again(const float* p) {
    float32x4_t v;
    asm volatile("ldr %q0, [%1]" : "=w"(v) : "r"(p), "m"(*reinterpret_cast<const float(*)[4]>(p)));
    return v;
  }
};

struct Scalar {
  static float load(const float* p) { return *p; }
  static void store(float* p, float v) { *p = v; }
  static void stream(float* p, float v) { *p = v; }
  static float splat(float x) { return x; }
  static float load_again(const float* p) { return *p; }
};

inline void finish_streaming() {}

inline float32x4_t plus(float32x4_t a, float32x4_t b) { return vaddq_f32(a, b); }
inline float32x4_t minus(float32x4_t a, float32x4_t b) { return vsubq_f32(a, b); }
inline float32x4_t times(float32x4_t a, float32x4_t b) { return vmulq_f32(a, b); }
inline float32x4_t fmadd(float32x4_t a, float32x4_t b, float32x4_t c) { return vfmaq_f32(c, a, b); }
inline float plus(float a, float b) { return a + b; }
inline float minus(float a, float b) { return a - b; }
inline float times(float a, float b) { return a * b; }
inline float fmadd(float a, float b, float c) { return a * b + c; }
inline float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

class Channels {
 public:
  explicit Channels(int c) : c_(c) {}
  // Calls body(j, Vector{}) for j = 0, 4, 8, ... while 4 channels remain, then
  // body(j, Scalar{}) for each remaining channel j.
  template <class Body>
  void each(Body&& body) const {
    int j = 0;
    for (; j + 4 <= c_; j += 4) body(j, Vector{});
    for (; j < c_; ++j) body(j, Scalar{});
  }

 private:
  int c_;
};

// Copies n floats between buffers that do not overlap, with no scalar remainder from 4
// floats on: whole vectors, then one more ending exactly at n.
inline void copy_floats(const float* src, int64_t n, float* dst) {
  if (n < 4) {
    for (int64_t j = 0; j < n; ++j) dst[j] = src[j];
    return;
  }
  for (int64_t j = 0; j + 4 <= n; j += 4) vst1q_f32(dst + j, vld1q_f32(src + j));
  if (n % 4) vst1q_f32(dst + n - 4, vld1q_f32(src + n - 4));
}

// Depthwise interior columns through a stepping pointer (avx512_channels.h says why):
// bench/arm_model.py's 3x3 s1 loop went from 69 to 62 cycles on Neoverse-N1.
constexpr bool kStepColumns = true;

// Depthwise interior blocks keep a kernel of up to this many weight vectors in registers
// across blocks (depthwise_lanes.inl): 3x3's 9, beside a block's 8 accumulators and the
// column being read, fit NEON's 32 registers; 5x5's 25 do not. bench/arm_model.py's 3x3 s1
// loop went from 62 to 53 cycles on Neoverse-N1 (262 -> 154 instructions), and to 48 with
// the bias loaded into each accumulator (Vector::load_again), and to 44 against the
// 40-cycle FMA bound with the stores as ST1 (Vector::store; 181 instructions: the
// addresses now take integer adds, which the in-order Cortex-A55 model pays for, 142 ->
// 159 cycles).
constexpr int kDepthwiseWeightRegisters = 16;

// v as a value GCC cannot look into: it may not fuse the multiply that made v with an add
// of v into one FMA. The depthwise interior with its weights held (depthwise_lanes.inl)
// adds the residual after the activation; without this GCC fused HardSwish's last
// multiply into that add there, while the other depthwise paths round between them.
template <class V>
inline V opaque(V v) {
  asm("" : "+w"(v));
  return v;
}

// Nothing to do here: avx512_channels.h says why AVX-512 pins loaded vectors.
template <class V>
inline void keep_in_register(V&) {}

}  // namespace ampi::neon
