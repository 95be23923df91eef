// AVX2 + FMA micro-kernels (8 floats per vector). Declarations only: the definitions
// are compiled with -mavx2 -mfma in *_avx2.cpp files.
#pragma once
#include <cstdint>

#include "kernels/activation.h"

namespace ampi::avx2 {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate_inplace(float* x, int64_t n, ActivationSpec act);

}  // namespace ampi::avx2
