// Vector activation functions for AVX-512 (16 floats). Include only from *_avx512.cpp.
// exp, exp2_nonpositive and gelu evaluate the polynomials of kernels/exp_polynomials.h.
#pragma once
#include <immintrin.h>

#include "kernels/activation.h"
#include "kernels/exp_polynomials.h"

namespace ampi::avx512 {

// Horner's rule on coefficients listed highest degree first.
template <size_t N>
inline __m512 horner(const float (&c)[N], __m512 x) {
  __m512 p = _mm512_set1_ps(c[0]);
#pragma GCC unroll 8
  for (size_t i = 1; i < N; ++i) p = _mm512_fmadd_ps(p, x, _mm512_set1_ps(c[i]));
  return p;
}

// n = round(x log2e) by the float shifter 1.5 * 2^23 (adding it leaves n in the low
// mantissa bits, rounded to nearest-even) and 2^n applied by adding n to the exponent
// field, where roundscale and scalef took pipes the FMAs need: a ViT-S attention layer
// (1,370 tokens, 6 heads; its softmax is the exp) 15.8 -> 14.6 ms on 1 thread, this Zen 5.
// The shifter goes in by an explicit FMA, so no compiler contraction can change n: n
// rounds the exact product instead of its float, which against roundscale moved 9 of the
// 645 million float inputs in [-200, 200] by one ulp. x is clamped so that n is in
// [-126, 127] and 2^n e^r stays normal, where the exponent add is exact.
inline __m512 exp(__m512 x) {
  using namespace exp_poly;
  x = _mm512_min_ps(_mm512_max_ps(x, _mm512_set1_ps(kMin)), _mm512_set1_ps(kMax));
  const __m512 shifter = _mm512_set1_ps(12582912.0f);  // 1.5 * 2^23
  const __m512 shifted = _mm512_fmadd_ps(x, _mm512_set1_ps(kLog2e), shifter);
  const __m512 n = _mm512_sub_ps(shifted, shifter);
  __m512 r = _mm512_fnmadd_ps(n, _mm512_set1_ps(kLn2Hi), x);
  r = _mm512_fnmadd_ps(n, _mm512_set1_ps(kLn2Lo), r);
  __m512 p = horner(kExp, r);
  p = _mm512_fmadd_ps(p, _mm512_mul_ps(r, r), _mm512_add_ps(r, _mm512_set1_ps(1.0f)));
  // The shifter's low mantissa bits hold n (two's complement): n << 23 onto p's exponent.
  const __m512i exponent = _mm512_slli_epi32(_mm512_castps_si512(shifted), 23);
  return _mm512_castsi512_ps(_mm512_add_epi32(_mm512_castps_si512(p), exponent));
}

// 2^y for y <= 0, as in avx2_math.h, with n = round(y) by the shifter and 2^n by the
// exponent add as in exp (roundscale and scalef took 26% more time in the softmax). y is
// clamped at -126, so n >= -126 and f = y - n >= 0 where n = -126: 2^n p stays normal.
inline __m512 exp2_nonpositive(__m512 y) {
  y = _mm512_max_ps(y, _mm512_set1_ps(exp_poly::kExp2Min));
  const __m512 shifter = _mm512_set1_ps(12582912.0f);  // 1.5 * 2^23
  const __m512 shifted = _mm512_add_ps(y, shifter);
  const __m512 p = horner(exp_poly::kExp2, _mm512_sub_ps(y, _mm512_sub_ps(shifted, shifter)));
  const __m512i exponent = _mm512_slli_epi32(_mm512_castps_si512(shifted), 23);
  return _mm512_castsi512_ps(_mm512_add_epi32(_mm512_castps_si512(p), exponent));
}

inline __m512 sigmoid(__m512 x) {
  const __m512 one = _mm512_set1_ps(1.0f);
  return _mm512_div_ps(one, _mm512_add_ps(one, exp(_mm512_sub_ps(_mm512_setzero_ps(), x))));
}

// gelu(x) = x Phi(x) by the reference's formula (kernels/activation.h): the tail
// h = exp(-x^2 / 2) Q(min(|x|, kMaxArg)), 0 past kZeroArg; Phi = 1 - h for x >= 0, else h.
inline __m512 gelu(__m512 x) {
  using namespace erfc_poly;
  const __m512 ax = _mm512_abs_ps(x);
  const __m512 t = _mm512_sub_ps(_mm512_min_ps(ax, _mm512_set1_ps(kMaxArg)), _mm512_set1_ps(kCentre));
  const __m512 e = exp2_nonpositive(_mm512_mul_ps(_mm512_set1_ps(erfc_poly::kMinusHalfLog2e), _mm512_mul_ps(x, x)));
  const __mmask16 in_range = _mm512_cmp_ps_mask(ax, _mm512_set1_ps(kZeroArg), _CMP_LE_OQ);
  const __m512 h = _mm512_maskz_mul_ps(in_range, e, horner(kQ, t));
  const __mmask16 nonnegative = _mm512_cmp_ps_mask(x, _mm512_setzero_ps(), _CMP_GE_OQ);
  return _mm512_mul_ps(x, _mm512_mask_sub_ps(h, nonnegative, _mm512_set1_ps(1.0f), h));
}

inline __m512 activate(__m512 x, ActivationSpec a) {
  const __m512 zero = _mm512_setzero_ps();
  switch (a.kind) {
    case Activation::None: return x;
    case Activation::ReLU: return _mm512_max_ps(x, zero);
    case Activation::ReLU6: return _mm512_min_ps(_mm512_max_ps(x, zero), _mm512_set1_ps(6.0f));
    case Activation::HardSigmoid:
    case Activation::HardSwish: {
      // clamp(x/6 + 1/2, 0, 1): one FMA where (x + 3) / 6 takes an add and a multiply
      __m512 g = _mm512_fmadd_ps(x, _mm512_set1_ps(kOneSixth), _mm512_set1_ps(0.5f));
      g = _mm512_min_ps(_mm512_max_ps(g, zero), _mm512_set1_ps(1.0f));
      return a.kind == Activation::HardSwish ? _mm512_mul_ps(x, g) : g;
    }
    case Activation::Sigmoid: return sigmoid(x);
    case Activation::LeakyReLU: {
      const __mmask16 neg = _mm512_cmp_ps_mask(x, zero, _CMP_LT_OQ);
      return _mm512_mask_mul_ps(x, neg, x, _mm512_set1_ps(a.alpha));
    }
    case Activation::ELU: {
      const __mmask16 neg = _mm512_cmp_ps_mask(x, zero, _CMP_LT_OQ);
      const __m512 e = _mm512_mul_ps(_mm512_set1_ps(a.alpha), _mm512_sub_ps(exp(x), _mm512_set1_ps(1.0f)));
      return _mm512_mask_blend_ps(neg, x, e);
    }
    case Activation::Tanh: {
      const __m512 s = sigmoid(_mm512_add_ps(x, x));
      return _mm512_sub_ps(_mm512_add_ps(s, s), _mm512_set1_ps(1.0f));
    }
    case Activation::GELU: return gelu(x);
  }
  return x;
}

}  // namespace ampi::avx512
