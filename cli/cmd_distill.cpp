// ampi distill --teacher FILE.ampw --images DIR -o LABELS: the paper's pseudo ground
// truth, a teacher's 10x ensemble per photo, for training the bundled networks.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/eval_common.h"
#include "distill/ensemble.h"
#include "distill/label_folder.h"
#include "nets/model_loader.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/photo_io.h"

namespace ampi::cli {
namespace {

namespace fs = std::filesystem;

// Five sides times the mirror image make the paper's ten predictions. The paper spread
// MiDaS over 512..1920 px; a ViT's attention grows with the square of its tokens, so
// these go from Depth Anything V2's own 518 up to about a 1024-px photo's size, in
// multiples of its 14-px patch: one 1024x768 photo costs ViT-S about 25 s of CPU here,
// 11.8 s on 2 threads, within the 30 s aimed at (README, "A stronger depth model").
#define DEFAULT_RESOLUTIONS "518,644,770,896,1022"

const char kUsage[] =
    "usage: ampi distill --teacher FILE.ampw --images DIR -o LABELS\n"
    "                    [--resolutions LIST] [--keep-aspect] [--threads N]\n"
    "\n"
    "Labels every photo under DIR (searched recursively, .jpg .jpeg .png) with the paper's\n"
    "pseudo ground truth: the teacher runs at each square resolution on the photo (area-\n"
    "averaged first down to the largest side) and on its mirror image, each prediction is\n"
    "normalised by its median and mean absolute deviation, and the per-pixel median of all\n"
    "of them, at the photo's size, is written as a 16-bit PNG (0..65535, larger = nearer).\n"
    "LABELS/labels.tsv records the teacher, the resolutions and each photo's label; a\n"
    "second run with the same teacher skips what is done, so a stopped run resumes.\n"
    "training/train_depth.py trains on LABELS with --data distilled:LABELS, or on the\n"
    "ordinal set's training photos beside their pairs with --teacher-labels LABELS.\n"
    "\n"
    "  --teacher FILE    a depth weight file of any depth architecture (a Depth Anything V2\n"
    "                    file from training/import_depth_anything.py, or lite/heavy)\n"
    "  --images DIR      the photos\n"
    "  -o LABELS         the label folder: new, empty, or one this command made\n"
    "  --resolutions L   comma-separated square sides (default " DEFAULT_RESOLUTIONS ")\n"
    "  --keep-aspect     the resolutions are long sides, the photo's aspect kept (for\n"
    "                    networks trained on whole photos: lite and heavy)\n"
    "  --threads N       worker threads (default: all hardware threads)\n";

struct DistillOptions {
  std::string teacher, images, labels;
  std::vector<int> resolutions;
  EnsembleShape shape = EnsembleShape::kSquare;
  int threads = 0;
};

std::vector<int> parse_resolutions(const std::string& text) {
  std::vector<int> sides;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    size_t used = 0;
    int side = 0;
    try {
      side = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || item.empty() || side < 16 || side > 4096)
      throw std::runtime_error("--resolutions: '" + item + "' is not a side from 16 to 4096");
    sides.push_back(side);
    start = comma + 1;
  }
  return sides;
}

DistillOptions parse(int argc, char** argv, bool& help) {
  DistillOptions o;
  o.resolutions = parse_resolutions(DEFAULT_RESOLUTIONS);
  std::vector<std::string> extra;
  ArgParser p("distill", kUsage);
  p.option("--teacher", &o.teacher);
  p.option("--images", &o.images);
  p.option("-o", &o.labels);
  p.option("--output", &o.labels);
  p.option("--resolutions", [&](const std::string& v) { o.resolutions = parse_resolutions(v); });
  p.flag("--keep-aspect", [&] { o.shape = EnsembleShape::kAspectKept; });
  p.option("--threads", &o.threads, 1, 1024);
  p.positionals(&extra);
  help = !p.parse(argc, argv);
  if (help) return o;
  if (!extra.empty()) throw std::runtime_error("unexpected argument '" + extra[0] + "' (see ampi distill --help)");
  if (o.teacher.empty()) throw std::runtime_error("missing --teacher FILE.ampw (see ampi distill --help)");
  if (o.images.empty()) throw std::runtime_error("missing --images DIR (see ampi distill --help)");
  if (o.labels.empty()) throw std::runtime_error("missing -o LABELS (see ampi distill --help)");
  return o;
}

// The photos under `images`, relative to it; two photos whose labels would share a name
// (a/b_c.jpg and a_b/c.jpg, or x.jpg and x.png) are refused before any work. Lexically
// relative: a photo in a linked folder keeps the name it has under `images`.
std::vector<std::string> relative_photos(const std::string& images) {
  std::vector<std::string> photos;
  std::map<std::string, std::string> by_label;
  for (const std::string& path : list_images(images)) {
    const std::string relative = fs::path(path).lexically_relative(images).generic_string();
    const auto [it, added] = by_label.emplace(label_name(relative), relative);
    if (!added)
      throw std::runtime_error(images + ": " + it->second + " and " + relative + " would share the label " + it->first);
    photos.push_back(relative);
  }
  return photos;
}

// The teacher as the ensemble calls it: the model run at the image's own size (each
// square of the ensemble at its own resolution, whatever the file's working size).
Teacher teacher_of(DepthModel& net, ThreadPool& pool) {
  return [&net, &pool](const cv::Mat& rgb) {
    const cv::Mat input = rgb.isContinuous() ? rgb : rgb.clone();
    net.set_working_size(std::max(input.rows, input.cols));
    const Tensor d = net.run(input.ptr<float>(), input.rows, input.cols, pool);
    return cv::Mat(input.rows, input.cols, CV_32FC1, const_cast<float*>(d.f32())).clone();
  };
}

cv::Mat rgb_float(const cv::Mat& bgr) {
  cv::Mat rgb, out;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  rgb.convertTo(out, CV_32FC3, 1.0 / 255.0);
  return out;
}

// The photo brought down by area averaging until its long side is at most `long_side`.
// The ensemble's bilinear squares would alias a large photo (a 4000-px wallpaper sampled
// at 256 px keeps one pixel in 16 and loses everything between).
cv::Mat area_shrunk(const cv::Mat& photo, int long_side) {
  const double scale = static_cast<double>(long_side) / std::max(photo.rows, photo.cols);
  if (scale >= 1.0) return photo;
  cv::Mat out;
  cv::resize(photo, out, cv::Size(std::max(1, cvRound(photo.cols * scale)), std::max(1, cvRound(photo.rows * scale))), 0,
             0, cv::INTER_AREA);
  return out;
}

// The pseudo ground truth of a photo at the photo's own size.
cv::Mat label_of(const cv::Mat& photo, const Teacher& teacher, const std::vector<int>& resolutions,
                 EnsembleShape shape) {
  const int largest = *std::max_element(resolutions.begin(), resolutions.end());
  cv::Mat label = pseudo_ground_truth(rgb_float(area_shrunk(photo, largest)), teacher, resolutions, shape);
  if (label.size() != photo.size()) cv::resize(label, label, photo.size(), 0, 0, cv::INTER_LINEAR);
  return label;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int cmd_distill(int argc, char** argv) {
  bool help = false;
  const DistillOptions o = parse(argc, argv, help);
  if (help) return 0;
  const std::vector<std::string> photos = relative_photos(o.images);
  const std::unique_ptr<DepthModel> net = load_depth_model(o.teacher);
  for (int side : o.resolutions) set_working_size_option(*net, side, "--resolutions");  // before any photo
  const LabelRecipe recipe{fs::path(o.teacher).filename().string(), net->architecture(), net->variant(),
                           o.resolutions, o.shape, fs::absolute(o.images).lexically_normal().string()};
  LabelFolder labels(o.labels, recipe);
  ThreadPool pool(o.threads);
  const Teacher teacher = teacher_of(*net, pool);
  const size_t already = labels.size();
  for (size_t i = 0; i < photos.size(); ++i) {
    if (labels.has(photos[i])) continue;
    const auto start = std::chrono::steady_clock::now();
    const cv::Mat photo = read_photo((fs::path(o.images) / photos[i]).string());
    labels.add(photos[i], label_of(photo, teacher, o.resolutions, o.shape));
    std::fprintf(stderr, "ampi distill: [%zu/%zu] %s %.1f s\n", i + 1, photos.size(), photos[i].c_str(),
                 seconds_since(start));
  }
  std::printf("%s: %zu photos labelled (%zu by earlier runs) with %s (%s) -> %s\n", o.images.c_str(), labels.size(),
              already, recipe.teacher_file.c_str(), net->variant().c_str(), o.labels.c_str());
  return 0;
}

}  // namespace ampi::cli
