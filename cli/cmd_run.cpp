// ampi run PHOTO... -o DIR: one command from photo to 3D photo.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <new>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli/args.h"
#include "cli/commands.h"
#include "nets/bundled_weights.h"
#include "engine/thread_pool.h"
#include "mpi/mpi_io.h"
#include "pipeline/depth_io.h"
#include "pipeline/full_resolution.h"
#include "pipeline/make_mpi.h"
#include "pipeline/output_staging.h"
#include "pipeline/photo_io.h"
#include "pipeline/progress.h"
#include "pipeline/video.h"
#include "render/viewer.h"

namespace fs = std::filesystem;

namespace ampi::cli {
namespace {

const char kUsage[] =
    "usage: ampi run PHOTO... -o DIR [options]\n"
    "\n"
    "Turns each photo into an adaptive multiplane image and its outputs:\n"
    "  DIR/depth.png   16-bit disparity (larger = nearer) at the photo's size\n"
    "  DIR/mpi/        layer_XX.png (RGBA, back to front) and mpi.json\n"
    "  DIR/video.mp4   a parallax video (video.gif or frames/ with --video-format)\n"
    "  DIR/viewer.html a standalone page showing the MPI with parallax (mouse, touch, tilt)\n"
    "Several photos, or a folder of photos: one sub-folder of DIR each, named after the\n"
    "photo. A photo that fails is reported and skipped; the exit code is then 1.\n"
    "\n"
    "  -o, --output DIR        where to write (refused if it exists, unless --force)\n"
    "  --force                 replace ampi's own outputs in an existing DIR (nothing else\n"
    "                          in it is touched)\n"
    "  --model NAME            bundled depth network by name: lite (default), heavy\n"
    "  --weights FILE          depth network weight file instead of the bundled one\n"
    "  --depth FILE            your own depth map instead of the network (one photo only):\n"
    "                          8/16-bit PNG, float TIFF or .npy, the photo's size\n"
    "  --depth-is-distance     the --depth map holds distances (larger = farther)\n"
    "  --working-size N        the depth network's working size (default: what the weight\n"
    "                          file asks for): the long side for lite and heavy, the input's\n"
    "                          shorter side for Depth Anything V2; layers are always cut at\n"
    "                          full resolution\n"
    "  --max-planes N          at most N planes (default 8)\n"
    "  --uniform               equal disparity intervals (the paper's baseline)\n"
    "  --slicer S              optimal (default): the paper's rule decides how many planes,\n"
    "                          the cuts minimise the planes' squared disparity error; paper:\n"
    "                          the paper's cuts (its largest transition indices)\n"
    "  --min-plane-share F     the paper's rule takes a cut only if each plane keeps more than\n"
    "                          F/N of the depth histogram, N = --max-planes (default 0: the\n"
    "                          paper's rule exactly)\n"
    "  --tear-penalty P        optimal slicer: a cut also costs P squared levels per pixel of the\n"
    "                          edge-free depth histogram at the cut (default 0)\n"
    "  --soft-alpha L          alpha ramp L disparity levels wide across plane cuts (default 0;\n"
    "                          > 0 keeps the snapped depth edges but not their feathered borders)\n"
    "  --no-edge-snap          slice the depth map's soft edges as they are (the paper), instead\n"
    "                          of snapping them to the photo's colour edges and cleaning the\n"
    "                          layers' borders there (ampi eval edges compares the two)\n"
    "  --inpainter NAME        what fills occluded margins: network (default), harmonic (as close\n"
    "                          to the truth, no texture, faster) or push-pull (fastest)\n"
    "  --inpaint-weights FILE  inpainting network weight file (implies --inpainter network)\n"
    "  --fov DEG               assumed horizontal field of view (default 60)\n"
    "  --trajectory NAME       circle, swing, zoom-in or dolly-zoom (default circle)\n"
    "  --keyframes FILE        a JSON keyframe file instead of --trajectory\n"
    "  --frames N              frames of the video (default 90)\n"
    "  --fps N                 frames per second (default 30)\n"
    "  --amplitude A           camera travel, fraction of the nearest plane's depth (default 0.05)\n"
    "  --boomerang, --one-way  back and forth, or once (default: by trajectory)\n"
    "  --stereo MODE           mono, sbs (side by side) or anaglyph (red-cyan) (default mono)\n"
    "  --video-format F        mp4, gif (needs ffmpeg) or png (a PNG sequence) (default mp4)\n"
    "  --no-overscan           keep the full frame (its edges show black where the camera\n"
    "                          looks past the photo) instead of zooming in just enough\n"
    "  --no-video              skip the video\n"
    "  --threads N             worker threads (default: all cores)\n"
    "  --quiet                 no progress on stderr\n";

struct RunArgs {
  std::vector<std::string> inputs;
  std::string output;
  bool force = false;
  bool quiet = false;
  int threads = 0;
  bool video = true;
  MpiOptions mpi;
  VideoOptions video_options;
};

RunArgs parse(int argc, char** argv, bool& help) {
  RunArgs a;
  ArgParser p("run", kUsage);
  p.positionals(&a.inputs);
  p.option("-o", &a.output);
  p.option("--output", &a.output);
  p.flag("--force", &a.force);
  p.flag("--quiet", &a.quiet);
  p.option("--threads", &a.threads, 1, 256);
  p.option("--model", [&](const std::string& v) {
    check_depth_model_name(v);
    a.mpi.depth_model = v;
  });
  p.option("--weights", &a.mpi.depth_weights);
  p.option("--depth", &a.mpi.depth_file);
  p.flag("--depth-is-distance", &a.mpi.depth_is_distance);
  p.option("--working-size", &a.mpi.working_size, kMinPhotoSide, 16384);
  p.option("--max-planes", &a.mpi.slicing.max_planes, 1, kDisparityLevels - 1);
  p.flag("--uniform", &a.mpi.uniform);
  p.option("--slicer", [&](const std::string& v) { a.mpi.slicing.slicer = parse_slicer(v); });
  p.option("--min-plane-share", &a.mpi.slicing.min_plane_share, 0.0, 1.0);
  p.option("--tear-penalty", &a.mpi.slicing.tear_penalty, 0.0, 1e9);
  p.option("--soft-alpha", &a.mpi.soft_alpha, 0, 64);
  p.flag("--no-edge-snap", [&] { a.mpi.snap_depth_edges = false; });
  p.option("--inpaint-weights", &a.mpi.inpaint_weights);
  p.option("--inpainter", [&](const std::string& v) { a.mpi.inpainter = parse_inpainter(v); });
  p.option("--fov", &a.mpi.fov_degrees, 1, 179);
  PathOptions& path = a.video_options.path;
  p.option("--trajectory", [&](const std::string& v) { path.kind = parse_path_kind(v); });
  p.option("--keyframes", &a.video_options.keyframes);
  p.option("--frames", &path.frames, 1, kMaxPathFrames);
  p.option("--fps", &path.fps, 1, 240);
  p.option("--amplitude", &path.amplitude, 1e-4, 0.9);
  p.flag("--boomerang", [&] { path.boomerang = true; });
  p.flag("--one-way", [&] { path.boomerang = false; });
  p.option("--stereo", [&](const std::string& v) { a.video_options.stereo = parse_stereo_mode(v); });
  p.option("--video-format",
           [&](const std::string& v) { a.video_options.container = parse_video_format(v); });
  p.flag("--no-overscan", [&] { a.video_options.overscan = false; });
  bool no_video = false;
  p.flag("--no-video", &no_video);
  help = !p.parse(argc, argv);
  if (help) return a;
  a.video = !no_video;
  if (a.inputs.empty()) throw std::runtime_error("missing PHOTO (see ampi run --help)");
  if (a.output.empty()) throw std::runtime_error("missing -o DIR (see ampi run --help)");
  return a;
}

bool is_photo_name(const fs::path& p) {
  static const std::set<std::string> kExtensions = {".jpg", ".jpeg", ".png", ".tif", ".tiff",
                                                    ".bmp", ".webp", ".jp2", ".ppm", ".pgm"};
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return kExtensions.count(ext) > 0;
}

// The photos named on the command line; a folder stands for the photos in it (sorted).
// A path that does not exist stays in the list, so its error is reported in turn.
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs) {
  std::vector<std::string> photos;
  for (const std::string& input : inputs) {
    std::error_code ec;
    if (!fs::is_directory(input, ec)) {
      photos.push_back(input);
      continue;
    }
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(input))
      if (entry.is_regular_file() && is_photo_name(entry.path())) found.push_back(entry.path().string());
    if (found.empty()) throw std::runtime_error(input + ": folder holds no photos");
    std::sort(found.begin(), found.end());
    photos.insert(photos.end(), found.begin(), found.end());
  }
  return photos;
}

