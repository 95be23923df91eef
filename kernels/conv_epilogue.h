// Batch activation for the convolution micro-kernels' epilogues. A tile of accumulators
// is activated with one dispatch on the activation kind; inside each case the kind is a
// constant, so the ISA's activate() (kernels/x86/avx2_math.h etc.) inlines without its
// switch into a straight loop over the tile.
#pragma once
#include "kernels/activation.h"

namespace ampi {

template <Activation kKind, typename Vec, int N, typename Activate>
inline void activate_tile_as(Vec (&v)[N], float alpha, Activate activate) {
  const ActivationSpec spec{kKind, alpha};
  for (int i = 0; i < N; ++i) v[i] = activate(v[i], spec);
}

// v[i] = activate(v[i], act) for every i; activate is the ISA's vector activation.
template <typename Vec, int N, typename Activate>
inline void activate_tile(Vec (&v)[N], ActivationSpec act, Activate activate) {
  switch (act.kind) {
    case Activation::None: return;
    case Activation::ReLU: return activate_tile_as<Activation::ReLU>(v, act.alpha, activate);
    case Activation::ReLU6: return activate_tile_as<Activation::ReLU6>(v, act.alpha, activate);
    case Activation::HardSwish: return activate_tile_as<Activation::HardSwish>(v, act.alpha, activate);
    case Activation::HardSigmoid: return activate_tile_as<Activation::HardSigmoid>(v, act.alpha, activate);
    case Activation::Sigmoid: return activate_tile_as<Activation::Sigmoid>(v, act.alpha, activate);
    case Activation::LeakyReLU: return activate_tile_as<Activation::LeakyReLU>(v, act.alpha, activate);
    case Activation::ELU: return activate_tile_as<Activation::ELU>(v, act.alpha, activate);
    case Activation::Tanh: return activate_tile_as<Activation::Tanh>(v, act.alpha, activate);
    case Activation::GELU: return activate_tile_as<Activation::GELU>(v, act.alpha, activate);
  }
}

}  // namespace ampi
