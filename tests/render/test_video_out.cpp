#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "render/renderer.h"
#include "render/video_out.h"
#include "synthetic_mpi.h"
#include "temp_dir.h"

using namespace ampi;
namespace fs = std::filesystem;

namespace {

// A frame whose colours change with k, so frames can be told apart after lossy coding.
cv::Mat test_frame(int k, cv::Size size = {63, 47}) {
  cv::Mat f(size, CV_8UC3, cv::Scalar(40 + 20 * k, 200 - 15 * k, 90));
  cv::rectangle(f, {5 + k, 5}, {30 + k, 30}, cv::Scalar(250, 250, 250), cv::FILLED);
  return f;
}

double mean_difference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar m = cv::mean(d);
  return (m[0] + m[1] + m[2]) / 3.0;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Sets PATH for the scope of a test and restores it.
class ScopedPath {
 public:
  explicit ScopedPath(const std::string& value) : old_(std::getenv("PATH") ? std::getenv("PATH") : "") {
    ::setenv("PATH", value.c_str(), 1);
  }
  ~ScopedPath() { ::setenv("PATH", old_.c_str(), 1); }

 private:
  std::string old_;
};

}  // namespace

TEST_CASE("the container follows the output's extension") {
  CHECK(container_for_path("a/b.mp4") == Container::Mp4);
  CHECK(container_for_path("b.MP4") == Container::Mp4);
  CHECK(container_for_path("b.gif") == Container::Gif);
  CHECK(container_for_path("frame.png") == Container::Png);
  CHECK(container_for_path("frames") == Container::PngSequence);
  CHECK(container_for_path("frames/") == Container::PngSequence);
}

TEST_CASE("PNG sequences and single PNGs appear only when finished, pixel for pixel") {
  test::TempDir dir;
  const std::string seq = dir.file("frames");
  {
    FrameWriter w(seq, Container::PngSequence, 24, false);
    for (int k = 0; k < 3; ++k) w.add(test_frame(k));
    CHECK_FALSE(fs::exists(seq));
    w.finish();
  }
  REQUIRE(entries(seq) == std::vector<std::string>{"frame_000000.png", "frame_000001.png", "frame_000002.png"});
  for (int k = 0; k < 3; ++k) {
    INFO("frame " << k);
    const cv::Mat read = cv::imread(seq + "/frame_00000" + std::to_string(k) + ".png");
    CHECK(mean_difference(read, test_frame(k)) == 0);
  }
  const std::string single = dir.file("one.png");
  FrameWriter w(single, Container::Png, 24, false);
  w.add(test_frame(4));
  CHECK_THROWS_WITH(w.add(test_frame(5)), Catch::Contains("single frame"));
  w.finish();
  CHECK(mean_difference(cv::imread(single), test_frame(4)) == 0);
  CHECK(entries(dir.path()) == std::vector<std::string>{"frames", "one.png"});
}

// Writes ten frames of odd size to `name` and checks what a reader gets back; returns the
// writer's encoder peak.
double check_mp4(const test::TempDir& dir, const std::string& name) {
  const std::string path = dir.file(name);
  FrameWriter w(path, Container::Mp4, 30, false);
  for (int k = 0; k < 10; ++k) w.add(test_frame(k));
  w.finish();
  INFO("writer note: " << w.note());
  cv::VideoCapture video(path);
  REQUIRE(video.isOpened());
  if (w.note().empty()) {
    const int fourcc = static_cast<int>(video.get(cv::CAP_PROP_FOURCC));
    const std::string codec{char(fourcc & 255), char((fourcc >> 8) & 255), char((fourcc >> 16) & 255), char(fourcc >> 24)};
    CHECK((codec == "avc1" || codec == "h264"));
  }
  cv::Mat frame;
  int count = 0;
  while (video.read(frame)) {
    INFO("frame " << count);
    REQUIRE(frame.size() == cv::Size(64, 48));
    CHECK(mean_difference(frame(cv::Rect(0, 0, 63, 47)), test_frame(count)) < 6);
    ++count;
  }
  CHECK(count == 10);
  return w.encoder_peak_mb();
}

TEST_CASE("MP4 videos hold every frame, padded to an even size, through ffmpeg or OpenCV") {
  test::TempDir dir;
  {
    ScopedPath no_programs(dir.path().string());
    CHECK(check_mp4(dir, "opencv.mp4") == 0);  // encoded in this process
  }
  if (!program_on_path("ffmpeg")) {
    WARN("ffmpeg is not installed: MP4 encoding through it not tested");
    CHECK(entries(dir.path()) == std::vector<std::string>{"opencv.mp4"});
    return;
  }
  CHECK(check_mp4(dir, "piped.mp4") > 0);  // the encoder's own peak, measured when it exits
  CHECK(entries(dir.path()) == std::vector<std::string>{"opencv.mp4", "piped.mp4"});
}

TEST_CASE("an MP4 given up on leaves nothing behind and stops its encoder") {
  test::TempDir dir;
  {
    FrameWriter w(dir.file("abandoned.mp4"), Container::Mp4, 30, false);
    for (int k = 0; k < 3; ++k) w.add(test_frame(k));
  }
  CHECK(entries(dir.path()).empty());
}

TEST_CASE("an ffmpeg that fails while encoding gives one error naming the video and leaves nothing") {
  test::TempDir programs, dir;
  // Passes the libx264 probe, fails on the real work without reading its input.
  const std::string fake = programs.write("ffmpeg", "#!/bin/sh\ncase \"$*\" in *lavfi*) exit 0 ;; esac\nexit 3\n");
  fs::permissions(fake, fs::perms::owner_all);
  ScopedPath only_fake(programs.path().string());
  const std::string path = dir.file("broken.mp4");
  auto encode = [&] {
    FrameWriter w(path, Container::Mp4, 30, false);
    for (int k = 0; k < 10; ++k) w.add(test_frame(k, {640, 480}));
    w.finish();
  };
  // Which of the two errors depends on whether the pipe still took the frames.
  CHECK_THROWS_WITH(encode(), Catch::Contains(path) && Catch::Contains("ffmpeg") &&
                                  (Catch::Contains("stopped while encoding") || Catch::Contains("exit status 3")));
  CHECK(entries(dir.path()).empty());
}

