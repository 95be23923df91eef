// AVX-512 depthwise row: channels across the 16 lanes, the channels left over (c % 16) in
// one masked vector (AVX-512 masks cost nothing extra, avx512_channels.h). The kernel is
// written once for every ISA: kernels/depthwise_lanes.inl explains its shape.
#include <algorithm>

// GCC 12 warns that the _mm512_undefined_ps() inside _mm512_max_ps is used uninitialized
// once the row loops inline it (GCC bug 105593, a false positive). The
// warning is raised where the templates are instantiated, so it is off for the file.
#pragma GCC diagnostic ignored "-Wuninitialized"

#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx512_channels.h"
#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {

#include "kernels/depthwise_lanes.inl"

}  // namespace ampi::avx512
