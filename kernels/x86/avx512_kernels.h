// AVX-512 micro-kernels (16 floats per vector, masked tails). Declarations only: the
// definitions are compiled with -mavx512f/bw/vl/dq in *_avx512.cpp files.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::avx512 {

// The families kernels/kernel_list.def claims for AVX-512 (contracts there).
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx512(return_type name parameters;)
#include "kernels/kernel_list.def"

// The gemm tile (conv_gemm_avx512.cpp: a 12x32 tile).
constexpr int kGemmMr = 12, kGemmNr = 32;

}  // namespace ampi::avx512
