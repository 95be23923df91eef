#include <catch2/catch.hpp>

#include "pipeline/video.h"
#include "render/renderer.h"

using namespace ampi;

namespace {

// One opaque plane filling the frame.
Mpi single_plane(double depth) {
  Mpi mpi;
  mpi.camera = camera_from_fov(200, 100, 60);
  Plane plane;
  plane.depth = depth;
  mpi.planes = {plane};
  mpi.layers = {cv::Mat(100, 200, CV_8UC4, cv::Scalar(90, 120, 150, 255))};
  return mpi;
}

}  // namespace

TEST_CASE("overscan zoom is 1 for a still camera and just hides the edges of a moved one") {
  const Mpi mpi = single_plane(2.0);
  CHECK(overscan_zoom(mpi, {Pose{}}) == Approx(1.0));
  Pose moved;
  moved.t = {0.1, -0.05, 0};  // the plane shifts by fx * t / z pixels
  const double zoom = overscan_zoom(mpi, {Pose{}, moved});
  // The plane moves about fx * 0.1 / 2 = 8.7 px sideways and 4.3 px up and down: about
  // 9% of the half-width and of the half-height.
  CHECK(zoom > 1.09);
  CHECK(zoom < 1.10);

  const Renderer renderer(mpi);
  moved.zoom = zoom * 1.001;
  cv::Mat frame = renderer.render(moved);
  CHECK(cv::countNonZero(frame.reshape(1) == 0) == 0);  // no black edge left
  moved.zoom = 1;
  frame = renderer.render(moved);
  CHECK(cv::countNonZero(frame.reshape(1) == 0) > 0);  // without it there is one
}
