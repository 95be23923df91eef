#include "slicing/bilateral.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "slicing/row_kernels.h"

namespace ampi {
namespace {

// The filter's taps and weight tables, built as OpenCV builds them, with each tap tied
// to the pair of opposite taps it shares its weights with (slicing/row_kernels.h).
struct Geometry {
  int radius = 0;
  std::vector<int64_t> pair_offset;  // the forward tap o of each pair
  std::vector<float> space_weight, log2_space_weight, color_weight;
  slicing::BilateralPairs pairs;
  struct Tap {
    int dy = 0, dx = 0;
    int pair = -1;         // -1: the centre, whose weight is 1
    bool forward = false;  // o itself, or -o
  };
  std::vector<Tap> taps;  // in OpenCV's order
  std::vector<int64_t> tap_offset;
};

Geometry make_geometry(const BilateralParams& p, int64_t row_step) {
  Geometry g;
  g.radius = std::max(p.diameter / 2, 1);
  const int r = g.radius;
  const double space_coeff = -0.5 / (p.sigma_space * p.sigma_space);
  const double color_coeff = -0.5 / (p.sigma_color * p.sigma_color);
  auto in_disk = [r](int i, int j) { return std::sqrt(double(i) * i + double(j) * j) <= r; };
  // Forward taps come after the centre in OpenCV's order; each opens a pair.
  std::vector<std::pair<int, int>> forward;
  for (int i = 0; i <= r; ++i)
    for (int j = (i == 0 ? 1 : -r); j <= r; ++j) {
      if (!in_disk(i, j)) continue;
      const double r2 = double(i) * i + double(j) * j;
      forward.emplace_back(i, j);
      g.pair_offset.push_back(i * row_step + j);
      g.space_weight.push_back(static_cast<float>(std::exp(r2 * space_coeff)));
      g.log2_space_weight.push_back(static_cast<float>(r2 * space_coeff * M_LOG2E));
    }
  for (int d = 0; d < 256; ++d) g.color_weight.push_back(static_cast<float>(std::exp(d * d * color_coeff)));
  g.pairs = {static_cast<int>(forward.size()), g.pair_offset.data(), g.space_weight.data(),
             g.log2_space_weight.data(), g.color_weight.data(), static_cast<float>(color_coeff * M_LOG2E)};
  auto pair_of = [&](int i, int j) {
    return static_cast<int>(std::find(forward.begin(), forward.end(), std::make_pair(i, j)) - forward.begin());
  };
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j) {
      if (!in_disk(i, j)) continue;
      Geometry::Tap t{i, j};
      if (i != 0 || j != 0) {
        t.forward = i > 0 || (i == 0 && j > 0);
        t.pair = t.forward ? pair_of(i, j) : pair_of(-i, -j);
      }
      g.taps.push_back(t);
      g.tap_offset.push_back(i * row_step + j);
    }
  return g;
}

// Filters rows [begin, end). Pair weights are kept for the last radius + 1 rows: a
// backward tap of row y reads the weights its pair computed at row y + dy (dy < 0). Each
// row's weights cover columns [-radius, width + radius), where backward taps look.
void filter_rows(const cv::Mat& padded, const Geometry& g, const slicing::SlicingKernels& k, int begin,
                 int end, cv::Mat& out) {
  const int r = g.radius, width = out.cols, row_len = width + 2 * r, slots = r + 1;
  std::vector<float> ring(static_cast<size_t>(slots) * g.pairs.count * row_len);
  const std::vector<float> ones(width, 1.0f);
  auto weights_of = [&](int y, int pair) {  // row y's weights of a pair, from column -r
    return &ring[(static_cast<size_t>((y + slots) % slots) * g.pairs.count + pair) * row_len];
  };
  auto weigh_row = [&](int y) {  // y >= -r
    std::vector<float*> rows(g.pairs.count);
    for (int h = 0; h < g.pairs.count; ++h) rows[h] = weights_of(y, h);
    k.bilateral_weights(padded.ptr<uint8_t>(y + r) + r, row_len, g.pairs, rows.data());
  };
  for (int y = begin - r; y < begin; ++y) weigh_row(y);
  std::vector<const float*> tap_weights(g.taps.size());
  for (int y = begin; y < end; ++y) {
    weigh_row(y);
    for (size_t t = 0; t < g.taps.size(); ++t) {
      const Geometry::Tap& tap = g.taps[t];
      tap_weights[t] = tap.pair < 0   ? ones.data()
                       : tap.forward ? weights_of(y, tap.pair) + r
                                     : weights_of(y + tap.dy, tap.pair) + r + tap.dx;
    }
    const slicing::BilateralTaps taps{static_cast<int>(g.taps.size()), g.tap_offset.data(), tap_weights.data()};
    k.bilateral_combine(padded.ptr<uint8_t>(y + r) + 2 * r, width, taps, out.ptr<uint8_t>(y));
  }
}

}  // namespace

cv::Mat bilateral_filter_levels(const cv::Mat& levels, const BilateralParams& p, Isa isa, ThreadPool& pool) {
  CV_Assert(levels.type() == CV_8UC1 && !levels.empty());
  if (!(p.diameter >= 1 && p.sigma_color > 0 && p.sigma_space > 0))
    throw std::invalid_argument("bilateral filter: diameter must be at least 1 and the sigmas positive");
  const slicing::SlicingKernels kernels = slicing::slicing_kernels(isa);
  const int r = std::max(p.diameter / 2, 1);
  // Rows padded by the radius; columns by twice that, where the pair weights of the
  // border columns look.
  cv::Mat padded;
  cv::copyMakeBorder(levels, padded, r, r, 2 * r, 2 * r, cv::BORDER_REFLECT_101);
  const Geometry geometry = make_geometry(p, static_cast<int64_t>(padded.step));
  cv::Mat out(levels.size(), CV_8UC1);
  // About 16 rows of 256 pixels per task: enough work to pay for waking a thread and for
  // the radius rows of weights each task computes before its first row.
  const int64_t grain = std::max<int64_t>(1, 4096 / levels.cols);
  pool.parallel_for(levels.rows, grain, [&](int64_t begin, int64_t end) {
    filter_rows(padded, geometry, kernels, static_cast<int>(begin), static_cast<int>(end), out);
  });
  return out;
}

cv::Mat bilateral_filter_levels(const cv::Mat& levels, const BilateralParams& p) {
  return bilateral_filter_levels(levels, p, active_isa(), default_pool());
}

}  // namespace ampi
