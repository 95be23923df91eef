// AVX2 + FMA micro-kernels (8 floats per vector). Declarations only: the definitions
// are compiled with -mavx2 -mfma in *_avx2.cpp files.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::avx2 {

// The families kernels/kernel_list.def claims for AVX2 (contracts there).
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx2(return_type name parameters;)
#include "kernels/kernel_list.def"

// The gemm tile (conv_gemm_avx2.cpp: a 6x16 tile).
constexpr int kGemmMr = 6, kGemmNr = 16;

}  // namespace ampi::avx2
