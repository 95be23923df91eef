// AVX2 depthwise row: channels across the 8 lanes (NHWC keeps them contiguous), the
// channels left over (c % 8) as scalar lanes, since masked AVX2 stores are microcoded on
// AMD Zen (avx2_channels.h). The kernel is written once for every ISA:
// kernels/depthwise_lanes.inl explains its shape.
#include <algorithm>

#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx2_channels.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {

#include "kernels/depthwise_lanes.inl"

}  // namespace ampi::avx2
