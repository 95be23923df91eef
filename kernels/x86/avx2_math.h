// Vector activation functions for AVX2 (8 floats). Include only from *_avx2.cpp files.
// exp, exp2_nonpositive and gelu evaluate the polynomials of kernels/exp_polynomials.h.
#pragma once
#include <immintrin.h>

#include "kernels/activation.h"
#include "kernels/exp_polynomials.h"

namespace ampi::avx2 {

// Horner's rule on coefficients listed highest degree first.
template <size_t N>
inline __m256 horner(const float (&c)[N], __m256 x) {
  __m256 p = _mm256_set1_ps(c[0]);
#pragma GCC unroll 8
  for (size_t i = 1; i < N; ++i) p = _mm256_fmadd_ps(p, x, _mm256_set1_ps(c[i]));
  return p;
}

inline __m256 exp(__m256 x) {
  using namespace exp_poly;
  x = _mm256_min_ps(_mm256_max_ps(x, _mm256_set1_ps(kMin)), _mm256_set1_ps(kMax));
  // n and 2^n as in avx512_math.h's exp: the float shifter, then n onto the exponent.
  const __m256 shifter = _mm256_set1_ps(12582912.0f);  // 1.5 * 2^23
  const __m256 shifted = _mm256_fmadd_ps(x, _mm256_set1_ps(kLog2e), shifter);
  const __m256 n = _mm256_sub_ps(shifted, shifter);
  __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(kLn2Hi), x);
  r = _mm256_fnmadd_ps(n, _mm256_set1_ps(kLn2Lo), r);
  __m256 p = horner(kExp, r);
  p = _mm256_fmadd_ps(p, _mm256_mul_ps(r, r), _mm256_add_ps(r, _mm256_set1_ps(1.0f)));
  const __m256i exponent = _mm256_slli_epi32(_mm256_castps_si256(shifted), 23);
  return _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(p), exponent));
}

// 2^y for y <= 0 (below -126 it returns 2^-126). Cheaper than exp (no clamp from above,
// no two-part range reduction): the slicer's bilateral weights, where it is the inner
// loop, use it.
// n = round(y) by the shifter and 2^n by the exponent add, as in exp: y >= -126 keeps
// 2^n p normal.
inline __m256 exp2_nonpositive(__m256 y) {
  y = _mm256_max_ps(y, _mm256_set1_ps(exp_poly::kExp2Min));
  const __m256 shifter = _mm256_set1_ps(12582912.0f);  // 1.5 * 2^23
  const __m256 shifted = _mm256_add_ps(y, shifter);
  const __m256 p = horner(exp_poly::kExp2, _mm256_sub_ps(y, _mm256_sub_ps(shifted, shifter)));
  const __m256i exponent = _mm256_slli_epi32(_mm256_castps_si256(shifted), 23);
  return _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(p), exponent));
}

inline __m256 sigmoid(__m256 x) {
  const __m256 one = _mm256_set1_ps(1.0f);
  return _mm256_div_ps(one, _mm256_add_ps(one, exp(_mm256_sub_ps(_mm256_setzero_ps(), x))));
}

// gelu(x) = x Phi(x) by the reference's formula (kernels/activation.h): the tail
// h = exp(-x^2 / 2) Q(min(|x|, kMaxArg)), 0 past kZeroArg; Phi = 1 - h for x >= 0, else h.
inline __m256 gelu(__m256 x) {
  using namespace erfc_poly;
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 ax = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), x);
  const __m256 t = _mm256_sub_ps(_mm256_min_ps(ax, _mm256_set1_ps(kMaxArg)), _mm256_set1_ps(kCentre));
  const __m256 e = exp2_nonpositive(_mm256_mul_ps(_mm256_set1_ps(erfc_poly::kMinusHalfLog2e), _mm256_mul_ps(x, x)));
  __m256 h = _mm256_mul_ps(e, horner(kQ, t));
  h = _mm256_andnot_ps(_mm256_cmp_ps(ax, _mm256_set1_ps(kZeroArg), _CMP_GT_OQ), h);
  const __m256 nonnegative = _mm256_cmp_ps(x, _mm256_setzero_ps(), _CMP_GE_OQ);
  return _mm256_mul_ps(x, _mm256_blendv_ps(h, _mm256_sub_ps(one, h), nonnegative));
}

inline __m256 activate(__m256 x, ActivationSpec a) {
  const __m256 zero = _mm256_setzero_ps();
  switch (a.kind) {
    case Activation::None: return x;
    case Activation::ReLU: return _mm256_max_ps(x, zero);
    case Activation::ReLU6: return _mm256_min_ps(_mm256_max_ps(x, zero), _mm256_set1_ps(6.0f));
    case Activation::HardSigmoid:
    case Activation::HardSwish: {
      // clamp(x/6 + 1/2, 0, 1): one FMA where (x + 3) / 6 takes an add and a multiply
      __m256 g = _mm256_fmadd_ps(x, _mm256_set1_ps(kOneSixth), _mm256_set1_ps(0.5f));
      g = _mm256_min_ps(_mm256_max_ps(g, zero), _mm256_set1_ps(1.0f));
      return a.kind == Activation::HardSwish ? _mm256_mul_ps(x, g) : g;
    }
    case Activation::Sigmoid: return sigmoid(x);
    case Activation::LeakyReLU: {
      const __m256 neg = _mm256_mul_ps(x, _mm256_set1_ps(a.alpha));
      return _mm256_blendv_ps(x, neg, _mm256_cmp_ps(x, zero, _CMP_LT_OQ));
    }
    case Activation::ELU: {
      const __m256 neg = _mm256_mul_ps(_mm256_set1_ps(a.alpha),
                                       _mm256_sub_ps(exp(x), _mm256_set1_ps(1.0f)));
      return _mm256_blendv_ps(x, neg, _mm256_cmp_ps(x, zero, _CMP_LT_OQ));
    }
    case Activation::Tanh: {  // tanh(x) = 2 sigmoid(2x) - 1
      const __m256 s = sigmoid(_mm256_add_ps(x, x));
      return _mm256_sub_ps(_mm256_add_ps(s, s), _mm256_set1_ps(1.0f));
    }
    case Activation::GELU: return gelu(x);
  }
  return x;
}

}  // namespace ampi::avx2
