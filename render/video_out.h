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
  // H.264: through the ffmpeg program when it is on PATH and has libx264, with x264's
  // frame buffers bounded (kMp4EncoderSettings); otherwise through OpenCV's video writer
  // (MPEG-4 Part 2 if H.264 is missing there too).
  Mp4,
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
  // The peak resident memory (MB) of the ffmpeg process encoding the MP4, as of the
  // last frame given to it; 0 when OpenCV encodes it (its memory is this process's own).
  double encoder_peak_mb() const { return encoder_peak_mb_; }
  // A remark for the user about how the output was made (empty if nothing to say).
  const std::string& note() const { return note_; }

 private:
  void open_video(cv::Size size);
  void start_encoder(cv::Size size);
  void send_to_encoder(const cv::Mat& bgr);
  void finish_encoder();
  void stop_encoder();
  void write_png(const std::string& file, const cv::Mat& bgr) const;
  void encode_gif() const;

  std::string path_, staging_;  // destination and its temporary twin (same directory)
  Container container_;
  double fps_;
  bool overwrite_, finished_ = false;
  int frames_ = 0;
  cv::Size size_;
  cv::VideoWriter video_;
  int encoder_pid_ = -1;    // the ffmpeg process encoding the MP4, fed raw frames
  int encoder_input_ = -1;  // the write end of its stdin
  double encoder_peak_mb_ = 0;
  std::string note_;
};

// What the ffmpeg program is asked to give x264 for MP4s. Left to itself x264 keeps a
// 40-frame lookahead and 1.5 frame threads per core, each frame with its half-pel planes:
// 1.5 GB at 3840x2160 on two cores, more with more cores. Ten frames of lookahead and two
// threads hold about 0.7 GB at that size, whatever the core count; the file is about the
// same size at the same CRF.
extern const char* const kMp4EncoderSettings;

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
