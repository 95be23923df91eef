// eval/edge_eval.h: scenes whose new views are known exactly, and the judge that traces
// what an MPI shows. The exact MPI scores nothing wrong; the disk scene (a disk over a
// background, its map made at a quarter of the size) tears without edge snapping and
// stays whole with it.
#include <catch2/catch.hpp>

#include "eval/edge_eval.h"
#include "pipeline/make_mpi.h"

using namespace ampi;

namespace {

const cv::Size kSize(320, 240);

const EdgeScene& scene_named(const std::vector<EdgeScene>& scenes, const std::string& name) {
  for (const EdgeScene& s : scenes)
    if (s.name == name) return s;
  FAIL("no scene " << name);
  return scenes.front();
}

Pose pose_at(double tx, double ty) {
  Pose pose;
  pose.t = {tx, ty, 0};
  return pose;
}

MpiResult make(const EdgeScene& scene, const cv::Mat& disparity, bool snap) {
  MpiOptions options;
  options.inpainter = Inpainter::PushPull;
  options.snap_depth_edges = snap;
  options.keep_fill_masks = true;
  MpiMaker maker(options);
  Progress quiet(true);
  return maker.make_from_disparity(scene.photo, disparity, quiet);
}

}  // namespace

TEST_CASE("the scene set: a background and objects in front of it, composited") {
  const std::vector<EdgeScene> scenes = edge_scenes(kSize, 1);
  REQUIRE(scenes.size() == 4);
  for (const EdgeScene& s : scenes) {
    INFO(s.name);
    REQUIRE(s.surfaces.size() >= 2);
    CHECK(s.photo.size() == kSize);
    CHECK(cv::countNonZero(s.surfaces[0].coverage != 1.0f) == 0);  // the background covers all
    double lo = 0, hi = 0;
    cv::minMaxLoc(s.disparity, &lo, &hi);
    CHECK(lo == Approx(0.25));
    CHECK(hi == Approx(1.0));
  }
  CHECK(edge_scenes(kSize, 1)[0].photo.at<cv::Vec3b>(10, 10) == scenes[0].photo.at<cv::Vec3b>(10, 10));
  CHECK_THROWS_WITH(edge_scenes({32, 32}, 1), Catch::Contains("at least"));
}

TEST_CASE("soften_disparity: made at a fraction of the size and enlarged, or left hard") {
  const std::vector<EdgeScene> scenes = edge_scenes(kSize, 1);
  const EdgeScene& disk = scenes[0];
  CHECK(cv::norm(soften_disparity(disk.disparity, 1), disk.disparity, cv::NORM_INF) == 0);
  const cv::Mat soft = soften_disparity(disk.disparity, 4);
  CHECK(cv::countNonZero((soft > 0.3f) & (soft < 0.95f)) > 100);  // a ramp around the disk
  CHECK_THROWS(soften_disparity(disk.disparity, 0));
}

TEST_CASE("the exact MPI scores nothing wrong at any pose") {
  const Camera camera = camera_from_fov(kSize.width, kSize.height, 60);
  for (const EdgeScene& scene : edge_scenes(kSize, 2)) {
    const EdgeJudge judge(scene, camera, {});
    const Mpi exact = exact_mpi(scene, camera, {});
    // What the photo does not show of a surface (under a nearer one, even partly) plays
    // the part of the inpainted pixels: the judge labels those from the layer's own.
    std::vector<cv::Mat> hidden(exact.layers.size());
    cv::Mat nearer = cv::Mat::zeros(kSize, CV_32FC1);
    for (size_t s = exact.layers.size(); s-- > 0;) {
      hidden[s] = nearer > 0;
      nearer = cv::max(nearer, scene.surfaces[s].coverage);
    }
    for (const Pose& pose : {pose_at(0.08, 0), pose_at(-0.08, 0.04), pose_at(0, 0)}) {
      const EdgeScore s = judge.score(exact, hidden, pose);
      INFO(scene.name << " pose " << pose.t);
      CHECK(s.object_pixels > 0);
      CHECK(s.wrong == 0);
      CHECK(s.fringe == 0);
      CHECK(s.holes == 0);
    }
  }
}

TEST_CASE("the disk scene: torn without edge snapping, whole with it") {
  const Camera camera = camera_from_fov(kSize.width, kSize.height, 60);
  const std::vector<EdgeScene> scenes = edge_scenes(kSize, 1);
  const EdgeScene& disk = scene_named(scenes, "disk");
  const EdgeJudge judge(disk, camera, {});
  const cv::Mat soft = soften_disparity(disk.disparity, 4);
  const Pose pose = pose_at(0.16, 0);  // the disk moves over 40 px at this size
  const MpiResult before = make(disk, soft, false), after = make(disk, soft, true);
  const EdgeScore b = judge.score(before.mpi, before.fill_masks, pose);
  const EdgeScore a = judge.score(after.mpi, after.fill_masks, pose);
  CHECK(b.motion_px >= 40);
  CHECK(before.mpi.planes.size() > 2);
  CHECK(b.wrong_share() > 0.05);
  CHECK(b.fringe > 0);
  CHECK(after.mpi.planes.size() == 2);
  CHECK(a.wrong_share() <= 0.03);
  CHECK(a.fringe == 0);
  CHECK_THROWS_WITH(judge.score(after.mpi, {}, pose), Catch::Contains("fill mask"));
}
