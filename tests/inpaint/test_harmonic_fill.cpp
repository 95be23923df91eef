#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include <random>
#include <stdexcept>

#include "inpaint/harmonic_fill.h"
#include "inpaint/push_pull.h"

using namespace ampi;

namespace {

// A colour ramp linear in x and y (harmonic, so the exact fill of any hole in it) with a
// disc and a bar unknown; the hole pixels hold noise, which no fill may read.
struct RampCase {
  cv::Mat image, known;
};

RampCase ramp_case(int h, int w) {
  RampCase c;
  c.image.create(h, w, CV_8UC4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) c.image.at<cv::Vec4b>(y, x) = cv::Vec4b(20 + 3 * x, 200 - 2 * y, 60 + x + y, 255);
  c.known = cv::Mat(h, w, CV_8UC1, cv::Scalar(255));
  cv::circle(c.known, {w / 3, h / 2}, h / 4, cv::Scalar(0), cv::FILLED);
  cv::rectangle(c.known, cv::Rect(2 * w / 3, 4, 3, h - 8), cv::Scalar(0), cv::FILLED);
  cv::Mat noise(h, w, CV_8UC4);
  cv::randu(noise, 0, 256);
  noise.copyTo(c.image, c.known == 0);
  return c;
}

double worst_error(const cv::Mat& filled, const cv::Mat& truth, const cv::Mat& mask) {
  cv::Mat diff;
  cv::absdiff(filled, truth, diff);
  std::vector<cv::Mat> channels;
  cv::split(diff, channels);
  double worst = 0;
  for (int c = 0; c < 3; ++c) {
    double m = 0;
    cv::minMaxLoc(channels[c], nullptr, &m, nullptr, nullptr, mask);
    worst = std::max(worst, m);
  }
  return worst;
}

}  // namespace

TEST_CASE("harmonic fill continues a linear ramp into its holes, where push-pull does not", "[inpaint][harmonic]") {
  const RampCase c = ramp_case(48, 64);
  cv::Mat truth(48, 64, CV_8UC4);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) truth.at<cv::Vec4b>(y, x) = cv::Vec4b(20 + 3 * x, 200 - 2 * y, 60 + x + y, 255);
  const cv::Mat hole = c.known == 0;
  const cv::Mat harmonic = harmonic_fill(c.image, c.known, hole);
  const cv::Mat push_pull = push_pull_fill(c.image, c.known, hole);
  CHECK(worst_error(harmonic, truth, hole) <= 1);  // 8-bit rounding
  CHECK(worst_error(push_pull, truth, hole) >= 4);  // the reason for the relaxation
  // known pixels and alpha are untouched
  std::vector<cv::Mat> a, b;
  cv::split(harmonic, a);
  cv::split(c.image, b);
  CHECK(cv::countNonZero(a[3] != b[3]) == 0);
  for (int ch = 0; ch < 3; ++ch) CHECK(cv::countNonZero((a[ch] != b[ch]) & c.known) == 0);
}

TEST_CASE("harmonic fill changes only the pixels to fill, whatever the thread count", "[inpaint][harmonic]") {
  cv::Mat image(37, 53, CV_8UC3), known(37, 53, CV_8UC1), fill;
  cv::randu(image, 0, 256);
  std::mt19937 rng(5);
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 53; ++x) known.at<uint8_t>(y, x) = (rng() % 3 == 0 || x < 10) ? 255 : 0;
  known(cv::Rect(20, 8, 30, 22)).setTo(0);  // a hole wider than the band
  fill = (known == 0);
  fill(cv::Rect(0, 0, 53, 18)).setTo(0);  // fill only the lower half of the hole
  const cv::Mat image_before = image.clone(), known_before = known.clone(), fill_before = fill.clone();
  HarmonicFill cascade;  // three levels, the finer two within a band: every step runs
  cascade.coarsest_side = 12;
  cascade.band = 2;
  ThreadPool one(1), three(3);
  const cv::Mat a = harmonic_fill(image, known, fill, cascade, one);
  const cv::Mat b = harmonic_fill(image, known, fill, cascade, three);
  CHECK(cv::norm(a, b, cv::NORM_INF) == 0);  // red-black sweeps have no order to race on
  // the inputs are the caller's: none is written
  CHECK(cv::norm(image, image_before, cv::NORM_INF) == 0);
  CHECK(cv::norm(known, known_before, cv::NORM_INF) == 0);
  CHECK(cv::norm(fill, fill_before, cv::NORM_INF) == 0);
  const cv::Mat differs = a != image;  // per channel
  cv::Mat changed;
  cv::reduce(differs.reshape(1, 37 * 53), changed, 1, cv::REDUCE_MAX);
  changed = changed.reshape(1, 37);
  CHECK(cv::countNonZero(changed & ~fill) == 0);
  CHECK(cv::countNonZero(changed) > cv::countNonZero(fill) / 2);
}

