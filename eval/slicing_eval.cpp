#include "eval/slicing_eval.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "eval/inpaint_eval.h"
#include "render/renderer.h"
#include "render/trajectory.h"
#include "slicing/adaptive.h"
#include "slicing/assemble.h"

namespace ampi {
namespace {

std::vector<cv::Mat> render_views(const Mpi& mpi, const std::vector<Pose>& poses) {
  const Renderer renderer(mpi);
  std::vector<cv::Mat> views;
  for (const Pose& pose : poses) views.push_back(renderer.render(pose));
  return views;
}

void check_options(const SlicingEvalOptions& o) {
  if (o.counts.empty()) throw std::invalid_argument("slicing eval: no plane counts");
  for (int c : o.counts)
    if (c < 1 || c >= kDisparityLevels)
      throw std::invalid_argument("slicing eval: plane count " + std::to_string(c) + " is outside 1..255");
  if (o.reference_planes < 2 || o.reference_planes >= kDisparityLevels)
    throw std::invalid_argument("slicing eval: the reference plane count must be in 2..255");
  if (o.poses < 1) throw std::invalid_argument("slicing eval: at least one target pose is needed");
  if (!(o.amplitude > 0 && o.amplitude < 1)) throw std::invalid_argument("slicing eval: amplitude must be in (0, 1)");
}

}  // namespace

Mpi inpainted_mpi(const cv::Mat& bgr, const cv::Mat& disparity, const std::vector<Plane>& planes,
                  const LayerFiller& filler, const SlicingEvalOptions& options, const cv::Mat& band) {
  const Camera camera = camera_from_fov(bgr.cols, bgr.rows, options.fov_degrees);
  Mpi mpi = assemble_mpi(bgr, disparity, planes, camera, options.range);
  const int feathered = band.empty() ? 0 : options.edge_feather;
  feather_depth_edges(mpi, bgr, band, feathered);
  inpaint_mpi(mpi, filler, margin_for_photo(bgr.size(), feathered));
  return mpi;
}

std::vector<Pose> target_poses(const std::vector<Plane>& reference_planes, const SlicingEvalOptions& options) {
  PathOptions path;
  path.kind = PathKind::Circle;
  path.frames = options.poses;
  path.amplitude = options.amplitude;
  return camera_path(path, reference_planes);
}

ViewScore compare_views(const std::vector<cv::Mat>& views, const std::vector<cv::Mat>& reference_views) {
  if (views.size() != reference_views.size() || views.empty())
    throw std::invalid_argument("compare_views: the view counts differ or are zero");
  ViewScore sum;
  for (size_t i = 0; i < views.size(); ++i) {
    const cv::Mat all(views[i].size(), CV_8UC1, cv::Scalar(255));
    sum.ssim += masked_ssim(views[i], reference_views[i], all);
    sum.psnr += masked_psnr(views[i], reference_views[i], all);
  }
  return {sum.ssim / views.size(), sum.psnr / views.size()};
}

SlicingEvaluator::SlicingEvaluator(SlicingEvalOptions options, LayerFiller filler)
    : options_(std::move(options)), filler_(std::move(filler)) {
  check_options(options_);
  std::sort(options_.counts.begin(), options_.counts.end());
  options_.counts.erase(std::unique(options_.counts.begin(), options_.counts.end()), options_.counts.end());
  for (int c : options_.counts)
    for (const char* method : {"uniform", "adaptive"}) sums_.push_back({c, method});
}

std::vector<SlicingScore> SlicingEvaluator::add(const cv::Mat& bgr, const cv::Mat& disparity, const cv::Mat& band) {
  const std::vector<Plane> dense = slice_uniform(disparity, options_.reference_planes, options_.range);
  const std::vector<Pose> poses = target_poses(dense, options_);
  const std::vector<cv::Mat> reference_views =
      render_views(inpainted_mpi(bgr, disparity, dense, filler_, options_, band), poses);
  const auto score = [&](int count, const char* method, const std::vector<Plane>& planes) {
    const ViewScore s = compare_views(render_views(inpainted_mpi(bgr, disparity, planes, filler_, options_, band), poses),
                                      reference_views);
    return SlicingScore{count, method, double(planes.size()), s.ssim, s.psnr, 1};
  };
  std::vector<SlicingScore> rows;
  for (int count : options_.counts) {
    SlicingParams params;
    params.max_planes = count;
    params.slicer = options_.slicer;
    params.min_plane_share = options_.min_plane_share;
    params.tear_penalty = options_.tear_penalty;
    params.range = options_.range;
    const std::vector<Plane> adaptive = slice_adaptive(disparity, params);
    rows.push_back(score(count, "uniform", slice_uniform(disparity, int(adaptive.size()), options_.range)));
    rows.push_back(score(count, "adaptive", adaptive));
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    sums_[i].planes += rows[i].planes;
    sums_[i].ssim += rows[i].ssim;
    sums_[i].psnr += rows[i].psnr;
    sums_[i].photos += 1;
  }
  return rows;
}

std::vector<SlicingScore> SlicingEvaluator::mean() const {
  std::vector<SlicingScore> out = sums_;
  for (SlicingScore& s : out)
    if (s.photos > 0) {
      s.planes /= s.photos;
      s.ssim /= s.photos;
      s.psnr /= s.photos;
    }
  return out;
}

}  // namespace ampi
