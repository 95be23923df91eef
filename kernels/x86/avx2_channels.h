// Loops over the channels of one NHWC pixel in 8-float vectors, the last one partial.
// Include only from *_avx2.cpp files.
//
// Channel counts in the networks are often not multiples of 8 (3 for RGB, 12 after a
// DWT of RGB), so every kernel walks channels through Channels::each: the body is a
// generic lambda called with a full-vector accessor for each whole block and a masked
// one for the remainder, so it is written once and never reads or writes past c.
#pragma once
#include <immintrin.h>

#include <cstdint>

namespace ampi::avx2 {

// Loads and stores all 8 lanes.
struct FullVector {
  __m256 load(const float* p) const { return _mm256_loadu_ps(p); }
  void store(float* p, __m256 v) const { _mm256_storeu_ps(p, v); }
};

// Loads and stores only the first n lanes (masked-off loads read as 0 and never fault).
struct PartialVector {
  __m256i mask;
  explicit PartialVector(int n) {
    static const int32_t bits[16] = {-1, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0};
    mask = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(bits + 8 - n));
  }
  __m256 load(const float* p) const { return _mm256_maskload_ps(p, mask); }
  void store(float* p, __m256 v) const { _mm256_maskstore_ps(p, mask, v); }
};

class Channels {
 public:
  explicit Channels(int c) : c_(c), whole_(c - c % 8), tail_(c % 8) {}
  // Calls body(j, accessor) for j = 0, 8, 16, ... < c.
  template <class Body>
  void each(Body&& body) const {
    for (int j = 0; j < whole_; j += 8) body(j, FullVector{});
    if (whole_ < c_) body(whole_, tail_);
  }

 private:
  int c_, whole_;
  PartialVector tail_;
};

inline float horizontal_sum(__m256 v) {
  __m128 s = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  s = _mm_add_ps(s, _mm_movehl_ps(s, s));
  s = _mm_add_ss(s, _mm_movehdup_ps(s));
  return _mm_cvtss_f32(s);
}

}  // namespace ampi::avx2
