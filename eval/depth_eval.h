// `ampi eval depth`: the paper's depth metrics (Luvizon et al., WACV 2021, section
// "Evaluation metrics", after Eigen et al. 2014), on predictions that are only known up
// to scale and shift.
//
// Everything here works on disparity (larger = nearer), the quantity the networks
// predict and the slicer cuts. Per image:
//   1. valid pixels: the reference is positive (zero or negative = no measurement, or the
//      sky at infinite distance; finite values are guaranteed by the reader);
//   2. alignment, as the paper does after Ranftl et al. (MiDaS): over the valid pixels,
//      aligned = (p - median(p)) * std(r) / std(p) + median(r), std the population
//      standard deviation; a constant prediction (std(p) = 0) becomes median(r);
//   3. aligned values below the smallest valid reference value are raised to it, so
//      every ratio below is defined (the alignment can push far pixels below zero);
//   4. over the valid pixels, with a the aligned prediction and r the reference:
//      delta_k = fraction with max(a / r, r / a) < 1.25^k (k = 1, 2, 3),
//      RMSE = sqrt(mean((a - r)^2)) in the reference's units, REL = mean(|a - r| / r).
// A folder's score is the mean of its images' scores (every image weighs the same).
#pragma once
#include <string>

#include <opencv2/core.hpp>

namespace ampi {

struct DepthMetrics {
  double delta1 = 0, delta2 = 0, delta3 = 0;  // higher is better
  double rmse = 0, rel = 0;                   // lower is better
};

// A reference map as disparity and the pixels it measures.
struct DepthReference {
  cv::Mat disparity;  // CV_32FC1, larger = nearer
  cv::Mat valid;      // CV_8UC1, 255 where the reference has a measurement
};

// Reads a reference map in any format `ampi run --depth` reads (pipeline/depth_io.h).
// is_distance: the values are distances and become 1/x. Zero or negative values are no
// measurement either way. Throws std::runtime_error "PATH: problem" for an unreadable
// map, NaN or infinite values (from the reader), or a map with no valid pixel.
DepthReference read_depth_reference(const std::string& path, bool is_distance);

// The median/std alignment of steps 2-3 above, over the pixels where valid != 0.
// prediction, reference: CV_32FC1 of one size; returns CV_32FC1 of that size.
cv::Mat align_median_std(const cv::Mat& prediction, const cv::Mat& reference, const cv::Mat& valid);

// Steps 2-4 above. Throws std::invalid_argument for mismatched sizes or types, or no
// valid pixel.
DepthMetrics depth_metrics(const cv::Mat& prediction, const DepthReference& reference);

// The floor any depth network should beat: disparity increasing linearly from the top
// row (0) to the bottom row (1), as if the photo showed only a ground plane below the
// horizon. CV_32FC1 of `size`.
cv::Mat vertical_gradient_disparity(const cv::Size& size);

// The reference for `photo` (a file under `images_dir`): the one file in `reference_dir`
// at the same relative folder whose name without extension is the photo's (any
// extension: .png, .npy, .tif, ...). Throws std::runtime_error naming the photo and the
// folder searched when there is none, or naming both candidates when there are several.
std::string find_depth_reference(const std::string& photo, const std::string& images_dir,
                                 const std::string& reference_dir);

// Mean of per-image metrics.
class DepthMetricsMean {
 public:
  void add(const DepthMetrics& m);
  DepthMetrics mean() const;
  int count() const { return count_; }

 private:
  DepthMetrics sum_;
  int count_ = 0;
};

}  // namespace ampi
