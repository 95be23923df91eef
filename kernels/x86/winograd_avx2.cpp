// AVX2 Winograd F(4x4, 3x3) transforms: the lane-generic kernels/winograd_lanes.inl.
#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx2_channels.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {

#include "kernels/winograd_lanes.inl"

}  // namespace ampi::avx2
