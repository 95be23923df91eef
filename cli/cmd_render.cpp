// ampi render MPI_DIR -o OUT: new views of a saved MPI, as one frame, a video along a
// camera path, a stereo pair or a standalone viewer page.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/thread_pool.h"
#include "mpi/mpi_io.h"
#include "pipeline/video.h"
#include "render/render_frames.h"
#include "render/renderer.h"
#include "render/trajectory.h"
#include "render/video_out.h"
#include "render/viewer.h"

namespace ampi::cli {
namespace {

const char kUsage[] =
    "usage: ampi render MPI_DIR -o OUT [--pose TX,TY,TZ] [--trajectory circle|swing|zoom-in|dolly-zoom]\n"
    "                   [--keyframes FILE] [--frames N] [--fps N] [--amplitude A]\n"
    "                   [--boomerang|--one-way] [--format mp4|gif|png|sbs|anaglyph|viewer]\n"
    "                   [--baseline B] [--focus-plane J] [--fov DEG] [--threads N] [--force]\n"
    "\n"
    "Renders new views of the MPI in MPI_DIR (layer_XX.png + mpi.json, as ampi run writes).\n"
    "\n"
    "  -o OUT              what to write; its extension picks the container: .mp4 (H.264),\n"
    "                      .gif (needs ffmpeg), .png (one frame), .html (viewer page), or a\n"
    "                      folder name for a PNG sequence (frame_000000.png, ...)\n"
    "  --pose TX,TY,TZ     one frame from this camera (X_new = X + t, in the units of the\n"
    "                      plane depths); OUT must be a .png\n"
    "  --trajectory T      camera path (default circle): circle, swing, zoom-in, dolly-zoom\n"
    "  --keyframes FILE    camera path from a JSON keyframe file instead:\n"
    "                      {\"keyframes\": [{\"time\": 0, \"t\": [x,y,z], \"rotation\": [rx,ry,rz],\n"
    "                      \"zoom\": 1}, ...]} (seconds, scene units, degrees; poses interpolated)\n"
    "  --frames N          frames of the path (default 90; keyframes: from their times)\n"
    "  --fps N             frames per second (default 30)\n"
    "  --amplitude A       camera travel as a fraction of the nearest plane's depth, in (0, 1)\n"
    "                      (default 0.05: the nearest layer moves about A x focal length pixels)\n"
    "  --boomerang         go there and back (default for zoom-in and dolly-zoom)\n"
    "  --one-way           go one way (default for circle and swing, which close on themselves)\n"
    "  --format F          mp4, gif, png (frames) or viewer, checked against OUT; sbs or anaglyph\n"
    "                      for a stereo pair per frame (side by side, red-cyan) in OUT's container\n"
    "  --baseline B        stereo eye distance as a fraction of the nearest depth (default 0.03)\n"
    "  --focus-plane J     dolly-zoom: the plane (0 = farthest) that keeps its size (default nearest)\n"
    "  --fov DEG           render with this horizontal field of view instead of the MPI's camera\n"
    "  --threads N         worker threads (default: all hardware threads)\n"
    "  --no-overscan       keep the full frame along a path (by default it zooms in just\n"
    "                      enough that the camera never looks past the photo's edges)\n"
    "  --force             replace OUT if it exists\n";

struct RenderOptions {
  std::string mpi_dir, output, trajectory = "circle", keyframes, format;
  std::optional<cv::Vec3d> pose;
  PathOptions path;
  bool trajectory_given = false, boomerang = false, one_way = false, force = false;
  bool overscan = true;
  double baseline = 0.03, fov = 0;
  int threads = 0;
};

// Parses the command line; returns nullopt after --help.
std::optional<RenderOptions> parse(int argc, char** argv) {
  RenderOptions o;
  std::vector<std::string> positionals;
  ArgParser p("render", kUsage);
  p.positionals(&positionals);
  p.option("-o", &o.output);
  p.option("--output", &o.output);
  p.option("--pose", [&](const std::string& v) { const std::array<double, 3> t = parse_pose(v);
    o.pose = cv::Vec3d(t[0], t[1], t[2]); });
  p.option("--trajectory", [&](const std::string& v) {
    o.trajectory = v;
    o.trajectory_given = true;
  });
  p.option("--keyframes", &o.keyframes);
  p.option("--frames", &o.path.frames, 1, kMaxPathFrames);
  p.option("--fps", &o.path.fps, 0.1, 1000);
  p.option("--amplitude", &o.path.amplitude, 1e-6, 0.999);
  p.flag("--boomerang", &o.boomerang);
  p.flag("--one-way", &o.one_way);
  p.option("--format", &o.format);
  p.option("--baseline", &o.baseline, 0, 0.999);
  p.option("--focus-plane", &o.path.focus_plane, 0, 1000);
  p.option("--fov", &o.fov, 1, 179);
  p.option("--threads", &o.threads, 1, 1024);
  p.flag("--force", &o.force);
  p.flag("--no-overscan", [&] { o.overscan = false; });
  if (!p.parse(argc, argv)) return std::nullopt;
  if (positionals.size() != 1) throw std::runtime_error("expected one MPI_DIR (see ampi render --help)");
  o.mpi_dir = positionals[0];
  if (o.output.empty()) throw std::runtime_error("missing -o OUT (see ampi render --help)");
  if (o.boomerang && o.one_way) throw std::runtime_error("--boomerang and --one-way exclude each other");
  if (o.boomerang || o.one_way) o.path.boomerang = o.boomerang;
  o.path.kind = parse_path_kind(o.trajectory);
  const int paths = (o.pose ? 1 : 0) + (o.keyframes.empty() ? 0 : 1) + (o.trajectory_given ? 1 : 0);
  if (paths > 1) throw std::runtime_error("--pose, --keyframes and --trajectory exclude each other");
  return o;
}

// What OUT and --format ask for: a container and how stereo pairs are shown.
struct OutputKind {
  bool viewer = false;
  Container container = Container::Mp4;
  StereoMode stereo = StereoMode::Mono;
};

OutputKind output_kind(const RenderOptions& o) {
  OutputKind k;
  const std::string ext = std::filesystem::path(o.output).extension().string();
  k.viewer = ext == ".html" || o.format == "viewer";
  if (k.viewer) {
    if (ext != ".html") throw std::runtime_error(o.output + ": a viewer page needs a name ending in .html");
    return k;
  }
  k.container = container_for_path(o.output);
  if (o.format == "sbs") k.stereo = StereoMode::SideBySide;
  if (o.format == "anaglyph") k.stereo = StereoMode::Anaglyph;
  const bool matches = o.format.empty() || o.format == "sbs" || o.format == "anaglyph" ||
                       (o.format == "mp4" && k.container == Container::Mp4) ||
                       (o.format == "gif" && k.container == Container::Gif) ||
                       (o.format == "png" && (k.container == Container::Png || k.container == Container::PngSequence));
  if (!matches) {
    if (o.format != "mp4" && o.format != "gif" && o.format != "png")
      throw std::runtime_error("--format: '" + o.format + "' is not mp4, gif, png, sbs, anaglyph or viewer");
    throw std::runtime_error(o.output + ": does not suit --format " + o.format +
                             " (.mp4, .gif, .png for one frame, a folder for PNG frames)");
  }
  if (o.pose && k.container != Container::Png)
    throw std::runtime_error(o.output + ": --pose writes one frame, so OUT must end in .png");
  if (!o.pose && k.container == Container::Png)
    throw std::runtime_error(o.output + ": a .png holds one frame: add --pose, or name a folder for PNG frames");
  return k;
}

double nearest_depth(const Mpi& mpi) {
  double nearest = mpi.planes[0].depth;
  for (const Plane& p : mpi.planes) nearest = std::min(nearest, p.depth);
  return nearest;
}

std::vector<Pose> poses_for(const RenderOptions& o, const Mpi& mpi) {
  if (o.pose) {
    Pose p;
    p.t = *o.pose;
    return {p};
  }
  if (!o.keyframes.empty()) {
    const std::vector<Keyframe> keyframes = read_keyframes(o.keyframes);
    try {
      return keyframe_path(keyframes, o.path.fps);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o.keyframes + ": " + e.what());
    }
  }
  return camera_path(o.path, mpi.planes);
}

void show_progress(int done, int total) {
  if (!::isatty(STDERR_FILENO)) return;
  std::fprintf(stderr, "\rampi render: frame %d/%d", done, total);
  if (done == total) std::fputc('\n', stderr);
}

int write_viewer_page(const RenderOptions& o, const Mpi& mpi) {
  if (!o.force && std::filesystem::exists(o.output))
    throw std::runtime_error(o.output + ": already exists (use --force to replace it)");
  ViewerOptions v;
  v.amplitude = o.path.amplitude;
  const std::string page = viewer_html(mpi, v);
  write_file_atomic(o.output, std::vector<unsigned char>(page.begin(), page.end()));
  std::printf("%s: viewer page for %zu layers of %dx%d\n", o.output.c_str(), mpi.layers.size(),
              mpi.camera.width, mpi.camera.height);
  return 0;
}

}  // namespace