void run_one(MpiMaker& maker, const RunArgs& a, const std::string& photo,
             const std::string& destination, Progress& progress) {
  OutputStaging staging(destination, a.force);
  cv::Mat bgr = progress.stage("decode", [&] { return read_photo(photo); });
  MpiResult result = maker.make(bgr, photo, progress);
  bgr.release();  // each buffer is let go once no later stage needs it (peak memory)
  if (is_reduced(result))
    progress.note(photo + ": " + std::to_string(result.full_bgr.cols) + "x" + std::to_string(result.full_bgr.rows) +
                  " is made into an MPI at " + std::to_string(result.mpi.camera.width) + "x" +
                  std::to_string(result.mpi.camera.height) + " (video and viewer too); the layers are written at full size");
  progress.stage("write mpi", [&] {
    const fs::path dir(staging.dir());
    write_depth_png16(disparity_at_photo_size(result), (dir / "depth.png").string());
    write_mpi_at_photo_size(result, (dir / "mpi").string());
  });
  result.disparity.release();
  result.full_bgr.release();
  const size_t planes = result.mpi.planes.size();
  // The viewer before the video: the video consumes the layers.
  progress.stage("viewer", [&] { return write_viewer(result.mpi, staging.dir()); });
  if (a.video)
    progress.stage("video", [&] {
      const fs::path file = fs::path(staging.dir()) / video_file_name(a.video_options.container);
      return write_video(std::move(result.mpi), a.video_options, file.string(), false);
    });
  staging.commit();
  release_free_memory();  // the next photo's buffers do not come on top of this one's
  progress.note(photo + ": " + std::to_string(planes) + " planes, inpainted by " +
                result.inpainter + " -> " + destination);
}

}  // namespace

