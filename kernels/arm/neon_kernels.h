// NEON micro-kernels (4 floats per vector), AArch64 only.
#pragma once
#include <cstdint>

#include "kernels/activation.h"

namespace ampi::neon {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate_inplace(float* x, int64_t n, ActivationSpec act);

}  // namespace ampi::neon
