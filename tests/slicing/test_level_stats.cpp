// The interleaved histogram against its reference (bit for bit equal: slicing's results
// must not change), and the finiteness check on extreme maps.
#include <algorithm>
#include <catch2/catch.hpp>
#include <limits>
#include <random>
#include <stdexcept>

#include "slicing/adaptive.h"
#include "slicing/level_stats.h"

using namespace ampi;

TEST_CASE("finite maps with extreme values are accepted, non-finite ones refused") {
  // The finiteness check sums the map: extreme finite values must not overflow it.
  const cv::Mat wide = (cv::Mat_<float>(2, 3) << -3e38f, -3e38f, 0.0f, 1e-30f, 3e38f, 3e38f);
  const std::vector<Plane> planes = slice_adaptive(wide);
  REQUIRE(!planes.empty());
  CHECK(planes.front().disparity_lo == 0);
  CHECK(planes.back().disparity_hi == 255);
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()}) {
    cv::Mat m = wide.clone();
    m.at<float>(1, 1) = bad;
    CHECK_THROWS_AS(slice_adaptive(m), std::invalid_argument);
    CHECK_THROWS_AS(normalize_disparity(m), std::invalid_argument);
  }
  cv::Mat both = wide.clone();  // +inf and -inf: their sum is NaN, refused too
  both.at<float>(0, 0) = -std::numeric_limits<float>::infinity();
  both.at<float>(1, 2) = std::numeric_limits<float>::infinity();
  CHECK_THROWS_AS(slice_adaptive(both), std::invalid_argument);
}

TEST_CASE("level_histogram equals its reference, with and without excluded pixels") {
  std::mt19937 rng(5);
  for (int w : {1, 3, 4, 5, 130, 257}) {
    for (int run : {1, 9}) {  // runs of equal levels, as smooth maps have
      cv::Mat levels(23, w, CV_8UC1), excluded(23, w, CV_8UC1);
      for (int y = 0; y < levels.rows; ++y)
        for (int x = 0; x < w; ++x) {
          levels.at<uchar>(y, x) = static_cast<uchar>(x % run == 0 ? rng() % 256 : levels.at<uchar>(y, x - 1));
          excluded.at<uchar>(y, x) = static_cast<uchar>(rng() % 3 == 0 ? 255 : 0);
        }
      INFO("width " << w << ", runs of " << run);
      CHECK(level_histogram(levels, cv::Mat()) == level_histogram_reference(levels, cv::Mat()));
      CHECK(level_histogram(levels, excluded) == level_histogram_reference(levels, excluded));
      const cv::Rect inner(0, 2, std::max(1, w - 1), 17);  // not continuous in memory
      CHECK(level_histogram(levels(inner), excluded(inner)) ==
            level_histogram_reference(levels(inner), excluded(inner)));
      const cv::Mat all(levels.size(), CV_8UC1, cv::Scalar(1));
      CHECK(level_histogram(levels, all) == std::vector<double>(kDisparityLevels, 0.0));
    }
  }
}

TEST_CASE("normalize_with_stats equals the float map's levels and their reference stats") {
  std::mt19937 rng(11);
  std::normal_distribution<float> value(0.0f, 40.0f);
  for (int w : {1, 3, 4, 5, 130, 257}) {
    cv::Mat disparity(17, w, CV_32FC1);
    for (int y = 0; y < disparity.rows; ++y)
      for (int x = 0; x < w; ++x)  // runs of equal values, as flat regions have
        disparity.at<float>(y, x) = x % 5 == 0 ? value(rng) : disparity.at<float>(y, x - 1);
    const NormalizedLevels got = normalize_with_stats(disparity);
    const cv::Mat levels = normalize_disparity(disparity);
    const LevelStats expected = level_stats(levels, normalize_disparity_float(disparity));
    INFO("width " << w);
    REQUIRE(cv::norm(got.levels, levels, cv::NORM_INF) == 0);
    REQUIRE(got.stats.count == expected.count);
    for (int l = 0; l < kDisparityLevels; ++l)  // the same values, summed in another order
      REQUIRE(got.stats.sum[l] == Approx(expected.sum[l]).epsilon(1e-12).margin(1e-9));
  }
  CHECK_THROWS_AS(normalize_with_stats(cv::Mat()), std::invalid_argument);
  CHECK_THROWS_AS(normalize_with_stats(cv::Mat(2, 2, CV_8UC1)), std::invalid_argument);
}
