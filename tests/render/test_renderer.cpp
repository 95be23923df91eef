// The tiled renderer on whole frames: against exact composites, shifts and the naive
// warpPerspective compositor, on every ISA, tile size and thread count. Its per-row
// kernels against the scalar reference: tests/kernels/test_composite_rows.cpp.
#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "render/renderer.h"
#include "synthetic_mpi.h"

using namespace ampi;

namespace {

// Over-composites the layers at the identity pose in double precision: the exact answer.
cv::Mat composite_in_place(const Mpi& mpi) {
  cv::Mat out(mpi.layers[0].size(), CV_8UC3);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      double acc[3] = {0, 0, 0};
      for (const cv::Mat& layer : mpi.layers) {
        const cv::Vec4b p = layer.at<cv::Vec4b>(y, x);
        const double a = p[3] / 255.0;
        for (int k = 0; k < 3; ++k) acc[k] = p[k] / 255.0 * a + acc[k] * (1 - a);
      }
      for (int k = 0; k < 3; ++k) out.at<cv::Vec3b>(y, x)[k] = cv::saturate_cast<uint8_t>(acc[k] * 255.0);
    }
  return out;
}

int max_difference(const cv::Mat& a, const cv::Mat& b) {
  double m = 0;
  cv::minMaxLoc(cv::abs(cv::Mat(a - b)) + cv::abs(cv::Mat(b - a)), nullptr, &m);
  return static_cast<int>(m);
}

double mean_difference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar m = cv::mean(d);
  return (m[0] + m[1] + m[2]) / 3.0;
}

Pose moved(double tx, double ty, double tz, cv::Vec3d degrees = {0, 0, 0}, double zoom = 1.0) {
  Pose p;
  p.t = {tx, ty, tz};
  p.R = rotation_from_degrees(degrees);
  p.zoom = zoom;
  return p;
}

// A spread of poses: translations, a rotation, a zoom, and all of them together.
std::vector<Pose> test_poses() {
  return {moved(0.05, 0, 0),  moved(-0.03, 0.04, 0),  moved(0, 0, -0.3),
          moved(0, 0, 0.2, {1.5, -2, 3}), moved(0.02, -0.01, 0.1, {0, 0, 0}, 1.15),
          moved(-0.04, 0.02, -0.2, {-1, 2, -4}, 0.9)};
}

}  // namespace

TEST_CASE("the identity pose reproduces a fully covered MPI exactly") {
  for (Isa isa : runnable_isas()) {
    for (uint32_t seed : {1u, 2u, 3u}) {
      INFO("isa " << isa_name(isa) << ", seed " << seed);
      const Mpi mpi = test::synthetic_mpi(61, 37, 5, seed, test::Alpha::Binary);
      ThreadPool pool(2);
      const cv::Mat got = Renderer(mpi, {64, 16, isa}).render(Pose{}, pool);
      CHECK(max_difference(got, composite_in_place(mpi)) == 0);
      // Soft alpha: the half-float premultiplied layers round within one level.
      const Mpi soft = test::synthetic_mpi(61, 37, 5, seed, test::Alpha::Soft);
      CHECK(max_difference(Renderer(soft, {64, 16, isa}).render(Pose{}, pool), composite_in_place(soft)) <= 1);
    }
  }
}

TEST_CASE("a fronto-parallel plane at depth z shifts by fx * t / z pixels") {
  const Mpi mpi = test::synthetic_mpi(80, 50, 1, 7, test::Alpha::Binary);
  const double z = mpi.planes[0].depth, fx = mpi.camera.fx, fy = mpi.camera.fy;
  const cv::Mat source = composite_in_place(mpi);
  ThreadPool pool(2);
  for (Isa isa : runnable_isas()) {
    const Renderer renderer(mpi, {64, 16, isa});
    for (int shift : {-9, -1, 3, 11}) {
      INFO("isa " << isa_name(isa) << ", shift " << shift << " px");
      const cv::Mat right = renderer.render(moved(shift * z / fx, 0, 0), pool);
      const cv::Mat down = renderer.render(moved(0, shift * z / fy, 0), pool);
      const int n = std::abs(shift);
      const cv::Rect kept_x(std::max(0, shift), 0, source.cols - n, source.rows);
      const cv::Rect kept_y(0, std::max(0, shift), source.cols, source.rows - n);
      CHECK(max_difference(right(kept_x), source(kept_x - cv::Point(shift, 0))) == 0);
      CHECK(max_difference(down(kept_y), source(kept_y - cv::Point(0, shift))) == 0);
      // What moved in from outside the layer is transparent: black.
      const cv::Rect uncovered_x(shift > 0 ? 0 : source.cols - n, 0, n, source.rows);
      CHECK(cv::countNonZero(right(uncovered_x).reshape(1)) == 0);
    }
    // Half a pixel: every output pixel is the mean of two neighbours.
    const cv::Mat half = renderer.render(moved(0.5 * z / fx, 0, 0), pool);
    cv::Mat expected;
    cv::Mat a = source(cv::Rect(0, 0, source.cols - 1, source.rows)), b = source(cv::Rect(1, 0, source.cols - 1, source.rows));
    cv::addWeighted(a, 0.5, b, 0.5, 0.0, expected);
    INFO("isa " << isa_name(isa) << ", half-pixel shift");
    CHECK(max_difference(half(cv::Rect(1, 0, source.cols - 1, source.rows)), expected) <= 1);
  }
}

