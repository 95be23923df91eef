#include "slicing/adaptive.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "slicing/bilateral.h"
#include "slicing/edges.h"
#include "slicing/level_stats.h"
#include "slicing/optimal_cuts.h"

namespace ampi {
namespace {

void check_params(const SlicingParams& p) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("slicing parameters: ") + what);
  };
  require(p.max_planes >= 1 && p.max_planes <= kDisparityLevels - 1, "max_planes must be in 1..255");
  require(p.eps > 0, "eps must be positive");
  require(p.xi >= 0, "xi must not be negative");
  require(p.tear_penalty >= 0, "tear_penalty must not be negative");
  require(p.min_plane_share >= 0 && p.min_plane_share <= 1, "min_plane_share must be in [0, 1]");
  require(p.bilateral_diameter >= 1, "bilateral_diameter must be at least 1");
  require(p.bilateral_sigma_color > 0 && p.bilateral_sigma_space > 0, "bilateral sigmas must be positive");
  require(p.canny_low >= 0 && p.canny_high >= p.canny_low, "Canny thresholds must satisfy 0 <= low <= high");
  require(p.border_erosion_size >= 1, "border_erosion_size must be at least 1");
}

// Mass of h over the levels [lo, end), from prefix sums (prefix[i] = h[0] + .. + h[i-1]).
double mass(const std::vector<double>& prefix, int lo, int end) { return prefix[end] - prefix[lo]; }

// Cost of cutting at each level: tear_penalty times the pixels of h on both sides of the
// cut, halved (h is normalised to 1: scaled back to pixels).
std::vector<double> tear_costs(const std::vector<double>& h, double tear_penalty, size_t pixels) {
  std::vector<double> cost(h.size(), 0.0);
  for (size_t c = 1; c < h.size(); ++c) cost[c] = tear_penalty * 0.5 * (h[c - 1] + h[c]) * static_cast<double>(pixels);
  return cost;
}

}  // namespace

Slicer parse_slicer(const std::string& name) {
  if (name == "paper") return Slicer::Paper;
  if (name == "optimal") return Slicer::Optimal;
  throw std::runtime_error("--slicer: '" + name + "' is not paper or optimal");
}

cv::Mat normalize_disparity_float(const cv::Mat& disparity) {
  cv::Mat values;
  normalize_to_levels(disparity, &values);
  return values;
}

cv::Mat normalize_disparity(const cv::Mat& disparity) { return normalize_to_levels(disparity); }

std::vector<double> slicing_histogram(const cv::Mat& normalized, const SlicingParams& p) {
  CV_Assert(normalized.type() == CV_8UC1 && !normalized.empty());
  const cv::Mat filtered = bilateral_filter_levels(
      normalized, {p.bilateral_diameter, p.bilateral_sigma_color, p.bilateral_sigma_space});
  const cv::Mat edges = canny_edges(filtered, p.canny_low, p.canny_high);
  // The paper's "erosion" of the borders: eroding the map's non-edge region is dilating
  // the edge band. Leaving the band out deepens the valleys between depth clusters.
  const cv::Mat band = widen_edges(edges, p.border_erosion_size);
  std::vector<double> h = level_histogram(filtered, band);
  if (static_cast<size_t>(cv::countNonZero(band)) == band.total()) h = level_histogram(filtered, cv::Mat());
  return h;
}

std::vector<double> histogram_laplacian(const std::vector<double>& h) {
  std::vector<double> lap(h.size(), 0.0);
  for (size_t i = 1; i + 1 < h.size(); ++i) lap[i] = h[i - 1] - 2.0 * h[i] + h[i + 1];
  return lap;
}

std::vector<double> transition_index(const std::vector<double>& h, double eps) {
  std::vector<double> t = histogram_laplacian(h);
  for (size_t i = 0; i < t.size(); ++i) t[i] /= std::max(eps, h[i]);
  return t;
}

std::vector<int> select_transitions(const std::vector<double>& t, const std::vector<double>& h,
                                    int xi, double threshold, int max_selected, double min_mass) {
  CV_Assert(t.size() == h.size());
  const int n = static_cast<int>(t.size());
  std::vector<int> selected;
  if (n < 3) return selected;
  std::vector<double> prefix(n + 1, 0.0);
  for (int i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + h[i];
  std::vector<int> boundaries = {0, n - 1};  // sorted
  std::vector<double> work = t;
  while (static_cast<int>(selected.size()) < max_selected) {
    const auto best = std::max_element(work.begin() + 1, work.end() - 1);  // first of equals
    if (!(*best > threshold)) break;
    const int i = static_cast<int>(best - work.begin());
    const auto above = std::upper_bound(boundaries.begin(), boundaries.end(), i);
    const int lo = *(above - 1);
    const int end = *above == n - 1 ? n : *above;  // the top interval holds the last bin
    if (mass(prefix, lo, i) > min_mass && mass(prefix, i, end) > min_mass) {
      selected.push_back(i);
      boundaries.insert(above, i);
      std::fill(work.begin() + std::max(0, i - xi), work.begin() + std::min(n, i + xi + 1), 0.0);
    } else {
      work[i] = 0.0;  // would cut off an empty interval or a sliver
    }
  }
  return selected;
}

std::vector<int> plane_boundaries(const std::vector<int>& selected,
                                  const std::vector<long long>& bin_counts) {
  const int n = static_cast<int>(bin_counts.size());
  std::vector<int> b = selected;
  b.push_back(0);
  b.push_back(n - 1);
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  auto count = [&](size_t j) {
    long long c = 0;
    const int end = b[j + 1] == n - 1 ? n : b[j + 1];  // the top interval holds the last bin
    for (int level = b[j]; level < end; ++level) c += bin_counts[level];
    return c;
  };
  for (size_t j = 0; j + 1 < b.size() && b.size() > 2;) {
    if (count(j) > 0) {
      ++j;
      continue;
    }
    // Interval j is empty: drop its lower boundary (its upper one for the first interval).
    b.erase(b.begin() + (j > 0 ? j : 1));
    if (j > 0) --j;
  }
  return b;
}

int plane_of_level(const std::vector<Plane>& planes, int level) {
  for (size_t j = 0; j < planes.size(); ++j) {
    const int lo = static_cast<int>(planes[j].disparity_lo);
    const int end = interval_end(static_cast<int>(planes[j].disparity_hi));
    if (level >= lo && level < end) return static_cast<int>(j);
  }
  return -1;
}

std::vector<Plane> slice_adaptive(const cv::Mat& disparity, const SlicingParams& p) {
  check_params(p);
  const NormalizedLevels normalized = normalize_with_stats(disparity);
  const LevelStats& stats = normalized.stats;
  const std::vector<double> h = slicing_histogram(normalized.levels, p);
  const std::vector<double> t = transition_index(h, p.eps);
  const std::vector<int> selected = select_transitions(t, h, p.xi, p.threshold, p.max_planes - 1,
                                                         p.min_plane_share / p.max_planes);
  std::vector<int> b = plane_boundaries(selected, stats.count);
  if (p.slicer == Slicer::Optimal)
    b = optimal_boundaries(stats.count, static_cast<int>(b.size()) - 1, tear_costs(h, p.tear_penalty, disparity.total()));
  std::vector<Plane> planes;
  for (size_t j = 0; j + 1 < b.size(); ++j) planes.push_back(plane_for_interval(stats, b[j], b[j + 1], p.range));
  return planes;
}

}  // namespace ampi
