// NEON 2x resampling kernels: Haar DWT and inverse, nearest and bilinear upscaling.
// Bandwidth-bound; the vectors pay by moving 4 channels per load and store. The bodies
// are lane-generic (kernels/resample_lanes.inl over neon_channels.h): leftover channels
// run as scalar code.
#include <algorithm>

#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"

namespace ampi::neon {

#include "kernels/resample_lanes.inl"

}  // namespace ampi::neon