TEST_CASE("SIMD and scalar renderers agree on whole frames") {
  const Mpi mpi = test::synthetic_mpi(133, 71, 6, 21, test::Alpha::Soft);
  ThreadPool pool(2);
  const Renderer scalar(mpi, {64, 16, Isa::Scalar});
  for (Isa isa : runnable_isas()) {
    const Renderer simd(mpi, {64, 16, isa});
    int pose_index = 0;
    for (const Pose& pose : test_poses()) {
      INFO("isa " << isa_name(isa) << ", pose " << pose_index++ << ", seed 21");
      CHECK(max_difference(simd.render(pose, pool), scalar.render(pose, pool)) <= 1);
    }
  }
}

TEST_CASE("the compositor agrees with the naive warpPerspective reference") {
  for (uint32_t seed : {31u, 32u}) {
    const Mpi mpi = test::synthetic_mpi(160, 96, 8, seed, test::Alpha::Soft);
    const Renderer renderer(mpi);
    int pose_index = 0;
    for (const Pose& pose : test_poses()) {
      INFO("seed " << seed << ", pose " << pose_index++);
      const cv::Mat fast = renderer.render(pose), naive = render_naive(mpi, pose);
      // warpPerspective quantises coordinates to 1/32 pixel; the textures are smooth.
      CHECK(mean_difference(fast, naive) < 0.5);
      CHECK(max_difference(fast, naive) <= 6);
    }
  }
}

TEST_CASE("a layer with one visible pixel is drawn wherever it lands (tile skipping)") {
  // The occupancy blocks and the projected tile footprints must never skip a tile the
  // pixel reaches: put it near block and tile boundaries and move it by fractions.
  std::mt19937 rng(41);
  INFO("seed 41");
  for (int trial = 0; trial < 12; ++trial) {
    Mpi mpi = test::synthetic_mpi(96, 64, 2, 41 + trial, test::Alpha::Binary);
    mpi.layers[0].setTo(cv::Scalar(0, 0, 0, 255));
    mpi.layers[1].setTo(cv::Scalar::all(0));
    const int px = 15 + 16 * (trial % 5) + trial % 2, py = 15 + 16 * (trial % 3) + trial % 2;
    mpi.layers[1].at<cv::Vec4b>(py, px) = cv::Vec4b(255, 255, 255, 255);
    const double shift = std::uniform_real_distribution<double>(-3.0, 3.0)(rng);
    const Pose pose = moved(shift * mpi.planes[1].depth / mpi.camera.fx, 0.7 * mpi.planes[1].depth / mpi.camera.fy, 0);
    INFO("trial " << trial << ", pixel (" << px << ", " << py << "), shift " << shift);
    const cv::Mat fast = Renderer(mpi, {8, 4, active_isa()}).render(pose), naive = render_naive(mpi, pose);
    CHECK(max_difference(fast, naive) <= 6);
    CHECK(cv::countNonZero(fast.reshape(1)) > 0);
  }
}

TEST_CASE("tile sizes and thread counts give identical frames") {
  const Mpi mpi = test::synthetic_mpi(150, 90, 5, 51, test::Alpha::Soft);
  ThreadPool one(1), two(2), three(3);
  const Pose pose = moved(0.03, -0.02, 0.1, {1, -1, 2}, 1.05);
  const cv::Mat expected = Renderer(mpi, {64, 16, active_isa()}).render(pose, one);
  struct Case {
    int tile_width, tile_height;
    ThreadPool* pool;
  };
  for (const Case& c : {Case{64, 16, &two}, Case{7, 5, &two}, Case{1, 1, &three},
                        Case{150, 90, &two}, Case{500, 500, &one}, Case{33, 8, &three}}) {
    INFO("tiles " << c.tile_width << "x" << c.tile_height << ", threads " << c.pool->size() << ", seed 51");
    CHECK(max_difference(Renderer(mpi, {c.tile_width, c.tile_height, active_isa()}).render(pose, *c.pool), expected) == 0);
  }
}

