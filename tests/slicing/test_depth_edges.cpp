// Depth edges snapped to the photo (slicing/depth_edges.h) and the layer borders cleaned
// at them (feather_depth_edges, slicing/assemble.h).
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "engine/isa.h"
#include "slicing/assemble.h"
#include "slicing/depth_edges.h"

using namespace ampi;

namespace {

// Two textured colours split at column `edge`: blue-ish left, red-ish right.
cv::Mat two_colour_photo(int w, int h, int edge, uint64_t seed) {
  cv::Mat photo(h, w, CV_8UC3);
  cv::RNG rng(seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int n = rng.uniform(-12, 13);
      photo.at<cv::Vec3b>(y, x) = x < edge ? cv::Vec3b(cv::saturate_cast<uchar>(170 + n), 110, 60)
                                           : cv::Vec3b(50, 70, cv::saturate_cast<uchar>(190 + n));
    }
  return photo;
}

// Disparity 0 left of `edge`, 1 from it on.
cv::Mat step_map(int w, int h, int edge) {
  cv::Mat d(h, w, CV_32FC1, cv::Scalar(0));
  d.colRange(edge, w).setTo(1.0);
  return d;
}

cv::Mat reduced(const cv::Mat& m, int factor) {
  cv::Mat out;
  cv::resize(m, out, {m.cols / factor, m.rows / factor}, 0, 0, cv::INTER_AREA);
  return out;
}

cv::Mat enlarged(const cv::Mat& m, cv::Size size) {
  cv::Mat out;
  cv::resize(m, out, size, 0, 0, cv::INTER_LINEAR);
  return out;
}

// How many pixels differ from the exact step.
int off_step(const cv::Mat& d, int edge) {
  int wrong = 0;
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) wrong += d.at<float>(y, x) != (x < edge ? 0.0f : 1.0f);
  return wrong;
}

}  // namespace

TEST_CASE("a soft depth step becomes a step on the photo's colour edge") {
  // The colour edge falls inside a reduced pixel; the windows (long side / 64 = 5 px)
  // span the ramp of a map reduced 4 times.
  const int w = 320, h = 32, edge = 157;
  const cv::Mat photo = two_colour_photo(w, h, edge, 3);
  const cv::Mat small = reduced(step_map(w, h, edge), 4);
  SECTION("from a map smaller than the photo (a network's)") {
    const DepthEdges out = snap_depth_edges(photo, small);
    CHECK(off_step(enlarged(small, photo.size()), edge) > 4 * h);  // the ramp before
    CHECK(off_step(out.disparity, edge) == 0);
    CHECK(out.band.at<uchar>(h / 2, edge) == 255);
    CHECK(out.band.at<uchar>(h / 2, 5) == 0);
  }
  SECTION("from a soft map of the photo's size (ampi run --depth)") {
    const DepthEdges out = snap_depth_edges(photo, enlarged(small, photo.size()));
    CHECK(off_step(out.disparity, edge) == 0);
  }
  SECTION("every ISA the host runs gives the same map") {
    const DepthEdges reference = snap_depth_edges(photo, small, {}, Isa::Scalar);
    for (Isa isa : runnable_isas()) {
      const DepthEdges out = snap_depth_edges(photo, small, {}, isa);
      INFO(isa_name(isa));
      CHECK(cv::norm(out.disparity, reference.disparity, cv::NORM_INF) == 0);
      CHECK(cv::norm(out.band, reference.band, cv::NORM_INF) == 0);
    }
  }
}

TEST_CASE("maps without a soft edge come back as they were") {
  const int w = 120, h = 40;
  cv::Mat photo(h, w, CV_8UC3);
  cv::RNG(5).fill(photo, cv::RNG::UNIFORM, cv::Scalar::all(0), cv::Scalar::all(256));
  SECTION("a slope (a ground plane), however steep: no edge anywhere") {
    cv::Mat slope(h / 4, w / 4, CV_32FC1);  // the whole range over 10 pixels
    for (int y = 0; y < slope.rows; ++y)
      for (int x = 0; x < slope.cols; ++x) slope.at<float>(y, x) = float(y);
    const DepthEdges out = snap_depth_edges(photo, slope);
    CHECK(cv::norm(out.disparity, enlarged(slope, photo.size()), cv::NORM_INF) == 0);
    CHECK(cv::countNonZero(out.band) == 0);
  }
  SECTION("a hard step at the photo's size: its pixels are at the extremes already") {
    const cv::Mat step = step_map(w, h, 61);
    const DepthEdges out = snap_depth_edges(photo, step);
    CHECK(cv::norm(out.disparity, step, cv::NORM_INF) == 0);
    CHECK(cv::countNonZero(out.band) > 0);
  }
  SECTION("a constant map") {
    const DepthEdges out = snap_depth_edges(photo, cv::Mat(h, w, CV_32FC1, cv::Scalar(2.5)));
    CHECK(cv::countNonZero(out.disparity != 2.5f) == 0);
    CHECK(cv::countNonZero(out.band) == 0);
  }
}

