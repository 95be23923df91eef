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

// The taps and weight tables, built as OpenCV builds them.
struct TapTables {
  std::vector<int64_t> offset;
  std::vector<float> space_weight, log2_space_weight, color_weight;
  slicing::BilateralTaps view;
};

void make_tables(const BilateralParams& p, int radius, int64_t row_step, TapTables& t) {
  const double space_coeff = -0.5 / (p.sigma_space * p.sigma_space);
  const double color_coeff = -0.5 / (p.sigma_color * p.sigma_color);
  for (int i = -radius; i <= radius; ++i)
    for (int j = -radius; j <= radius; ++j) {
      const double r = std::sqrt(double(i) * i + double(j) * j);
      if (r > radius) continue;
      t.offset.push_back(i * row_step + j);
      t.space_weight.push_back(static_cast<float>(std::exp(r * r * space_coeff)));
      t.log2_space_weight.push_back(static_cast<float>(r * r * space_coeff * M_LOG2E));
    }
  for (int d = 0; d < 256; ++d) t.color_weight.push_back(static_cast<float>(std::exp(d * d * color_coeff)));
  t.view = {static_cast<int>(t.offset.size()), t.offset.data(), t.space_weight.data(),
            t.log2_space_weight.data(), t.color_weight.data(), static_cast<float>(color_coeff * M_LOG2E)};
}

}  // namespace

cv::Mat bilateral_filter_levels(const cv::Mat& levels, const BilateralParams& p, Isa isa, ThreadPool& pool) {
  CV_Assert(levels.type() == CV_8UC1 && !levels.empty());
  if (!(p.diameter >= 1 && p.sigma_color > 0 && p.sigma_space > 0))
    throw std::invalid_argument("bilateral filter: diameter must be at least 1 and the sigmas positive");
  const slicing::BilateralRowFn row = slicing::slicing_kernels(isa).bilateral_row;
  const int radius = std::max(p.diameter / 2, 1);
  cv::Mat padded;
  cv::copyMakeBorder(levels, padded, radius, radius, radius, radius, cv::BORDER_REFLECT_101);
  TapTables tables;
  make_tables(p, radius, static_cast<int64_t>(padded.step), tables);
  cv::Mat out(levels.size(), CV_8UC1);
  // About 16 rows of 256 pixels per task: enough work to pay for waking a thread.
  const int64_t grain = std::max<int64_t>(1, 4096 / levels.cols);
  pool.parallel_for(levels.rows, grain, [&](int64_t begin, int64_t end) {
    for (int64_t y = begin; y < end; ++y)
      row(padded.ptr<uint8_t>(static_cast<int>(y) + radius) + radius, levels.cols, tables.view,
          out.ptr<uint8_t>(static_cast<int>(y)));
  });
  return out;
}

cv::Mat bilateral_filter_levels(const cv::Mat& levels, const BilateralParams& p) {
  return bilateral_filter_levels(levels, p, active_isa(), default_pool());
}

}  // namespace ampi
