#include "pipeline/video.h"

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

int write_video(const Mpi& mpi, const VideoOptions& options, const std::string& path,
                bool overwrite, ThreadPool& pool) {
  const std::vector<Pose> poses =
      options.keyframes.empty()
          ? camera_path(options.path, mpi.planes)
          : keyframe_path(read_keyframes(options.keyframes), options.path.fps);
  // Eyes 6% of the nearest plane's distance apart: a comfortable stereo budget whatever
  // the scene's scale.
  const double baseline = options.baseline > 0 ? options.baseline : 0.06 * mpi.planes.back().depth;
  const Renderer renderer(mpi);
  FrameWriter writer(path, options.container, options.path.fps, overwrite);
  render_frames(renderer, poses, options.stereo, baseline, writer, pool);
  writer.finish();
  return writer.frames();
}

}  // namespace ampi
