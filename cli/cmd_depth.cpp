// ampi depth PHOTO -o FILE.png: the depth network on one photo, a 16-bit disparity PNG out.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "cli/commands.h"
#include "nets/depth_net.h"
#include "nets/weights_path.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/depth_io.h"
#include "pipeline/photo_io.h"

namespace ampi::cli {
namespace {

const char kUsage[] =
    "usage: ampi depth PHOTO -o FILE.png [--model lite|heavy] [--weights FILE]\n"
    "                  [--max-size N] [--threads N]\n"
    "\n"
    "Estimates the photo's disparity (relative inverse depth) with the depth network and\n"
    "writes it as a 16-bit PNG of the photo's own size, normalised to 0..65535, larger =\n"
    "nearer. The photo is decoded with its EXIF orientation, scaled down so its long side\n"
    "is at most --max-size (never up), run through the network, and the map resized back.\n"
    "\n"
    "  -o FILE.png       the disparity map to write (replaced atomically)\n"
    "  --model M         lite (default, faster) or heavy (more accurate)\n"
    "  --weights FILE    a depth weight file instead of the bundled weights/depth_M.ampw\n"
    "                    (found via $AMPI_WEIGHTS_DIR or weights/ beside the program)\n"
    "  --max-size N      working resolution: long side in pixels (default: what the\n"
    "                    weight file asks for, depth.working_long_side, else 1024)\n"
    "  --threads N       worker threads (default: all hardware threads)\n";

struct DepthOptions {
  std::string photo, output, model = "lite", weights;
  int max_size = 0;  // 0: the weight file's working_long_side
  int threads = 0;
};

int parse_positive(const std::string& option, const char* text, int max) {
  char* end = nullptr;
  const long n = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || n < 1 || n > max)
    throw std::runtime_error(option + ": '" + text + "' is not a number in 1.." + std::to_string(max));
  return static_cast<int>(n);
}

DepthOptions parse(int argc, char** argv) {
  DepthOptions o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value (see ampi depth --help)");
      return argv[++i];
    };
    if (arg == "-o" || arg == "--output") {
      o.output = value();
    } else if (arg == "--model") {
      o.model = value();
      if (o.model != "lite" && o.model != "heavy")
        throw std::runtime_error("--model: '" + o.model + "' is not lite or heavy");
    } else if (arg == "--weights") {
      o.weights = value();
    } else if (arg == "--max-size") {
      o.max_size = parse_positive(arg, value(), 16384);
    } else if (arg == "--threads") {
      o.threads = parse_positive(arg, value(), 1024);
    } else if (arg.size() > 1 && arg[0] == '-') {
      throw std::runtime_error("unknown option '" + arg + "' (see ampi depth --help)");
    } else if (o.photo.empty()) {
      o.photo = arg;
    } else {
      throw std::runtime_error("one photo only; also got '" + arg + "'");
    }
  }
  if (o.photo.empty()) throw std::runtime_error("missing PHOTO (see ampi depth --help)");
  if (o.output.empty()) throw std::runtime_error("missing -o FILE.png (see ampi depth --help)");
  return o;
}

// The network's map at the working resolution, brought back to the photo's size.
cv::Mat disparity_at_photo_size(DepthNet& net, const cv::Mat& bgr, int max_size, ThreadPool& pool) {
  const cv::Mat work = estimate_disparity(net, bgr, max_size, pool);
  if (work.size() == bgr.size()) return work;
  cv::Mat full;
  cv::resize(work, full, bgr.size(), 0, 0, cv::INTER_LINEAR);
  return full;
}

}  // namespace

int cmd_depth(int argc, char** argv) {
  if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  const DepthOptions o = parse(argc, argv);
  const std::string weights = o.weights.empty() ? find_weights("depth_" + o.model + ".ampw") : o.weights;
  DepthNet net = DepthNet::load(weights);
  const int max_size = o.max_size ? o.max_size : net.working_long_side();
  const cv::Mat photo = read_photo(o.photo);
  ThreadPool pool(o.threads);
  const auto start = std::chrono::steady_clock::now();
  const cv::Mat disparity = disparity_at_photo_size(net, photo, max_size, pool);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_depth_png16(disparity, o.output);
  const ImageSize work = depth_working_size(photo.rows, photo.cols, max_size);
  std::printf("%s: %dx%d disparity (%s network at %dx%d, %.2f s) -> %s\n", o.photo.c_str(), photo.cols,
              photo.rows, net.variant().c_str(), work.width, work.height, seconds, o.output.c_str());
  return 0;
}

}  // namespace ampi::cli
