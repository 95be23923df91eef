#include "pipeline/make_mpi.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "engine/memory_budget.h"
#include "inpaint/net_filler.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/depth_io.h"
#include "pipeline/photo_io.h"
#include "slicing/assemble.h"

namespace ampi {

LayerFiller make_layer_filler(Inpainter kind, const std::string& weights) {
  switch (kind) {
    case Inpainter::Harmonic: return harmonic_filler();
    case Inpainter::PushPull: return push_pull_filler();
    case Inpainter::Network: break;
  }
  return inpaint_net_filler(std::make_shared<const InpaintNet>(load_inpaint_net(inpaint_weights_path(weights))));
}

MpiMaker::MpiMaker(MpiOptions options) : options_(std::move(options)) {
  if (options_.working_size != 0 && options_.working_size < kMinPhotoSide)
    throw std::invalid_argument("working size must be at least " + std::to_string(kMinPhotoSide) + " px");
}

MpiMaker::~MpiMaker() = default;

cv::Mat MpiMaker::working_disparity(const cv::Mat& bgr, cv::Size photo_size, const std::string& photo_path,
                                    Progress& progress) {
  if (!options_.depth_file.empty()) {
    cv::Mat disparity = progress.stage("depth (file)", [&] {
      return read_depth_map(options_.depth_file, options_.depth_is_distance);
    });
    if (disparity.size() != photo_size)
      throw std::runtime_error(options_.depth_file + ": depth map is " + std::to_string(disparity.cols) +
                               "x" + std::to_string(disparity.rows) + " but the photo " + photo_path +
                               " is " + std::to_string(photo_size.width) + "x" + std::to_string(photo_size.height));
    if (disparity.size() != bgr.size())  // a reduced photo: the map is reduced with it
      cv::resize(disparity, disparity, bgr.size(), 0, 0, cv::INTER_AREA);
    return disparity;
  }
  if (!depth_net_) {
    const std::string path = depth_weights_path(options_.depth_weights, options_.depth_model);
    depth_net_ = progress.stage("load depth", [&] { return load_depth_model(path); });
  }
  return progress.stage("depth", [&] {
    if (options_.working_size) set_working_size_option(*depth_net_, options_.working_size);
    return estimate_disparity(*depth_net_, bgr, 0);
  });
}

LayerFiller& MpiMaker::filler() {
  if (filler_) return *filler_;
  const Inpainter kind = options_.inpaint_weights.empty() ? options_.inpainter : Inpainter::Network;
  filler_ = make_layer_filler(kind, options_.inpaint_weights);
  inpainter_ = inpainter_name(kind);
  return *filler_;
}

MpiResult MpiMaker::make(const cv::Mat& photo, const std::string& photo_path, Progress& progress) {
  MpiResult result;
  cv::Mat bgr = photo;
  const int cap = options_.max_working_side;
  if (cap > 0 && std::max(photo.cols, photo.rows) > cap) {
    result.full_bgr = photo;
    result.full_camera = camera_from_fov(photo.cols, photo.rows, options_.fov_degrees);
    bgr = progress.stage("reduce", [&] {
      const ImageSize work = depth_working_size(photo.rows, photo.cols, cap);
      cv::Mat reduced;
      cv::resize(photo, reduced, {work.width, work.height}, 0, 0, cv::INTER_AREA);
      return reduced;
    });
  }
  // The layers are the run's largest buffers: a photo they would not fit in memory is
  // refused before any work is done.
  const int layers = options_.slicing.max_planes;
  check_allocation(bytes_for({uint64_t(layers), uint64_t(bgr.cols), uint64_t(bgr.rows), 4}), photo_path,
                   std::to_string(layers) + " RGBA layers at " + std::to_string(bgr.cols) + "x" +
                       std::to_string(bgr.rows));
  const cv::Mat disparity = working_disparity(bgr, photo.size(), photo_path, progress);
  MpiResult made = make_from_disparity(bgr, disparity, progress);
  made.full_bgr = result.full_bgr;
  made.full_camera = result.full_camera;
  return made;
}

// Slice at the working resolution (the histogram needs no more pixels): the size of the
// map depth gave (the network's working size), at most 1024 px or --working-size.
std::vector<Plane> MpiMaker::slice(const cv::Mat& disparity, cv::Size depth_size, MpiResult& result) const {
  cv::Mat small = disparity;
  const ImageSize work = depth_working_size(depth_size.height, depth_size.width,
                                            options_.working_size ? options_.working_size : 1024);
  if (work.width != disparity.cols || work.height != disparity.rows)
    cv::resize(disparity, small, {work.width, work.height}, 0, 0, cv::INTER_AREA);
  result.slicing_size = small.size();
  return options_.uniform ? slice_uniform(small, options_.slicing.max_planes, options_.slicing.range)
                          : slice_adaptive(small, options_.slicing);
}

MpiResult MpiMaker::make_from_disparity(const cv::Mat& bgr, const cv::Mat& disparity, Progress& progress) {
  MpiResult result;
  const bool snap = options_.snap_depth_edges;
  DepthEdges edges;
  if (snap) edges = progress.stage("depth edges", [&] { return snap_depth_edges(bgr, disparity, options_.depth_edges); });
  // Without snapping, the paper's way: the map is sliced as depth made it and the layers
  // are cut from it enlarged bilinearly.
  std::vector<Plane> planes =
      progress.stage("slicing", [&] { return slice(snap ? edges.disparity : disparity, disparity.size(), result); });
  const int feathered = snap && options_.soft_alpha == 0 ? options_.edge_feather : 0;
  result.mpi = progress.stage("assembly", [&] {
    result.disparity = snap ? edges.disparity : enlarge_disparity(disparity, bgr.size());
    const Camera camera = camera_from_fov(bgr.cols, bgr.rows, options_.fov_degrees);
    Mpi mpi = assemble_mpi(bgr, result.disparity, planes, camera, options_.slicing.range, options_.soft_alpha);
    feather_depth_edges(mpi, bgr, edges.band, feathered);
    return mpi;
  });
  LayerFiller& fill = filler();
  progress.stage("inpainting", [&] {
    return inpaint_mpi(result.mpi, fill, margin_for_photo(bgr.size(), feathered),
                       options_.keep_fill_masks ? &result.fill_masks : nullptr);
  });
  result.inpainter = inpainter_;
  return result;
}

}  // namespace ampi
