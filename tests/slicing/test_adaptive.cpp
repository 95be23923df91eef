#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "slicing/adaptive.h"

using namespace ampi;

namespace {

// A map of vertical bands, band k at disparity values[k] (arbitrary units).
cv::Mat banded_map(const std::vector<float>& values, int width_per_band, int height) {
  cv::Mat m(height, width_per_band * static_cast<int>(values.size()), CV_32FC1);
  for (int x = 0; x < m.cols; ++x) m.col(x).setTo(values[x / width_per_band]);
  return m;
}

// A smooth random surface (sum of a few broad cosines) plus per-pixel noise.
cv::Mat random_smooth_map(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  float fx[3], fy[3], ph[3];
  for (int k = 0; k < 3; ++k) fx[k] = 6 * u(rng), fy[k] = 6 * u(rng), ph[k] = 6.28f * u(rng);
  cv::Mat m(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v = 0;
      for (int k = 0; k < 3; ++k) v += std::cos(fx[k] * x / w + fy[k] * y / h + ph[k]);
      m.at<float>(y, x) = v + noise(rng);
    }
  return m;
}

std::vector<int> interior_boundaries(const std::vector<Plane>& planes) {
  std::vector<int> b;
  for (size_t j = 1; j < planes.size(); ++j) b.push_back(static_cast<int>(planes[j].disparity_lo));
  return b;
}

// Planes are back to front, contiguous over 0..255, and every pixel is in exactly one.
void check_plane_structure(const std::vector<Plane>& planes, const cv::Mat& disparity) {
  REQUIRE(!planes.empty());
  CHECK(planes.front().disparity_lo == 0);
  CHECK(planes.back().disparity_hi == 255);
  long long pixels = 0;
  for (size_t j = 0; j < planes.size(); ++j) {
    INFO("plane " << j);
    CHECK(planes[j].pixel_count > 0);
    CHECK(planes[j].disparity >= planes[j].disparity_lo - 0.5);
    CHECK(planes[j].disparity <= planes[j].disparity_hi + 0.5);
    if (j > 0) {
      CHECK(planes[j].disparity_lo == planes[j - 1].disparity_hi);
      CHECK(planes[j].depth < planes[j - 1].depth);
    }
    pixels += planes[j].pixel_count;
  }
  CHECK(pixels == static_cast<long long>(disparity.total()));
}

}  // namespace

TEST_CASE("histogram_laplacian is the second difference, zero at the ends") {
  const std::vector<double> lap = histogram_laplacian({1, 2, 4, 2, 1});
  CHECK(lap == std::vector<double>{0, 1, -4, 1, 0});
  CHECK(histogram_laplacian({0.5, 0.5}) == std::vector<double>{0, 0});
}

TEST_CASE("transition_index divides by max(eps, h)") {
  const std::vector<double> t = transition_index({0, 0, 0.5, 0, 0.5}, 0.001);
  CHECK(t[0] == 0);
  CHECK(t[1] == Approx(0.5 / 0.001));
  CHECK(t[2] == Approx(-1.0 / 0.5));
  CHECK(t[3] == Approx(1.0 / 0.001));
  CHECK(t[4] == 0);
}

TEST_CASE("select_transitions: largest first, xi spacing, threshold, count") {
  //                         0    1    2    3    4    5    6    7    8    9
  const std::vector<double> t = {9, 0.5, 3.0, 0.2, 2.0, 0.05, 0.0, 1.0, 0.3, 9};
  const std::vector<double> h(10, 0.1);
  CHECK(select_transitions(t, h, 1, 0.1, 10) == std::vector<int>{2, 4, 7});
  CHECK(select_transitions(t, h, 0, 0.1, 10) == std::vector<int>{2, 4, 7, 1, 8, 3});
  CHECK(select_transitions(t, h, 0, 0.1, 2) == std::vector<int>{2, 4});
  CHECK(select_transitions(t, h, 0, 2.5, 10) == std::vector<int>{2});
  CHECK(select_transitions(t, h, 3, 0.1, 10) == std::vector<int>{2, 7});
  // Equal values: the lowest index wins.
  CHECK(select_transitions({0, 1, 1, 0}, {0.25, 0.25, 0.25, 0.25}, 0, 0.1, 1) == std::vector<int>{1});
}

