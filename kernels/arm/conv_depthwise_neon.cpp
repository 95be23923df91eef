// NEON depthwise row: channels across the 4 lanes, the channels left over (c % 4) as
// scalar lanes (NEON has no masked loads, neon_channels.h). The kernel is written once for
// every ISA: kernels/depthwise_lanes.inl explains its shape.
#include <algorithm>

#include "kernels/conv_epilogue.h"
#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"

namespace ampi::neon {

#include "kernels/depthwise_lanes.inl"

}  // namespace ampi::neon
