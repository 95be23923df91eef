// Activation functions of the fused epilogues, as plain scalar definitions. These are
// the reference every SIMD variant is tested against; the formulas follow PyTorch's.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "kernels/exp_polynomials.h"

namespace ampi {

// GELU is the exact (erf) form, torch.nn.GELU()'s default: 0.5 x (1 + erf(x / sqrt 2)).
enum class Activation { None, ReLU, ReLU6, HardSwish, HardSigmoid, Sigmoid, LeakyReLU, ELU, Tanh, GELU };

struct ActivationSpec {
  Activation kind = Activation::None;
  float alpha = 0.0f;  // LeakyReLU: negative slope; ELU: alpha; unused otherwise
};

const char* activation_name(Activation a);
// Parses the names above in lower case ("none", "relu", "relu6", "hardswish",
// "hardsigmoid", "sigmoid", "leakyrelu", "elu", "tanh", "gelu"); throws std::invalid_argument.
Activation parse_activation(const char* name);

// The vector activations compute the gate as clamp(x * (1/6) + 1/2, 0, 1), one FMA, where
// this reference divides x + 3 by 6 (within a few ulp): a vector divide costs several FMAs'
// time, and hardswish ends every GEMM tile and depthwise block of the depth network.
constexpr float kOneSixth = 1.0f / 6.0f;

// 2^y for y <= 0 (below kExp2Min it returns 2^kExp2Min) by the vector exp2_nonpositive's
// own steps (exp_polynomials.h): the references of GELU and the softmax must evaluate the
// formula the vector code does, so they agree within a few ulp. The rounding and the 2^n
// are done in float bits, as the vector code does them, rather than through
// std::nearbyint and std::ldexp, library calls on the baseline x86-64 target.
inline float exp2_polynomial_nonpositive(float y) {
  using namespace exp_poly;
  y = std::max(y, kExp2Min);
  // Adding and subtracting 1.5 * 2^23 rounds to the nearest integer (ties to even) for
  // |v| < 2^22; here |y| <= 126.
  constexpr float kRoundingShift = 12582912.0f;
  const float n = (y + kRoundingShift) - kRoundingShift;
  const float f = y - n;
  float p = kExp2[0];
  for (size_t i = 1; i < sizeof(kExp2) / sizeof(kExp2[0]); ++i) p = p * f + kExp2[i];
  const uint32_t bits = static_cast<uint32_t>(static_cast<int32_t>(n) + 127) << 23;
  float two_to_n;
  std::memcpy(&two_to_n, &bits, sizeof two_to_n);
  return p * two_to_n;
}

// gelu(x) = x Phi(x), Phi the standard normal CDF. Both signs go through the tail
// h = Phi(-|x|) = erfc(|x| / sqrt 2) / 2, which keeps its relative accuracy where it is
// tiny: Phi(x) = 1 - h for x >= 0, h for x < 0. h = exp(-x^2 / 2) Q(min(|x|, kMaxArg)),
// Q the polynomial of exp_polynomials.h; h = 0 past kZeroArg.
inline float gelu(float x) {
  const float t = std::min(std::fabs(x), erfc_poly::kMaxArg) - erfc_poly::kCentre;
  float q = erfc_poly::kQ[0];
  for (size_t i = 1; i < sizeof(erfc_poly::kQ) / sizeof(erfc_poly::kQ[0]); ++i) q = q * t + erfc_poly::kQ[i];
  const float h = std::fabs(x) > erfc_poly::kZeroArg
                      ? 0.0f
                      : exp2_polynomial_nonpositive(erfc_poly::kMinusHalfLog2e * (x * x)) * q;
  return x * (x >= 0.0f ? 1.0f - h : h);
}

inline float activate(float x, ActivationSpec a) {
  switch (a.kind) {
    case Activation::None: return x;
    case Activation::ReLU: return std::max(x, 0.0f);
    case Activation::ReLU6: return std::min(std::max(x, 0.0f), 6.0f);
    case Activation::HardSwish: return x * std::min(std::max(x + 3.0f, 0.0f), 6.0f) / 6.0f;
    case Activation::HardSigmoid: return std::min(std::max(x + 3.0f, 0.0f), 6.0f) / 6.0f;
    case Activation::Sigmoid: return 1.0f / (1.0f + std::exp(-x));
    case Activation::LeakyReLU: return x >= 0.0f ? x : a.alpha * x;
    case Activation::ELU: return x >= 0.0f ? x : a.alpha * (std::exp(x) - 1.0f);
    case Activation::Tanh: return std::tanh(x);
    case Activation::GELU: return gelu(x);
  }
  return x;
}

}  // namespace ampi
