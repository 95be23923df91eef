// The parallax video of an MPI: a camera path (a named move or a keyframe file), mono or
// stereo, into an MP4, a GIF or a PNG sequence.
#pragma once
#include <string>

#include "engine/thread_pool.h"
#include "mpi/mpi.h"
#include "render/render_frames.h"
#include "render/trajectory.h"
#include "render/video_out.h"

namespace ampi {

struct VideoOptions {
  PathOptions path;           // the named move, frames, fps, amplitude, boomerang
  std::string keyframes;      // a keyframe file instead of the named move
  StereoMode stereo = StereoMode::Mono;
  double baseline = 0.03;     // between the eyes, as a fraction of the nearest plane's depth
  Container container = Container::Mp4;
  // Zoom in just enough that the nearest layer never uncovers the frame's edges (nothing
  // exists beyond the photo, so they would show black): the usual crop of 3D photos.
  bool overscan = true;
};

// The smallest zoom factor (>= 1) at which the nearest plane, seen from every pose,
// still covers the whole frame.
double overscan_zoom(const Mpi& mpi, const std::vector<Pose>& poses);

// "mp4", "gif", "png" (a PNG sequence); throws std::invalid_argument otherwise.
Container parse_video_format(const std::string& name);
// "mono", "sbs", "anaglyph"; throws std::invalid_argument otherwise.
StereoMode parse_stereo_mode(const std::string& name);

// video.mp4, video.gif or frames/ (a PNG sequence).
std::string video_file_name(Container container);

// What writing a video did.
struct VideoWritten {
  int frames = 0;
  // The peak resident memory (MB) of the ffmpeg process that encoded an MP4, beside this
  // process's own; 0 when this process encoded it (render/video_out.h).
  double encoder_peak_mb = 0;
};

// Renders the whole path into `path` (staged by FrameWriter: all or nothing), one frame
// at a time straight into the encoder.
VideoWritten write_video(const Mpi& mpi, const VideoOptions& options, const std::string& path,
                         bool overwrite, ThreadPool& pool = default_pool());
// The same, consuming the MPI: each 8-bit layer is released as soon as the renderer
// holds its own copy, so they are not kept through the encoding (at 4K, 265 MB of 8
// layers beside the renderer's 530 MB and the encoder's frames).
VideoWritten write_video(Mpi&& mpi, const VideoOptions& options, const std::string& path, bool overwrite,
                         ThreadPool& pool = default_pool());

}  // namespace ampi
