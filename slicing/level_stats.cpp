#include "slicing/level_stats.h"

#include "slicing/adaptive.h"

namespace ampi {

LevelStats level_stats(const cv::Mat& normalized, const cv::Mat& normalized_float) {
  CV_Assert(normalized.type() == CV_8UC1 && normalized_float.type() == CV_32FC1 &&
            normalized.size() == normalized_float.size());
  LevelStats s{std::vector<long long>(kDisparityLevels, 0), std::vector<double>(kDisparityLevels, 0.0)};
  for (int y = 0; y < normalized.rows; ++y) {
    const uchar* level = normalized.ptr<uchar>(y);
    const float* value = normalized_float.ptr<float>(y);
    for (int x = 0; x < normalized.cols; ++x) {
      ++s.count[level[x]];
      s.sum[level[x]] += value[x];
    }
  }
  return s;
}

Plane plane_for_interval(const LevelStats& stats, int lo, int hi, const DepthRange& range) {
  const int end = interval_end(hi);
  long long n = 0;
  double sum = 0.0;
  for (int level = lo; level < end; ++level) {
    n += stats.count[level];
    sum += stats.sum[level];
  }
  Plane p;
  p.disparity_lo = lo;
  p.disparity_hi = hi;
  p.pixel_count = n;
  p.disparity = n > 0 ? sum / static_cast<double>(n) : 0.5 * (lo + hi);
  p.depth = depth_from_disparity(p.disparity, range);
  return p;
}

}  // namespace ampi