TEST_CASE("select_transitions drops a candidate that would cut off an empty interval") {
  // Mass only at bins 0 and 5.
  std::vector<double> h(10, 0.0);
  h[0] = 0.5;
  h[5] = 0.5;
  std::vector<double> t(10, 0.0);
  t[7] = 5;  // [7, 9] would hold no mass: dropped
  t[3] = 4;  // [0, 3) and [3, 9] both hold mass: chosen
  t[4] = 3;  // [3, 4) would be empty: dropped, not counted
  t[1] = 2;  // [1, 3) would be empty: dropped
  CHECK(select_transitions(t, h, 0, 0.1, 10) == std::vector<int>{3});
}

TEST_CASE("select_transitions with min_mass drops a candidate that would leave a sliver") {
  // Two dense clusters with a gap between them, and sparse ends: every edge of a
  // populated run has a large transition index, the ones by the sparse ends included.
  std::vector<double> h(kDisparityLevels, 0.0);
  for (int i = 5; i <= 12; ++i) h[i] = h[240 + i] = 0.02;
  for (int i = 30; i <= 120; ++i) h[i] = 1.0;
  for (int i = 140; i <= 225; ++i) h[i] = 1.0;
  const double total = std::accumulate(h.begin(), h.end(), 0.0);
  for (double& v : h) v /= total;
  const std::vector<double> t = transition_index(h, 0.001);
  auto smallest_plane = [&](std::vector<int> cuts) {
    cuts.push_back(0);
    cuts.push_back(kDisparityLevels);  // the top interval holds the last bin
    std::sort(cuts.begin(), cuts.end());
    double least = 1.0;
    for (size_t j = 0; j + 1 < cuts.size(); ++j)
      least = std::min(least, std::accumulate(h.begin() + cuts[j], h.begin() + cuts[j + 1], 0.0));
    return least;
  };
  const std::vector<int> paper = select_transitions(t, h, 8, 0.1, 3);
  REQUIRE(paper.size() == 3);
  CHECK(smallest_plane(paper) < 0.01);  // the paper's rule cuts off a tail
  for (double min_mass : {0.05, 0.2}) {
    const std::vector<int> guarded = select_transitions(t, h, 8, 0.1, 3, min_mass);
    INFO("min_mass " << min_mass);
    CHECK(!guarded.empty());
    CHECK(smallest_plane(guarded) > min_mass);
  }
}

TEST_CASE("select_transitions properties on random histograms") {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> h(kDisparityLevels);
    for (double& v : h) v = u(rng) < 0.3 ? u(rng) : 0.0;
    const double total = std::accumulate(h.begin(), h.end(), 0.0);
    for (double& v : h) v /= total;
    const int xi = static_cast<int>(seed % 12);
    const int max_selected = 1 + static_cast<int>(seed % 9);
    const double min_mass = 0.02 * (seed % 4);
    const std::vector<double> t = transition_index(h, 0.001);
    const std::vector<int> s = select_transitions(t, h, xi, 0.1, max_selected, min_mass);
    INFO("seed " << seed << ", xi " << xi << ", max " << max_selected << ", min_mass " << min_mass);
    CHECK(static_cast<int>(s.size()) <= max_selected);
    std::vector<int> cuts = s;
    cuts.push_back(0);
    cuts.push_back(kDisparityLevels);
    std::sort(cuts.begin(), cuts.end());
    for (size_t j = 0; j + 1 < cuts.size(); ++j)  // every plane holds more than min_mass
      CHECK(std::accumulate(h.begin() + cuts[j], h.begin() + cuts[j + 1], 0.0) > min_mass);
    for (size_t a = 0; a < s.size(); ++a) {
      CHECK(s[a] > 0);
      CHECK(s[a] < kDisparityLevels - 1);
      CHECK(t[s[a]] > 0.1);
      for (size_t b = a + 1; b < s.size(); ++b) CHECK(std::abs(s[a] - s[b]) > xi);
    }
  }
}

