// ampi eval MODE: reproduce the paper's evaluations on any folder of photos. One entry
// per mode in kModes; each mode parses its own options and leaves the measuring to the
// library (eval/).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/eval_common.h"
#include "engine/thread_pool.h"
#include "eval/depth_eval.h"
#include "eval/ordinal_eval.h"
#include "eval/slicing_eval.h"
#include "eval/inpaint_eval.h"
#include "inpaint/net_filler.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/depth_io.h"
#include "pipeline/photo_io.h"
#include "slicing/depth_edges.h"
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
    "(the network), telea and ns (OpenCV cv::inpaint), push-pull and harmonic (the two\n"
    "classic fills a network may start from; the bundled one refines harmonic).\n"
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

// The depth network is required: without it there are no planes to evaluate on.
std::unique_ptr<DepthModel> load_depth(const std::string& path) {
  std::string file = path;
  if (file.empty()) {
    try {
      file = depth_weights_path({}, "lite");
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
  return load_depth_model(info);
}

// The map of images/sub/photo.jpg is depth_dir/sub/photo.jpg.png.
std::string depth_map_path(const std::string& depth_dir, const std::string& images, const std::string& photo) {
  return (fs::path(depth_dir) / fs::path(photo).lexically_relative(images)).string() + ".png";
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
  std::unique_ptr<DepthModel> depth;
  if (a.depth_dir.empty()) depth = load_depth(a.depth_weights);
  auto net = std::make_shared<const InpaintNet>(load_inpaint_net(inpaint_weights_path(a.weights)));
  InpaintEvaluator eval({{"ampi", network_filler(net)},
                         {"telea", telea_filler(a.radius)},
                         {"ns", navier_stokes_filler(a.radius)},
                         {"push-pull", push_pull_margin_filler()},
                         {"harmonic", harmonic_margin_filler()}});
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

// ---- eval depth ------------------------------------------------------------------------------

const char kDepthUsage[] =
    "usage: ampi eval depth --images DIR --reference DIR [--model NAME | --weights FILE]\n"
    "                       [--reference-is-distance] [--working-size N] [--limit N] [--threads N]\n"
    "       ampi eval depth --images DIR --ordinal FILE [--split val|test|holdout|train|all]\n"
    "                       [...]\n"
    "\n"
    "The paper's depth metrics (delta < 1.25, 1.25^2, 1.25^3, RMSE, REL; Luvizon et al.,\n"
    "after Eigen et al. 2014) of the depth network on every photo under DIR (.jpg, .jpeg,\n"
    ".png, recursively, sorted), one row per method: the network, and vertical-gradient,\n"
    "a baseline whose disparity grows linearly from the top row to the bottom (the floor).\n"
    "\n"
    "The reference of DIR/sub/name.jpg is the one file --reference/sub/name.* in any format\n"
    "`ampi run --depth` reads (8/16-bit PNG, float TIFF, .npy), larger = nearer unless\n"
    "--reference-is-distance. The prediction is resized (bilinear) to the reference's size.\n"
    "\n"
    "How each image is scored, all in disparity (the quantity the network predicts):\n"
    "  valid pixels: reference > 0 (0 = no measurement, e.g. the sky); NaN/inf is an error\n"
    "  alignment:    a = (p - median(p)) * std(r) / std(p) + median(r) over the valid pixels\n"
    "                (p prediction, r reference, std the population standard deviation),\n"
    "                then a = max(a, min(r)) so every ratio is defined\n"
    "  delta < T:    fraction of valid pixels with max(a/r, r/a) < T\n"
    "  RMSE:         sqrt(mean((a - r)^2)), in the reference's units\n"
    "  REL:          mean(|a - r| / r), the reference in the denominator\n"
    "The folder's scores are the means of the images' scores.\n"
    "\n"
    "With --ordinal, real photos are judged by point pairs labelled by eye instead\n"
    "(training/ordinal/ordinal.json.gz; a name ending in .gz is read as gzip; DIR is the\n"
    "folder its photo names are relative to):\n"
    "WHDR, the share of pairs labelled A or B nearer whose order the network's disparity\n"
    "(bilinear at the two points) gets wrong; a tie counts half. NAME-snapped scores the\n"
    "map `ampi run` slices: the disparity with its depth edges snapped to the photo\n"
    "(unless ampi run --no-edge-snap). Beside them the vertical gradient (lower = nearer) and\n"
    "a constant map (0.5, every pair a tie).\n"
    "\n"
    "  --images DIR              photos\n"
    "  --reference DIR           reference depth maps, same relative paths and names\n"
    "  --reference-is-distance   the references hold distances (larger = farther); 0 = none\n"
    "  --ordinal FILE            an ordinal set instead of reference maps (WHDR)\n"
    "  --split S                 the ordinal set's part scored: val (default), test (the\n"
    "                            validation photos' held-out pairs, never used to pick a\n"
    "                            network), holdout (photos never trained or picked on,\n"
    "                            scored only to judge a pick), train or all\n"
    "  --model M                 a bundled depth model by name: lite (default), heavy\n"
    "  --weights FILE            a depth weight file instead\n"
    "  --working-size N          the network's working size (default: the weight file's): the\n"
    "                            long side for lite and heavy, the input's shorter side for\n"
    "                            Depth Anything V2\n"
    "  --limit N                 only the first N photos\n"
    "  --threads N               worker threads (default: all hardware threads)\n";

struct DepthEvalArgs {
  std::string images, reference, ordinal, split = "val", model = "lite", weights;
  bool reference_is_distance = false;
  int working_size = 0, limit = 0, threads = 0;
};

void print_depth_row(const std::string& method, const DepthMetrics& m, int images) {
  std::printf("%-20s %10.4f %12.4f %12.4f %10.4f %8.4f %7d\n", method.c_str(), m.delta1, m.delta2, m.delta3, m.rmse,
              m.rel, images);
}

// --weights FILE, or the bundled file of --model.
std::unique_ptr<DepthModel> load_depth_net(const DepthEvalArgs& a) {
  return load_depth_model(depth_weights_path(a.weights, a.model));
}

void print_ordinal_row(const std::string& method, const OrdinalScore& s, int photos) {
  std::printf("%-20s %8.4f %7d %7d\n", method.c_str(), s.whdr(), s.pairs, photos);
}

int eval_depth_ordinal(const DepthEvalArgs& a) {
  if (a.images.empty()) throw std::runtime_error("--ordinal needs --images DIR, the folder its photo names are under");
  if (!a.reference.empty()) throw std::runtime_error("--ordinal and --reference: give one of them");
  std::vector<OrdinalPhoto> set = read_ordinal_set(a.ordinal);
  if (a.split != "all")
    set.erase(std::remove_if(set.begin(), set.end(), [&](const OrdinalPhoto& e) { return e.split != a.split; }),
              set.end());
  if (a.limit > 0 && size_t(a.limit) < set.size()) set.resize(a.limit);
  if (set.empty()) throw std::runtime_error(a.ordinal + ": no photos in split " + a.split);
  for (const OrdinalPhoto& e : set)  // a missing photo stops before the network runs
    if (!fs::is_regular_file(fs::path(a.images) / e.photo))
      throw std::runtime_error((fs::path(a.images) / e.photo).string() + ": photo of the ordinal set not found");
  const std::unique_ptr<DepthModel> net = load_depth_net(a);
  if (a.working_size) set_working_size_option(*net, a.working_size);
  const int side = 0;  // the network's working size, set above
  OrdinalScore network, snapped, gradient, constant;
  for (const OrdinalPhoto& e : set) {
    const std::string path = (fs::path(a.images) / e.photo).string();
    const cv::Mat bgr = read_photo(path);
    if (bgr.size() != e.size)
      throw std::runtime_error(path + ": is " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
                               " but was labelled at " + std::to_string(e.size.width) + "x" +
                               std::to_string(e.size.height));
    const cv::Mat disparity = estimate_disparity(*net, bgr, side);
    const OrdinalScore s = score_ordinal(disparity, e);
    network.add(s);
    snapped.add(score_ordinal(snap_depth_edges(bgr, disparity).disparity, e));
    gradient.add(score_ordinal(vertical_gradient_disparity(e.size), e));
    constant.add(score_ordinal(cv::Mat(e.size, CV_32FC1, cv::Scalar(1)), e));
    std::fprintf(stderr, "%s: %d pairs, WHDR %.4f\n", e.photo.c_str(), s.pairs, s.whdr());
  }
  std::printf("%-20s %8s %7s %7s\n", "method", "WHDR", "pairs", "photos");
  std::set<std::string> names;  // a validation photo has a val and a test entry
  for (const OrdinalPhoto& e : set) names.insert(e.photo);
  const int photos = int(names.size());
  const std::string name = a.weights.empty() ? a.model : fs::path(a.weights).filename().string();
  print_ordinal_row(name, network, photos);
  print_ordinal_row(name + "-snapped", snapped, photos);
  print_ordinal_row("vertical-gradient", gradient, photos);
  print_ordinal_row("constant", constant, photos);
  std::printf("(WHDR: share of labelled pairs ordered wrongly, lower is better; split %s; see --help)\n",
              a.split.c_str());
  return 0;
}

int eval_depth(int argc, char** argv) {
  DepthEvalArgs a;
  ArgParser p("ampi eval depth", kDepthUsage);
  p.option("--images", &a.images);
  p.option("--reference", &a.reference);
  p.flag("--reference-is-distance", &a.reference_is_distance);
  p.option("--ordinal", &a.ordinal);
  p.option("--split", [&](const std::string& v) {
    if (v != "val" && v != "test" && v != "holdout" && v != "train" && v != "all")
      throw std::runtime_error("--split: '" + v + "' is not val, test, holdout, train or all");
    a.split = v;
  });
  p.option("--model", [&](const std::string& v) {
    check_depth_model_name(v);
    a.model = v;
  });
  p.option("--weights", &a.weights);
  p.option("--working-size", &a.working_size, 16, 16384);
  p.option("--limit", &a.limit, 0, 1 << 30);
  p.option("--threads", &a.threads, 0, 1024);
  if (!p.parse(argc, argv)) return 0;
  if (a.threads > 0) set_default_threads(a.threads);
  if (!a.ordinal.empty()) return eval_depth_ordinal(a);
  if (a.images.empty() || a.reference.empty())
    throw std::runtime_error("--images DIR and --reference DIR are required (see ampi eval depth --help)");
  if (!fs::is_directory(a.reference)) throw std::runtime_error(a.reference + ": not a directory");

  std::vector<std::string> photos = list_images(a.images);
  if (a.limit > 0 && size_t(a.limit) < photos.size()) photos.resize(a.limit);
  // Every reference is looked up before the network runs: a missing one stops at once.
  std::vector<std::string> references;
  for (const std::string& photo : photos) references.push_back(find_depth_reference(photo, a.images, a.reference));
  const std::unique_ptr<DepthModel> net = load_depth_net(a);
  if (a.working_size) set_working_size_option(*net, a.working_size);
  const int side = 0;  // the network's working size, set above
  DepthMetricsMean network, gradient;
  for (size_t i = 0; i < photos.size(); ++i) {
    const cv::Mat bgr = read_photo(photos[i]);
    const DepthReference ref = read_depth_reference(references[i], a.reference_is_distance);
    if (ref.disparity.size() != bgr.size())
      std::fprintf(stderr, "note: %s is %dx%d but its reference %s is %dx%d: the prediction is resized to the reference\n",
                   photos[i].c_str(), bgr.cols, bgr.rows, references[i].c_str(), ref.disparity.cols,
                   ref.disparity.rows);
    cv::Mat prediction;
    cv::resize(estimate_disparity(*net, bgr, side), prediction, ref.disparity.size(), 0, 0, cv::INTER_LINEAR);
    const DepthMetrics m = depth_metrics(prediction, ref);
    network.add(m);
    gradient.add(depth_metrics(vertical_gradient_disparity(ref.disparity.size()), ref));
    std::fprintf(stderr, "%s: delta<1.25 %.4f, RMSE %.4f, REL %.4f\n", photos[i].c_str(), m.delta1, m.rmse, m.rel);
  }
  std::printf("%-20s %10s %12s %12s %10s %8s %7s\n", "method", "d<1.25", "d<1.25^2", "d<1.25^3", "RMSE", "REL",
              "images");
  print_depth_row(a.weights.empty() ? a.model : fs::path(a.weights).filename().string(), network.mean(),
                  network.count());
  print_depth_row("vertical-gradient", gradient.mean(), gradient.count());
  std::printf("(disparity aligned to each reference by median and standard deviation; RMSE in the reference's "
              "units; see --help)\n");
  return 0;
}

// ---- eval slicing ----------------------------------------------------------------------------

const char kSlicingUsage[] =
    "usage: ampi eval slicing --images DIR [--counts 4,8,16] [--reference-planes N] [--poses N]\n"
    "                         [--amplitude A] [--max-size N] [--model NAME | --weights FILE]\n"
    "                         [--working-size N] [--depth-dir D] [--inpainter push-pull|network]\n"
    "                         [--slicer paper|optimal] [--min-plane-share F] [--tear-penalty P]\n"
    "                         [--no-edge-snap] [--limit N] [--threads N]\n"
    "\n"
    "The paper's Table 3 (Luvizon et al., WACV 2021: adaptive against uniform slicing, SSIM and\n"
    "PSNR of novel views) on every photo under DIR (.jpg, .jpeg, .png, recursively, sorted).\n"
    "Photos have no second view, so, as the paper does for its own photos, views are compared\n"
    "with those of a densely sampled MPI. Per photo (scaled down to --max-size) and per\n"
    "maximum plane count N, three MPIs from the same depth (our network, or --depth-dir: the map\n"
    "snapped to the photo's edges and the layer borders feathered there, as ampi run does), the\n"
    "same slicing depth range and the same inpainting:\n"
    "  adaptive   adaptive slicing (--slicer: the paper's rule decides the count, the cuts\n"
    "             minimise the squared disparity error; or the paper's cuts), at most N\n"
    "             planes (it makes n)\n"
    "  uniform    equal disparity intervals, n planes: the count adaptive made for the photo\n"
    "             (empty intervals are dropped, so it may hold fewer)\n"
    "  reference  equal disparity intervals, --reference-planes planes\n"
    "Each is rendered at the same target poses: the camera on a circle in the image plane,\n"
    "radius A times the nearest reference plane's depth (as ampi run's circle path).\n"
    "SSIM (11x11 Gaussian window, sigma 1.5) and PSNR of the full frame against the\n"
    "reference's frame, averaged over poses, then photos. One row per count and method;\n"
    "planes = the mean count made.\n"
    "\n"
    "  --images DIR            photos\n"
    "  --counts LIST           maximum plane counts, comma-separated (default 4,8,16)\n"
    "  --reference-planes N    planes of the dense reference MPI (default 255: one per level)\n"
    "  --poses N               target poses (default 8)\n"
    "  --amplitude A           circle radius / nearest reference depth (default 0.05)\n"
    "  --max-size N            photos are scaled down to this long side (default 512)\n"
    "  --model M, --weights F  depth network: bundled lite (default) or heavy, or a file\n"
    "  --working-size N        the network's working size (default: the weight file's; the\n"
    "                          long side for lite and heavy, the shorter side for Depth\n"
    "                          Anything V2)\n"
    "  --depth-dir D           depth maps instead of the network: the one file D/sub/name.* for\n"
    "                          DIR/sub/name.jpg, any format ampi run --depth reads, larger = nearer\n"
    "  --inpainter I           push-pull (default) or network (weights/inpaint.ampw; ampi run's default)\n"
    "  --slicer S              optimal (default) or paper, as ampi slice --slicer\n"
    "  --min-plane-share F     the paper's rule takes a cut only if each plane keeps more than\n"
    "                          F/N of the depth histogram (default 0: the paper's rule exactly)\n"
    "  --tear-penalty P        optimal slicer: a cut also costs P squared levels per pixel of the\n"
    "                          edge-free depth histogram at the cut (default 0)\n"
    "  --no-edge-snap          the map enlarged bilinearly and sliced as it is (ampi run\n"
    "                          --no-edge-snap), as before depth edges followed the photo\n"
    "  --limit N               only the first N photos\n"
    "  --threads N             worker threads (default: all hardware threads)\n";

struct SlicingEvalArgs {
  std::string images, model = "lite", weights, depth_dir, inpainter = "push-pull";
  SlicingEvalOptions options;
  int max_size = 512, working_size = 0, limit = 0, threads = 0;
  bool snap_edges = true;
};

LayerFiller slicing_filler(const std::string& inpainter) {
  if (inpainter == "push-pull") return push_pull_filler();
  return inpaint_net_filler(std::make_shared<const InpaintNet>(load_inpaint_net(inpaint_weights_path())));
}

void print_slicing_table(const std::vector<SlicingScore>& rows, const std::vector<int>& psnr_wins,
                         const std::vector<int>& ssim_wins) {
  std::printf("%-6s %-9s %7s %8s %8s\n", "count", "method", "planes", "SSIM", "PSNR");
  for (const SlicingScore& s : rows)
    std::printf("%-6d %-9s %7.2f %8.4f %8.3f\n", s.count, s.method.c_str(), s.planes, s.ssim, s.psnr);
  bool all = true;
  for (size_t i = 0; i + 1 < rows.size(); i += 2) {
    const SlicingScore &uniform = rows[i], &adaptive = rows[i + 1];
    const bool at_or_above = adaptive.ssim >= uniform.ssim && adaptive.psnr >= uniform.psnr;
    all = all && at_or_above;
    std::printf("count %d: adaptive %s uniform in mean SSIM and PSNR; above it on %d (SSIM) and %d (PSNR) of %d photos\n",
                uniform.count, at_or_above ? "at or above" : "NOT at or above", ssim_wins[i / 2], psnr_wins[i / 2],
                uniform.photos);
  }
  std::printf("adaptive >= uniform at every count: %s\n", all ? "yes" : "no");
}

int eval_slicing(int argc, char** argv) {
  SlicingEvalArgs a;
  ArgParser p("ampi eval slicing", kSlicingUsage);
  p.option("--images", &a.images);
  p.option("--counts", [&](const std::string& v) { a.options.counts = parse_int_list("--counts", v, 1, 255, "a plane count"); });
  p.option("--reference-planes", &a.options.reference_planes, 2, 255);
  p.option("--poses", &a.options.poses, 1, 1000);
  p.option("--amplitude", &a.options.amplitude, 1e-6, 0.999);
  p.option("--max-size", &a.max_size, 32, 16384);
  p.option("--model", [&](const std::string& v) {
    check_depth_model_name(v);
    a.model = v;
  });
  p.option("--weights", &a.weights);
  p.option("--working-size", &a.working_size, 16, 16384);
  p.option("--depth-dir", &a.depth_dir);
  p.option("--inpainter", [&](const std::string& v) {
    if (v != "push-pull" && v != "network") throw std::runtime_error("--inpainter: '" + v + "' is not push-pull or network");
    a.inpainter = v;
  });
  p.option("--slicer", [&](const std::string& v) { a.options.slicer = parse_slicer(v); });
  p.option("--min-plane-share", &a.options.min_plane_share, 0.0, 1.0);
  p.option("--tear-penalty", &a.options.tear_penalty, 0.0, 1e9);
  p.option("--limit", &a.limit, 0, 1 << 30);
  p.option("--threads", &a.threads, 0, 1024);
  p.flag("--no-edge-snap", [&] { a.snap_edges = false; });
  if (!p.parse(argc, argv)) return 0;
  if (a.images.empty()) throw std::runtime_error("--images DIR is required (see ampi eval slicing --help)");
  if (a.threads > 0) set_default_threads(a.threads);

  std::vector<std::string> photos = list_images(a.images);
  if (a.limit > 0 && size_t(a.limit) < photos.size()) photos.resize(a.limit);
  std::vector<std::string> depth_maps;  // looked up first: a missing one stops at once
  if (!a.depth_dir.empty()) {
    if (!fs::is_directory(a.depth_dir)) throw std::runtime_error(a.depth_dir + ": not a directory");
    for (const std::string& photo : photos) depth_maps.push_back(find_depth_reference(photo, a.images, a.depth_dir));
  }
  std::unique_ptr<DepthModel> net;
  if (depth_maps.empty()) net = load_depth_model(depth_weights_path(a.weights, a.model));
  if (net && a.working_size) set_working_size_option(*net, a.working_size);
  const int side = 0;  // the network's working size, set above
  SlicingEvaluator eval(a.options, slicing_filler(a.inpainter));
  std::vector<int> psnr_wins(a.options.counts.size()), ssim_wins(a.options.counts.size());
  for (size_t k = 0; k < photos.size(); ++k) {
    const std::string& path = photos[k];
    const cv::Mat bgr = fit_long_side(read_photo(path), a.max_size);
    cv::Mat map = net ? estimate_disparity(*net, bgr, side) : read_depth_map(depth_maps[k], false);
    if (map.cols > bgr.cols || map.rows > bgr.rows) cv::resize(map, map, bgr.size(), 0, 0, cv::INTER_AREA);
    // The map ampi run cuts the layers from: snapped to the photo's edges, or enlarged.
    const DepthEdges edges =
        a.snap_edges ? snap_depth_edges(bgr, map) : DepthEdges{enlarge_disparity(map, bgr.size()), cv::Mat()};
    const std::vector<SlicingScore> rows = eval.add(bgr, edges.disparity, edges.band);
    std::string line;
    for (size_t i = 0; i + 1 < rows.size(); i += 2) {
      psnr_wins[i / 2] += rows[i + 1].psnr > rows[i].psnr;
      ssim_wins[i / 2] += rows[i + 1].ssim > rows[i].ssim;
      char part[160];
      std::snprintf(part, sizeof part, "  %d: %.0f planes %.2f dB vs uniform %.0f planes %.2f dB", rows[i].count,
                    rows[i + 1].planes, rows[i + 1].psnr, rows[i].planes, rows[i].psnr);
      line += part;
    }
    std::fprintf(stderr, "%s:%s\n", path.c_str(), line.c_str());
  }
  print_slicing_table(eval.mean(), psnr_wins, ssim_wins);
  std::printf("(%zu photos at most %d px, %d poses, amplitude %g, reference of %d planes, %s inpainting, %s depth)\n",
              photos.size(), a.max_size, a.options.poses, a.options.amplitude, a.options.reference_planes,
              a.inpainter.c_str(),
              !a.depth_dir.empty() ? "--depth-dir" : a.weights.empty() ? a.model.c_str() : a.weights.c_str());
  return 0;
}

// ---- the mode table ---------------------------------------------------------------------------

struct Mode {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};

const Mode kModes[] = {
    {"depth", eval_depth, "depth metrics (delta, RMSE, REL) against reference maps, or WHDR on an ordinal set"},
    {"slicing", eval_slicing, "the paper's Table 3: adaptive vs. uniform MPIs against a dense one (SSIM, PSNR)"},
    {"inpaint", eval_inpaint, "margin filling: ampi vs. cv::inpaint Telea / Navier-Stokes, push-pull, harmonic"},
    {"edges", eval_edges, "objects kept whole in new views: wrong object pixels and fringe at depth edges"},
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
