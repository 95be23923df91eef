// The paper's baseline: equal intervals of normalised disparity.
#include <stdexcept>

#include "slicing/adaptive.h"
#include "slicing/level_stats.h"

namespace ampi {

std::vector<Plane> slice_uniform(const cv::Mat& disparity, int planes, const DepthRange& range) {
  if (planes < 1 || planes > kDisparityLevels - 1)
    throw std::invalid_argument("uniform slicing: the plane count must be in 1..255");
  const LevelStats stats = normalize_with_stats(disparity).stats;
  std::vector<Plane> out;
  for (int j = 0; j < planes; ++j) {
    // Interval j covers the levels [256 j / N, 256 (j + 1) / N); the last ends at 255,
    // which it holds.
    const int lo = kDisparityLevels * j / planes;
    const int hi = j + 1 == planes ? kDisparityLevels - 1 : kDisparityLevels * (j + 1) / planes;
    Plane p = plane_for_interval(stats, lo, hi, range);
    if (p.pixel_count > 0) out.push_back(p);
  }
  return out;
}

}  // namespace ampi
