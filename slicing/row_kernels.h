// Row kernels of the slicer: the normalisation of a disparity map to levels and the
// bilateral filter on those levels. Pure functions (single-threaded, no allocation);
// slicing/level_stats.cpp and slicing/bilateral.cpp walk the rows and call one per row.
//
// normalize_row is the same computation in every variant (double precision, a
// subtraction then a product, no fused operations), so all variants agree bit for bit.
//
// The bilateral scalar reference is OpenCV's cv::bilateralFilter for CV_8UC1 step by step: tap
// weight = space table * colour table, sums taken tap by tap in float, the ratio rounded
// to nearest (the tests check it against OpenCV pixel for pixel). The vector variants
// compute each weight as one power of two, 2^(log2 space weight + coeff * d^2), instead of
// two table lookups: a gather per tap costs more than the polynomial on the CPUs we
// measured. Weights then differ from the tables by a few 1e-7 relative, so an output may
// differ by one level where the ratio lies within that of a half-integer.
#pragma once
#include <cstdint>

#include "engine/isa.h"

namespace ampi::slicing {

// The filter's taps, in OpenCV's order (rows top to bottom, columns left to right, only
// those within the disk of radius diameter / 2).
struct BilateralTaps {
  int count = 0;
  const int64_t* offset = nullptr;          // from the centre pixel, in bytes of the padded map
  const float* space_weight = nullptr;      // exp(-r^2 / (2 sigma_space^2))
  const float* log2_space_weight = nullptr;  // log2 of the same (the vector variants)
  const float* color_weight = nullptr;      // [256]: exp(-d^2 / (2 sigma_color^2))
  float color_log2_coeff = 0;               // -log2(e) / (2 sigma_color^2)
};

// out[x] for x in [0, width): the filtered value of the pixel at center[x], whose
// neighbours center[x + offset[k]] all lie inside the padded map.
using BilateralRowFn = void (*)(const uint8_t* center, int width, const BilateralTaps& taps,
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

struct SlicingKernels {
  Isa isa = Isa::Scalar;
  RangeRowFn range_row = nullptr;
  NormalizeRowFn normalize_row = nullptr;
  BilateralRowFn bilateral_row = nullptr;
};

// The variant for an instruction set; throws std::runtime_error if this build or CPU
// cannot run it.
SlicingKernels slicing_kernels(Isa isa);

#define AMPI_SLICING_ROW_KERNELS                                                              \
  void range_row(const float* in, int n, ValueRange& range);                                  \
  void normalize_row(const float* in, int n, double lo, double scale, float* value,           \
                     uint8_t* level);                                                         \
  void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out);

namespace scalar {
AMPI_SLICING_ROW_KERNELS
}
#if defined(__x86_64__)
namespace avx2 {
AMPI_SLICING_ROW_KERNELS
}
namespace avx512 {
AMPI_SLICING_ROW_KERNELS
}
#endif
#if defined(__aarch64__)
namespace neon {
AMPI_SLICING_ROW_KERNELS
}
#endif
#undef AMPI_SLICING_ROW_KERNELS

}  // namespace ampi::slicing
