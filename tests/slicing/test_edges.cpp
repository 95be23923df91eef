// Our Canny (slicing/edges.h) against cv::Canny (3x3 Sobel, L1 norm) pixel for pixel.
#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "slicing/edges.h"

using namespace ampi;

namespace {

// Smooth blobs with steps and noise (edges of every direction, plateaus, weak and strong
// gradients) or plain noise.
cv::Mat test_map(int w, int h, uint32_t seed, bool smooth) {
  cv::Mat m(h, w, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  if (smooth && w > 2 && h > 2) {
    cv::GaussianBlur(m, m, {0, 0}, 2.0);
    cv::Mat steps(h, w, CV_8UC1, cv::Scalar(0));
    cv::circle(steps, {w / 2, h / 2}, std::max(1, std::min(w, h) / 3), cv::Scalar(90), -1);
    cv::rectangle(steps, {0, 0}, {w / 4, h}, cv::Scalar(40), -1);
    cv::add(m, steps, m);
  }
  return m;
}

}  // namespace

TEST_CASE("canny_edges equals cv::Canny pixel for pixel") {
  const std::pair<double, double> thresholds[] = {{20, 50}, {0, 0}, {5, 5}, {10, 200}, {13.7, 40.2}, {60, 61}};
  const cv::Size sizes[] = {{1, 1}, {2, 3}, {3, 2}, {17, 9}, {64, 48}, {256, 192}};
  uint32_t seed = 1;
  for (const cv::Size& size : sizes)
    for (bool smooth : {false, true})
      for (auto [low, high] : thresholds) {
        const cv::Mat levels = test_map(size.width, size.height, seed++, smooth);
        cv::Mat expected;
        cv::Canny(levels, expected, low, high, 3, false);
        const cv::Mat got = canny_edges(levels, low, high);
        INFO(size.width << "x" << size.height << (smooth ? " smooth" : " noise") << " thresholds " << low << "/" << high);
        REQUIRE(got.size() == expected.size());
        REQUIRE(cv::countNonZero(got != expected) == 0);
      }
}

TEST_CASE("canny_edges refuses bad thresholds") {
  const cv::Mat levels(4, 4, CV_8UC1, cv::Scalar(1));
  CHECK_THROWS_AS(canny_edges(levels, -1, 5), std::invalid_argument);
  CHECK_THROWS_AS(canny_edges(levels, 6, 5), std::invalid_argument);
}

TEST_CASE("widen_edges equals cv::dilate with a square element") {
  cv::RNG rng(7);
  for (cv::Size size : {cv::Size(1, 1), cv::Size(2, 3), cv::Size(9, 4), cv::Size(40, 31), cv::Size(256, 192)})
    for (int k : {1, 2, 3, 4, 7, 8, 15})
      for (double density : {0.0, 0.01, 0.2}) {
        cv::Mat noise(size, CV_32FC1), mask;
        rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
        mask = noise < density;  // 0 or 255
        cv::Mat expected;
        cv::dilate(mask, expected, cv::getStructuringElement(cv::MORPH_RECT, {k, k}));
        INFO(size.width << "x" << size.height << " element " << k << " density " << density);
        REQUIRE(cv::countNonZero(widen_edges(mask, k) != expected) == 0);
      }
}
