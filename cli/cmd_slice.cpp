// ampi slice DEPTH: the planes slicing cuts a depth map into, as JSON on stdout.
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "pipeline/depth_io.h"
#include "slicing/adaptive.h"

namespace ampi::cli {
namespace {

const char kUsage[] =
    "usage: ampi slice DEPTH [--max-planes N] [--slicer paper|optimal] [--min-plane-share F]\n"
    "                        [--tear-penalty P] [--uniform] [--depth-is-distance]\n"
    "\n"
    "Cuts a depth map into planes (adaptive slicing unless --uniform) and\n"
    "prints them back to front as JSON: {\"planes\": [{\"depth\", \"disparity\", \"interval\",\n"
    "\"pixels\"}, ...]}. Disparity is normalised to 0..255 (255 = nearest); an interval\n"
    "[lo, hi) holds those normalised disparities (the one ending at 255 holds 255);\n"
    "depth is the plane's distance for near 1 and far 100.\n"
    "\n"
    "  DEPTH                 disparity map (larger = nearer): PNG (8/16-bit), TIFF, .npy\n"
    "  --max-planes N        at most N planes (1..255; default 8); with --uniform, exactly\n"
    "                        N equal intervals, of which empty ones are dropped\n"
    "  --slicer S            optimal (default): the paper's rule decides how many planes,\n"
    "                        the cuts then minimise the planes' squared disparity error\n"
    "                        over all pixels; paper: the paper's cuts (its largest\n"
    "                        transition indices)\n"
    "  --min-plane-share F   the paper's rule takes a cut only if each plane keeps more\n"
    "                        than F/N of the depth histogram, N = --max-planes, F in 0..1\n"
    "                        (default 0: the paper's rule exactly, which only refuses\n"
    "                        empty planes)\n"
    "  --tear-penalty P      optimal slicer: a cut also costs P squared levels per pixel of\n"
    "                        the edge-free depth histogram at the cut, against tearing a\n"
    "                        continuous surface (default 0)\n"
    "  --uniform             equal disparity intervals (the paper's baseline)\n"
    "  --depth-is-distance   DEPTH holds distances (larger = farther), not disparity\n";

struct SliceOptions {
  std::string depth_path;
  int max_planes = SlicingParams{}.max_planes;
  double min_plane_share = SlicingParams{}.min_plane_share;
  Slicer slicer = SlicingParams{}.slicer;
  double tear_penalty = SlicingParams{}.tear_penalty;
  bool uniform = false;
  bool depth_is_distance = false;
};

int parse_plane_count(const char* text) {
  char* end = nullptr;
  const long n = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || n < 1 || n > kDisparityLevels - 1)
    throw std::runtime_error(std::string("--max-planes: '") + text + "' is not a number in 1..255");
  return static_cast<int>(n);
}

// `text` as a number in [lo, hi], else a runtime_error naming `option`.
double parse_number(const char* option, const char* text, double lo, double hi) {
  char* end = nullptr;
  const double f = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(f >= lo && f <= hi)) {
    char range[64];
    std::snprintf(range, sizeof range, "%g..%g", lo, hi);
    throw std::runtime_error(std::string(option) + ": '" + text + "' is not a number in " + range);
  }
  return f;
}

SliceOptions parse(int argc, char** argv) {
  SliceOptions o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--max-planes") {
      if (i + 1 >= argc) throw std::runtime_error("--max-planes needs a number");
      o.max_planes = parse_plane_count(argv[++i]);
    } else if (arg == "--min-plane-share") {
      if (i + 1 >= argc) throw std::runtime_error("--min-plane-share needs a number");
      o.min_plane_share = parse_number("--min-plane-share", argv[++i], 0, 1);
    } else if (arg == "--tear-penalty") {
      if (i + 1 >= argc) throw std::runtime_error("--tear-penalty needs a number");
      o.tear_penalty = parse_number("--tear-penalty", argv[++i], 0, 1e9);
    } else if (arg == "--slicer") {
      if (i + 1 >= argc) throw std::runtime_error("--slicer needs paper or optimal");
      o.slicer = parse_slicer(argv[++i]);
    } else if (arg == "--uniform") {
      o.uniform = true;
    } else if (arg == "--depth-is-distance") {
      o.depth_is_distance = true;
    } else if (arg.size() > 1 && arg[0] == '-') {
      throw std::runtime_error("unknown option '" + arg + "' (see ampi slice --help)");
    } else if (o.depth_path.empty()) {
      o.depth_path = arg;
    } else {
      throw std::runtime_error("one depth map only; also got '" + arg + "'");
    }
  }
  if (o.depth_path.empty()) throw std::runtime_error("missing DEPTH (see ampi slice --help)");
  return o;
}

void print_planes(const std::vector<Plane>& planes) {
  std::printf("{\"planes\": [");
  for (size_t j = 0; j < planes.size(); ++j) {
    const Plane& p = planes[j];
    std::printf("%s\n  {\"depth\": %.6g, \"disparity\": %.6g, \"interval\": [%.6g, %.6g], \"pixels\": %lld}",
                j ? "," : "", p.depth, p.disparity, p.disparity_lo, p.disparity_hi, p.pixel_count);
  }
  std::printf("\n]}\n");
}

}  // namespace

int cmd_slice(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::fputs(kUsage, stdout);
      return 0;
    }
  const SliceOptions o = parse(argc, argv);
  const cv::Mat disparity = read_depth_map(o.depth_path, o.depth_is_distance);
  SlicingParams params;
  params.max_planes = o.max_planes;
  params.min_plane_share = o.min_plane_share;
  params.slicer = o.slicer;
  params.tear_penalty = o.tear_penalty;
  print_planes(o.uniform ? slice_uniform(disparity, o.max_planes, params.range) : slice_adaptive(disparity, params));
  return 0;
}

}  // namespace ampi::cli
