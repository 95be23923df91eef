// AVX-512 variants of the slicer's row kernels (see row_kernels.h): 16 pixels at a
// time, the row's tail under a lane mask.
#include <immintrin.h>

#include <algorithm>
#include <cstdint>

#include "kernels/x86/avx512_math.h"
#include "slicing/row_kernels.h"

namespace ampi::slicing::avx512 {
namespace {

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
  // Lane by lane: GCC 12's _mm512_reduce_min_ps warns falsely inside its own header.
  alignas(64) float los[16], his[16];
  _mm512_store_ps(los, lo);
  _mm512_store_ps(his, hi);
  range.lo = *std::min_element(los, los + 16);
  range.hi = *std::max_element(his, his + 16);
  range.finite = range.finite && finite == 0xFFFF;
}

void normalize_row(const float* in, int n, double lo, double scale, float* value, uint8_t* level) {
  const __m512d lo8 = _mm512_set1_pd(lo), scale8 = _mm512_set1_pd(scale);
  for (int x = 0; x < n; x += 8) {  // 8 doubles a vector
    const __mmask8 lanes = static_cast<__mmask8>(lanes_left(n - x));
    // Masked-off lanes read lo: 0, defined, never stored.
    const __m256 v = normalize8(_mm256_mask_loadu_ps(_mm256_set1_ps(static_cast<float>(lo)), lanes, in + x), lo8, scale8);
    _mm256_mask_storeu_ps(value + x, lanes, v);
    _mm_mask_storeu_epi8(level + x, lanes, _mm256_cvtusepi32_epi8(_mm256_cvtps_epi32(v)));  // ties to even
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
      _mm512_mask_storeu_ps(weight[h] + x, lanes, ampi::avx512::exp2_nonpositive(y));
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

void snap_row(const SnapRowInputs& in, int n, float min_step, float margin, float* out, uint8_t* band) {
  const __m512 step = _mm512_set1_ps(min_step), m = _mm512_set1_ps(margin), neg_m = _mm512_set1_ps(-margin);
  const __m512 half = _mm512_set1_ps(0.5f);
  for (int x = 0; x < n; x += 16) {
    const __mmask16 lanes = lanes_left(n - x);
    auto load = [&](const float* p) { return _mm512_maskz_loadu_ps(lanes, p + x); };  // zeros past the row
    const __m512 lo = load(in.lo), hi = load(in.hi), d = load(in.disparity);
    const __m512 spread = _mm512_sub_ps(hi, lo);
    const __mmask16 edge = _mm512_cmp_ps_mask(spread, step, _CMP_GE_OQ);
    const __mmask16 inside = _mm512_cmp_ps_mask(d, _mm512_fmadd_ps(m, spread, lo), _CMP_GT_OQ) &
                             _mm512_cmp_ps_mask(d, _mm512_fmadd_ps(neg_m, spread, hi), _CMP_LT_OQ);
    __m512 fit = _mm512_fmadd_ps(load(in.a0), load(in.blue), _mm512_add_ps(load(in.b), d));
    fit = _mm512_fmadd_ps(load(in.a1), load(in.green), fit);
    fit = _mm512_fmadd_ps(load(in.a2), load(in.red), fit);
    const __mmask16 near = _mm512_cmp_ps_mask(fit, _mm512_mul_ps(_mm512_add_ps(lo, hi), half), _CMP_GE_OQ);
    const __m512 side = _mm512_mask_blend_ps(near, lo, hi);
    _mm512_mask_storeu_ps(out + x, lanes, _mm512_mask_blend_ps(edge & inside, d, side));
    _mm_mask_storeu_epi8(band + x, lanes, _mm_maskz_set1_epi8(edge, static_cast<char>(255)));
  }
}

}  // namespace ampi::slicing::avx512
