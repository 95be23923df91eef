#include "slicing/level_stats.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/isa.h"
#include "engine/thread_pool.h"
#include "slicing/adaptive.h"
#include "slicing/row_kernels.h"

namespace ampi {

Normalization normalization_of(const cv::Mat& disparity) {
  if (disparity.empty()) throw std::invalid_argument("slicing: the disparity map is empty");
  if (disparity.type() != CV_32FC1)
    throw std::invalid_argument("slicing: the disparity map must be CV_32FC1 (one float channel)");
  slicing::ValueRange range{disparity.at<float>(0, 0), disparity.at<float>(0, 0), true};
  const slicing::RangeRowFn range_row = slicing::slicing_kernels(active_isa()).range_row;
  for (int y = 0; y < disparity.rows; ++y) range_row(disparity.ptr<float>(y), disparity.cols, range);
  if (!range.finite) throw std::invalid_argument("slicing: the disparity map contains NaN or infinite values");
  const double lo = range.lo, hi = range.hi;
  return {lo, hi > lo ? (kDisparityLevels - 1) / (hi - lo) : 0.0};
}

cv::Mat normalize_to_levels(const cv::Mat& disparity, cv::Mat* values) {
  const Normalization n = normalization_of(disparity);
  const slicing::NormalizeRowFn normalize_row = slicing::slicing_kernels(active_isa()).normalize_row;
  cv::Mat levels(disparity.size(), CV_8UC1);
  if (values) values->create(disparity.size(), CV_32FC1);
  std::vector<float> row(values ? 0 : disparity.cols);
  for (int y = 0; y < disparity.rows; ++y)
    normalize_row(disparity.ptr<float>(y), disparity.cols, n.lo, n.scale,
                  values ? values->ptr<float>(y) : row.data(), levels.ptr<uchar>(y));
  return levels;
}

namespace {

// A level's count and sum side by side.
struct Accumulator {
  long long count = 0;
  double sum = 0;
};

// Four tables per block of rows, each padded off a 4 KiB multiple so that no two tables'
// counters alias in the CPU's store forwarding.
constexpr int kTables = 4, kPaddedLevels = kDisparityLevels + 4;

// Counts and sums the levels of rows [begin, end) (normalising them on the way) into
// `tables`, pixel x in table x % 4, as in level_histogram: neighbours, which mostly share
// a level, then update different counters instead of waiting on one.
void gather_rows(const cv::Mat& disparity, const Normalization& n, slicing::NormalizeRowFn normalize_row,
                 int begin, int end, cv::Mat& levels, Accumulator* tables) {
  Accumulator* table[kTables] = {tables, tables + kPaddedLevels, tables + 2 * kPaddedLevels,
                                 tables + 3 * kPaddedLevels};
  auto add = [&](int t, uchar l, float value) {
    ++table[t][l].count;
    table[t][l].sum += value;
  };
  std::vector<float> values(disparity.cols);
  for (int y = begin; y < end; ++y) {
    uchar* level = levels.ptr<uchar>(y);
    normalize_row(disparity.ptr<float>(y), disparity.cols, n.lo, n.scale, values.data(), level);
    int x = 0;
    for (; x + kTables <= disparity.cols; x += kTables)
      for (int k = 0; k < kTables; ++k) add(k, level[x + k], values[x + k]);
    for (; x < disparity.cols; ++x) add(0, level[x], values[x]);
  }
}

}  // namespace

NormalizedLevels normalize_with_stats(const cv::Mat& disparity) {
  const Normalization n = normalization_of(disparity);
  const slicing::NormalizeRowFn normalize_row = slicing::slicing_kernels(active_isa()).normalize_row;
  // Blocks of rows in parallel, each into its own tables, added up in block order: the
  // sums do not depend on the thread count.
  constexpr int kBlockRows = 32;
  const int blocks = (disparity.rows + kBlockRows - 1) / kBlockRows;
  std::vector<Accumulator> tables(static_cast<size_t>(blocks) * kTables * kPaddedLevels);
  NormalizedLevels out{cv::Mat(disparity.size(), CV_8UC1), {}};
  default_pool().parallel_for(blocks, 1, [&](int64_t first, int64_t last) {
    for (int64_t b = first; b < last; ++b)
      gather_rows(disparity, n, normalize_row, static_cast<int>(b) * kBlockRows,
                  std::min(disparity.rows, static_cast<int>(b + 1) * kBlockRows), out.levels,
                  &tables[static_cast<size_t>(b) * kTables * kPaddedLevels]);
  });
  out.stats = {std::vector<long long>(kDisparityLevels, 0), std::vector<double>(kDisparityLevels, 0.0)};
  for (int t = 0; t < blocks * kTables; ++t)
    for (int l = 0; l < kDisparityLevels; ++l) {
      out.stats.count[l] += tables[static_cast<size_t>(t) * kPaddedLevels + l].count;
      out.stats.sum[l] += tables[static_cast<size_t>(t) * kPaddedLevels + l].sum;
    }
  return out;
}

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

std::vector<double> level_histogram_reference(const cv::Mat& levels, const cv::Mat& excluded) {
  std::vector<double> h(kDisparityLevels, 0.0);
  long long total = 0;
  for (int y = 0; y < levels.rows; ++y) {
    const uchar* level = levels.ptr<uchar>(y);
    const uchar* skip = excluded.empty() ? nullptr : excluded.ptr<uchar>(y);
    for (int x = 0; x < levels.cols; ++x) {
      if (skip && skip[x]) continue;
      h[level[x]] += 1.0;
      ++total;
    }
  }
  if (total > 0)
    for (double& v : h) v /= static_cast<double>(total);
  return h;
}

std::vector<double> level_histogram(const cv::Mat& levels, const cv::Mat& excluded) {
  CV_Assert(levels.type() == CV_8UC1 && (excluded.empty() || (excluded.type() == CV_8UC1 &&
                                                                excluded.size() == levels.size())));
  // Four tables, pixel x counted in table x % 4: neighbours, which mostly share a level,
  // then increment different counters instead of waiting on one.
  // Each table has one bin more, where excluded pixels go.
  constexpr int kTables = 4, kBins = kDisparityLevels + 1;
  std::vector<long long> table(kTables * kBins, 0);
  long long* t[kTables] = {&table[0], &table[kBins], &table[2 * kBins], &table[3 * kBins]};
  for (int y = 0; y < levels.rows; ++y) {
    const uchar* level = levels.ptr<uchar>(y);
    const uchar* skip = excluded.empty() ? nullptr : excluded.ptr<uchar>(y);
    int x = 0;
    if (skip) {
      // An excluded pixel is counted in a bin past the histogram's end: no branch.
      for (; x + kTables <= levels.cols; x += kTables)
        for (int k = 0; k < kTables; ++k) ++t[k][skip[x + k] ? kDisparityLevels : level[x + k]];
      for (; x < levels.cols; ++x) ++t[0][skip[x] ? kDisparityLevels : level[x]];
    } else {
      for (; x + kTables <= levels.cols; x += kTables)
        for (int k = 0; k < kTables; ++k) ++t[k][level[x + k]];
      for (; x < levels.cols; ++x) ++t[0][level[x]];
    }
  }
  std::vector<double> h(kDisparityLevels, 0.0);
  long long total = 0;
  for (int i = 0; i < kDisparityLevels; ++i) {
    long long n = 0;
    for (int k = 0; k < kTables; ++k) n += t[k][i];
    h[i] = static_cast<double>(n);
    total += n;
  }
  if (total > 0)
    for (double& v : h) v /= static_cast<double>(total);
  return h;
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
