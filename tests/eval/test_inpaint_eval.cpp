// The pieces of `ampi eval inpaint`: margin samples as in training, masked metrics, and
// the evaluator's guarantee that no method sees the pixels it must fill.
#include <catch2/catch.hpp>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "eval/inpaint_eval.h"

using namespace ampi;

namespace {

cv::Mat random_bgr(int h, int w, uint32_t seed) {
  cv::Mat m(h, w, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

// Two planes: the left `split` columns are the far plane 0, the rest the near plane 1.
cv::Mat two_plane_labels(int h, int w, int split) {
  cv::Mat labels(h, w, CV_8UC1, cv::Scalar(1));
  labels.colRange(0, split).setTo(0);
  return labels;
}

}  // namespace

TEST_CASE("eval inpaint: the removed border is the eroded width along nearer planes", "[inpaint][eval]") {
  const int h = 40, w = 60, split = 30, k = 5;
  const cv::Mat bgr = random_bgr(h, w, 1);
  const auto samples = margin_samples(bgr, two_plane_labels(h, w, split), 2, k, 1);
  REQUIRE(samples.size() == 1);  // the nearest plane has no sample
  const MarginSample& s = samples[0];
  // the photo's own edges are not eroded: only the k columns next to the near plane go
  CHECK(cv::countNonZero(s.removed) == k * h);
  CHECK(cv::countNonZero(s.removed.colRange(split - k, split)) == k * h);
  CHECK(cv::countNonZero(s.known) == (split - k) * h);
  CHECK(cv::countNonZero(s.known & s.removed) == 0);
  // too small a border is no sample
  CHECK(margin_samples(bgr, two_plane_labels(h, w, split), 2, k, k * h + 1).empty());
}

TEST_CASE("eval inpaint: plane labels follow the slicer's intervals", "[inpaint][eval]") {
  cv::Mat disparity(4, 4, CV_32FC1);
  for (int i = 0; i < 16; ++i) disparity.at<float>(i / 4, i % 4) = float(i);
  const std::vector<Plane> planes = slice_uniform(disparity, 2);
  REQUIRE(planes.size() == 2);
  const cv::Mat labels = plane_labels(disparity, planes);
  CHECK(labels.at<uint8_t>(0, 0) == 0);   // farthest
  CHECK(labels.at<uint8_t>(3, 3) == 1);   // nearest
  CHECK(cv::countNonZero(labels) == 8);
}

TEST_CASE("eval inpaint: masked PSNR and SSIM", "[inpaint][eval]") {
  const cv::Mat truth = random_bgr(32, 32, 2);
  cv::Mat mask(32, 32, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(8, 8, 16, 16)).setTo(255);
  CHECK(masked_psnr(truth, truth, mask) == 100.0);
  CHECK(masked_ssim(truth, truth, mask) == Approx(1.0).margin(1e-6));

  // an error of 10 on every channel of the masked pixels only: 20 log10(255 / 10) dB
  const double expected = 20 * std::log10(255.0 / 10.0);
  const cv::Mat mid(32, 32, CV_8UC3, cv::Scalar::all(100));
  cv::Mat mid_off = mid.clone();
  mid_off.setTo(cv::Scalar::all(110), mask);
  mid_off(cv::Rect(0, 0, 4, 4)).setTo(cv::Scalar::all(0));  // outside the mask: ignored
  CHECK(masked_psnr(mid_off, mid, mask) == Approx(expected).epsilon(1e-9));
  CHECK(masked_ssim(random_bgr(32, 32, 3), truth, mask) < 0.2);
  CHECK_THROWS_AS(masked_psnr(truth, truth, cv::Mat::zeros(32, 32, CV_8UC1)), std::invalid_argument);
}

TEST_CASE("eval inpaint: methods never see the pixels they fill", "[inpaint][eval]") {
  const int h = 40, w = 60;
  const cv::Mat bgr = random_bgr(h, w, 4);
  const auto samples = margin_samples(bgr, two_plane_labels(h, w, 30), 2, 6);
  REQUIRE(samples.size() == 1);
  // "peek" returns what it was given: if the evaluator leaked the truth it would score
  // perfectly; "oracle" returns the truth on purpose to pin the metric's best value
  InpaintEvaluator eval({{"peek", [](const cv::Mat& visible, const MarginSample&) { return visible; }},
                         {"oracle", [](const cv::Mat&, const MarginSample& s) { return s.bgr; }},
                         {"telea", telea_filler(5)},
                         {"push-pull", push_pull_margin_filler()}});
  eval.add(samples[0]);
  const auto scores = eval.scores();
  REQUIRE(scores.size() == 4);
  CHECK(scores[0].psnr < 10);
  CHECK(scores[1].psnr == 100.0);
  CHECK(scores[1].ssim == Approx(1.0).margin(1e-6));
  for (const MethodScore& s : scores) CHECK(s.samples == 1);
  // on uniform noise the classic fillers cannot beat noise statistics by much, but they
  // must beat filling with black
  CHECK(scores[2].psnr > scores[0].psnr);
  CHECK(scores[3].psnr > scores[0].psnr);
}
