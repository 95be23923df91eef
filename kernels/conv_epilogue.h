// Batch activation for the convolution micro-kernels' epilogues. A tile of accumulators
// is activated with one dispatch on the activation kind; inside each case the kind is a
// constant, so the ISA's activate() (kernels/x86/avx2_math.h etc.) inlines without its
// switch into a straight loop over the tile.
#pragma once
#include <type_traits>

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

// An epilogue's activation kind as a template argument: one of a FixedActivations set, or
// kActivationAtRunTime (read from the arguments, by activate_tile).
constexpr int kActivationAtRunTime = -1;

// A set of activation kinds that a kernel compiles an epilogue of its own for.
template <Activation... kKinds>
struct FixedActivations {};
// The kinds the networks' GEMMs and Winograd convolutions use. A GEMM tile compiled for
// one kind keeps its accumulators in registers through the epilogue; with the dispatch
// per row (activate_tile) GCC spilled them (AVX-512, 1x1 16->64 hard-swish at 512x384:
// 4.4-4.7 -> 2.4-2.8 ms on 1 thread). Winograd's output transform gains about 4% (3x3
// 64->64 at 148x148).
inline constexpr FixedActivations<Activation::None, Activation::ReLU, Activation::HardSwish, Activation::GELU>
    kGemmActivations{};
// The kinds the depthwise convolutions of the networks use (MobileNet blocks).
inline constexpr FixedActivations<Activation::None, Activation::ReLU, Activation::ReLU6, Activation::HardSwish>
    kDepthwiseActivations{};

// f(std::integral_constant<int, kind>): the kind fixed at compile time when it is one of
// the set, kActivationAtRunTime for the others.
template <Activation... kKinds, class F>
void with_fixed_activation(FixedActivations<kKinds...>, Activation kind, F&& f) {
  const bool fixed = ((kind == kKinds && (f(std::integral_constant<int, static_cast<int>(kKinds)>{}), true)) || ...);
  if (!fixed) f(std::integral_constant<int, kActivationAtRunTime>{});
}

// activate(v, act) with the kind fixed at compile time unless kKind is kActivationAtRunTime.
template <int kKind, typename Vec, typename Activate>
inline Vec activate_of(Vec v, ActivationSpec act, Activate activate) {
  if constexpr (kKind == kActivationAtRunTime)
    return activate(v, act);
  else
    return activate(v, ActivationSpec{static_cast<Activation>(kKind), act.alpha});
}

// activate_tile with the kind fixed at compile time unless kKind is kActivationAtRunTime.
template <int kKind, typename Vec, int N, typename Activate>
inline void activate_tile_of(Vec (&v)[N], ActivationSpec act, Activate activate) {
  if constexpr (kKind == kActivationAtRunTime)
    activate_tile(v, act, activate);
  else
    activate_tile_as<static_cast<Activation>(kKind)>(v, act.alpha, activate);
}

}  // namespace ampi
