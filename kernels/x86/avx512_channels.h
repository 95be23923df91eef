// Loops over the channels of one NHWC pixel in 16-float vectors, the last one masked.
// Include only from *_avx512.cpp files. Unlike AVX2 (see avx2_channels.h), the channels
// left over take one masked vector: AVX-512 masked loads and stores (mask registers, not
// vmaskmovps) run at the speed of plain ones, so kernel bodies use the intrinsics directly.
#pragma once
#include <immintrin.h>

namespace ampi::avx512 {

// Loads and stores the lanes set in mask (masked-off loads read as 0 and never fault).
struct MaskedVector {
  __mmask16 mask;
  __m512 load(const float* p) const { return _mm512_maskz_loadu_ps(mask, p); }
  void store(float* p, __m512 v) const { _mm512_mask_storeu_ps(p, mask, v); }
  // A part of a line: no streaming store for it.
  void stream(float* p, __m512 v) const { store(p, v); }
  __m512 splat(float x) const { return _mm512_set1_ps(x); }
};

struct FullVector {
  __m512 load(const float* p) const { return _mm512_loadu_ps(p); }
  void store(float* p, __m512 v) const { _mm512_storeu_ps(p, v); }
  // Non-temporal store of one whole, 64-byte-aligned cache line: written to memory
  // without reading the line first and without evicting cached data for it.
  void stream(float* p, __m512 v) const { _mm512_stream_ps(p, v); }
  __m512 splat(float x) const { return _mm512_set1_ps(x); }
};

// Orders the streaming stores before the stores that follow (the thread pool's "done").
inline void finish_streaming() { _mm_sfence(); }

// The arithmetic lane-generic kernel bodies (kernels/*_lanes.inl) are written with.
inline __m512 plus(__m512 a, __m512 b) { return _mm512_add_ps(a, b); }
inline __m512 minus(__m512 a, __m512 b) { return _mm512_sub_ps(a, b); }
inline __m512 fmadd(__m512 a, __m512 b, __m512 c) { return _mm512_fmadd_ps(a, b, c); }
// Keeps a loaded vector in a register: GCC otherwise folds the load into each FMA that
// uses it, and a 3x3 depthwise block then issues 27 loads per kernel row for 24 FMAs,
// which makes it load-bound (this AMD EPYC, Zen 5:
// 3x3 over 64 channels in cache went from 0.23-0.32 to 0.18-0.25 ms in a one-off harness,
// four alternating rounds; 5x5 unchanged).
template <class V>
inline void keep_in_register(V& v) { asm("" : "+v"(v)); }

// Depthwise interior columns read through a stepping pointer (kernels/depthwise_lanes.inl):
// indexed from the block's first column, each load's address cost a 64-bit multiply-add;
// 3x3 s1 over 512x384x64 went from 9.7 to 3.7-4.4 ms (`ampi bench kernels`, cpu clock,
// alternating runs), the other depthwise rows unchanged within noise.
constexpr bool kStepColumns = true;

// Depthwise interior blocks reload their weights each block (depthwise_lanes.inl): 0 keeps
// no kernel in registers across blocks.
constexpr int kDepthwiseWeightRegisters = 0;

class Channels {
 public:
  explicit Channels(int c)
      : c_(c), whole_(c - c % 16), tail_{static_cast<__mmask16>((1u << (c % 16)) - 1u)} {}
  // Calls body(j, accessor) for j = 0, 16, 32, ... < c.
  template <class Body>
  void each(Body&& body) const {
    for (int j = 0; j < whole_; j += 16) body(j, FullVector{});
    if (whole_ < c_) body(whole_, tail_);
  }

 private:
  int c_, whole_;
  MaskedVector tail_;
};

}  // namespace ampi::avx512
