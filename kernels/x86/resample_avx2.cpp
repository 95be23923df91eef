// AVX2 2x resampling kernels: Haar DWT and inverse, nearest and bilinear upscaling.
// Bandwidth-bound; the vectors pay by moving 8 channels per load and store. The bodies
// are lane-generic (kernels/resample_lanes.inl over avx2_channels.h): leftover channels
// run as scalar code.
#include <algorithm>

#include "kernels/x86/avx2_channels.h"
#include "kernels/x86/avx2_kernels.h"

namespace ampi::avx2 {

#include "kernels/resample_lanes.inl"

}  // namespace ampi::avx2
