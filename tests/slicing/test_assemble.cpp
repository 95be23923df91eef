#include <catch2/catch.hpp>
#include <vector>

#include "slicing/adaptive.h"
#include "slicing/assemble.h"

using namespace ampi;

namespace {

cv::Mat random_photo(int w, int h, uint64_t seed) {
  cv::Mat m(h, w, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, cv::Scalar::all(1), cv::Scalar::all(256));  // no black pixels
  return m;
}

// A horizontal disparity ramp 0..255 (normalised), so every level occurs.
cv::Mat ramp_disparity(int w, int h) {
  cv::Mat d(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d.at<float>(y, x) = static_cast<float>(x) + 0.3f * static_cast<float>(y % 3);
  return d;
}

// Back-to-front "over" of straight-alpha layers: the coverage (alpha) of the result.
double composite_alpha(const std::vector<cv::Mat>& layers, int y, int x) {
  double alpha = 0.0;
  for (const cv::Mat& layer : layers) {
    const double a = layer.at<cv::Vec4b>(y, x)[3] / 255.0;
    alpha = a + (1.0 - a) * alpha;
  }
  return alpha;
}

}  // namespace

TEST_CASE("hard assembly: every pixel opaque in exactly the plane that holds it") {
  const cv::Mat bgr = random_photo(300, 20, 7);
  const cv::Mat d = ramp_disparity(300, 20);
  const std::vector<Plane> planes = slice_uniform(d, 5);
  const Camera cam = camera_from_fov(300, 20, 60);
  const Mpi mpi = assemble_mpi(bgr, d, planes, cam, {1, 50});
  REQUIRE(mpi.layers.size() == planes.size());
  CHECK(mpi.range.far == 50);
  CHECK(mpi.camera.fx == cam.fx);
  const cv::Mat levels = normalize_disparity(d);
  for (const cv::Mat& layer : mpi.layers) REQUIRE(layer.type() == CV_8UC4);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) {
      const int owner = plane_of_level(planes, levels.at<uchar>(y, x));
      INFO("pixel " << x << "," << y << " level " << int(levels.at<uchar>(y, x)) << " plane " << owner);
      REQUIRE(owner >= 0);
      for (size_t j = 0; j < planes.size(); ++j) {
        const cv::Vec4b px = mpi.layers[j].at<cv::Vec4b>(y, x);
        const cv::Vec3b c = bgr.at<cv::Vec3b>(y, x);
        if (static_cast<int>(j) == owner)
          CHECK((px == cv::Vec4b(c[0], c[1], c[2], 255)));
        else
          CHECK((px == cv::Vec4b(0, 0, 0, 0)));
      }
    }
  for (size_t j = 0; j < planes.size(); ++j) {
    std::vector<cv::Mat> channels;
    cv::split(mpi.layers[j], channels);
    CHECK(cv::countNonZero(channels[3]) == planes[j].pixel_count);
  }
}

TEST_CASE("soft alpha covers every pixel fully and reduces to the hard cut at width 0") {
  const cv::Mat bgr = random_photo(256, 6, 3);
  const cv::Mat d = ramp_disparity(256, 6);
  const std::vector<Plane> planes = slice_uniform(d, 4);
  const Camera cam = camera_from_fov(256, 6, 60);
  for (double width : {1.0, 4.0, 16.0}) {
    INFO("soft_alpha " << width);
    const Mpi soft = assemble_mpi(bgr, d, planes, cam, {}, width);
    int partial = 0;
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x) {
        INFO("pixel " << x << "," << y);
        CHECK(composite_alpha(soft.layers, y, x) == Approx(1.0).margin(1e-9));
        for (const cv::Mat& layer : soft.layers) {
          const cv::Vec4b px = layer.at<cv::Vec4b>(y, x);
          if (px[3] > 0 && px[3] < 255) ++partial;
          if (px[3] == 0) CHECK((px == cv::Vec4b(0, 0, 0, 0)));
        }
      }
    // About `width` levels per cut are blended, 3 cuts, 6 rows.
    CHECK(partial > 0);
    CHECK(partial <= 6 * 3 * (static_cast<int>(width) + 1));
  }
  const Mpi hard = assemble_mpi(bgr, d, planes, cam, {}, 0.0);
  const Mpi tiny = assemble_mpi(bgr, d, planes, cam, {}, 1e-4);
  for (size_t j = 0; j < planes.size(); ++j) CHECK(cv::norm(hard.layers[j], tiny.layers[j], cv::NORM_INF) == 0);
}

TEST_CASE("assembly refuses mismatched inputs") {
  const cv::Mat bgr(10, 12, CV_8UC3, cv::Scalar(9, 9, 9));
  const cv::Mat d = ramp_disparity(12, 10);
  const std::vector<Plane> planes = slice_uniform(d, 2);
  const Camera cam = camera_from_fov(12, 10, 60);
  CHECK_THROWS_WITH(assemble_mpi(bgr, ramp_disparity(11, 10), planes, cam, {}), Catch::Contains("11x10"));
  CHECK_THROWS_WITH(assemble_mpi(bgr, d, planes, camera_from_fov(24, 20, 60), {}), Catch::Contains("24x20"));
  CHECK_THROWS_WITH(assemble_mpi(cv::Mat(10, 12, CV_8UC1), d, planes, cam, {}), Catch::Contains("BGR"));
  CHECK_THROWS_WITH(assemble_mpi(bgr, d, {}, cam, {}), Catch::Contains("no planes"));
  CHECK_THROWS_WITH(assemble_mpi(bgr, d, {planes[1], planes[0]}, cam, {}), Catch::Contains("back to front"));
  CHECK_THROWS_WITH(assemble_mpi(bgr, d, planes, cam, {}, -1), Catch::Contains("soft_alpha"));
}
