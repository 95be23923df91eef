#include "distill/ensemble.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace ampi {
namespace {

// Bilinear with half-pixel centres and no antialiasing: torch's
// F.interpolate(mode="bilinear", align_corners=False), which training/distill.py uses.
cv::Mat resize_bilinear(const cv::Mat& image, int height, int width) {
  if (image.rows == height && image.cols == width) return image.clone();
  cv::Mat out;
  cv::resize(image, out, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  return out;
}

// numpy's median: the middle value, or the mean of the middle two of an even count.
double median_of(std::vector<double>& values) {
  const size_t n = values.size(), half = n / 2;
  std::nth_element(values.begin(), values.begin() + half, values.end());
  const double upper = values[half];
  if (n % 2) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + half));
}

// One prediction of the ensemble, back in the orientation of `scaled`.
cv::Mat predict(const Teacher& teacher, const cv::Mat& scaled, bool mirrored) {
  cv::Mat input = scaled;
  if (mirrored) cv::flip(scaled, input, 1);
  cv::Mat d = teacher(input);
  if (d.type() != CV_32FC1 || d.empty())
    throw std::runtime_error("distill: the teacher returned no one-channel float map");
  d = resize_bilinear(d, scaled.rows, scaled.cols);
  if (mirrored) cv::flip(d, d, 1);
  return d;
}

// out(y, x) = the median over maps of maps[i](y, x); every map the same size.
cv::Mat per_pixel_median(const std::vector<cv::Mat>& maps) {
  cv::Mat out(maps[0].size(), CV_32FC1);
  std::vector<double> values(maps.size());
  for (int y = 0; y < out.rows; ++y) {
    float* row = out.ptr<float>(y);
    for (int x = 0; x < out.cols; ++x) {
      for (size_t i = 0; i < maps.size(); ++i) values[i] = maps[i].at<float>(y, x);
      row[x] = static_cast<float>(median_of(values));
    }
  }
  return out;
}

void check_inputs(const cv::Mat& rgb, const std::vector<int>& resolutions) {
  if (rgb.type() != CV_32FC3 || rgb.empty()) throw std::runtime_error("distill: expected an RGB float image");
  if (resolutions.empty()) throw std::runtime_error("distill: no resolutions");
  for (int side : resolutions)
    if (side < 1) throw std::runtime_error("distill: resolution " + std::to_string(side) + " is not positive");
}

}  // namespace

cv::Mat normalise_median_mad(const cv::Mat& disparity) {
  CV_Assert(disparity.type() == CV_32FC1);
  const cv::Mat d = disparity.isContinuous() ? disparity : disparity.clone();
  const float* p = d.ptr<float>();
  const size_t n = d.total();
  std::vector<double> values(p, p + n);
  const double median = median_of(values);
  double deviation = 0;
  for (size_t i = 0; i < n; ++i) deviation += std::abs(p[i] - median);
  const double mad = std::max(deviation / static_cast<double>(n), 1e-8);
  cv::Mat out;
  d.convertTo(out, CV_32FC1, 1.0 / mad, -median / mad);
  return out;
}

std::vector<cv::Size> ensemble_sizes(cv::Size photo, const std::vector<int>& resolutions, EnsembleShape shape) {
  std::vector<cv::Size> sizes;
  const double long_side = std::max(photo.width, photo.height);
  for (int side : resolutions) {
    if (shape == EnsembleShape::kSquare) {
      sizes.emplace_back(side, side);
    } else {  // Python's round: half to even, as training/distill.py rounds
      const auto scaled = [&](int n) { return std::max(1, static_cast<int>(std::nearbyint(n * side / long_side))); };
      sizes.emplace_back(scaled(photo.width), scaled(photo.height));
    }
  }
  return sizes;
}

cv::Mat ensemble_median(const cv::Mat& rgb, const Teacher& teacher, const std::vector<int>& resolutions,
                        EnsembleShape shape) {
  check_inputs(rgb, resolutions);
  const std::vector<cv::Size> sizes = ensemble_sizes(rgb.size(), resolutions, shape);
  const cv::Size largest = *std::max_element(sizes.begin(), sizes.end(),
                                             [](cv::Size a, cv::Size b) { return a.area() < b.area(); });
  std::vector<cv::Mat> predictions;
  for (cv::Size size : sizes) {
    const cv::Mat scaled = resize_bilinear(rgb, size.height, size.width);
    for (bool mirrored : {false, true})
      predictions.push_back(
          resize_bilinear(normalise_median_mad(predict(teacher, scaled, mirrored)), largest.height, largest.width));
  }
  return per_pixel_median(predictions);
}

cv::Mat pseudo_ground_truth(const cv::Mat& rgb, const Teacher& teacher, const std::vector<int>& resolutions,
                            EnsembleShape shape) {
  const cv::Mat d = resize_bilinear(ensemble_median(rgb, teacher, resolutions, shape), rgb.rows, rgb.cols);
  double lo = 0, hi = 0;
  cv::minMaxLoc(d, &lo, &hi);
  cv::Mat out;
  d.convertTo(out, CV_32FC1, 1.0 / std::max(hi - lo, 1e-8), -lo / std::max(hi - lo, 1e-8));
  return out;
}

}  // namespace ampi