TEST_CASE("plane_boundaries merges intervals without pixels") {
  std::vector<long long> counts(kDisparityLevels, 0);
  counts[0] = 5;
  counts[128] = 5;
  counts[255] = 5;
  // [0,1) [1,127) [127,254) [254,255]: the second is empty and joins the first.
  CHECK(plane_boundaries({1, 127, 254}, counts) == std::vector<int>{0, 127, 254, 255});
  // [0,40) is empty and joins the next one.
  counts[0] = 0;
  CHECK(plane_boundaries({40, 200}, counts) == std::vector<int>{0, 200, 255});
  // Nothing but the top level: one interval.
  counts.assign(kDisparityLevels, 0);
  counts[255] = 1;
  CHECK(plane_boundaries({10, 100}, counts) == std::vector<int>{0, 255});
}

TEST_CASE("normalize_disparity maps min..max to 0..255, any range") {
  cv::Mat d = (cv::Mat_<float>(1, 4) << -3.0f, -1.0f, 1.0f, 5.0f);
  const cv::Mat n = normalize_disparity(d);
  REQUIRE(n.type() == CV_8UC1);
  CHECK(n.at<uchar>(0, 0) == 0);
  CHECK(n.at<uchar>(0, 1) == 64);  // 2/8 * 255 = 63.75
  CHECK(n.at<uchar>(0, 2) == 128);
  CHECK(n.at<uchar>(0, 3) == 255);
  CHECK(cv::countNonZero(normalize_disparity(cv::Mat(3, 3, CV_32FC1, cv::Scalar(7.0f)))) == 0);
}

TEST_CASE("maps with K well separated flat levels give exactly K planes") {
  for (int k = 2; k <= 6; ++k) {
    for (uint32_t seed = 1; seed <= 5; ++seed) {
      // Levels spread over an arbitrary range, 28 or more normalised levels apart.
      std::mt19937 rng(seed * 100 + k);
      std::vector<float> levels(k);
      for (int i = 0; i < k; ++i) levels[i] = 2.0f + 10.0f * i + std::uniform_real_distribution<float>(0, 4)(rng);
      std::shuffle(levels.begin(), levels.end(), rng);
      const cv::Mat d = banded_map(levels, 24 + static_cast<int>(seed), 40);
      INFO("K " << k << ", seed " << seed);
      const std::vector<Plane> planes = slice_adaptive(d);
      REQUIRE(static_cast<int>(planes.size()) == k);
      check_plane_structure(planes, d);
      // Each plane holds one band: a boundary lies between every two adjacent levels.
      std::sort(levels.begin(), levels.end());
      const cv::Mat n = normalize_disparity(d);
      for (int j = 0; j < k; ++j) {
        const int band_level = n.at<uchar>(0, static_cast<int>(std::find(d.ptr<float>(0), d.ptr<float>(0) + d.cols,
                                                                          levels[j]) - d.ptr<float>(0)));
        CHECK(plane_of_level(planes, band_level) == j);
        CHECK(planes[j].pixel_count == 40LL * (24 + seed));
        CHECK(planes[j].disparity == Approx(band_level).margin(0.5));
      }
    }
  }
}

TEST_CASE("a smooth ramp gives few planes") {
  // Disparity rising over a tilted plane: every level is about equally frequent.
  cv::Mat d(300, 400, CV_32FC1);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) = 0.5f + 0.01f * x + 0.0137f * y;
  const std::vector<Plane> planes = slice_adaptive(d);
  INFO("planes " << planes.size());
  CHECK(planes.size() <= 3);
  check_plane_structure(planes, d);
}

