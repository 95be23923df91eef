// AVX2 + FMA variants of the slicer's row kernels (see row_kernels.h): 8 pixels at a
// time; the bilateral weights are powers of two computed in registers
// (exp2_nonpositive, kernels/x86/avx2_math.h).
#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "kernels/x86/avx2_math.h"
#include "slicing/row_kernels.h"

namespace ampi::slicing::avx2 {
namespace {

inline __m256 load8(const uint8_t* p) {
  return _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
}

// 8 int32 in [0, 255] to 8 bytes.
inline void store8_bytes(__m256i q, uint8_t* out) {
  const __m256i bytes = _mm256_packus_epi16(_mm256_packus_epi32(q, q), _mm256_setzero_si256());
  const __m256i gathered = _mm256_permutevar8x32_epi32(bytes, _mm256_setr_epi32(0, 4, 0, 0, 0, 0, 0, 0));
  _mm_storel_epi64(reinterpret_cast<__m128i*>(out), _mm256_castsi256_si128(gathered));
}

// min((x - lo) * scale, 255) on 4 values in double, back to float.
inline __m128 normalize4(__m128 x, __m256d lo, __m256d scale) {
  const __m256d v = _mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(x), lo), scale);
  return _mm256_cvtpd_ps(_mm256_min_pd(v, _mm256_set1_pd(255.0)));
}

// The first `count` (1..8) bytes at p as floats; lanes past count hold 0. A short block
// goes through a copy so that nothing past the row is read.
inline __m256 load_levels(const uint8_t* p, int count) {
  if (count == 8) return load8(p);
  uint8_t copy[8] = {};
  std::memcpy(copy, p, count);
  return load8(copy);
}

inline __m256 load_floats(const float* p, int count) {
  if (count == 8) return _mm256_loadu_ps(p);
  alignas(32) float copy[8] = {};
  std::memcpy(copy, p, count * sizeof(float));
  return _mm256_load_ps(copy);
}

inline void store_floats(float* p, __m256 v, int count) {
  if (count == 8) return _mm256_storeu_ps(p, v);
  alignas(32) float copy[8];
  _mm256_store_ps(copy, v);
  std::memcpy(p, copy, count * sizeof(float));
}

inline void store_levels(uint8_t* p, __m256i q, int count) {
  if (count == 8) return store8_bytes(q, p);
  uint8_t copy[8];
  store8_bytes(q, copy);
  std::memcpy(p, copy, count);
}

}  // namespace

void range_row(const float* in, int n, ValueRange& range) {
  int x = 0;
  if (n >= 8) {
    __m256 lo = _mm256_set1_ps(range.lo), hi = _mm256_set1_ps(range.hi);
    __m256 finite = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    for (; x + 8 <= n; x += 8) {
      const __m256 v = _mm256_loadu_ps(in + x);
      // v - v is 0 for a finite v, NaN for an infinite or NaN one.
      finite = _mm256_and_ps(finite, _mm256_cmp_ps(_mm256_sub_ps(v, v), _mm256_setzero_ps(), _CMP_EQ_OQ));
      lo = _mm256_min_ps(lo, v);
      hi = _mm256_max_ps(hi, v);
    }
    alignas(32) float los[8], his[8];
    _mm256_store_ps(los, lo);
    _mm256_store_ps(his, hi);
    for (int k = 0; k < 8; ++k) {
      range.lo = los[k] < range.lo ? los[k] : range.lo;
      range.hi = his[k] > range.hi ? his[k] : range.hi;
    }
    range.finite = range.finite && _mm256_movemask_ps(finite) == 0xFF;
  }
  scalar::range_row(in + x, n - x, range);
}

void normalize_row(const float* in, int n, double lo, double scale, float* value, uint8_t* level) {
  const __m256d lo4 = _mm256_set1_pd(lo), scale4 = _mm256_set1_pd(scale);
  int x = 0;
  for (; x + 8 <= n; x += 8) {
    const __m256 x8 = _mm256_loadu_ps(in + x);
    const __m256 v = _mm256_set_m128(normalize4(_mm256_extractf128_ps(x8, 1), lo4, scale4),
                                     normalize4(_mm256_castps256_ps128(x8), lo4, scale4));
    _mm256_storeu_ps(value + x, v);
    store8_bytes(_mm256_cvtps_epi32(v), level + x);  // nearest, ties to even
  }
  scalar::normalize_row(in + x, n - x, lo, scale, value + x, level + x);
}

