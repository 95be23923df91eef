// ampi slice DEPTH: the planes slicing cuts a depth map into, as JSON on stdout.
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/args.h"
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

SliceOptions parse(int argc, char** argv, bool& help) {
  SliceOptions o;
  std::vector<std::string> maps;
  ArgParser p("slice", kUsage);
  p.option("--max-planes", &o.max_planes, 1, kDisparityLevels - 1);
  p.option("--min-plane-share", &o.min_plane_share, 0, 1);
  p.option("--tear-penalty", &o.tear_penalty, 0, 1e9);
  p.option("--slicer", [&](const std::string& v) { o.slicer = parse_slicer(v); });
  p.flag("--uniform", &o.uniform);
  p.flag("--depth-is-distance", &o.depth_is_distance);
  p.positionals(&maps);
  help = !p.parse(argc, argv);
  if (help) return o;
  if (maps.empty()) throw std::runtime_error("missing DEPTH (see ampi slice --help)");
  if (maps.size() > 1) throw std::runtime_error("one depth map only; also got '" + maps[1] + "'");
  o.depth_path = maps[0];
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
  bool help = false;
  const SliceOptions o = parse(argc, argv, help);
  if (help) return 0;
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
