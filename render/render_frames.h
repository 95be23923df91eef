// Renders a sequence of poses into a FrameWriter: one view per pose, or a stereo pair
// composed side by side or as an anaglyph.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "engine/thread_pool.h"
#include "render/renderer.h"
#include "render/video_out.h"

namespace ampi {

enum class StereoMode { Mono, SideBySide, Anaglyph };

// "mono", "sbs", "anaglyph".
const char* stereo_mode_name(StereoMode mode);

// The view (or composed stereo pair, eyes `baseline` scene units apart) at `pose`.
cv::Mat render_view(const Renderer& renderer, const Pose& pose, StereoMode stereo, double baseline,
                    ThreadPool& pool);

// Adds one frame per pose to `writer` (not finished here); `progress(done, total)` is
// called after each frame when given.
void render_frames(const Renderer& renderer, const std::vector<Pose>& poses, StereoMode stereo,
                   double baseline, FrameWriter& writer, ThreadPool& pool,
                   const std::function<void(int, int)>& progress = {});

}  // namespace ampi
