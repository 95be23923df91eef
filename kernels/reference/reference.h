// The plain scalar reference of every micro-kernel: the definition each SIMD variant is
// tested against, and the fallback where no variant pays.
#pragma once
#include <cstdint>

#include "kernels/activation.h"

namespace ampi::reference {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate(float* x, int64_t n, ActivationSpec act);

}  // namespace ampi::reference
