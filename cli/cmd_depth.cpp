// ampi depth PHOTO -o FILE.png: the depth network on one photo, a 16-bit disparity PNG out.
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cli/args.h"
#include "cli/commands.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/depth_io.h"
#include "pipeline/photo_io.h"

namespace ampi::cli {
namespace {

const char kUsage[] =
    "usage: ampi depth PHOTO -o FILE.png [--model NAME] [--weights FILE]\n"
    "                  [--max-size N] [--threads N]\n"
    "\n"
    "Estimates the photo's disparity (relative inverse depth) with the depth network and\n"
    "writes it as a 16-bit PNG of the photo's own size, normalised to 0..65535, larger =\n"
    "nearer. The photo is decoded with its EXIF orientation, scaled down so its long side\n"
    "is at most --max-size (never up), run through the network, and the map resized back.\n"
    "\n"
    "  -o FILE.png       the disparity map to write (replaced atomically)\n"
    "  --model NAME      a bundled depth model by name (the depth.variant of a file in\n"
    "                    $AMPI_WEIGHTS_DIR or weights/ beside the program): lite (default,\n"
    "                    faster) or heavy (more accurate)\n"
    "  --weights FILE    a depth weight file of any depth architecture instead\n"
    "  --working-size N  the network's working resolution (default: the weight file's):\n"
    "                    the long side in pixels for lite and heavy (the photo is never\n"
    "                    scaled up), the input's shorter side for Depth Anything V2\n"
    "                    (depth.working_size, 518; rounded to multiples of its patch)\n"
    "  --max-size N      the same as --working-size (its older name)\n"
    "  --threads N       worker threads (default: all hardware threads)\n";

struct DepthOptions {
  std::string photo, output, model = "lite", weights;
  int working_size = 0;  // 0: the weight file's
  int threads = 0;
};

DepthOptions parse(int argc, char** argv, bool& help) {
  DepthOptions o;
  std::vector<std::string> photos;
  ArgParser p("depth", kUsage);
  p.option("-o", &o.output);
  p.option("--output", &o.output);
  p.option("--model", [&](const std::string& v) {
    check_depth_model_name(v);
    o.model = v;
  });
  p.option("--weights", &o.weights);
  p.option("--working-size", &o.working_size, 1, 16384);
  p.option("--max-size", &o.working_size, 1, 16384);
  p.option("--threads", &o.threads, 1, 1024);
  p.positionals(&photos);
  help = !p.parse(argc, argv);
  if (help) return o;
  if (photos.empty()) throw std::runtime_error("missing PHOTO (see ampi depth --help)");
  if (photos.size() > 1) throw std::runtime_error("one photo only; also got '" + photos[1] + "'");
  if (o.output.empty()) throw std::runtime_error("missing -o FILE.png (see ampi depth --help)");
  o.photo = photos[0];
  return o;
}

// The network's map at the working resolution, brought back to the photo's size.
cv::Mat disparity_at_photo_size(DepthModel& net, const cv::Mat& bgr, ThreadPool& pool) {
  const cv::Mat work = estimate_disparity(net, bgr, 0, pool);
  if (work.size() == bgr.size()) return work;
  cv::Mat full;
  cv::resize(work, full, bgr.size(), 0, 0, cv::INTER_LINEAR);
  return full;
}

}  // namespace

int cmd_depth(int argc, char** argv) {
  bool help = false;
  const DepthOptions o = parse(argc, argv, help);
  if (help) return 0;
  const std::unique_ptr<DepthModel> net = load_depth_model(depth_weights_path(o.weights, o.model));
  if (o.working_size) set_working_size_option(*net, o.working_size);
  const cv::Mat photo = read_photo(o.photo);
  ThreadPool pool(o.threads);
  const auto start = std::chrono::steady_clock::now();
  const cv::Mat disparity = disparity_at_photo_size(*net, photo, pool);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_depth_png16(disparity, o.output);
  std::printf("%s: %dx%d disparity (%s network, working size %d, %.2f s) -> %s\n", o.photo.c_str(), photo.cols,
              photo.rows, net->variant().c_str(), net->working_size(), seconds, o.output.c_str());
  return 0;
}

}  // namespace ampi::cli
