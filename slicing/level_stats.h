// What slicing needs to know about a disparity map per normalised level, gathered in one
// pass: how many pixels round to each level and the sum of their unrounded values. Plane
// statistics (pixel count, mean disparity) then cost 256 additions instead of a pass.
#pragma once
#include <opencv2/core.hpp>
#include <vector>

#include "mpi/mpi.h"
#include "slicing/adaptive.h"

namespace ampi {

struct LevelStats {
  std::vector<long long> count;  // kDisparityLevels entries
  std::vector<double> sum;       // of the unrounded normalised values
};

// Min-max normalisation of a disparity map onto [0, 255]: value = min((d - lo) * scale,
// 255), in double precision (the difference of any two finite floats is finite there),
// so the extremes land exactly on 0 and 255; levels are values rounded to nearest, ties
// to even. scale 0: a constant map, all zeros. Computed by the slicing row kernels
// (slicing/row_kernels.h), identical on every instruction set.
struct Normalization {
  double lo = 0, scale = 0;
};
// Checks the map (std::invalid_argument if it is empty, not CV_32FC1, or holds NaN or
// infinite values) and finds its range.
Normalization normalization_of(const cv::Mat& disparity);

// The map's levels (CV_8UC1), and its values (CV_32FC1) if `values` is not null.
cv::Mat normalize_to_levels(const cv::Mat& disparity, cv::Mat* values = nullptr);

// The reference: from the levels (CV_8UC1) and the same map before rounding.
LevelStats level_stats(const cv::Mat& normalized, const cv::Mat& normalized_float);

// The disparity map normalised and rounded to levels (CV_8UC1, as normalize_disparity)
// and their LevelStats, in one pass over the map without the unrounded copy.
struct NormalizedLevels {
  cv::Mat levels;
  LevelStats stats;
};
NormalizedLevels normalize_with_stats(const cv::Mat& disparity);

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
