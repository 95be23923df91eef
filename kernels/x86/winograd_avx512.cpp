// AVX-512 Winograd F(4x4, 3x3) transforms: the lane-generic kernels/winograd_lanes.inl.
#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx512_channels.h"
#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {

#include "kernels/winograd_lanes.inl"

}  // namespace ampi::avx512
