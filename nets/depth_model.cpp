#include "nets/depth_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ampi {

ImageSize depth_working_size(int height, int width, int max_side) {
  if (height <= 0 || width <= 0 || max_side <= 0)
    throw std::invalid_argument("depth_working_size: sizes must be positive");
  const int long_side = std::max(height, width);
  if (long_side <= max_side) return {height, width};
  const double scale = double(max_side) / long_side;
  return {std::max(1, int(std::lround(height * scale))), std::max(1, int(std::lround(width * scale)))};
}

}  // namespace ampi