TEST_CASE("the maximum count and xi spacing hold on random smooth maps (the paper's slicer)") {
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    const cv::Mat d = random_smooth_map(120, 90, seed);
    for (int max_planes : {1, 2, 3, 5, 8}) {
      for (int xi : {0, 4, 8, 16}) {
        SlicingParams p;
        p.slicer = Slicer::Paper;
        p.max_planes = max_planes;
        p.xi = xi;
        INFO("seed " << seed << ", max_planes " << max_planes << ", xi " << xi);
        const std::vector<Plane> planes = slice_adaptive(d, p);
        CHECK(static_cast<int>(planes.size()) <= max_planes);
        check_plane_structure(planes, d);
        const std::vector<int> b = interior_boundaries(planes);
        for (size_t i = 1; i < b.size(); ++i) CHECK(b[i] - b[i - 1] > xi);
      }
    }
  }
}

// Summed squared error, in levels, of the pixels of `levels` (CV_8UC1) to their plane's
// mean level.
double quantization_error(const std::vector<Plane>& planes, const cv::Mat& levels) {
  std::vector<double> sum(planes.size(), 0.0), sum2(planes.size(), 0.0), n(planes.size(), 0.0);
  for (auto it = levels.begin<uchar>(); it != levels.end<uchar>(); ++it) {
    const int j = plane_of_level(planes, *it);
    REQUIRE(j >= 0);
    n[j] += 1, sum[j] += *it, sum2[j] += double(*it) * *it;
  }
  double error = 0;
  for (size_t j = 0; j < planes.size(); ++j)
    if (n[j] > 0) error += sum2[j] - sum[j] * sum[j] / n[j];
  return error;
}

TEST_CASE("the optimal slicer makes the paper's count with no more error than its cuts or equal intervals") {
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    const cv::Mat d = random_smooth_map(120, 90, seed);
    const cv::Mat levels = normalize_disparity(d);
    for (int max_planes : {2, 4, 8, 16}) {
      SlicingParams p;
      p.max_planes = max_planes;
      p.slicer = Slicer::Paper;
      const std::vector<Plane> paper = slice_adaptive(d, p);
      p.slicer = Slicer::Optimal;
      const std::vector<Plane> optimal = slice_adaptive(d, p);
      const std::vector<Plane> uniform = slice_uniform(d, static_cast<int>(optimal.size()));
      INFO("seed " << seed << ", max_planes " << max_planes);
      check_plane_structure(optimal, d);
      CHECK(optimal.size() == paper.size());
      const double error = quantization_error(optimal, levels);
      CHECK(error <= quantization_error(paper, levels) * (1 + 1e-9));
      CHECK(error <= quantization_error(uniform, levels) * (1 + 1e-9));
    }
  }
}

TEST_CASE("a tear penalty moves the optimal cuts off populated levels of h") {
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    const cv::Mat d = random_smooth_map(120, 90, seed);
    SlicingParams p;
    const std::vector<double> h = slicing_histogram(normalize_disparity(d), p);
    auto torn = [&](const std::vector<Plane>& planes) {
      double sum = 0;
      for (int c : interior_boundaries(planes)) sum += h[c - 1] + h[c];
      return sum;
    };
    const std::vector<Plane> free_cuts = slice_adaptive(d, p);
    p.tear_penalty = 1e4;
    const std::vector<Plane> careful = slice_adaptive(d, p);
    INFO("seed " << seed);
    CHECK(careful.size() == free_cuts.size());
    CHECK(torn(careful) <= torn(free_cuts));
  }
}

TEST_CASE("parse_slicer knows paper and optimal") {
  CHECK(parse_slicer("paper") == Slicer::Paper);
  CHECK(parse_slicer("optimal") == Slicer::Optimal);
  CHECK_THROWS_WITH(parse_slicer("greedy"), Catch::Contains("not paper or optimal"));
}

TEST_CASE("a constant map gives one plane") {
  const cv::Mat d(50, 70, CV_32FC1, cv::Scalar(3.25f));
  const std::vector<Plane> planes = slice_adaptive(d);
  REQUIRE(planes.size() == 1);
  check_plane_structure(planes, d);
  CHECK(slice_uniform(d, 8).size() == 1);
}

