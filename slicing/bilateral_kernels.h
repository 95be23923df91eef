// Row kernels of the slicer's bilateral filter on 8-bit disparity levels. Pure functions
// (single-threaded, no allocation); slicing/bilateral.cpp pads the map, splits the rows
// over the thread pool and calls one kernel per row.
//
// The scalar reference is OpenCV's cv::bilateralFilter for CV_8UC1 step by step: tap
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

// The variant for an instruction set; throws std::runtime_error if this build or CPU
// cannot run it.
BilateralRowFn bilateral_row_kernel(Isa isa);

namespace scalar {
void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out);
}
#if defined(__x86_64__)
namespace avx2 {
void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out);
}
namespace avx512 {
void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out);
}
#endif
#if defined(__aarch64__)
namespace neon {
void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out);
}
#endif

}  // namespace ampi::slicing
