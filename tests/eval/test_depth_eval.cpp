// eval/depth_eval.h: the median/std alignment and the paper's depth metrics on maps with
// known answers, and the reference files' lookup and reading.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "eval/depth_eval.h"
#include "render/temp_dir.h"
#include "support/random.h"
#include "weights_format/npy.h"

using namespace ampi;
using ampi::test::TempDir;

namespace {

cv::Mat random_disparity(int rows, int cols, uint32_t seed) {
  const std::vector<float> v = ampi::test::random_floats(size_t(rows) * cols, seed, 0.05f, 3.0f);
  return cv::Mat(rows, cols, CV_32FC1, const_cast<float*>(v.data())).clone();
}

DepthReference all_valid(const cv::Mat& disparity) {
  return {disparity, cv::Mat(disparity.size(), CV_8UC1, cv::Scalar(255))};
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a prediction equal to the reference up to scale and shift scores perfectly", "[eval][depth]") {
  const cv::Mat ref = random_disparity(24, 32, 7);
  // Exact up to the float32 rounding of the scaled and shifted prediction itself.
  for (double scale : {1.0, 0.1, 250.0})
    for (double shift : {0.0, -4.0, 3.5}) {
      INFO("scale " << scale << ", shift " << shift);
      const cv::Mat prediction = ref * scale + shift;
      const DepthMetrics m = depth_metrics(prediction, all_valid(ref));
      CHECK(m.delta1 == 1.0);
      CHECK(m.delta2 == 1.0);
      CHECK(m.delta3 == 1.0);
      CHECK(m.rmse == Approx(0).margin(1e-4));
      CHECK(m.rel == Approx(0).margin(1e-4));
    }
}

TEST_CASE("pixels without a reference value are left out", "[eval][depth]") {
  cv::Mat ref = random_disparity(16, 16, 3);
  cv::Mat prediction = ref * 2 + 1;
  ref(cv::Rect(0, 0, 8, 16)).setTo(0);              // no measurement on the left half
  prediction(cv::Rect(0, 0, 8, 16)).setTo(-1000);   // garbage there must not count
  const DepthReference reference{ref, ref > 0};
  const DepthMetrics m = depth_metrics(prediction, reference);
  CHECK(m.delta1 == 1.0);
  CHECK(m.rmse == Approx(0).margin(1e-5));
}

TEST_CASE("a constant prediction becomes the reference's median: metrics by hand", "[eval][depth]") {
  // r = 1, 2, 4: aligned a = 2 everywhere; ratios 2, 1, 2.
  const cv::Mat ref = (cv::Mat_<float>(1, 3) << 1, 2, 4);
  const DepthMetrics m = depth_metrics(cv::Mat(1, 3, CV_32FC1, cv::Scalar(7)), all_valid(ref));
  CHECK(m.delta1 == Approx(1.0 / 3));
  CHECK(m.delta2 == Approx(1.0 / 3));  // 1.5625 < 2
  CHECK(m.delta3 == Approx(1.0 / 3));  // 1.953 < 2
  CHECK(m.rmse == Approx(std::sqrt(5.0 / 3)));
  CHECK(m.rel == Approx((1.0 + 0.0 + 0.5) / 3));
}

TEST_CASE("alignment: median and std of the reference, floored at its smallest value", "[eval][depth]") {
  const cv::Mat p = (cv::Mat_<float>(1, 4) << 0, 1, 2, 3);
  const cv::Mat r = (cv::Mat_<float>(1, 4) << 1, 2, 3, 5);
  // median(p) = 1.5, std(p) = sqrt(1.25); median(r) = 2.5, std(r) = sqrt(2.1875).
  const double scale = std::sqrt(2.1875 / 1.25);
  const cv::Mat a = align_median_std(p, r, cv::Mat(1, 4, CV_8UC1, cv::Scalar(255)));
  CHECK(a.at<float>(0) == Approx(1.0));  // (0 - 1.5) * 1.32 + 2.5 = 0.52, raised to min(r) = 1
  CHECK(a.at<float>(1) == Approx(2.5 - 0.5 * scale));
  CHECK(a.at<float>(2) == Approx(2.5 + 0.5 * scale));
  CHECK(a.at<float>(3) == Approx(2.5 + 1.5 * scale));
}

TEST_CASE("a prediction with near and far swapped scores below a correct one", "[eval][depth]") {
  const cv::Mat ref = random_disparity(32, 32, 11);
  const DepthMetrics good = depth_metrics(ref * 3, all_valid(ref));
  const DepthMetrics inverted = depth_metrics(-ref, all_valid(ref));
  CHECK(inverted.delta1 < good.delta1);
  CHECK(inverted.rmse > 0.1);
  CHECK(inverted.rel > good.rel);
}

TEST_CASE("the vertical gradient grows linearly downward and matches a ground-plane reference", "[eval][depth]") {
  const cv::Mat g = vertical_gradient_disparity({5, 9});
  CHECK(g.at<float>(0, 3) == 0.0f);
  CHECK(g.at<float>(4, 0) == Approx(0.5));
  CHECK(g.at<float>(8, 4) == 1.0f);
  cv::Mat ground(9, 5, CV_32FC1);
  for (int y = 0; y < 9; ++y) ground.row(y).setTo(0.2 + 0.1 * y);
  const DepthMetrics m = depth_metrics(g, all_valid(ground));
  CHECK(m.delta1 == 1.0);
  CHECK(m.rmse == Approx(0).margin(1e-5));
}

TEST_CASE("mismatched inputs are refused", "[eval][depth]") {
  const cv::Mat ref = random_disparity(8, 8, 1);
  CHECK_THROWS_AS(depth_metrics(random_disparity(8, 9, 2), all_valid(ref)), std::invalid_argument);
  CHECK_THROWS_AS(depth_metrics(ref, DepthReference{ref, cv::Mat::zeros(8, 8, CV_8UC1)}), std::invalid_argument);
}

TEST_CASE("references: 16-bit PNG, distances, NaN and empty maps", "[eval][depth]") {
  TempDir dir;
  cv::Mat png = (cv::Mat_<uint16_t>(1, 3) << 0, 100, 400);
  REQUIRE(cv::imwrite(dir.file("r.png"), png));
  const DepthReference disparity = read_depth_reference(dir.file("r.png"), false);
  CHECK(disparity.valid.at<uchar>(0) == 0);
  CHECK(disparity.disparity.at<float>(2) == 400.0f);
  const DepthReference distance = read_depth_reference(dir.file("r.png"), true);
  CHECK(distance.valid.at<uchar>(0) == 0);
  CHECK(distance.disparity.at<float>(1) == Approx(0.01));
  CHECK(distance.disparity.at<float>(2) == Approx(0.0025));

  Tensor nan = Tensor::empty({2, 2});
  for (int i = 0; i < 4; ++i) nan.f32()[i] = i == 2 ? std::numeric_limits<float>::quiet_NaN() : 1.0f;
  write_npy(dir.file("nan.npy"), nan);
  const std::string nan_error = error_of([&] { read_depth_reference(dir.file("nan.npy"), false); });
  CHECK(nan_error.find(dir.file("nan.npy")) != std::string::npos);
  CHECK(nan_error.find("NaN") != std::string::npos);

  REQUIRE(cv::imwrite(dir.file("zero.png"), cv::Mat::zeros(4, 4, CV_16UC1)));
  CHECK(error_of([&] { read_depth_reference(dir.file("zero.png"), false); }).find("no valid") != std::string::npos);
}

TEST_CASE("the reference of a photo is found by relative path and name, in any format", "[eval][depth]") {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "images" / "sub");
  std::filesystem::create_directories(dir.path() / "ref" / "sub");
  const std::string photo = dir.write("images/sub/a.jpg", "x");
  const std::string images = dir.file("images"), ref = dir.file("ref");
  CHECK(error_of([&] { find_depth_reference(photo, images, ref); }).find("no reference") != std::string::npos);
  const std::string npy = dir.write("ref/sub/a.npy", "x");
  dir.write("ref/sub/ab.png", "x");  // another photo's map
  dir.write("ref/a.png", "x");       // another folder's
  CHECK(find_depth_reference(photo, images, ref) == npy);
  dir.write("ref/sub/a.png", "x");
  CHECK(error_of([&] { find_depth_reference(photo, images, ref); }).find("several") != std::string::npos);
}

TEST_CASE("the folder's score is the mean of the images' scores", "[eval][depth]") {
  DepthMetricsMean mean;
  mean.add({1, 1, 1, 0, 0});
  mean.add({0.5, 0.7, 0.9, 2, 0.4});
  const DepthMetrics m = mean.mean();
  CHECK(mean.count() == 2);
  CHECK(m.delta1 == Approx(0.75));
  CHECK(m.delta3 == Approx(0.95));
  CHECK(m.rmse == Approx(1.0));
  CHECK(m.rel == Approx(0.2));
}