TEST_CASE("1x1 and 2x3 maps work") {
  const cv::Mat one(1, 1, CV_32FC1, cv::Scalar(0.5f));
  const std::vector<Plane> planes = slice_adaptive(one);
  REQUIRE(planes.size() == 1);
  CHECK(planes[0].pixel_count == 1);
  const cv::Mat tiny = (cv::Mat_<float>(2, 3) << 1, 1, 5, 1, 9, 9);
  const std::vector<Plane> tiny_planes = slice_adaptive(tiny);
  check_plane_structure(tiny_planes, tiny);
  CHECK(tiny_planes.size() <= 3);
  check_plane_structure(slice_uniform(tiny, 3), tiny);
}

TEST_CASE("plane depth is the mean disparity mapped through the depth range") {
  const cv::Mat d = banded_map({0.0f, 1.0f}, 20, 20);
  SlicingParams p;
  p.range = {2.0, 50.0};
  const std::vector<Plane> planes = slice_adaptive(d, p);
  REQUIRE(planes.size() == 2);
  CHECK(planes[0].disparity == 0.0);
  CHECK(planes[1].disparity == 255.0);
  CHECK(planes[0].depth == Approx(50.0));
  CHECK(planes[1].depth == Approx(2.0));
}

TEST_CASE("uniform slicing: equal intervals, empty ones dropped") {
  cv::Mat ramp(10, 256, CV_32FC1);
  for (int x = 0; x < 256; ++x) ramp.col(x).setTo(static_cast<float>(x));
  const std::vector<Plane> four = slice_uniform(ramp, 4);
  REQUIRE(four.size() == 4);
  check_plane_structure(four, ramp);
  for (int j = 0; j < 4; ++j) {
    CHECK(four[j].disparity_lo == 64 * j);
    CHECK(four[j].pixel_count == 640);
  }
  CHECK(four[3].disparity_hi == 255);
  const std::vector<Plane> two_levels = slice_uniform(banded_map({1.0f, 2.0f}, 5, 5), 4);
  REQUIRE(two_levels.size() == 2);
  CHECK(two_levels[0].disparity_lo == 0);
  CHECK(two_levels[1].disparity_lo == 192);
  CHECK(slice_uniform(ramp, 255).size() == 255);
  CHECK_THROWS_AS(slice_uniform(ramp, 0), std::invalid_argument);
  CHECK_THROWS_AS(slice_uniform(ramp, 256), std::invalid_argument);
}

TEST_CASE("bad disparity maps and parameters are refused") {
  cv::Mat d(4, 4, CV_32FC1, cv::Scalar(1.0f));
  d.at<float>(2, 1) = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(slice_adaptive(d), Catch::Contains("NaN or infinite"));
  d.at<float>(2, 1) = std::numeric_limits<float>::infinity();
  CHECK_THROWS_WITH(slice_uniform(d, 4), Catch::Contains("NaN or infinite"));
  CHECK_THROWS_WITH(slice_adaptive(cv::Mat()), Catch::Contains("empty"));
  CHECK_THROWS_WITH(slice_adaptive(cv::Mat(4, 4, CV_8UC1, cv::Scalar(1))), Catch::Contains("CV_32FC1"));
  const cv::Mat ok(4, 4, CV_32FC1, cv::Scalar(1.0f));
  SlicingParams p;
  p.max_planes = 0;
  CHECK_THROWS_WITH(slice_adaptive(ok, p), Catch::Contains("max_planes"));
  p = {};
  p.eps = 0;
  CHECK_THROWS_WITH(slice_adaptive(ok, p), Catch::Contains("eps"));
  p = {};
  p.xi = -1;
  CHECK_THROWS_WITH(slice_adaptive(ok, p), Catch::Contains("xi"));
  p = {};
  p.border_erosion_size = 0;
  CHECK_THROWS_WITH(slice_adaptive(ok, p), Catch::Contains("border_erosion_size"));
  p = {};
  p.tear_penalty = -1;
  CHECK_THROWS_WITH(slice_adaptive(ok, p), Catch::Contains("tear_penalty"));
}
