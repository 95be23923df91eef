// ampi eval MODE: reproduce the paper's evaluations on any folder of photos. One entry
// per mode in kModes; each mode parses its own options.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/thread_pool.h"
#include "inpaint/eval_inpaint.h"
#include "inpaint/inpaint_net.h"
#include "nets/depth_net.h"
#include "nets/weights_path.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/depth_io.h"
#include "pipeline/photo_io.h"
#include "weights_format/weight_file.h"

namespace ampi::cli {
namespace {

namespace fs = std::filesystem;

// ---- eval inpaint ---------------------------------------------------------------------------

const char kInpaintUsage[] =
    "usage: ampi eval inpaint --images DIR [--weights FILE] [--depth-weights FILE | --depth-dir D]\n"
    "                         [--limit N] [--erode N] [--max-size N] [--radius R] [--threads N]\n"
    "\n"
    "Measures how well each method recovers MPI margins whose truth is known, the way the\n"
    "inpainting network is trained: every photo under DIR (.jpg, .jpeg, .png, recursively,\n"
    "sorted) is sliced with our depth network; for every plane but the nearest, the plane\n"
    "and every plane behind it are eroded with a 3x3 element N times, and each method fills\n"
    "the removed border from the eroded region alone. Prints PSNR (dB) and SSIM over the\n"
    "removed pixels, averaged over the (photo, plane) samples, one row per method: ampi\n"
    "(the network), telea and ns (OpenCV cv::inpaint), push-pull.\n"
    "\n"
    "  --images DIR          photos to evaluate on (use photos the network never trained on)\n"
    "  --weights FILE        inpainting weights (default: the bundled weights/inpaint.ampw)\n"
    "  --depth-weights FILE  depth weights (default: the bundled weights/depth_lite.ampw)\n"
    "  --depth-dir D         depth maps instead of the network: D/<photo path under DIR>.png\n"
    "                        (any map `ampi run --depth` reads; larger = nearer)\n"
    "  --limit N             only the first N photos\n"
    "  --erode N             erosion iterations, the margin width in pixels (default 24)\n"
    "  --max-size N          photos are scaled down to this long side first (default 1024)\n"
    "  --radius R            cv::inpaint radius for telea and ns (default 5)\n"
    "  --threads N           worker threads (default: all hardware threads)\n";

struct InpaintEvalArgs {
  std::string images, weights, depth_weights, depth_dir;
  int limit = 0, erode = 24, max_size = 1024, threads = 0;
  double radius = 5;
};

std::vector<std::string> list_images(const std::string& dir) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a directory");
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".png") found.push_back(entry.path().string());
  }
  if (found.empty()) throw std::runtime_error(dir + ": no .jpg, .jpeg or .png photos");
  std::sort(found.begin(), found.end());
  return found;
}

// The depth network is required: without it there are no planes to evaluate on.
DepthNet load_depth(const std::string& path) {
  std::string file = path;
  if (file.empty()) {
    try {
      file = find_weights("depth_lite.ampw");
    } catch (const std::exception& e) {
      throw std::runtime_error(
          std::string("the depth network is needed to slice the photos (or give --depth-weights FILE "
                      "or --depth-dir DIR): ") + e.what());
    }
  }
  const WeightFile info = WeightFile::open(file);
  if (info.has("train.steps") && info.get_int("train.steps") == 0)
    std::fprintf(stderr, "note: %s is untrained (train.steps = 0): planes follow its arbitrary output\n",
                 file.c_str());
  return DepthNet::load(file);
}

// The map of images/sub/photo.jpg is depth_dir/sub/photo.jpg.png.
std::string depth_map_path(const std::string& depth_dir, const std::string& images, const std::string& photo) {
  return (fs::path(depth_dir) / fs::path(photo).lexically_relative(images)).string() + ".png";
}

cv::Mat fit_long_side(const cv::Mat& bgr, int max_side) {
  const double scale = double(max_side) / std::max(bgr.cols, bgr.rows);
  if (scale >= 1) return bgr;
  cv::Mat out;
  cv::resize(bgr, out, {}, scale, scale, cv::INTER_AREA);
  return out;
}

