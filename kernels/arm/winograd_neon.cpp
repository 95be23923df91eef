// NEON Winograd F(4x4, 3x3) transforms: the lane-generic kernels/winograd_lanes.inl.
#include "kernels/conv_epilogue.h"
#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"

namespace ampi::neon {

#include "kernels/winograd_lanes.inl"

}  // namespace ampi::neon