TEST_CASE("harmonic fill: no sweeps is push-pull; edge cases; bad input", "[inpaint][harmonic]") {
  const RampCase c = ramp_case(20, 30);
  const cv::Mat hole = c.known == 0;
  HarmonicFill none;  // one level (the image is under coarsest_side), no sweeps
  none.coarsest_sweeps = 0;
  CHECK(cv::norm(harmonic_fill(c.image, c.known, hole, none), push_pull_fill(c.image, c.known, hole),
                 cv::NORM_INF) == 0);
  // nothing known: nothing to spread, the image comes back unchanged
  const cv::Mat nothing(20, 30, CV_8UC1, cv::Scalar(0));
  CHECK(cv::norm(harmonic_fill(c.image, nothing, hole), c.image, cv::NORM_INF) == 0);
  // a single row and a single pixel
  cv::Mat row(1, 9, CV_8UC3, cv::Scalar(40, 80, 120)), row_known(1, 9, CV_8UC1, cv::Scalar(0));
  row_known.at<uint8_t>(0, 0) = 255;
  const cv::Mat row_filled = harmonic_fill(row, row_known, row_known == 0);
  CHECK(cv::norm(row_filled, row, cv::NORM_INF) == 0);  // a constant continues as itself
  cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)), pixel_known(1, 1, CV_8UC1, cv::Scalar(255));
  CHECK(cv::norm(harmonic_fill(pixel, pixel_known, pixel_known == 0), pixel, cv::NORM_INF) == 0);

  // known pixels too scattered for any coarse cell to be half known: the cascade stays at
  // full size rather than start from nothing, and the fill stays within the known colours
  cv::Mat sparse(40, 40, CV_8UC3), sparse_known(40, 40, CV_8UC1, cv::Scalar(0));
  cv::randu(sparse, 100, 201);
  for (int y = 0; y < 40; y += 4)
    for (int x = 0; x < 40; x += 4) sparse_known.at<uint8_t>(y, x) = 255;
  HarmonicFill small;
  small.coarsest_side = 8;
  const cv::Mat sparse_filled = harmonic_fill(sparse, sparse_known, sparse_known == 0, small);
  double lo = 0, hi = 0;
  cv::minMaxLoc(sparse_filled.reshape(1), &lo, &hi);
  CHECK(lo >= 100);
  CHECK(hi <= 200);

  HarmonicFill bad;
  bad.omega = 2.0f;
  CHECK_THROWS_AS(harmonic_fill(c.image, c.known, hole, bad), std::invalid_argument);
  bad = HarmonicFill{};
  bad.sweeps = -1;
  CHECK_THROWS_AS(harmonic_fill(c.image, c.known, hole, bad), std::invalid_argument);
  CHECK_THROWS_AS(harmonic_fill(c.image, c.known, cv::Mat(3, 3, CV_8UC1)), std::invalid_argument);
  CHECK_THROWS_AS(harmonic_fill(cv::Mat(20, 30, CV_32FC3), c.known, hole), std::invalid_argument);
}
