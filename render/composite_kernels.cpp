#include "render/composite_kernels.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ampi::render {

ShiftSpan shift_span(const PlaneView& plane, float du, float dv, int y, int x_begin, int count) {
  ShiftSpan span;
  // v as the general warp computes it; outside [-1, height] it reads only the border.
  const float v = static_cast<float>(y) + dv;
  if (!(v >= -1.0f && v <= static_cast<float>(plane.height)) || !std::isfinite(du)) return span;
  const float fv = std::floor(v), fu = std::floor(du);
  // Rows fv and fv + 1 both outside the stored block: only its transparent border.
  const int row = static_cast<int>(fv) - plane.stored_y;
  if (row < -1 || row > plane.stored_height) return span;
  // Pixel x's footprint starts at stored column x + fu - stored_x: it must lie in
  // [-1, stored_width] (within the layer's [-1, width], as the block is in the layer).
  const double offset = static_cast<double>(fu) - plane.stored_x;
  const double first = std::max<double>(x_begin, -1.0 - offset);
  const double last = std::min<double>(x_begin + count - 1.0, plane.stored_width - offset);
  if (first > last) return span;
  span.empty = false;
  span.first = static_cast<int>(first);
  span.last = static_cast<int>(last);
  span.column_offset = static_cast<int>(offset);  // within [-1 - last, stored_width - first]: no overflow
  span.row = row;
  span.ax = du - fu;
  span.ay = v - fv;
  return span;
}

CompositeKernels composite_kernels(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("compositor kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  switch (isa) {
#if defined(__x86_64__)
    case Isa::Avx2:
    case Isa::Avx512:  // no wider variant: AVX-512 CPUs run the AVX2 one
      return {isa, avx2::warp_over_row, avx2::shift_over_row, avx2::accum_to_bgr};
#endif
#if defined(__aarch64__)
    case Isa::Neon: return {isa, neon::warp_over_row, neon::shift_over_row, neon::accum_to_bgr};
#endif
    default: return {Isa::Scalar, scalar::warp_over_row, scalar::shift_over_row, scalar::accum_to_bgr};
  }
}

}  // namespace ampi::render