TEST_CASE("snap_depth_edges refuses bad inputs with a message") {
  const cv::Mat photo(40, 60, CV_8UC3, cv::Scalar(1, 2, 3));
  const cv::Mat map(10, 15, CV_32FC1, cv::Scalar(0));
  CHECK_THROWS_WITH(snap_depth_edges(cv::Mat(40, 60, CV_8UC1), map), Catch::Contains("BGR"));
  CHECK_THROWS_WITH(snap_depth_edges(photo, cv::Mat(10, 15, CV_8UC1)), Catch::Contains("CV_32FC1"));
  CHECK_THROWS_WITH(snap_depth_edges(photo, cv::Mat(41, 60, CV_32FC1, cv::Scalar(0))), Catch::Contains("larger"));
  cv::Mat nan = map.clone();
  nan.at<float>(3, 4) = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(snap_depth_edges(photo, nan), Catch::Contains("NaN"));
  DepthEdgeParams p;
  p.min_step = 0;
  CHECK_THROWS_WITH(snap_depth_edges(photo, map, p), Catch::Contains("min_step"));
  p = {};
  p.min_growth_share = 0.5;
  CHECK_THROWS_WITH(snap_depth_edges(photo, map, p), Catch::Contains("min_growth_share"));
  p = {};
  p.ramp_margin = 0.5;
  CHECK_THROWS_WITH(snap_depth_edges(photo, map, p), Catch::Contains("ramp_margin"));
}

TEST_CASE("feathering moves the far layer's border pixels at a depth edge into the near layer") {
  const int w = 30, h = 20;
  cv::Mat photo(h, w, CV_8UC3);
  cv::RNG(9).fill(photo, cv::RNG::UNIFORM, cv::Scalar::all(1), cv::Scalar::all(256));
  Mpi mpi;
  mpi.planes.resize(2);
  const cv::Rect object(10, 5, 8, 8);
  cv::Mat back, front = cv::Mat::zeros(h, w, CV_8UC4);
  cv::cvtColor(photo, back, cv::COLOR_BGR2BGRA);
  back(object).setTo(cv::Scalar(0, 0, 0, 0));
  cv::cvtColor(photo(object), front(object), cv::COLOR_BGR2BGRA);
  mpi.layers = {back, front};

  SECTION("no band: nothing moves") {
    Mpi copy = mpi;
    copy.layers = {back.clone(), front.clone()};
    CHECK(feather_depth_edges(copy, photo, cv::Mat::zeros(h, w, CV_8UC1), 2) == 0);
    CHECK(cv::norm(copy.layers[0], back, cv::NORM_INF) == 0);
  }
  SECTION("rings of one and two pixels get alpha 2/3 and 1/3 in the near layer") {
    const cv::Mat band(h, w, CV_8UC1, cv::Scalar(255));
    const int64_t moved = feather_depth_edges(mpi, photo, band, 2);
    CHECK(moved == (12 * 12 - 8 * 8));
    const cv::Vec4b ring1 = mpi.layers[1].at<cv::Vec4b>(4, 12), ring2 = mpi.layers[1].at<cv::Vec4b>(3, 12);
    CHECK(ring1[3] == 170);
    CHECK(ring2[3] == 85);
    CHECK(ring1[0] == photo.at<cv::Vec3b>(4, 12)[0]);
    CHECK(mpi.layers[0].at<cv::Vec4b>(4, 12)[3] == 0);
    CHECK(mpi.layers[0].at<cv::Vec4b>(2, 12)[3] == 255);  // three pixels out: untouched
    CHECK(mpi.layers[1].at<cv::Vec4b>(8, 14)[3] == 255);  // the object itself: untouched
  }
}
