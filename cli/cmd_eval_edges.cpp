// ampi eval edges: objects kept whole in new views (eval/edge_eval.h), before and after
// depth edges follow the photo (slicing/depth_edges.h).
#include <cstdio>
#include <filesystem>
#include <optional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/eval_common.h"
#include "engine/thread_pool.h"
#include "eval/depth_eval.h"
#include "eval/edge_eval.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/depth_io.h"
#include "pipeline/make_mpi.h"
#include "pipeline/photo_io.h"
#include "render/renderer.h"

namespace ampi::cli {
namespace {

namespace fs = std::filesystem;

const char kUsage[] =
    "usage: ampi eval edges [--size WxH] [--seed N] [--texture PHOTO] [--softness LIST]\n"
    "                       [--pose TX,TY,TZ]... [--max-planes N] [--inpainter I] [-o DIR] [--threads N]\n"
    "       ampi eval edges --images DIR [--depth-dir D] -o DIR [--max-size N] [--pose TX,TY,TZ]...\n"
    "\n"
    "Do objects stay whole when the camera moves? Scenes of textured fronto-parallel surfaces\n"
    "whose new views are known exactly (each surface warped by its own homography): a disk\n"
    "in front of a background, a thin pole, a person-like silhouette, two objects at\n"
    "different depths. Each scene's exact disparity is made soft (reduced by each --softness\n"
    "factor and enlarged bilinearly, as a network's map is; 1 = hard), made into an MPI as\n"
    "`ampi run --depth` does, before (--no-edge-snap: the map sliced as it is) and after\n"
    "(depth edges snapped to the photo, borders cleaned), and rendered at every pose.\n"
    "Per scene, softness and pose: how far the nearest object moves (px), the planes made,\n"
    "the share of object pixels wrong (a pixel shows another surface than the exact view\n"
    "does, an object involved; clear pixels only: not on a surface border, not where the\n"
    "surfaces' colours are alike) and fringe pixels (uncovered background showing a nearer\n"
    "surface's colour). The target: at most 3% wrong and no fringe at poses moving an object\n"
    "40 px or more.\n"
    "\n"
    "With --images: for every photo, with its depth map from --depth-dir (as ampi eval slicing\n"
    "finds it) or the bundled lite network's, writes DIR/<name>.png: the photo and the snapped\n"
    "map above, the view before and after below, at the first pose.\n"
    "\n"
    "  --size WxH          scene size (default 640x480)\n"
    "  --seed N            texture seed (default 1)\n"
    "  --texture PHOTO     textures cut from this photo instead of the built-in noise\n"
    "  --softness LIST     reduction factors of the disparity map (default 1,4,8)\n"
    "  --pose TX,TY,TZ     a camera pose (repeatable; default 0.08,0,0 -0.08,0.04,0 0,-0.1,0\n"
    "                      0.03,0,0: the nearest plane is at depth 1)\n"
    "  --max-planes N      planes of the adaptive slicer (default 8)\n"
    "  --inpainter I       network (default, as ampi run), harmonic or push-pull\n"
    "  -o DIR              also write, per scene and softness, photo | map | exact | before |\n"
    "                      after views at the first pose\n"
    "  --images DIR        real photos\n"
    "  --depth-dir D       their depth maps: D/sub/name.* for DIR/sub/name.jpg\n"
    "  --max-size N        photos are scaled down to this long side (default 1024)\n"
    "  --threads N         worker threads (default: all hardware threads)\n";

struct EdgeEvalArgs {
  cv::Size size{640, 480};
  int seed = 1, max_planes = 8, max_size = 1024, threads = 0;
  std::string texture, output, images, depth_dir;
  std::vector<int> softness = {1, 4, 8};
  std::vector<cv::Vec3d> poses;
  Inpainter inpainter = Inpainter::Network;
};

cv::Size parse_size(const std::string& text) {
  int w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 64 || h < 48 || w > 8192 || h > 8192)
    throw std::runtime_error("--size: '" + text + "' is not WIDTHxHEIGHT between 64x48 and 8192x8192");
  return {w, h};
}

Pose pose_of(const cv::Vec3d& t) {
  Pose pose;
  pose.t = t;
  return pose;
}

std::string pose_text(const cv::Vec3d& t) {
  char text[64];
  std::snprintf(text, sizeof text, "%g,%g,%g", t[0], t[1], t[2]);
  return text;
}

// The MPI `ampi run --depth` makes from this photo and map, with or without snapping.
MpiResult make_mpi(const EdgeEvalArgs& a, const cv::Mat& bgr, const cv::Mat& disparity, bool snap) {
  MpiOptions options;
  options.slicing.max_planes = a.max_planes;
  options.inpainter = a.inpainter;
  options.snap_depth_edges = snap;
  options.keep_fill_masks = true;
  MpiMaker maker(options);
  Progress quiet(true);
  return maker.make_from_disparity(bgr, disparity, quiet);
}

cv::Mat grey_map(const cv::Mat& disparity) {
  cv::Mat out, bgr;
  cv::normalize(disparity, out, 0, 255, cv::NORM_MINMAX, CV_8UC1);
  cv::cvtColor(out, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

void write_png(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write");
}

std::string softness_text(int factor) { return factor == 1 ? "hard" : "1/" + std::to_string(factor); }

// The target over the poses that move an object 40 px or more: at most 3% wrong, no fringe.
struct Verdict {
  int judged = 0;
  double worst_before = 0, worst_after = 0;
  int64_t fringe_before = 0, fringe_after = 0;

  void add(const EdgeScore& before, const EdgeScore& after) {
    if (after.motion_px < 40) return;
    worst_before = std::max(worst_before, before.wrong_share());
    worst_after = std::max(worst_after, after.wrong_share());
    fringe_before += before.fringe;
    fringe_after += after.fringe;
    ++judged;
  }
  const char* outcome() const {
    if (judged == 0) return "not judged (no pose moves an object 40 px)";
    return worst_after <= 0.03 && fringe_after == 0 ? "met" : "NOT met";
  }
  void print(const std::string& what) const {
    std::printf("%s: %d; worst wrong share %.2f%% before, %.2f%% after; fringe pixels %lld before, %lld after\n",
                what.c_str(), judged, 100 * worst_before, 100 * worst_after, static_cast<long long>(fringe_before),
                static_cast<long long>(fringe_after));
  }
};

int eval_scenes(const EdgeEvalArgs& a) {
  const cv::Mat texture = a.texture.empty() ? cv::Mat() : read_photo(a.texture);
  const std::vector<EdgeScene> scenes = edge_scenes(a.size, uint32_t(a.seed), texture);
  const Camera camera = camera_from_fov(a.size.width, a.size.height, 60);
  const DepthRange range;
  if (!a.output.empty()) fs::create_directories(a.output);
  std::printf("%-12s %5s %-14s %7s %11s %15s %13s %13s\n", "scene", "soft", "pose", "motion", "planes b/a",
              "wrong% b/a", "fringe b/a", "holes b/a");
  Verdict all;
  std::vector<Verdict> by_softness(a.softness.size());
  for (const EdgeScene& scene : scenes) {
    const EdgeJudge judge(scene, camera, range);
    for (size_t f = 0; f < a.softness.size(); ++f) {
      const int factor = a.softness[f];
      const cv::Mat soft = soften_disparity(scene.disparity, factor);
      const MpiResult before = make_mpi(a, scene.photo, soft, false);
      const MpiResult after = make_mpi(a, scene.photo, soft, true);
      for (size_t k = 0; k < a.poses.size(); ++k) {
        const Pose pose = pose_of(a.poses[k]);
        const EdgeScore b = judge.score(before.mpi, before.fill_masks, pose);
        const EdgeScore s = judge.score(after.mpi, after.fill_masks, pose);
        std::printf("%-12s %5s %-14s %7.1f %5zu/%-5zu %7.2f/%-7.2f %6lld/%-6lld %6lld/%-6lld\n", scene.name.c_str(),
                    softness_text(factor).c_str(), pose_text(a.poses[k]).c_str(),
                    s.motion_px, before.mpi.planes.size(), after.mpi.planes.size(), 100 * b.wrong_share(),
                    100 * s.wrong_share(), static_cast<long long>(b.fringe), static_cast<long long>(s.fringe),
                    static_cast<long long>(b.holes), static_cast<long long>(s.holes));
        all.add(b, s);
        by_softness[f].add(b, s);
        if (k == 0 && !a.output.empty()) {
          cv::Mat strip;
          cv::hconcat(std::vector<cv::Mat>{scene.photo, grey_map(soft), judge.exact_view(pose),
                                           Renderer(before.mpi).render(pose), Renderer(after.mpi).render(pose)},
                      strip);
          write_png((fs::path(a.output) / (scene.name + "_soft" + std::to_string(factor) + ".png")).string(), strip);
        }
      }
    }
  }
  for (size_t f = 0; f < a.softness.size(); ++f) {
    by_softness[f].print("softness " + softness_text(a.softness[f]) + ", poses moving an object 40 px or more");
    std::printf("  target: %s\n", by_softness[f].outcome());
  }
  all.print("poses moving an object 40 px or more");
  std::printf("target (at most 3%% wrong, no fringe): %s\n", all.outcome());
  return 0;
}

int eval_photos(const EdgeEvalArgs& a) {
  if (a.output.empty()) throw std::runtime_error("--images needs -o DIR (see ampi eval edges --help)");
  if (!a.depth_dir.empty() && !fs::is_directory(a.depth_dir)) throw std::runtime_error(a.depth_dir + ": not a directory");
  const std::vector<std::string> photos = list_images(a.images);
  std::vector<std::string> maps;  // looked up first: a missing one stops at once
  if (!a.depth_dir.empty())
    for (const std::string& photo : photos) maps.push_back(find_depth_reference(photo, a.images, a.depth_dir));
  // Without maps, the bundled lite network at its working size, as ampi run uses it.
  std::unique_ptr<DepthModel> net;
  if (maps.empty()) net = load_depth_model(depth_weights_path({}, "lite"));
  fs::create_directories(a.output);
  const Pose pose = pose_of(a.poses[0]);
  for (size_t i = 0; i < photos.size(); ++i) {
    const cv::Mat bgr = fit_long_side(read_photo(photos[i]), a.max_size);
    cv::Mat disparity = net ? estimate_disparity(*net, bgr, 0) : read_depth_map(maps[i], false);
    if (disparity.cols > bgr.cols || disparity.rows > bgr.rows)
      cv::resize(disparity, disparity, bgr.size(), 0, 0, cv::INTER_AREA);
    const MpiResult before = make_mpi(a, bgr, disparity, false);
    const MpiResult after = make_mpi(a, bgr, disparity, true);
    cv::Mat top, bottom, sheet;
    cv::hconcat(bgr, grey_map(after.disparity), top);
    cv::hconcat(Renderer(before.mpi).render(pose), Renderer(after.mpi).render(pose), bottom);
    cv::vconcat(top, bottom, sheet);
    const std::string out =
        (fs::path(a.output) / (fs::path(photos[i]).lexically_relative(a.images).stem().string() + ".png")).string();
    fs::create_directories(fs::path(out).parent_path());
    write_png(out, sheet);
    std::printf("%s: %zu planes before, %zu after -> %s\n", photos[i].c_str(), before.mpi.planes.size(),
                after.mpi.planes.size(), out.c_str());
  }
  return 0;
}

}  // namespace

int eval_edges(int argc, char** argv) {
  EdgeEvalArgs a;
  ArgParser p("ampi eval edges", kUsage);
  p.option("--size", [&](const std::string& v) { a.size = parse_size(v); });
  p.option("--seed", &a.seed, 0, 1 << 30);
  p.option("--texture", &a.texture);
  p.option("--softness", [&](const std::string& v) { a.softness = parse_int_list("--softness", v, 1, 64, "a factor"); });
  p.option("--pose", [&](const std::string& v) { const std::array<double, 3> t = parse_pose(v);
    a.poses.push_back({t[0], t[1], t[2]}); });
  p.option("--max-planes", &a.max_planes, 1, 255);
  p.option("--inpainter", [&](const std::string& v) { a.inpainter = parse_inpainter(v); });
  p.option("-o", &a.output);
  p.option("--images", &a.images);
  p.option("--depth-dir", &a.depth_dir);
  p.option("--max-size", &a.max_size, 32, 16384);
  p.option("--threads", &a.threads, 0, 1024);
  if (!p.parse(argc, argv)) return 0;
  if (a.threads > 0) set_default_threads(a.threads);
  if (a.poses.empty()) a.poses = {{0.08, 0, 0}, {-0.08, 0.04, 0}, {0, -0.1, 0}, {0.03, 0, 0}};
  return a.images.empty() ? eval_scenes(a) : eval_photos(a);
}

}  // namespace ampi::cli
