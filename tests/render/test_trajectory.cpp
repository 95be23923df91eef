#include <catch2/catch.hpp>
#include <cmath>

#include "render/trajectory.h"
#include "temp_dir.h"

using namespace ampi;

namespace {

std::vector<Plane> planes_at(std::initializer_list<double> depths) {
  std::vector<Plane> planes;
  for (double d : depths) {
    Plane p;
    p.depth = d;
    planes.push_back(p);
  }
  return planes;
}

const Camera kCamera = camera_from_fov(640, 480, 60);

// How far apart two points of the plane at `depth`, 100 px apart in the source, land.
double imaged_length(const Pose& pose, double depth) {
  const cv::Matx33d h = plane_homography(kCamera, pose, depth);
  const cv::Vec3d a = h * cv::Vec3d(270, 240, 1), b = h * cv::Vec3d(370, 240, 1);
  return std::hypot(a[0] / a[2] - b[0] / b[2], a[1] / a[2] - b[1] / b[2]);
}

double rotation_angle_degrees(const cv::Matx33d& r) {
  return std::acos(std::clamp((cv::trace(r) - 1) / 2, -1.0, 1.0)) * 180 / M_PI;
}

}  // namespace

TEST_CASE("circle: the camera stays at the amplitude from the centre and loops seamlessly") {
  const auto planes = planes_at({20, 8, 4});
  PathOptions o;
  o.kind = PathKind::Circle;
  o.frames = 24;
  o.amplitude = 0.1;
  const auto poses = camera_path(o, planes);
  REQUIRE(poses.size() == 24);
  for (const Pose& p : poses) {
    CHECK(cv::norm(p.t) == Approx(0.4));  // 0.1 of the nearest depth, 4
    CHECK(p.t[2] == 0);
    CHECK(p.zoom == 1);
    CHECK(cv::norm(p.R - cv::Matx33d::eye()) == 0);
  }
  // The step from the last frame back to the first equals every other step.
  const double step = cv::norm(poses[1].t - poses[0].t);
  CHECK(cv::norm(poses[0].t - poses[23].t) == Approx(step));
}

TEST_CASE("swing sways horizontally; zoom-in moves forward one way or there and back") {
  const auto planes = planes_at({10, 5});
  PathOptions o;
  o.kind = PathKind::Swing;
  o.frames = 40;
  o.amplitude = 0.2;
  double widest = 0;
  for (const Pose& p : camera_path(o, planes)) {
    CHECK(p.t[1] == 0);
    CHECK(p.t[2] == 0);
    widest = std::max(widest, std::fabs(p.t[0]));
  }
  CHECK(widest == Approx(1.0));

  o.kind = PathKind::ZoomIn;
  o.frames = 11;
  o.boomerang = false;
  auto poses = camera_path(o, planes);
  CHECK(poses.front().t[2] == 0);
  CHECK(poses.back().t[2] == Approx(-1.0));  // X_new = X - c: forward by 1 scene unit
  for (size_t k = 1; k < poses.size(); ++k) CHECK(poses[k].t[2] < poses[k - 1].t[2]);

  o.boomerang = std::nullopt;  // zoom-in's default: boomerang
  o.frames = 10;
  poses = camera_path(o, planes);
  CHECK(poses[5].t[2] == Approx(-1.0));
  for (int k = 1; k < 5; ++k) CHECK(poses[k].t[2] == Approx(poses[10 - k].t[2]));
}

TEST_CASE("dolly-zoom keeps the focus plane's size while the background changes") {
  const auto planes = planes_at({30, 12, 6, 3});
  for (int focus : {-1, 1}) {
    PathOptions o;
    o.kind = PathKind::DollyZoom;
    o.frames = 16;
    o.amplitude = 0.5;
    o.focus_plane = focus;
    const double focus_depth = focus < 0 ? 3.0 : 12.0;
    const auto poses = camera_path(o, planes);
    INFO("focus plane " << focus);
    CHECK(poses[8].zoom > 1.1);
    for (const Pose& p : poses) CHECK(imaged_length(p, focus_depth) == Approx(100.0).epsilon(1e-9));
    CHECK(imaged_length(poses[8], 30) > 101);  // the background grows
  }
}

TEST_CASE("camera path options out of range are refused") {
  const auto planes = planes_at({10, 5});
  PathOptions o;
  o.amplitude = 1.0;
  CHECK_THROWS_WITH(camera_path(o, planes), Catch::Contains("amplitude"));
  o = PathOptions{};
  o.frames = 0;
  CHECK_THROWS_WITH(camera_path(o, planes), Catch::Contains("frame count"));
  o = PathOptions{};
  o.fps = 0;
  CHECK_THROWS_WITH(camera_path(o, planes), Catch::Contains("fps"));
  o = PathOptions{};
  o.focus_plane = 2;
  CHECK_THROWS_WITH(camera_path(o, planes), Catch::Contains("focus plane 2"));
  CHECK_THROWS_WITH(camera_path(PathOptions{}, {}), Catch::Contains("no planes"));
  CHECK_THROWS_WITH(parse_path_kind("spiral"), Catch::Contains("spiral") && Catch::Contains("dolly-zoom"));
  for (PathKind k : {PathKind::Circle, PathKind::Swing, PathKind::ZoomIn, PathKind::DollyZoom})
    CHECK(parse_path_kind(path_kind_name(k)) == k);
}

