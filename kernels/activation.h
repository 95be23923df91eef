// Activation functions of the fused epilogues, as plain scalar definitions. These are
// the reference every SIMD variant is tested against; the formulas follow PyTorch's.
#pragma once
#include <algorithm>
#include <cmath>

namespace ampi {

enum class Activation { None, ReLU, ReLU6, HardSwish, HardSigmoid, Sigmoid, LeakyReLU, ELU, Tanh };

struct ActivationSpec {
  Activation kind = Activation::None;
  float alpha = 0.0f;  // LeakyReLU: negative slope; ELU: alpha; unused otherwise
};

const char* activation_name(Activation a);
// Parses the names above in lower case ("none", "relu", "relu6", "hardswish",
// "hardsigmoid", "sigmoid", "leakyrelu", "elu", "tanh"); throws std::invalid_argument.
Activation parse_activation(const char* name);

// The vector activations compute the gate as clamp(x * (1/6) + 1/2, 0, 1), one FMA, where
// this reference divides x + 3 by 6 (within a few ulp): a vector divide costs several FMAs'
// time, and hardswish ends every GEMM tile and depthwise block of the depth network.
constexpr float kOneSixth = 1.0f / 6.0f;

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
  }
  return x;
}

}  // namespace ampi
