#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include <stdexcept>
#include <string>

#include "inpaint/mpi_inpaint.h"
#include "inpaint/push_pull.h"

using namespace ampi;

namespace {

// A back layer covering the left half and a front layer (a square) overlapping its
// right edge: the back layer's margin hidden behind the square must be filled.
Mpi two_layer_mpi() {
  Mpi mpi;
  cv::Mat back(60, 80, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  back(cv::Rect(0, 0, 40, 60)).setTo(cv::Scalar(10, 200, 30, 255));
  cv::Mat front(60, 80, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  front(cv::Rect(30, 10, 30, 30)).setTo(cv::Scalar(250, 0, 0, 255));
  mpi.layers = {back, front};
  mpi.planes.resize(2);
  return mpi;
}

}  // namespace

TEST_CASE("occlusion masks: the dilated border, hidden by nearer layers, outside the layer") {
  Mpi mpi = two_layer_mpi();
  const auto masks = occlusion_masks(mpi.layers, {5});
  REQUIRE(masks.size() == 2);
  CHECK(cv::countNonZero(masks[1]) == 0);  // nothing is nearer than the front layer
  // Hidden by the square and within 5 px of the back layer: x in [40, 45), y in [10, 40).
  CHECK(cv::countNonZero(masks[0]) == 5 * 30);
  CHECK(masks[0].at<uchar>(20, 42) == 255);
  CHECK(masks[0].at<uchar>(20, 46) == 0);   // beyond the margin
  CHECK(masks[0].at<uchar>(5, 42) == 0);    // not hidden by a nearer layer
  CHECK(masks[0].at<uchar>(20, 35) == 0);   // the layer's own pixel
}

TEST_CASE("inpaint_mpi fills only masked pixels, makes them opaque, keeps the rest") {
  Mpi mpi = two_layer_mpi();
  const Mpi before{mpi.camera, mpi.range, mpi.planes, {mpi.layers[0].clone(), mpi.layers[1].clone()}};
  const int64_t filled = inpaint_mpi(mpi, push_pull_filler(), {5});
  CHECK(filled == 150);
  const auto masks = occlusion_masks(before.layers, {5});
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      const cv::Vec4b now = mpi.layers[0].at<cv::Vec4b>(y, x);
      if (masks[0].at<uchar>(y, x)) {
        REQUIRE(now[3] == 255);
        // The fill continues the back layer's uniform colour.
        REQUIRE(std::abs(now[1] - 200) <= 2);
      } else {
        REQUIRE(now == before.layers[0].at<cv::Vec4b>(y, x));  // transparent stays transparent
      }
    }
  CHECK(cv::norm(mpi.layers[1], before.layers[1], cv::NORM_INF) == 0);
}

TEST_CASE("push-pull reproduces known pixels and interpolates holes smoothly") {
  cv::Mat img(32, 32, CV_8UC3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) img.at<cv::Vec3b>(y, x) = {uchar(x * 8), 100, 50};
  cv::Mat hole(32, 32, CV_8UC1, cv::Scalar(0));
  hole(cv::Rect(12, 12, 8, 8)).setTo(255);
  const cv::Mat known = ~hole;
  cv::Mat damaged = img.clone();
  damaged.setTo(cv::Scalar(0, 0, 255), hole);
  const cv::Mat out = push_pull_fill(damaged, known, hole);
  cv::Mat diff;
  cv::absdiff(out, img, diff);
  CHECK(cv::norm(diff, cv::NORM_INF, known) == 0);
  // Inside the hole, close to the ramp (blurred by the pyramid, so loosely).
  CHECK(cv::mean(diff, hole)[0] < 24);
  CHECK(cv::mean(diff, hole)[2] < 3);
  CHECK(cv::norm(diff, cv::NORM_INF, hole) < 48);
}

TEST_CASE("occlusion masks equal the paper's iterated 3x3 dilation on random layers") {
  cv::RNG rng(1234);
  for (int iterations : {1, 3, 7, 12}) {
    std::vector<cv::Mat> layers;
    for (int j = 0; j < 3; ++j) {
      cv::Mat layer(50, 70, CV_8UC4, cv::Scalar(0, 0, 0, 0));
      for (int blob = 0; blob < 4; ++blob)
        cv::circle(layer, {rng.uniform(0, 70), rng.uniform(0, 50)}, rng.uniform(2, 12),
                   cv::Scalar(1, 2, 3, 255), cv::FILLED);
      layers.push_back(layer);
    }
    const auto masks = occlusion_masks(layers, {iterations});
    cv::Mat nearer(50, 70, CV_8UC1, cv::Scalar(0));
    for (int j = 2; j >= 0; --j) {
      cv::Mat coverage, grown;
      cv::extractChannel(layers[j], coverage, 3);
      cv::dilate(coverage, grown, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, iterations);
      const cv::Mat expected = grown & ~coverage & nearer;
      INFO("iterations " << iterations << ", layer " << j);
      CHECK(cv::countNonZero(expected != masks[j]) == 0);
      nearer |= coverage;
    }
  }
}

TEST_CASE("inpainter names: parsed, named back, and a bad one refused with the choices") {
  for (Inpainter kind : {Inpainter::Network, Inpainter::Harmonic, Inpainter::PushPull})
    CHECK(parse_inpainter(inpainter_name(kind)) == kind);
  CHECK(std::string(inpainter_name(Inpainter::Harmonic)) == "harmonic");
  try {
    parse_inpainter("telea");
    FAIL("no error");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()) == "--inpainter: 'telea' is not network, harmonic or push-pull");
  }
}

TEST_CASE("inpaint_mpi with the harmonic filler continues the back layer's colour") {
  Mpi mpi = two_layer_mpi();
  const cv::Mat back = mpi.layers[0].clone();
  CHECK(inpaint_mpi(mpi, harmonic_filler(), {5}) == 150);
  const auto masks = occlusion_masks({back, mpi.layers[1]}, {5});
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x)
      if (masks[0].at<uchar>(y, x))
        REQUIRE(mpi.layers[0].at<cv::Vec4b>(y, x) == cv::Vec4b(10, 200, 30, 255));
}
