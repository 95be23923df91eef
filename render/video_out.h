// Where rendered frames go: an MP4 video, a GIF, a PNG sequence or a single PNG, written
// under a temporary name beside the destination and moved into place only when complete,
// so an interrupted or failed run never leaves a half-written output. Also the two ways
// of showing a stereo pair in one frame.
#pragma once
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "render/pose.h"

namespace ampi {

enum class Container {
  Mp4,          // H.264 through OpenCV's video writer (MPEG-4 Part 2 if H.264 is missing)
  Gif,          // through the ffmpeg program, with a palette computed for the clip
  PngSequence,  // a directory of frame_000000.png, frame_000001.png, ...
  Png,          // a single frame
};

// By the destination's extension: .mp4, .gif, .png (one frame); anything else names the
// directory of a PNG sequence.
Container container_for_path(const std::string& path);
const char* container_name(Container c);

// Whether an executable of this name is on PATH.
bool program_on_path(const std::string& name);

class FrameWriter {
 public:
  // Checks the destination before any frame is rendered: it must not exist unless
  // `overwrite`, its directory must exist, GIF output needs ffmpeg. Throws
  // std::runtime_error with one line naming the path.
  FrameWriter(const std::string& path, Container container, double fps, bool overwrite);
  // Removes the temporary output unless finish() completed.
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Appends a CV_8UC3 frame; every frame must have the first one's size. Videos of odd
  // width or height get one replicated column or row (H.264 needs even sizes).
  void add(const cv::Mat& bgr);
  // Completes the output and moves it to its destination (replacing what was there when
  // `overwrite`). At least one frame is needed.
  void finish();

  int frames() const { return frames_; }
  // A remark for the user about how the output was made (empty if nothing to say).
  const std::string& note() const { return note_; }

 private:
  void open_video(cv::Size size);
  void write_png(const std::string& file, const cv::Mat& bgr) const;
  void encode_gif() const;

  std::string path_, staging_;  // destination and its temporary twin (same directory)
  Container container_;
  double fps_;
  bool overwrite_, finished_ = false;
  int frames_ = 0;
  cv::Size size_;
  cv::VideoWriter video_;
  std::string note_;
};

// The two eyes of a stereo pair around `centre`: cameras moved by -baseline/2 and
// +baseline/2 along the view's own x axis (scene units).
struct StereoPoses {
  Pose left, right;
};
StereoPoses stereo_poses(const Pose& centre, double baseline);

// Left and right views next to each other (twice as wide).
cv::Mat side_by_side(const cv::Mat& left, const cv::Mat& right);
// Red-cyan anaglyph: the red channel from the left view, green and blue from the right.
cv::Mat anaglyph(const cv::Mat& left, const cv::Mat& right);

}  // namespace ampi
