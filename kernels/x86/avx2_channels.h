// Loops over the channels of one NHWC pixel: 8-float vectors, then single floats for the
// channels left over. Include only from *_avx2.cpp files.
//
// Channel counts in the networks are often not multiples of 8 (3 for RGB, 12 after a
// DWT of RGB), so every kernel walks channels through Channels::each. The kernel body
// is a generic lambda, written once with the lane-generic arithmetic below; each() calls
// it with Vector lanes for the whole blocks and Scalar lanes for the rest, so nothing is
// read or written past c. The leftover channels run as plain scalar code: masked AVX2
// stores (vmaskmovps) are microcoded on AMD Zen and made c = 3 maps 10x slower than the
// scalar reference, and a bounce buffer stalls store forwarding about as badly.
#pragma once
#include <immintrin.h>

#include <cmath>
#include <cstdint>

namespace ampi::avx2 {

struct Vector {
  static __m256 load(const float* p) { return _mm256_loadu_ps(p); }
  static void store(float* p, __m256 v) { _mm256_storeu_ps(p, v); }
  // Non-temporal store, 32-byte aligned: written to memory without reading the line
  // first and without evicting cached data for it.
  static void stream(float* p, __m256 v) { _mm256_stream_ps(p, v); }
  static __m256 splat(float x) { return _mm256_set1_ps(x); }
};

struct Scalar {
  static float load(const float* p) { return *p; }
  static void store(float* p, float v) { *p = v; }
  static void stream(float* p, float v) { *p = v; }
  static float splat(float x) { return x; }
};

// Orders the streaming stores before the stores that follow (the thread pool's "done").
inline void finish_streaming() { _mm_sfence(); }

inline __m256 plus(__m256 a, __m256 b) { return _mm256_add_ps(a, b); }
inline __m256 minus(__m256 a, __m256 b) { return _mm256_sub_ps(a, b); }
inline __m256 times(__m256 a, __m256 b) { return _mm256_mul_ps(a, b); }
inline __m256 fmadd(__m256 a, __m256 b, __m256 c) { return _mm256_fmadd_ps(a, b, c); }
inline float plus(float a, float b) { return a + b; }
inline float minus(float a, float b) { return a - b; }
inline float times(float a, float b) { return a * b; }
inline float fmadd(float a, float b, float c) { return a * b + c; }
inline float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

class Channels {
 public:
  explicit Channels(int c) : c_(c) {}
  // Calls body(j, Vector{}) for j = 0, 8, 16, ... while 8 channels remain, then
  // body(j, Scalar{}) for each remaining channel j.
  template <class Body>
  void each(Body&& body) const {
    int j = 0;
    for (; j + 8 <= c_; j += 8) body(j, Vector{});
    for (; j < c_; ++j) body(j, Scalar{});
  }

 private:
  int c_;
};

// Copies n floats between buffers that do not overlap, with no scalar remainder: whole
// vectors, then one more ending exactly at n (re-copying a few floats is harmless); SSE
// vectors the same way below 8 floats.
inline void copy_floats(const float* src, int64_t n, float* dst) {
  if (n >= 8) {
    for (int64_t j = 0; j + 8 <= n; j += 8) _mm256_storeu_ps(dst + j, _mm256_loadu_ps(src + j));
    if (n % 8) _mm256_storeu_ps(dst + n - 8, _mm256_loadu_ps(src + n - 8));
  } else if (n >= 4) {
    _mm_storeu_ps(dst, _mm_loadu_ps(src));
    _mm_storeu_ps(dst + n - 4, _mm_loadu_ps(src + n - 4));
  } else {
    for (int64_t j = 0; j < n; ++j) dst[j] = src[j];
  }
}

inline float horizontal_sum(__m256 v) {
  __m128 s = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  s = _mm_add_ps(s, _mm_movehl_ps(s, s));
  s = _mm_add_ss(s, _mm_movehdup_ps(s));
  return _mm_cvtss_f32(s);
}

// Depthwise columns stay indexed (avx512_channels.h has the stepping pointer): with
// 16 registers, stepping made 5x5 s1 over 256x192x96 slower (3.9-4.2 -> 5.0-6.1 ms).
constexpr bool kStepColumns = false;

// Nothing to do here: avx512_channels.h says why AVX-512 pins loaded vectors. Pinning
// them here too (asm "+x") measured no better: 5x5 s1 over 256x192x96 5.6 -> 6.8 ms,
// 3x3 s1 over 512x384x64 6.5 -> 6.8 ms (cpu clock, medians of alternating runs).
template <class V>
inline void keep_in_register(V&) {}

// Depthwise interior blocks reload their weights each block (depthwise_lanes.inl): 0 keeps
// no kernel in registers across blocks.
constexpr int kDepthwiseWeightRegisters = 0;

}  // namespace ampi::avx2