int cmd_render(int argc, char** argv) {
  const std::optional<RenderOptions> parsed = parse(argc, argv);
  if (!parsed) return 0;
  const RenderOptions& o = *parsed;
  const OutputKind kind = output_kind(o);
  Mpi mpi = read_mpi(o.mpi_dir);
  if (o.fov > 0) mpi.camera = camera_from_fov(mpi.camera.width, mpi.camera.height, o.fov);
  if (kind.viewer) return write_viewer_page(o, mpi);

  std::vector<Pose> poses = poses_for(o, mpi);
  if (!o.pose && o.overscan) {  // a path, not one exact pose: hide the photo's edges
    const double zoom = overscan_zoom(mpi, poses);
    for (Pose& pose : poses) pose.zoom *= zoom;
  }
  FrameWriter writer(o.output, kind.container, o.path.fps, o.force);
  if (o.threads > 0) set_default_threads(o.threads);
  const Renderer renderer(mpi);
  const auto start = std::chrono::steady_clock::now();
  render_frames(renderer, poses, kind.stereo, o.baseline * nearest_depth(mpi), writer, default_pool(),
                show_progress);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writer.finish();
  if (!writer.note().empty()) std::fprintf(stderr, "ampi render: note: %s\n", writer.note().c_str());
  std::printf("%s: %d %s frame%s of %dx%d (%s) rendered in %.2f s (%.1f frames/s)\n", o.output.c_str(),
              writer.frames(), stereo_mode_name(kind.stereo), writer.frames() == 1 ? "" : "s",
              mpi.camera.width, mpi.camera.height, container_name(kind.container), seconds,
              writer.frames() / std::max(seconds, 1e-9));
  return 0;
}

}  // namespace ampi::cli
