#include "inpaint/push_pull.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace ampi {
namespace {

// One pyramid level: colour premultiplied by confidence, and confidence in [0, 1].
struct Level {
  cv::Mat colour;  // CV_32FC3
  cv::Mat weight;  // CV_32FC1
};

Level push(const Level& fine) {
  const cv::Size half((fine.weight.cols + 1) / 2, (fine.weight.rows + 1) / 2);
  Level coarse;
  cv::resize(fine.colour, coarse.colour, half, 0, 0, cv::INTER_AREA);
  cv::resize(fine.weight, coarse.weight, half, 0, 0, cv::INTER_AREA);
  // A coarse cell is as confident as the sum of its children, at most fully. Scale the
  // premultiplied colour by the same factor so colour / weight stays the average.
  cv::Mat scale = cv::min(coarse.weight * 4.0, 1.0);
  cv::Mat safe = cv::max(coarse.weight, 1e-12);
  cv::Mat factor = scale / safe;
  cv::Mat factor3;
  cv::merge(std::vector<cv::Mat>(3, factor), factor3);
  coarse.colour = coarse.colour.mul(factor3);
  coarse.weight = scale;
  return coarse;
}

// Blends a level's own colour with the upsampled estimate from below, by confidence.
cv::Mat pull(const Level& level, const cv::Mat& coarse_estimate) {
  cv::Mat up;
  cv::resize(coarse_estimate, up, level.weight.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat rest = 1.0 - level.weight;
  cv::Mat rest3;
  cv::merge(std::vector<cv::Mat>(3, rest), rest3);
  return level.colour + up.mul(rest3);
}

}  // namespace

void check_fill_inputs(const char* who, const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill) {
  const auto is_mask = [&](const cv::Mat& m) { return m.type() == CV_8UC1 && m.size() == image.size(); };
  if ((image.type() != CV_8UC3 && image.type() != CV_8UC4) || !is_mask(known) || (!fill.empty() && !is_mask(fill)))
    throw std::invalid_argument(std::string(who) + ": expects 8-bit BGR(A) image and 8-bit masks of its size");
}

cv::Mat push_pull_estimate(const cv::Mat& image, const cv::Mat& known) {
  if (image.type() != CV_32FC3) check_fill_inputs("push_pull_estimate", image, known);
  CV_Assert(known.type() == CV_8UC1 && known.size() == image.size());
  cv::Mat bgr;
  if (image.channels() == 4)
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  else
    bgr = image;

  std::vector<Level> pyramid(1);
  known.convertTo(pyramid[0].weight, CV_32F, 1.0 / 255.0);
  cv::threshold(pyramid[0].weight, pyramid[0].weight, 0.0, 1.0, cv::THRESH_BINARY);
  if (cv::countNonZero(pyramid[0].weight) == 0) return cv::Mat();  // nothing to spread
  cv::Mat weight3;
  cv::merge(std::vector<cv::Mat>(3, pyramid[0].weight), weight3);
  bgr.convertTo(pyramid[0].colour, CV_32F);
  pyramid[0].colour = pyramid[0].colour.mul(weight3);
  while (pyramid.back().weight.cols > 1 || pyramid.back().weight.rows > 1)
    pyramid.push_back(push(pyramid.back()));

  // The coarsest cell has full confidence once any pixel is known.
  cv::Mat estimate = pyramid.back().colour / std::max(1e-12, double(pyramid.back().weight.at<float>(0, 0)));
  for (size_t l = pyramid.size() - 1; l-- > 0;) estimate = pull(pyramid[l], estimate);
  return estimate;
}

cv::Mat paste_estimate(const cv::Mat& image, const cv::Mat& estimate, const cv::Mat& fill) {
  CV_Assert(estimate.type() == CV_32FC3 && estimate.size() == image.size() && fill.size() == image.size());
  cv::Mat filled_bgr;
  estimate.convertTo(filled_bgr, CV_8U);
  cv::Mat out = image.clone();
  if (image.channels() == 3) {
    filled_bgr.copyTo(out, fill);
  } else {  // colour channels only: the caller decides what the filled pixels' alpha is
    std::vector<cv::Mat> filled, channels;
    cv::split(filled_bgr, filled);
    cv::split(out, channels);
    for (int c = 0; c < 3; ++c) filled[c].copyTo(channels[c], fill);
    cv::merge(channels, out);
  }
  return out;
}

cv::Mat push_pull_fill(const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill) {
  check_fill_inputs("push_pull_fill", image, known, fill);
  const cv::Mat estimate = push_pull_estimate(image, known);
  return estimate.empty() ? image.clone() : paste_estimate(image, estimate, fill);
}

}  // namespace ampi
