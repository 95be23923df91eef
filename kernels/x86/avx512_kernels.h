// AVX-512 micro-kernels (16 floats per vector, masked tails). Declarations only: the
// definitions are compiled with -mavx512f/bw/vl/dq in *_avx512.cpp files.
#pragma once
#include <cstdint>

#include "kernels/activation.h"

namespace ampi::avx512 {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate_inplace(float* x, int64_t n, ActivationSpec act);

}  // namespace ampi::avx512