int cmd_run(int argc, char** argv) {
  bool help = false;
  const RunArgs a = parse(argc, argv, help);
  if (help) return 0;
  if (a.threads > 0) set_default_threads(a.threads);
  const std::vector<std::string> photos = expand_inputs(a.inputs);
  const bool one = photos.size() == 1 && !fs::is_directory(a.inputs.front());
  if (!a.mpi.depth_file.empty() && !one)
    throw std::runtime_error("--depth: a depth map belongs to one photo, but " +
                             std::to_string(photos.size()) + " were given");
  if (!one) fs::create_directories(a.output);

  MpiMaker maker(a.mpi);
  Progress progress(a.quiet);
  int failed = 0;
  for (const std::string& photo : photos) {
    const std::string destination = one ? a.output : (fs::path(a.output) / fs::path(photo).stem()).string();
    if (!one) progress.note(photo);
    try {
      run_one(maker, a, photo, destination, progress);
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "ampi run: %s: out of memory (less was free than the memory budget, AMPI_MEMORY_BUDGET, allowed)\n",
                   photo.c_str());
      ++failed;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ampi run: %s\n", e.what());
      ++failed;
    }
  }
  if (failed && photos.size() > 1)
    std::fprintf(stderr, "ampi run: %d of %zu photos failed\n", failed, photos.size());
  return failed ? 1 : 0;
}

}  // namespace ampi::cli