TEST_CASE("interpolated rotations follow the shortest arc at constant speed") {
  Pose a, b;
  a.R = rotation_from_degrees({0, 10, 0});
  b.R = rotation_from_degrees({0, 50, 0});
  b.t = {1, 2, 3};
  b.zoom = 2;
  for (double s : {0.0, 0.25, 0.5, 1.0}) {
    const Pose p = interpolate(a, b, s);
    INFO("s = " << s);
    CHECK(cv::norm(p.R - rotation_from_degrees({0, 10 + 40 * s, 0})) < 1e-12);
    CHECK(cv::norm(p.t - cv::Vec3d(s, 2 * s, 3 * s)) < 1e-12);
    CHECK(p.zoom == Approx(1 + s));
  }
  // 170 and -170 degrees are 20 degrees apart the short way.
  a.R = rotation_from_degrees({0, 0, 170});
  b.R = rotation_from_degrees({0, 0, -170});
  CHECK(rotation_angle_degrees(interpolate(a, b, 0.5).R) == Approx(180));
  // Rotations about every pivot case of the matrix-to-quaternion conversion survive the trip.
  for (cv::Vec3d angles : {cv::Vec3d(170, 0, 0), cv::Vec3d(0, 175, 0), cv::Vec3d(0, 0, 179), cv::Vec3d(20, -30, 40)}) {
    INFO("angles " << angles);
    const Pose same{rotation_from_degrees(angles), {0, 0, 0}, 1};
    CHECK(cv::norm(interpolate(same, same, 0.3).R - same.R) < 1e-9);
  }
}

TEST_CASE("keyframe files give poses at every frame time") {
  test::TempDir dir;
  const std::string path = dir.write("keys.json", R"({
    "keyframes": [
      {"time": 0, "t": [0, 0, 0]},
      {"time": 1, "t": [0.5, 0, 0], "rotation": [0, 20, 0], "zoom": 1.5},
      {"time": 1.5, "t": [0.5, 0.25, -1]}
    ]
  })");
  const auto keyframes = read_keyframes(path);
  REQUIRE(keyframes.size() == 3);
  const auto poses = keyframe_path(keyframes, 10);
  REQUIRE(poses.size() == 16);  // 0, 0.1, ..., 1.5 s
  CHECK(cv::norm(poses[5].t - cv::Vec3d(0.25, 0, 0)) < 1e-12);
  CHECK(rotation_angle_degrees(poses[5].R) == Approx(10));
  CHECK(poses[5].zoom == Approx(1.25));
  CHECK(cv::norm(poses[10].t - cv::Vec3d(0.5, 0, 0)) < 1e-12);
  CHECK(cv::norm(poses[15].t - cv::Vec3d(0.5, 0.25, -1)) < 1e-12);
  CHECK(poses[15].zoom == 1.0);  // zoom left out: 1
  CHECK(keyframe_path({keyframes[0]}, 30).size() == 1);
  CHECK_THROWS_WITH(keyframe_path(keyframes, 1e6), Catch::Contains("frames"));
}

TEST_CASE("malformed keyframe files are refused with one line naming the file") {
  test::TempDir dir;
  const std::pair<const char*, const char*> cases[] = {
      {"{\"keyframes\": [ {\"time\": 0 ", "not a valid JSON"},
      {"", "not a valid JSON"},
      {"[1, 2]", "not a valid JSON keyframe file"},
      {"{\"frames\": []}", "\"keyframes\" list"},
      {"{\"keyframes\": []}", "\"keyframes\" list"},
      {"{\"keyframes\": [ 3 ]}", "keyframe 0 is not an object"},
      {"{\"keyframes\": [ {\"t\": [0, 0, 0]} ]}", "keyframe 0 has no \"time\""},
      {"{\"keyframes\": [ {\"time\": \"soon\"} ]}", "keyframe 0 \"time\" must be a number"},
      {"{\"keyframes\": [ {\"time\": 0, \"t\": [1, 2]} ]}", "keyframe 0 \"t\" must be a list of 3 numbers"},
      {"{\"keyframes\": [ {\"time\": 0, \"rotation\": [1, \"a\", 2]} ]}", "keyframe 0 \"rotation\" must be a number"},
      {"{\"keyframes\": [ {\"time\": 0, \"zoom\": -1} ]}", "\"zoom\" must be positive"},
      // Found by fuzz_keyframes (fuzz/corpus/keyframes/crash-huge-rotation): an angle of
      // 1e308 degrees made a rotation matrix of NaN.
      {"{\"keyframes\": [ {\"time\": 0, \"rotation\": [2, -3, 1e308]} ]}", "angles must be within [-360, 360]"},
      {"{\"keyframes\": [ {\"time\": 1}, {\"time\": 1} ]}", "keyframe 1 \"time\" must be later"},
  };
  int index = 0;
  for (const auto& [text, problem] : cases) {
    const std::string path = dir.write("bad" + std::to_string(index++) + ".json", text);
    INFO(text);
    try {
      read_keyframes(path);
      FAIL("accepted");
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      CHECK_THAT(message, Catch::StartsWith(path + ": ") && Catch::Contains(problem));
      CHECK(message.find('\n') == std::string::npos);
    }
  }
  CHECK_THROWS_WITH(read_keyframes(dir.file("missing.json")), Catch::Contains("missing.json: cannot open"));
  CHECK_THROWS_WITH(read_keyframes(dir.path().string()), Catch::Contains("cannot open"));
}
