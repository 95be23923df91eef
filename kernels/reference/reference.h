// The plain scalar reference of every micro-kernel: the definition each SIMD variant is
// tested against, and the fallback where no variant pays. One function per family of
// kernels/kernel_list.def (contracts there), in channels.cpp, elementwise.cpp,
// resample.cpp, conv_gemm.cpp, conv_depthwise.cpp and transformer_rows.cpp. The naive
// direct convolution and matrix product the ops are tested against are in
// conv_reference.h and gemm_reference.h.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::reference {

#define AMPI_KERNEL(name, return_type, parameters, ...) return_type name parameters;
#include "kernels/kernel_list.def"

// The gemm tile: 4x8, written plainly (the compiler may auto-vectorise it).
constexpr int kGemmMr = 4, kGemmNr = 8;

}  // namespace ampi::reference
