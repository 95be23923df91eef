// Vector activation functions for NEON (4 floats). Include only from *_neon.cpp files.
// Same Cephes exp as the x86 variants.
#pragma once
#include <arm_neon.h>

#include "kernels/activation.h"

namespace ampi::neon {

inline float32x4_t exp(float32x4_t x) {
  x = vminq_f32(vmaxq_f32(x, vdupq_n_f32(-87.3f)), vdupq_n_f32(88.3f));
  const float32x4_t n = vrndnq_f32(vmulq_f32(x, vdupq_n_f32(1.44269504088896341f)));
  float32x4_t r = vfmsq_f32(x, n, vdupq_n_f32(0.693359375f));
  r = vfmsq_f32(r, n, vdupq_n_f32(-2.12194440e-4f));
  float32x4_t p = vdupq_n_f32(1.9875691500e-4f);
  p = vfmaq_f32(vdupq_n_f32(1.3981999507e-3f), p, r);
  p = vfmaq_f32(vdupq_n_f32(8.3334519073e-3f), p, r);
  p = vfmaq_f32(vdupq_n_f32(4.1665795894e-2f), p, r);
  p = vfmaq_f32(vdupq_n_f32(1.6666665459e-1f), p, r);
  p = vfmaq_f32(vdupq_n_f32(5.0000001201e-1f), p, r);
  p = vfmaq_f32(vaddq_f32(r, vdupq_n_f32(1.0f)), p, vmulq_f32(r, r));
  const int32x4_t e = vshlq_n_s32(vaddq_s32(vcvtq_s32_f32(n), vdupq_n_s32(127)), 23);
  return vmulq_f32(p, vreinterpretq_f32_s32(e));
}

// 2^y for y <= 0, as in the x86 headers.
inline float32x4_t exp2_nonpositive(float32x4_t y) {
  y = vmaxq_f32(y, vdupq_n_f32(-126.0f));
  const float32x4_t n = vrndnq_f32(y);
  const float32x4_t f = vsubq_f32(y, n);
  float32x4_t p = vdupq_n_f32(1.540353039e-4f);
  p = vfmaq_f32(vdupq_n_f32(1.333355815e-3f), p, f);
  p = vfmaq_f32(vdupq_n_f32(9.618129108e-3f), p, f);
  p = vfmaq_f32(vdupq_n_f32(5.550410866e-2f), p, f);
  p = vfmaq_f32(vdupq_n_f32(2.402265070e-1f), p, f);
  p = vfmaq_f32(vdupq_n_f32(6.931471806e-1f), p, f);
  p = vfmaq_f32(vdupq_n_f32(1.0f), p, f);
  const int32x4_t e = vshlq_n_s32(vaddq_s32(vcvtq_s32_f32(n), vdupq_n_s32(127)), 23);
  return vmulq_f32(p, vreinterpretq_f32_s32(e));
}

inline float32x4_t sigmoid(float32x4_t x) {
  const float32x4_t one = vdupq_n_f32(1.0f);
  return vdivq_f32(one, vaddq_f32(one, exp(vnegq_f32(x))));
}

inline float32x4_t activate(float32x4_t x, ActivationSpec a) {
  const float32x4_t zero = vdupq_n_f32(0.0f);
  switch (a.kind) {
    case Activation::None: return x;
    case Activation::ReLU: return vmaxq_f32(x, zero);
    case Activation::ReLU6: return vminq_f32(vmaxq_f32(x, zero), vdupq_n_f32(6.0f));
    case Activation::HardSigmoid:
    case Activation::HardSwish: {
      float32x4_t g = vaddq_f32(x, vdupq_n_f32(3.0f));
      g = vmulq_f32(vminq_f32(vmaxq_f32(g, zero), vdupq_n_f32(6.0f)), vdupq_n_f32(kOneSixth));  // no divide (kOneSixth)
      return a.kind == Activation::HardSwish ? vmulq_f32(x, g) : g;
    }
    case Activation::Sigmoid: return sigmoid(x);
    case Activation::LeakyReLU:
      return vbslq_f32(vcltq_f32(x, zero), vmulq_n_f32(x, a.alpha), x);
    case Activation::ELU:
      return vbslq_f32(vcltq_f32(x, zero),
                       vmulq_n_f32(vsubq_f32(exp(x), vdupq_n_f32(1.0f)), a.alpha), x);
    case Activation::Tanh: {
      const float32x4_t s = sigmoid(vaddq_f32(x, x));
      return vsubq_f32(vaddq_f32(s, s), vdupq_n_f32(1.0f));
    }
  }
  return x;
}

}  // namespace ampi::neon
