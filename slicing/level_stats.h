// What slicing needs to know about a disparity map per normalised level, gathered in one
// pass: how many pixels round to each level and the sum of their unrounded values. Plane
// statistics (pixel count, mean disparity) then cost 256 additions instead of a pass.
#pragma once
#include <opencv2/core.hpp>
#include <vector>

#include "mpi/mpi.h"

namespace ampi {

struct LevelStats {
  std::vector<long long> count;  // kDisparityLevels entries
  std::vector<double> sum;       // of the unrounded normalised values
};

// normalized: CV_8UC1 levels; normalized_float: the same map before rounding.
LevelStats level_stats(const cv::Mat& normalized, const cv::Mat& normalized_float);

// Histogram of `levels` (CV_8UC1) over the pixels where `excluded` (CV_8UC1, or empty
// for none) is 0, normalised to sum 1 (all zeros when no pixel counts). The reference
// counts in doubles pixel by pixel; the fast one counts in integers into interleaved
// tables (runs of one level then do not wait on one counter), equal because counts are
// exact in either.
std::vector<double> level_histogram_reference(const cv::Mat& levels, const cv::Mat& excluded);
std::vector<double> level_histogram(const cv::Mat& levels, const cv::Mat& excluded);

// The plane holding levels [lo, hi) (and 255 when hi is 255), its disparity the mean
// of its pixels' values (the interval's centre when it holds none).
Plane plane_for_interval(const LevelStats& stats, int lo, int hi, const DepthRange& range);

}  // namespace ampi
