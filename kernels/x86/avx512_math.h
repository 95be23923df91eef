// Vector activation functions for AVX-512 (16 floats). Include only from *_avx512.cpp.
// Same Cephes exp as avx2_math.h.
#pragma once
#include <immintrin.h>

#include "kernels/activation.h"

namespace ampi::avx512 {

inline __m512 exp(__m512 x) {
  x = _mm512_min_ps(_mm512_max_ps(x, _mm512_set1_ps(-87.3f)), _mm512_set1_ps(88.3f));
  const __m512 n = _mm512_roundscale_ps(_mm512_mul_ps(x, _mm512_set1_ps(1.44269504088896341f)),
                                        _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  __m512 r = _mm512_fnmadd_ps(n, _mm512_set1_ps(0.693359375f), x);
  r = _mm512_fnmadd_ps(n, _mm512_set1_ps(-2.12194440e-4f), r);
  __m512 p = _mm512_set1_ps(1.9875691500e-4f);
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.3981999507e-3f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(8.3334519073e-3f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(4.1665795894e-2f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.6666665459e-1f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(5.0000001201e-1f));
  p = _mm512_fmadd_ps(p, _mm512_mul_ps(r, r), _mm512_add_ps(r, _mm512_set1_ps(1.0f)));
  return _mm512_scalef_ps(p, n);
}

// 2^y for y <= 0, as in avx2_math.h; scalef applies 2^n.
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

inline __m512 sigmoid(__m512 x) {
  const __m512 one = _mm512_set1_ps(1.0f);
  return _mm512_div_ps(one, _mm512_add_ps(one, exp(_mm512_sub_ps(_mm512_setzero_ps(), x))));
}

inline __m512 activate(__m512 x, ActivationSpec a) {
  const __m512 zero = _mm512_setzero_ps();
  switch (a.kind) {
    case Activation::None: return x;
    case Activation::ReLU: return _mm512_max_ps(x, zero);
    case Activation::ReLU6: return _mm512_min_ps(_mm512_max_ps(x, zero), _mm512_set1_ps(6.0f));
    case Activation::HardSigmoid:
    case Activation::HardSwish: {
      __m512 g = _mm512_add_ps(x, _mm512_set1_ps(3.0f));
      g = _mm512_min_ps(_mm512_max_ps(g, zero), _mm512_set1_ps(6.0f));
      g = _mm512_mul_ps(g, _mm512_set1_ps(kOneSixth));  // no divide (kOneSixth)
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
  }
  return x;
}

}  // namespace ampi::avx512
