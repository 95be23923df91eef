#include "pipeline/video.h"

#include <algorithm>
#include <stdexcept>

#include "render/renderer.h"

namespace ampi {

Container parse_video_format(const std::string& name) {
  if (name == "mp4") return Container::Mp4;
  if (name == "gif") return Container::Gif;
  if (name == "png") return Container::PngSequence;
  throw std::invalid_argument("video format '" + name + "' is not mp4, gif or png");
}

StereoMode parse_stereo_mode(const std::string& name) {
  for (StereoMode m : {StereoMode::Mono, StereoMode::SideBySide, StereoMode::Anaglyph})
    if (name == stereo_mode_name(m)) return m;
  throw std::invalid_argument("stereo mode '" + name + "' is not mono, sbs or anaglyph");
}

std::string video_file_name(Container container) {
  switch (container) {
    case Container::Mp4: return "video.mp4";
    case Container::Gif: return "video.gif";
    case Container::PngSequence: return "frames";
    case Container::Png: return "frame.png";
  }
  return "video";
}

double overscan_zoom(const Mpi& mpi, const std::vector<Pose>& poses) {
  const Camera& c = mpi.camera;
  const double w = c.width - 1, h = c.height - 1;
  double zoom = 1;
  for (const Pose& pose : poses) {
    const cv::Matx33d H = plane_homography(c, pose, mpi.planes.back().depth);
    auto map = [&](double x, double y) {
      const cv::Vec3d p = H * cv::Vec3d(x, y, 1);
      return cv::Point2d(p[0] / p[2], p[1] / p[2]);
    };
    const cv::Point2d tl = map(0, 0), tr = map(w, 0), bl = map(0, h), br = map(w, h);
    // Where each edge of the photo lands, taking the side that uncovers most; zooming by
    // f about the principal point moves a point x to cx + f (x - cx).
    const double left = std::max(tl.x, bl.x), right = std::min(tr.x, br.x);
    const double top = std::max(tl.y, tr.y), bottom = std::min(bl.y, br.y);
    if (left > 0 && left < c.cx) zoom = std::max(zoom, c.cx / (c.cx - left));
    if (right < w && right > c.cx) zoom = std::max(zoom, (w - c.cx) / (right - c.cx));
    if (top > 0 && top < c.cy) zoom = std::max(zoom, c.cy / (c.cy - top));
    if (bottom < h && bottom > c.cy) zoom = std::max(zoom, (h - c.cy) / (bottom - c.cy));
  }
  return zoom;
}

namespace {

// The path's poses, zoomed for overscan when asked.
std::vector<Pose> video_poses(const Mpi& mpi, const VideoOptions& options) {
  std::vector<Pose> poses =
      options.keyframes.empty()
          ? camera_path(options.path, mpi.planes)
          : keyframe_path(read_keyframes(options.keyframes), options.path.fps);
  if (options.overscan) {
    const double zoom = overscan_zoom(mpi, poses);
    for (Pose& pose : poses) pose.zoom *= zoom;
  }
  return poses;
}

VideoWritten render_video(const Renderer& renderer, const std::vector<Pose>& poses, double baseline,
                          const VideoOptions& options, const std::string& path, bool overwrite,
                          ThreadPool& pool) {
  FrameWriter writer(path, options.container, options.path.fps, overwrite);
  render_frames(renderer, poses, options.stereo, baseline, writer, pool);
  writer.finish();
  return {writer.frames(), writer.encoder_peak_mb()};
}

// Relative to the nearest plane, so the stereo budget is the same whatever the scale.
double stereo_baseline(const Mpi& mpi, const VideoOptions& options) {
  return options.baseline * mpi.planes.back().depth;
}

}  // namespace

VideoWritten write_video(const Mpi& mpi, const VideoOptions& options, const std::string& path,
                         bool overwrite, ThreadPool& pool) {
  const std::vector<Pose> poses = video_poses(mpi, options);
  const Renderer renderer(mpi);
  return render_video(renderer, poses, stereo_baseline(mpi, options), options, path, overwrite, pool);
}

VideoWritten write_video(Mpi&& mpi, const VideoOptions& options, const std::string& path, bool overwrite,
                         ThreadPool& pool) {
  const std::vector<Pose> poses = video_poses(mpi, options);
  const double baseline = stereo_baseline(mpi, options);
  const Renderer renderer(std::move(mpi));  // lets each layer go once it holds its own copy
  return render_video(renderer, poses, baseline, options, path, overwrite, pool);
}

}  // namespace ampi
