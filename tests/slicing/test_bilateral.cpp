// The slicer's bilateral filter: the scalar reference against OpenCV's
// cv::bilateralFilter pixel for pixel, every runnable vector variant against the
// reference, on a sweep of sizes around each vector width, diameters and sigmas.
#include <catch2/catch.hpp>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "slicing/bilateral.h"

using namespace ampi;

namespace {

// Disparity-like levels: a few flat regions with steps between them, a slope, and noise,
// so both the colour weights near 1 (smooth parts) and near 0 (steps) are exercised.
cv::Mat test_levels(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> noise(-12, 12), level(0, 255);
  const int a = level(rng), b = level(rng), c = level(rng);
  cv::Mat m(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int base = x < w / 3 ? a : (y < h / 2 ? b : c + (x * 40) / std::max(1, w));
      m.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(base + noise(rng));
    }
  return m;
}

const int kWidths[] = {1, 2, 3, 7, 8, 9, 15, 16, 17, 31, 33, 64, 257};
const int kHeights[] = {1, 3, 6, 19};
const BilateralParams kParams[] = {{5, 20.0, 3.0}, {1, 20.0, 3.0}, {3, 5.0, 1.0},
                                   {7, 60.0, 2.0}, {9, 1.0, 10.0}, {4, 0.3, 0.5}};

std::string describe(int w, int h, const BilateralParams& p) {
  return std::to_string(w) + "x" + std::to_string(h) + " d " + std::to_string(p.diameter) + " sigmas " +
         std::to_string(p.sigma_color) + "/" + std::to_string(p.sigma_space);
}

}  // namespace

TEST_CASE("the scalar bilateral filter equals OpenCV's pixel for pixel", "[slicing][bilateral]") {
  ThreadPool pool(2);
  uint32_t seed = 1;
  for (const BilateralParams& p : kParams)
    for (int w : kWidths)
      for (int h : kHeights) {
        const cv::Mat levels = test_levels(w, h, seed++);
        cv::Mat expected;
        cv::bilateralFilter(levels, expected, p.diameter, p.sigma_color, p.sigma_space);
        const cv::Mat got = bilateral_filter_levels(levels, p, Isa::Scalar, pool);
        INFO(describe(w, h, p));
        REQUIRE(cv::norm(got, expected, cv::NORM_INF) == 0);
      }
}

TEST_CASE("every vector bilateral variant matches the reference within one level",
          "[slicing][bilateral]") {
  ThreadPool pool(2);
  for (Isa isa : runnable_isas()) {
    if (isa == Isa::Scalar) continue;
    long long pixels = 0, differing = 0;
    uint32_t seed = 100;
    for (const BilateralParams& p : kParams)
      for (int w : kWidths)
        for (int h : kHeights) {
          const cv::Mat levels = test_levels(w, h, seed++);
          const cv::Mat reference = bilateral_filter_levels(levels, p, Isa::Scalar, pool);
          const cv::Mat got = bilateral_filter_levels(levels, p, isa, pool);
          INFO(isa_name(isa) << " " << describe(w, h, p));
          REQUIRE(cv::norm(got, reference, cv::NORM_INF) <= 1);
          pixels += levels.total();
          differing += cv::countNonZero(got != reference);
        }
    // A level apart only where the weighted mean lies within ~1e-6 of a half-integer.
    INFO(isa_name(isa) << ": " << differing << " of " << pixels << " pixels differ");
    CHECK(differing * 1000 <= pixels);
  }
}

TEST_CASE("the bilateral filter gives the same map on one thread and on two", "[slicing][bilateral]") {
  ThreadPool one(1), two(2);
  const cv::Mat levels = test_levels(256, 192, 7);
  for (Isa isa : runnable_isas()) {
    INFO(isa_name(isa));
    REQUIRE(cv::norm(bilateral_filter_levels(levels, {}, isa, one),
                     bilateral_filter_levels(levels, {}, isa, two), cv::NORM_INF) == 0);
  }
}

TEST_CASE("the bilateral filter keeps flat regions and steps", "[slicing][bilateral]") {
  // Two flat halves 100 levels apart: the colour weight across the step is e^-12.5, so
  // every pixel keeps its value on every variant.
  cv::Mat levels(20, 40, CV_8UC1, cv::Scalar(50));
  levels.colRange(20, 40).setTo(150);
  ThreadPool pool(1);
  for (Isa isa : runnable_isas()) {
    INFO(isa_name(isa));
    REQUIRE(cv::norm(bilateral_filter_levels(levels, {}, isa, pool), levels, cv::NORM_INF) == 0);
  }
}

TEST_CASE("bad bilateral parameters are refused", "[slicing][bilateral]") {
  const cv::Mat levels(4, 4, CV_8UC1, cv::Scalar(3));
  ThreadPool pool(1);
  CHECK_THROWS_AS(bilateral_filter_levels(levels, {0, 20.0, 3.0}, Isa::Scalar, pool), std::invalid_argument);
  CHECK_THROWS_AS(bilateral_filter_levels(levels, {5, 0.0, 3.0}, Isa::Scalar, pool), std::invalid_argument);
  CHECK_THROWS_AS(bilateral_filter_levels(levels, {5, 20.0, -1.0}, Isa::Scalar, pool), std::invalid_argument);
}