void bilateral_weights(const uint8_t* p, int n, const BilateralPairs& pairs, float* const* weight) {
  const __m256 coeff = _mm256_set1_ps(pairs.color_log2_coeff);
  for (int x = 0; x < n; x += 8) {
    const int count = n - x < 8 ? n - x : 8;
    const __m256 v0 = load_levels(p + x, count);
    for (int h = 0; h < pairs.count; ++h) {
      const __m256 d = _mm256_sub_ps(load_levels(p + x + pairs.offset[h], count), v0);
      const __m256 y = _mm256_fmadd_ps(_mm256_mul_ps(d, d), coeff, _mm256_set1_ps(pairs.log2_space_weight[h]));
      store_floats(weight[h] + x, ampi::avx2::exp2_nonpositive(y), count);
    }
  }
}

void bilateral_combine(const uint8_t* center, int n, const BilateralTaps& taps, uint8_t* out) {
  for (int x = 0; x < n; x += 8) {
    const int count = n - x < 8 ? n - x : 8;
    __m256 sum = _mm256_setzero_ps(), wsum = _mm256_setzero_ps();
    for (int k = 0; k < taps.count; ++k) {
      const __m256 w = load_floats(taps.weight[k] + x, count);
      sum = _mm256_fmadd_ps(w, load_levels(center + x + taps.offset[k], count), sum);
      wsum = _mm256_add_ps(wsum, w);
    }
    // Round to nearest (the default MXCSR mode); lanes past count are 0 / 0, not stored.
    store_levels(out + x, _mm256_cvtps_epi32(_mm256_div_ps(sum, wsum)), count);
  }
}

void snap_row(const SnapRowInputs& in, int n, float min_step, float margin, float* out, uint8_t* band) {
  const __m256 step = _mm256_set1_ps(min_step), m = _mm256_set1_ps(margin), neg_m = _mm256_set1_ps(-margin);
  const __m256 half = _mm256_set1_ps(0.5f);
  int x = 0;
  for (; x + 8 <= n; x += 8) {
    const __m256 lo = _mm256_loadu_ps(in.lo + x), hi = _mm256_loadu_ps(in.hi + x);
    const __m256 d = _mm256_loadu_ps(in.disparity + x);
    const __m256 spread = _mm256_sub_ps(hi, lo);
    const __m256 edge = _mm256_cmp_ps(spread, step, _CMP_GE_OQ);
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(d, _mm256_fmadd_ps(m, spread, lo), _CMP_GT_OQ),
                                        _mm256_cmp_ps(d, _mm256_fmadd_ps(neg_m, spread, hi), _CMP_LT_OQ));
    __m256 fit = _mm256_fmadd_ps(_mm256_loadu_ps(in.a0 + x), _mm256_loadu_ps(in.blue + x), _mm256_add_ps(_mm256_loadu_ps(in.b + x), d));
    fit = _mm256_fmadd_ps(_mm256_loadu_ps(in.a1 + x), _mm256_loadu_ps(in.green + x), fit);
    fit = _mm256_fmadd_ps(_mm256_loadu_ps(in.a2 + x), _mm256_loadu_ps(in.red + x), fit);
    const __m256 near = _mm256_cmp_ps(fit, _mm256_mul_ps(_mm256_add_ps(lo, hi), half), _CMP_GE_OQ);
    const __m256 side = _mm256_blendv_ps(lo, hi, near);
    _mm256_storeu_ps(out + x, _mm256_blendv_ps(d, side, _mm256_and_ps(edge, inside)));
    store8_bytes(_mm256_and_si256(_mm256_castps_si256(edge), _mm256_set1_epi32(255)), band + x);
  }
  scalar::snap_row({in.disparity + x, in.blue + x, in.green + x, in.red + x, in.a0 + x, in.a1 + x, in.a2 + x,
                    in.b + x, in.lo + x, in.hi + x},
                   n - x, min_step, margin, out + x, band + x);
}

}  // namespace ampi::slicing::avx2
