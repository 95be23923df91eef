// Vector activation functions for NEON (4 floats). Include only from *_neon.cpp files.
// exp, exp2_nonpositive and gelu evaluate the polynomials of kernels/exp_polynomials.h.
#pragma once
#include <arm_neon.h>

#include "kernels/activation.h"
#include "kernels/exp_polynomials.h"

namespace ampi::neon {

// Horner's rule on coefficients listed highest degree first.
template <size_t N>
inline float32x4_t horner(const float (&c)[N], float32x4_t x) {
  float32x4_t p = vdupq_n_f32(c[0]);
#pragma GCC unroll 8
  for (size_t i = 1; i < N; ++i) p = vfmaq_f32(vdupq_n_f32(c[i]), p, x);
  return p;
}

inline float32x4_t exp(float32x4_t x) {
  using namespace exp_poly;
  x = vminq_f32(vmaxq_f32(x, vdupq_n_f32(kMin)), vdupq_n_f32(kMax));
  const float32x4_t n = vrndnq_f32(vmulq_f32(x, vdupq_n_f32(kLog2e)));
  float32x4_t r = vfmsq_f32(x, n, vdupq_n_f32(kLn2Hi));
  r = vfmsq_f32(r, n, vdupq_n_f32(kLn2Lo));
  float32x4_t p = horner(kExp, r);
  p = vfmaq_f32(vaddq_f32(r, vdupq_n_f32(1.0f)), p, vmulq_f32(r, r));
  const int32x4_t e = vshlq_n_s32(vaddq_s32(vcvtq_s32_f32(n), vdupq_n_s32(127)), 23);
  return vmulq_f32(p, vreinterpretq_f32_s32(e));
}

// 2^y for y <= 0, as in the x86 headers.
inline float32x4_t exp2_nonpositive(float32x4_t y) {
  y = vmaxq_f32(y, vdupq_n_f32(exp_poly::kExp2Min));
  const float32x4_t n = vrndnq_f32(y);
  const float32x4_t p = horner(exp_poly::kExp2, vsubq_f32(y, n));
  const int32x4_t e = vshlq_n_s32(vaddq_s32(vcvtq_s32_f32(n), vdupq_n_s32(127)), 23);
  return vmulq_f32(p, vreinterpretq_f32_s32(e));
}

inline float32x4_t sigmoid(float32x4_t x) {
  const float32x4_t one = vdupq_n_f32(1.0f);
  return vdivq_f32(one, vaddq_f32(one, exp(vnegq_f32(x))));
}

// gelu(x) = x Phi(x) by the reference's formula (kernels/activation.h): the tail
// h = exp(-x^2 / 2) Q(min(|x|, kMaxArg)), 0 past kZeroArg; Phi = 1 - h for x >= 0, else h.
inline float32x4_t gelu(float32x4_t x) {
  using namespace erfc_poly;
  const float32x4_t ax = vabsq_f32(x);
  const float32x4_t t = vsubq_f32(vminq_f32(ax, vdupq_n_f32(kMaxArg)), vdupq_n_f32(kCentre));
  const float32x4_t e = exp2_nonpositive(vmulq_f32(vdupq_n_f32(erfc_poly::kMinusHalfLog2e), vmulq_f32(x, x)));
  const uint32x4_t in_range = vcleq_f32(ax, vdupq_n_f32(kZeroArg));
  const float32x4_t h = vreinterpretq_f32_u32(vandq_u32(in_range, vreinterpretq_u32_f32(vmulq_f32(e, horner(kQ, t)))));
  const uint32x4_t nonnegative = vcgeq_f32(x, vdupq_n_f32(0.0f));
  return vmulq_f32(x, vbslq_f32(nonnegative, vsubq_f32(vdupq_n_f32(1.0f), h), h));
}

inline float32x4_t activate(float32x4_t x, ActivationSpec a) {
  const float32x4_t zero = vdupq_n_f32(0.0f);
  switch (a.kind) {
    case Activation::None: return x;
    case Activation::ReLU: return vmaxq_f32(x, zero);
    case Activation::ReLU6: return vminq_f32(vmaxq_f32(x, zero), vdupq_n_f32(6.0f));
    case Activation::HardSigmoid:
    case Activation::HardSwish: {
      // clamp(x/6 + 1/2, 0, 1): one FMA where (x + 3) / 6 takes an add and a multiply
      float32x4_t g = vfmaq_f32(vdupq_n_f32(0.5f), x, vdupq_n_f32(kOneSixth));
      g = vminq_f32(vmaxq_f32(g, zero), vdupq_n_f32(1.0f));
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
    case Activation::GELU: return gelu(x);
  }
  return x;
}

}  // namespace ampi::neon
