#include "render/render_frames.h"

namespace ampi {

const char* stereo_mode_name(StereoMode mode) {
  switch (mode) {
    case StereoMode::Mono: return "mono";
    case StereoMode::SideBySide: return "sbs";
    case StereoMode::Anaglyph: return "anaglyph";
  }
  return "?";
}

cv::Mat render_view(const Renderer& renderer, const Pose& pose, StereoMode stereo, double baseline,
                    ThreadPool& pool) {
  if (stereo == StereoMode::Mono) return renderer.render(pose, pool);
  const StereoPoses eyes = stereo_poses(pose, baseline);
  const cv::Mat left = renderer.render(eyes.left, pool), right = renderer.render(eyes.right, pool);
  return stereo == StereoMode::SideBySide ? side_by_side(left, right) : anaglyph(left, right);
}

void render_frames(const Renderer& renderer, const std::vector<Pose>& poses, StereoMode stereo,
                   double baseline, FrameWriter& writer, ThreadPool& pool,
                   const std::function<void(int, int)>& progress) {
  const int total = static_cast<int>(poses.size());
  for (int k = 0; k < total; ++k) {
    writer.add(render_view(renderer, poses[k], stereo, baseline, pool));
    if (progress) progress(k + 1, total);
  }
}

}  // namespace ampi
