// AVX-512 variants of the slicer's row kernels (see row_kernels.h): 16 pixels at a
// time, the row's tail under a lane mask.
#include <cstdint>

#include "slicing/row_kernels.h"

#if defined(__x86_64__)
#include <immintrin.h>

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx512f,avx512bw,avx512vl,fma"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx512f,avx512bw,avx512vl,fma")
// GCC 12 warns falsely inside its own intrinsics (masked loads, 256-bit extracts), as
// cmake/isa.cmake notes.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

namespace ampi::slicing::avx512 {
namespace {

// 2^y for y <= 0, as in the AVX2 variant; scalef applies 2^n.
inline __m512 exp2_nonpositive(__m512 y) {
  y = _mm512_max_ps(y, _mm512_set1_ps(-126.0f));
  const __m512 n = _mm512_roundscale_ps(y, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  const __m512 f = _mm512_sub_ps(y, n);
  __m512 p = _mm512_set1_ps(1.540353039e-4f);
  p = _mm512_fmadd_ps(p, f, _mm512_set1_ps(1.333355815e-3f));
  p = _mm512_fmadd_ps(p, f, _mm512_set1_ps(9.618129108e-3f));
  p = _mm512_fmadd_ps(p, f, _mm512_set1_ps(5.550410866e-2f));
  p = _mm512_fmadd_ps(p, f, _mm512_set1_ps(2.402265070e-1f));
  p = _mm512_fmadd_ps(p, f, _mm512_set1_ps(6.931471806e-1f));
  p = _mm512_fmadd_ps(p, f, _mm512_set1_ps(1.0f));
  return _mm512_scalef_ps(p, n);
}

inline __m512 load16(const uint8_t* p, __mmask16 lanes) {
  return _mm512_cvtepi32_ps(_mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(lanes, p)));
}

// The lanes of a block of 16 pixels with `left` pixels left in the row.
inline __mmask16 lanes_left(int left) {
  return left >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << left) - 1);
}

// min((x - lo) * scale, 255) on 8 values in double, back to float.
inline __m256 normalize8(__m256 x, __m512d lo, __m512d scale) {
  const __m512d v = _mm512_mul_pd(_mm512_sub_pd(_mm512_cvtps_pd(x), lo), scale);
  return _mm512_cvtpd_ps(_mm512_min_pd(v, _mm512_set1_pd(255.0)));
}

}  // namespace

void range_row(const float* in, int n, ValueRange& range) {
  __m512 lo = _mm512_set1_ps(range.lo), hi = _mm512_set1_ps(range.hi);
  __mmask16 finite = 0xFFFF;
  for (int x = 0; x < n; x += 16) {
    const __mmask16 lanes = lanes_left(n - x);
    // Masked-off lanes repeat the running minimum: finite, and no new extreme.
    const __m512 v = _mm512_mask_loadu_ps(_mm512_set1_ps(range.lo), lanes, in + x);
    // v - v is 0 for a finite v, NaN for an infinite or NaN one.
    finite &= _mm512_cmp_ps_mask(_mm512_sub_ps(v, v), _mm512_setzero_ps(), _CMP_EQ_OQ);
    lo = _mm512_min_ps(lo, v);
    hi = _mm512_max_ps(hi, v);
  }
  range.lo = _mm512_reduce_min_ps(lo);
  range.hi = _mm512_reduce_max_ps(hi);
  range.finite = range.finite && finite == 0xFFFF;
}

void normalize_row(const float* in, int n, double lo, double scale, float* value, uint8_t* level) {
  const __m512d lo8 = _mm512_set1_pd(lo), scale8 = _mm512_set1_pd(scale);
  for (int x = 0; x < n; x += 16) {
    const __mmask16 lanes = lanes_left(n - x);
    // Masked-off lanes read lo: 0, defined, never stored.
    const __m512 x16 = _mm512_mask_loadu_ps(_mm512_set1_ps(static_cast<float>(lo)), lanes, in + x);
    const __m256 low = normalize8(_mm512_castps512_ps256(x16), lo8, scale8);
    const __m256 high = normalize8(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(x16), 1)), lo8, scale8);
    const __m512 v = _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castps_pd(_mm512_castps256_ps512(low)),
                                                         _mm256_castps_pd(high), 1));
    _mm512_mask_storeu_ps(value + x, lanes, v);
    _mm_mask_storeu_epi8(level + x, lanes, _mm512_cvtusepi32_epi8(_mm512_cvtps_epi32(v)));  // ties to even
  }
}

void bilateral_weights(const uint8_t* p, int n, const BilateralPairs& pairs, float* const* weight) {
  const __m512 coeff = _mm512_set1_ps(pairs.color_log2_coeff);
  for (int x = 0; x < n; x += 16) {
    const __mmask16 lanes = lanes_left(n - x);
    const __m512 v0 = load16(p + x, lanes);
    for (int h = 0; h < pairs.count; ++h) {
      const __m512 d = _mm512_sub_ps(load16(p + x + pairs.offset[h], lanes), v0);
      const __m512 y = _mm512_fmadd_ps(_mm512_mul_ps(d, d), coeff, _mm512_set1_ps(pairs.log2_space_weight[h]));
      _mm512_mask_storeu_ps(weight[h] + x, lanes, exp2_nonpositive(y));
    }
  }
}

void bilateral_combine(const uint8_t* center, int n, const BilateralTaps& taps, uint8_t* out) {
  for (int x = 0; x < n; x += 16) {
    const __mmask16 lanes = lanes_left(n - x);
    __m512 sum = _mm512_setzero_ps(), wsum = _mm512_setzero_ps();
    for (int k = 0; k < taps.count; ++k) {
      const __m512 w = _mm512_maskz_loadu_ps(lanes, taps.weight[k] + x);
      sum = _mm512_fmadd_ps(w, load16(center + x + taps.offset[k], lanes), sum);
      wsum = _mm512_add_ps(wsum, w);
    }
    // Lanes outside `lanes` are 0 / 0: never stored.
    const __m512i q = _mm512_cvtps_epi32(_mm512_div_ps(sum, wsum));  // nearest, MXCSR default
    _mm_mask_storeu_epi8(out + x, lanes, _mm512_cvtusepi32_epi8(q));
  }
}

}  // namespace ampi::slicing::avx512

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif  // __x86_64__
