// Micro-kernels of the MPI compositor: warp one premultiplied layer along a row of the
// new view and composite it over the row's accumulator; convert an accumulator row to
// 8-bit BGR. Pure functions (single-threaded, no allocation); the renderer splits the
// frame into tiles and calls them per tile row. Each instruction set has its own
// variant beside the scalar reference; all compute the same formulas in the same order,
// so they differ only by rounding (FMA contraction).
#pragma once
#include <cstdint>

#include "engine/isa.h"

namespace ampi::render {

// A premultiplied layer as the kernels read it: BGRA half floats in [0, 1]. Only a block
// of it is stored, the rest being transparent (zero): the whole layer, or the box around
// its visible pixels, which at 4K is about half of the frame. The block has a zero border
// of two pixels on the right and bottom, and of one on the left and top (two when the
// block starts inside the layer). Coordinates are clamped to [-1, width] x [-1, height]
// as for the whole layer, then the footprint's stored column and row to [-2, stored
// width] and [-2, stored height]: a footprint outside the block reads only its border,
// transparent as the layer is there, so a frame is the same bit for bit whatever block is
// stored (no edge branches).
struct PlaneView {
  const uint16_t* origin = nullptr;  // the block's pixel (0, 0): 4 halves per pixel
  int64_t stride = 0;                // pixels between rows of the padded block
  int width = 0, height = 0;         // the layer's size (without the border)
  int stored_x = 0, stored_y = 0;    // where the block starts in the layer
  int stored_width = 0, stored_height = 0;  // the block's size (without the border)
};
// A view of a whole stored layer.
inline PlaneView whole_layer_view(const uint16_t* origin, int64_t stride, int width, int height) {
  return {origin, stride, width, height, 0, 0, width, height};
}

// Row-major 3x3 map from new-view pixels to layer pixels (the inverse plane homography),
// pixel centres at integer coordinates.
struct InverseHomography {
  float m[9];
};

// Points whose homogeneous w is at most this lie behind the new camera: transparent.
constexpr float kMinHomogeneousW = 1e-6f;

// For x in [x_begin, x_begin + count) of output row y: samples the layer at
// H^-1 (x, y, 1) with bilinear interpolation and composites it over accum (4 floats per
// pixel, BGRA premultiplied): accum = sample + accum * (1 - sample.alpha).
using WarpOverRowFn = void (*)(const PlaneView& plane, const InverseHomography& h, int y,
                               int x_begin, int count, float* accum);
// The same for a map that only translates: the layer is sampled at (x + du, y + dv).
// Most camera paths (circle, swing) and the viewer move the camera parallel to the image,
// which makes every plane's map a translation; then the bilinear weights are the same
// for a whole row and neighbouring pixels read neighbouring memory.
using ShiftOverRowFn = void (*)(const PlaneView& plane, float du, float dv, int y, int x_begin,
                                int count, float* accum);
// Where a translated row reads the layer. Output pixels x in [first, last] read columns
// x + column_offset and x + column_offset + 1 of rows `row` and `row` + 1 of the padded
// stored block, with the weights ax (right) and ay (below); the row's other pixels read
// only the transparent border and are left alone. Empty when nothing is read.
struct ShiftSpan {
  bool empty = true;
  int first = 0, last = -1;
  int column_offset = 0, row = 0;
  float ax = 0, ay = 0;
};
ShiftSpan shift_span(const PlaneView& plane, float du, float dv, int y, int x_begin, int count);

// bgr[3i..3i+2] = round(255 * accum[4i..4i+2]) clamped to [0, 255], for i in [0, count):
// the composite over a black background.
using AccumToBgrFn = void (*)(const float* accum, int count, uint8_t* bgr);

struct CompositeKernels {
  Isa isa = Isa::Scalar;
  WarpOverRowFn warp_over_row = nullptr;
  ShiftOverRowFn shift_over_row = nullptr;
  AccumToBgrFn accum_to_bgr = nullptr;
};

// The variant for an instruction set (AVX-512 runs the AVX2 variant); throws
// std::runtime_error if this build or CPU cannot run it.
CompositeKernels composite_kernels(Isa isa);

namespace scalar {
void warp_over_row(const PlaneView& plane, const InverseHomography& h, int y, int x_begin,
                   int count, float* accum);
void shift_over_row(const PlaneView& plane, float du, float dv, int y, int x_begin, int count,
                    float* accum);
void accum_to_bgr(const float* accum, int count, uint8_t* bgr);
}  // namespace scalar

#if defined(__x86_64__)
namespace avx2 {
void warp_over_row(const PlaneView& plane, const InverseHomography& h, int y, int x_begin,
                   int count, float* accum);
void shift_over_row(const PlaneView& plane, float du, float dv, int y, int x_begin, int count,
                    float* accum);
void accum_to_bgr(const float* accum, int count, uint8_t* bgr);
}  // namespace avx2
#endif

#if defined(__aarch64__)
namespace neon {
void warp_over_row(const PlaneView& plane, const InverseHomography& h, int y, int x_begin,
                   int count, float* accum);
void shift_over_row(const PlaneView& plane, float du, float dv, int y, int x_begin, int count,
                    float* accum);
void accum_to_bgr(const float* accum, int count, uint8_t* bgr);
}  // namespace neon
#endif

}  // namespace ampi::render