TEST_CASE("a renderer that consumes its MPI draws the same frames and leaves no layers") {
  const Mpi mpi = test::synthetic_mpi(150, 90, 5, 53, test::Alpha::Soft);
  Mpi consumed = mpi;
  for (cv::Mat& layer : consumed.layers) layer = layer.clone();  // nothing shared with mpi
  const Renderer kept(mpi), took(std::move(consumed));
  CHECK(consumed.layers.empty());
  CHECK(consumed.planes.size() == mpi.planes.size());
  int pose_index = 0;
  for (const Pose& pose : test_poses()) {
    INFO("pose " << pose_index++ << ", seed 53");
    CHECK(max_difference(took.render(pose), kept.render(pose)) == 0);
  }
}

TEST_CASE("culling empty and hidden planes leaves every pixel unchanged") {
  // Binary discs give tiles covered by an opaque plane (the planes behind are skipped)
  // and tiles a plane misses (skipped too); small tiles make both frequent.
  for (uint32_t seed : {81u, 82u, 83u}) {
    for (test::Alpha kind : {test::Alpha::Binary, test::Alpha::Soft}) {
      const Mpi mpi = test::synthetic_mpi(120, 80, 6, seed, kind);
      const Renderer culled(mpi, {8, 4, active_isa(), true}), full(mpi, {8, 4, active_isa(), false});
      int pose_index = 0;
      for (const Pose& pose : test_poses()) {
        INFO("seed " << seed << ", soft alpha " << (kind == test::Alpha::Soft) << ", pose " << pose_index++);
        CHECK(max_difference(culled.render(pose), full.render(pose)) == 0);
      }
    }
  }
}

TEST_CASE("planes behind the new camera are transparent") {
  const Mpi mpi = test::synthetic_mpi(40, 30, 3, 61, test::Alpha::Binary);
  // Move the camera forward past the nearest plane: it must vanish, the others remain.
  const double past_nearest = 0.5 * (mpi.planes[2].depth + mpi.planes[1].depth);
  Mpi without_nearest = mpi;
  without_nearest.layers[2].setTo(cv::Scalar::all(0));
  const Pose pose = moved(0, 0, -past_nearest);
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa) << ", seed 61");
    CHECK(max_difference(Renderer(mpi, {64, 16, isa}).render(pose),
                         Renderer(without_nearest, {64, 16, isa}).render(pose)) == 0);
  }
}

TEST_CASE("MPIs the renderer cannot draw are refused with the reason") {
  const Mpi good = test::synthetic_mpi(20, 10, 3, 71, test::Alpha::Binary);
  Mpi no_planes = good;
  no_planes.planes.clear();
  no_planes.layers.clear();
  CHECK_THROWS_WITH(Renderer(no_planes), Catch::Contains("no planes"));
  Mpi wrong_size = good;
  wrong_size.layers[1] = cv::Mat(11, 20, CV_8UC4, cv::Scalar::all(0));
  CHECK_THROWS_WITH(Renderer(wrong_size), Catch::Contains("layer 1") && Catch::Contains("20x10"));
  Mpi wrong_type = good;
  wrong_type.layers[0] = cv::Mat(10, 20, CV_8UC3, cv::Scalar::all(0));
  CHECK_THROWS_WITH(Renderer(wrong_type), Catch::Contains("layer 0"));
  Mpi front_to_back = good;
  std::swap(front_to_back.planes[0], front_to_back.planes[2]);
  CHECK_THROWS_WITH(Renderer(front_to_back), Catch::Contains("back to front"));
  Mpi bad_depth = good;
  bad_depth.planes[2].depth = 0;
  CHECK_THROWS_WITH(render_naive(bad_depth, Pose{}), Catch::Contains("layer 2") && Catch::Contains("depth"));
  Mpi missing_layer = good;
  missing_layer.layers.pop_back();
  CHECK_THROWS_WITH(Renderer(missing_layer), Catch::Contains("2 layers for 3 planes"));
}