TEST_CASE("GIFs are made by ffmpeg, or refused up front with the reason") {
  test::TempDir dir;
  {
    ScopedPath no_programs(dir.path().string());
    CHECK_THROWS_WITH(FrameWriter(dir.file("a.gif"), Container::Gif, 10, false),
                      Catch::Contains("a.gif") && Catch::Contains("needs the ffmpeg program"));
  }
  if (!program_on_path("ffmpeg")) {
    WARN("ffmpeg is not installed: GIF encoding not tested");
    return;
  }
  const std::string path = dir.file("loop.gif");
  FrameWriter w(path, Container::Gif, 10, false);
  for (int k = 0; k < 5; ++k) w.add(test_frame(k));
  w.finish();
  cv::VideoCapture gif(path);
  REQUIRE(gif.isOpened());
  cv::Mat frame;
  int count = 0;
  while (gif.read(frame)) {
    INFO("frame " << count);
    CHECK(mean_difference(frame, test_frame(count)) < 8);
    ++count;
  }
  CHECK(count == 5);
  CHECK(entries(dir.path()) == std::vector<std::string>{"loop.gif"});
}

TEST_CASE("existing outputs are kept unless overwriting is asked for") {
  test::TempDir dir;
  const std::string path = dir.file("out.png");
  dir.write("out.png", "not an image");
  CHECK_THROWS_WITH(FrameWriter(path, Container::Png, 30, false),
                    Catch::Contains("out.png: already exists") && Catch::Contains("--force"));
  {
    FrameWriter w(path, Container::Png, 30, true);
    w.add(test_frame(1));
    w.finish();
  }
  CHECK(mean_difference(cv::imread(path), test_frame(1)) == 0);
  // A directory replaced by a directory, then by a file.
  const std::string seq = dir.file("seq");
  fs::create_directory(seq);
  dir.write("seq/old.txt", "old");
  {
    FrameWriter w(seq, Container::PngSequence, 30, true);
    w.add(test_frame(2));
    w.finish();
  }
  CHECK(entries(seq) == std::vector<std::string>{"frame_000000.png"});
  FrameWriter w(seq, Container::Png, 30, true);
  w.add(test_frame(3));
  w.finish();
  CHECK(fs::is_regular_file(seq));
  CHECK(mean_difference(cv::imread(seq), test_frame(3)) == 0);
  CHECK(entries(dir.path()) == std::vector<std::string>{"out.png", "seq"});
}

TEST_CASE("an unfinished output leaves nothing behind") {
  test::TempDir dir;
  for (Container c : {Container::Mp4, Container::PngSequence, Container::Png, Container::Gif}) {
    if (c == Container::Gif && !program_on_path("ffmpeg")) continue;
    INFO(container_name(c));
    {
      FrameWriter w(dir.file(c == Container::Png ? "x.png" : "x.gif"), c, 30, false);
      w.add(test_frame(0));
      // Destroyed without finish(): as if rendering had thrown.
    }
    CHECK(entries(dir.path()).empty());
  }
  CHECK_THROWS_WITH(FrameWriter(dir.file("nowhere/x.mp4"), Container::Mp4, 30, false),
                    Catch::Contains("nowhere/x.mp4: directory") && Catch::Contains("does not exist"));
  FrameWriter empty(dir.file("empty.mp4"), Container::Mp4, 30, false);
  CHECK_THROWS_WITH(empty.finish(), Catch::Contains("no frames"));
}

TEST_CASE("stereo pairs: eyes a baseline apart, side by side or red-cyan") {
  const Mpi mpi = test::synthetic_mpi(64, 40, 1, 91, test::Alpha::Binary);
  const double z = mpi.planes[0].depth, fx = mpi.camera.fx;
  const double baseline = 6 * z / fx;  // the plane's views lie 6 pixels apart
  const StereoPoses eyes = stereo_poses(Pose{}, baseline);
  const Renderer renderer(mpi);
  const cv::Mat left = renderer.render(eyes.left), right = renderer.render(eyes.right);
  // The left eye sees the scene 3 px to the right of the centre view, the right eye 3 px left.
  const cv::Mat centre = renderer.render(Pose{});
  CHECK(mean_difference(left(cv::Rect(3, 0, 61, 40)), centre(cv::Rect(0, 0, 61, 40))) == 0);
  CHECK(mean_difference(right(cv::Rect(0, 0, 61, 40)), centre(cv::Rect(3, 0, 61, 40))) == 0);

  const cv::Mat sbs = side_by_side(left, right);
  REQUIRE(sbs.size() == cv::Size(128, 40));
  CHECK(mean_difference(sbs(cv::Rect(0, 0, 64, 40)), left) == 0);
  CHECK(mean_difference(sbs(cv::Rect(64, 0, 64, 40)), right) == 0);

  const cv::Mat red_cyan = anaglyph(left, right);
  std::vector<cv::Mat> a, l, r;
  cv::split(red_cyan, a);
  cv::split(left, l);
  cv::split(right, r);
  CHECK(cv::countNonZero(a[2] != l[2]) == 0);
  CHECK(cv::countNonZero(a[1] != r[1]) == 0);
  CHECK(cv::countNonZero(a[0] != r[0]) == 0);
}