MarginFiller network_filler(std::shared_ptr<const InpaintNet> net) {
  return [net](const cv::Mat& visible, const MarginSample& s) {
    cv::Mat bgra, filled;
    cv::cvtColor(visible, bgra, cv::COLOR_BGR2BGRA);
    cv::cvtColor(inpaint_layer(*net, bgra, s.known, s.removed), filled, cv::COLOR_BGRA2BGR);
    return filled;
  };
}

void print_scores(const std::vector<MethodScore>& scores, int photos) {
  std::printf("%-10s %8s %8s %8s %10s\n", "method", "PSNR", "SSIM", "samples", "seconds");
  for (const MethodScore& s : scores)
    std::printf("%-10s %8.2f %8.4f %8d %10.2f\n", s.name.c_str(), s.psnr, s.ssim, s.samples, s.seconds);
  std::printf("(%d photos; PSNR in dB and SSIM over the removed pixels, means over samples)\n", photos);
}

int eval_inpaint(int argc, char** argv) {
  InpaintEvalArgs a;
  ArgParser p("ampi eval inpaint", kInpaintUsage);
  p.option("--images", &a.images);
  p.option("--weights", &a.weights);
  p.option("--depth-weights", &a.depth_weights);
  p.option("--depth-dir", &a.depth_dir);
  p.option("--limit", &a.limit, 0, 1 << 30);
  p.option("--erode", &a.erode, 1, 200);
  p.option("--max-size", &a.max_size, 64, 16384);
  p.option("--radius", &a.radius, 1, 100);
  p.option("--threads", &a.threads, 0, 1024);
  if (!p.parse(argc, argv)) return 0;
  if (a.images.empty()) throw std::runtime_error("--images DIR is required (see ampi eval inpaint --help)");
  if (a.threads > 0) set_default_threads(a.threads);

  std::vector<std::string> photos = list_images(a.images);
  if (a.limit > 0 && size_t(a.limit) < photos.size()) photos.resize(a.limit);
  std::optional<DepthNet> depth;
  if (a.depth_dir.empty()) depth.emplace(load_depth(a.depth_weights));
  auto net = std::make_shared<const InpaintNet>(
      InpaintNet::load(a.weights.empty() ? find_weights("inpaint.ampw") : a.weights));
  InpaintEvaluator eval({{"ampi", network_filler(net)},
                         {"telea", telea_filler(a.radius)},
                         {"ns", navier_stokes_filler(a.radius)},
                         {"push-pull", push_pull_margin_filler()}});
  for (const std::string& path : photos) {
    const cv::Mat bgr = fit_long_side(read_photo(path), a.max_size);
    const cv::Mat raw = depth ? estimate_disparity(*depth, bgr, a.max_size)
                              : read_depth_map(depth_map_path(a.depth_dir, a.images, path), false);
    cv::Mat disparity;
    cv::resize(raw, disparity, bgr.size(), 0, 0, cv::INTER_LINEAR);
    const std::vector<Plane> planes = slice_adaptive(disparity);
    const auto samples = margin_samples(bgr, plane_labels(disparity, planes), int(planes.size()), a.erode);
    for (const MarginSample& s : samples) eval.add(s);
    std::fprintf(stderr, "%s: %zu planes, %zu samples\n", path.c_str(), planes.size(), samples.size());
  }
  print_scores(eval.scores(), int(photos.size()));
  return 0;
}

// ---- the mode table ---------------------------------------------------------------------------

struct Mode {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};

const Mode kModes[] = {
    {"inpaint", eval_inpaint, "margin filling: ampi vs. cv::inpaint Telea / Navier-Stokes, push-pull"},
};

void usage(FILE* out) {
  std::fprintf(out, "usage: ampi eval MODE [OPTIONS]   (ampi eval MODE --help for details)\n\nmodes:\n");
  for (const Mode& m : kModes) std::fprintf(out, "  %-10s %s\n", m.name, m.summary);
}

}  // namespace

int cmd_eval(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (const Mode& m : kModes)
    if (!std::strcmp(argv[1], m.name)) return m.run(argc - 1, argv + 1);
  std::fprintf(stderr, "ampi eval: unknown mode '%s'\n", argv[1]);
  usage(stderr);
  return 2;
}

}  // namespace ampi::cli
