// NEON micro-kernels (4 floats per vector), AArch64 only.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::neon {

// The families kernels/kernel_list.def claims for NEON (contracts there).
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_neon(return_type name parameters;)
#include "kernels/kernel_list.def"

// The gemm tile (conv_gemm_neon.cpp: an 8x8 tile).
constexpr int kGemmMr = 8, kGemmNr = 8;

}  // namespace ampi::neon
