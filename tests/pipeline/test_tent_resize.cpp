// The depth networks' input filter (pipeline/tent_resize.h) against the same tent written
// out in two dimensions, worked examples, OpenCV's bilinear enlargement, and bad input.
#include <catch2/catch.hpp>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "pipeline/tent_resize.h"

using namespace ampi;

namespace {

// The weight of input sample j for output sample i along an axis of `in` -> `out`
// samples, before normalisation.
double tent_weight(int in, int out, int i, int j) {
  const double factor = double(in) / out, centre = (i + 0.5) * factor;
  return std::max(0.0, 1.0 - std::abs(j + 0.5 - centre) / std::max(factor, 1.0));
}

// Every output value a sum over the whole image of the product of the two axes' weights,
// normalised: no tap lists, no separable passes.
cv::Mat reference(const cv::Mat& src, cv::Size size) {
  cv::Mat f;
  src.convertTo(f, CV_64F);
  const int channels = src.channels();
  cv::Mat out(size, CV_32FC(channels));
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      for (int c = 0; c < channels; ++c) {
        double sum = 0, weights = 0;
        for (int sy = 0; sy < src.rows; ++sy)
          for (int sx = 0; sx < src.cols; ++sx) {
            const double w = tent_weight(src.rows, size.height, y, sy) * tent_weight(src.cols, size.width, x, sx);
            sum += w * f.ptr<double>(sy)[sx * channels + c];
            weights += w;
          }
        out.ptr<float>(y)[x * channels + c] = float(sum / weights);
      }
  return out;
}

cv::Mat noise(int rows, int cols, int type, int seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 255);
  return m;
}

double max_difference(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

}  // namespace

TEST_CASE("the tent resize equals the two-dimensional tent on odd sizes, factors and channel counts") {
  const int types[] = {CV_8UC1, CV_8UC3, CV_32FC3, CV_32FC4};
  const cv::Size sizes[][2] = {{{37, 23}, {9, 5}},  {{37, 23}, {12, 11}}, {{64, 48}, {32, 24}},
                               {{50, 7}, {3, 7}},   {{17, 31}, {17, 4}},  {{5, 4}, {13, 9}},
                               {{41, 29}, {1, 1}},  {{8, 8}, {8, 8}}};
  int seed = 1;
  for (int type : types)
    for (const auto& s : sizes) {
      const cv::Mat src = noise(s[0].height, s[0].width, type, seed++);
      const cv::Mat got = resize_tent(src, s[1]);
      INFO("type " << type << ", " << s[0] << " -> " << s[1]);
      REQUIRE(got.size() == s[1]);
      REQUIRE(got.type() == CV_MAKETYPE(CV_32F, src.channels()));
      CHECK(max_difference(got, reference(src, s[1])) < 1e-3);
    }
}

TEST_CASE("a tent halving weighs four samples 1/8, 3/8, 3/8, 1/8 along each axis") {
  cv::Mat row = (cv::Mat_<float>(1, 8) << 0, 8, 16, 0, 0, 64, 0, 8);
  const cv::Mat half = resize_tent(row, {4, 1});
  // The first sample's left neighbour is missing: its weights 3/8, 3/8, 1/8 renormalised.
  CHECK(half.at<float>(0, 0) == Approx((3 * 0 + 3 * 8 + 1 * 16) / 7.0));
  CHECK(half.at<float>(0, 1) == Approx((1 * 8 + 3 * 16 + 3 * 0 + 1 * 0) / 8.0));
  CHECK(half.at<float>(0, 2) == Approx((1 * 0 + 3 * 0 + 3 * 64 + 1 * 0) / 8.0));
  CHECK(half.at<float>(0, 3) == Approx((1 * 64 + 3 * 0 + 3 * 8) / 7.0));
}

TEST_CASE("the tent gives the same size and a constant image back unchanged") {
  const cv::Mat src = noise(19, 27, CV_8UC3, 7);
  cv::Mat as_float;
  src.convertTo(as_float, CV_32FC3);
  CHECK(max_difference(resize_tent(src, src.size()), as_float) < 1e-4);
  const cv::Mat grey(40, 60, CV_8UC3, cv::Scalar(17, 130, 255));
  const cv::Mat small = resize_tent(grey, {7, 5});
  CHECK(max_difference(small, cv::Mat(5, 7, CV_32FC3, cv::Scalar(17, 130, 255))) < 1e-3);
}

TEST_CASE("a tent enlargement is bilinear interpolation with the edges clamped") {
  const cv::Mat src = noise(6, 9, CV_32FC3, 11);
  cv::Mat bilinear;
  cv::resize(src, bilinear, {25, 14}, 0, 0, cv::INTER_LINEAR);
  CHECK(max_difference(resize_tent(src, {25, 14}), bilinear) < 1e-2);
}

TEST_CASE("the tent resize refuses what it cannot filter") {
  CHECK_THROWS_AS(resize_tent(cv::Mat(), {4, 4}), std::invalid_argument);
  CHECK_THROWS_AS(resize_tent(cv::Mat(4, 4, CV_16UC1, cv::Scalar(0)), {2, 2}), std::invalid_argument);
  CHECK_THROWS_AS(resize_tent(cv::Mat(4, 4, CV_8UC1, cv::Scalar(0)), {0, 2}), std::invalid_argument);
}
