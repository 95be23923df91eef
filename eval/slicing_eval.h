// `ampi eval slicing`: the paper's Table 3 (Luvizon et al., WACV 2021, "View synthesis"
// and "Evaluation metrics") on any photos.
//
// The paper renders RealEstate10K target frames, but says that where no calibrated pairs
// exist it compares "the views produced by our adaptive slicing method with a densely
// sampled MPI projected to the target view point"; that is what is done here, since
// photos carry no second view. Per photo, for every maximum plane count N:
//   - adaptive: slice_adaptive with max_planes = N and the chosen slicer; it makes n <= N
//               planes;
//   - uniform:  slice_uniform with n planes, the count adaptive actually produced (the
//               paper's "uniform slicing was performed with the number of planes resulting
//               from our method"); empty uniform planes are dropped, so it may hold fewer;
//   - reference: slice_uniform with reference_planes planes (dense).
// All three come from the same disparity, are assembled at the photo's resolution and
// inpainted by the same filler with the same margin, and use the same DepthRange, so the
// planes they share sit at the same depths. Each is rendered at the same target poses
// (a circle of the camera in the image plane, its radius `amplitude` times the nearest
// reference plane's depth, as `ampi run --trajectory circle` moves); SSIM and PSNR of
// each view against the reference's view at that pose (eval/inpaint_eval.h's
// full-frame metrics) are averaged over poses, then over photos.
#pragma once
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "inpaint/mpi_inpaint.h"
#include "mpi/mpi.h"
#include "render/pose.h"
#include "slicing/adaptive.h"

namespace ampi {

struct SlicingEvalOptions {
  std::vector<int> counts = {4, 8, 16};  // maximum plane counts of the adaptive slicer
  // Planes of the dense uniform reference MPI. 255: about one per level of the 8-bit
  // normalised disparity, the densest MPI the slicers can make. Every cut either slicer
  // makes is then one of the reference's, for adaptive and uniform alike; with 64, the
  // uniform cuts at 4, 8 and 16 planes would all be the reference's, adaptive's mostly not.
  int reference_planes = 255;
  int poses = 8;                         // target poses, evenly spaced on the circle
  double amplitude = 0.05;               // circle radius / nearest reference plane depth, in (0, 1)
  double fov_degrees = 60;               // assumed horizontal field of view
  DepthRange range;                      // where normalised disparity puts the planes
  Slicer slicer = SlicingParams{}.slicer;                    // how the adaptive slicer cuts
  double min_plane_share = SlicingParams{}.min_plane_share;  // the adaptive slicer's guard
  double tear_penalty = SlicingParams{}.tear_penalty;        // its cost of cutting a surface
  int edge_feather = 2;  // layer borders feathered at depth edges, as ampi run does (with a band)
};

// One row of the table: a count and a method, averaged over photos.
struct SlicingScore {
  int count = 0;            // the maximum plane count
  std::string method;       // "uniform" or "adaptive"
  double planes = 0;        // mean number of planes actually made
  double ssim = 0, psnr = 0;
  int photos = 0;
};

// Assembles the MPI of `planes` from the photo and its disparity (same size) and fills
// its margins with `filler`. With a depth-edge band (snap_depth_edges), the layer
// borders there are feathered first, as ampi run does.
Mpi inpainted_mpi(const cv::Mat& bgr, const cv::Mat& disparity, const std::vector<Plane>& planes,
                  const LayerFiller& filler, const SlicingEvalOptions& options, const cv::Mat& band = {});

// The target poses: `options.poses` camera positions evenly spaced on the circle.
std::vector<Pose> target_poses(const std::vector<Plane>& reference_planes, const SlicingEvalOptions& options);

// Mean full-frame SSIM and PSNR (dB; 100 for identical frames) of `views` against
// `reference_views`, pose by pose (same counts, sizes and types).
struct ViewScore {
  double ssim = 0, psnr = 0;
};
ViewScore compare_views(const std::vector<cv::Mat>& views, const std::vector<cv::Mat>& reference_views);

// Accumulates Table 3 photo by photo.
class SlicingEvaluator {
 public:
  // Throws std::invalid_argument for bad options (empty or out-of-range counts, fewer
  // than 2 reference planes, no poses, amplitude outside (0, 1)).
  SlicingEvaluator(SlicingEvalOptions options, LayerFiller filler);

  // bgr: CV_8UC3; disparity: CV_32FC1 of the same size, larger = nearer; band: its
  // depth-edge band when it was snapped (ampi run's map), else empty. Returns this
  // photo's rows (photos = 1), and adds them to the means.
  std::vector<SlicingScore> add(const cv::Mat& bgr, const cv::Mat& disparity, const cv::Mat& band = {});

  // Rows ordered by count, uniform before adaptive; means over the photos added.
  std::vector<SlicingScore> mean() const;

 private:
  SlicingEvalOptions options_;
  LayerFiller filler_;
  std::vector<SlicingScore> sums_;
};

}  // namespace ampi
