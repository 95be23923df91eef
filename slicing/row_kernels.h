// Row kernels of the slicer: the normalisation of a disparity map to levels, the
// bilateral filter on those levels, and the snapping of depth edges to the photo's
// colour edges. Pure functions (single-threaded, no allocation); slicing/level_stats.cpp,
// slicing/bilateral.cpp and slicing/depth_edges.cpp walk the rows and call one per row.
//
// normalize_row is the same computation in every variant (double precision, a
// subtraction then a product, no fused operations), so all variants agree bit for bit.
//
// The bilateral filter weighs each pair of opposite taps once: the weight of tap o at
// pixel p equals the weight of tap -o at p + o (same distance, same difference of levels).
// bilateral_weights computes a row of pair weights, bilateral_combine the filtered row
// from the weights of every tap. The scalar reference builds each weight as OpenCV's
// cv::bilateralFilter for CV_8UC1 does (space table * colour table) and sums the taps in
// its order in float, so the filter equals OpenCV's pixel for pixel (tested). The vector
// variants compute each weight as one power of two, 2^(log2 space weight + coeff * d^2),
// instead of two table lookups: a gather costs more than the polynomial on the CPUs we
// measured. Their weights differ from the tables by a few 1e-7 relative, so an output
// may differ by one level where the ratio lies within that of a half-integer.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/isa.h"
#include "kernels/kernel_lists.h"

namespace ampi::slicing {

// The pairs of opposite taps, one tap o of each (the one after the centre in OpenCV's
// order: rows top to bottom, columns left to right, within the disk of radius
// diameter / 2).
struct BilateralPairs {
  int count = 0;
  const int64_t* offset = nullptr;           // o, in bytes of the padded map
  const float* space_weight = nullptr;       // exp(-|o|^2 / (2 sigma_space^2))
  const float* log2_space_weight = nullptr;  // log2 of the same (the vector variants)
  const float* color_weight = nullptr;       // [256]: exp(-d^2 / (2 sigma_color^2))
  float color_log2_coeff = 0;                // -log2(e) / (2 sigma_color^2)
};

// weight[h][x] for x in [0, n): the weight of pair h between the pixels at p[x] and
// p[x] + offset[h], both inside the padded map.
using BilateralWeightsFn = void (*)(const uint8_t* p, int n, const BilateralPairs& pairs,
                                    float* const* weight);

// Every tap of one output row: the tap's offset, and its weights, weight[k][x] for
// output pixel x (the centre tap's are all 1).
struct BilateralTaps {
  int count = 0;
  const int64_t* offset = nullptr;  // from the centre pixel, in bytes of the padded map
  const float* const* weight = nullptr;
};

// out[x] for x in [0, n): sum_k weight[k][x] * center[x + offset[k]] / sum_k weight[k][x],
// summed in tap order in float, rounded to nearest (ties to even).
using BilateralCombineFn = void (*)(const uint8_t* center, int n, const BilateralTaps& taps,
                                    uint8_t* out);

// The range of a map, gathered row by row: lo and hi fold in the row's values; finite is
// cleared if one of them is NaN or infinite (lo and hi then mean nothing).
struct ValueRange {
  float lo, hi;
  bool finite;
};
using RangeRowFn = void (*)(const float* in, int n, ValueRange& range);

// For x in [0, n): value[x] = min((in[x] - lo) * scale, 255) computed in double and
// rounded to float; level[x] = value[x] rounded to the nearest integer, ties to even (as
// cv::Mat::convertTo rounds). in[x] >= lo and finite.
using NormalizeRowFn = void (*)(const float* in, int n, double lo, double scale, float* value,
                                uint8_t* level);

// One row of depth-edge snapping (slicing/depth_edges.h), every input a row of n floats
// at the photo's resolution: the disparity d, the photo's blue, green and red (0..255),
// the colour-guided fit's coefficients (a0 B + a1 G + a2 R + b: how far the pixel's
// colour puts its disparity from its window's mean) and the local extremes of the
// disparity (lo, hi). For x in [0, n):
//   band[x] = hi - lo >= min_step ? 255 : 0   (a depth edge is near)
//   a pixel of the band strictly inside the ramp, lo + margin (hi - lo) < d < hi -
//   margin (hi - lo), takes the side d and its colour point to: with
//   g = d + a0 B + a1 G + a2 R + b, out = g >= (lo + hi) / 2 ? hi : lo;
//   every other pixel keeps its disparity: out = d.
// g is fma(a2, R, fma(a1, G, fma(a0, B, b + d))) in float in every variant, so all agree
// bit for bit.
struct SnapRowInputs {
  const float* disparity;
  const float* blue;
  const float* green;
  const float* red;
  const float* a0;
  const float* a1;
  const float* a2;
  const float* b;
  const float* lo;
  const float* hi;
};
using SnapRowFn = void (*)(const SnapRowInputs& in, int n, float min_step, float margin, float* out,
                           uint8_t* band);

// Which instruction set's code each entry runs (slicing/row_kernel_list.def).
struct SlicingProviders {
#define AMPI_KERNEL(name, ...) Isa name = Isa::Scalar;
#include "slicing/row_kernel_list.def"
};

// One entry per kernel of slicing/row_kernel_list.def.
struct SlicingKernels {
  Isa isa = Isa::Scalar;
#define AMPI_KERNEL(name, return_type, parameters, ...) return_type(*name) parameters = nullptr;
#include "slicing/row_kernel_list.def"
  SlicingProviders provided_by;
};

// The variant for an instruction set; throws std::runtime_error if this build or CPU
// cannot run it.
SlicingKernels slicing_kernels(Isa isa);

// Every kernel of slicing/row_kernel_list.def, and what `table` runs for each, in the
// list's order.
const std::vector<KernelFamily>& slicing_kernel_families();
std::vector<KernelEntry> slicing_kernel_entries(const SlicingKernels& table);

// The scalar reference and each ISA's variants of the kernels the list claims for it.
namespace scalar {
#define AMPI_KERNEL(name, return_type, parameters, ...) return_type name parameters;
#include "slicing/row_kernel_list.def"
}  // namespace scalar
#if defined(AMPI_ARCH_X86)
namespace avx2 {
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx2(return_type name parameters;)
#include "slicing/row_kernel_list.def"
}  // namespace avx2
namespace avx512 {
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx512(return_type name parameters;)
#include "slicing/row_kernel_list.def"
}  // namespace avx512
#endif
#if defined(AMPI_ARCH_ARM64)
namespace neon {
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_neon(return_type name parameters;)
#include "slicing/row_kernel_list.def"
}  // namespace neon
#endif

}  // namespace ampi::slicing
