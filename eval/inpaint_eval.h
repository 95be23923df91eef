// `ampi eval inpaint`: how well each filler recovers MPI margins whose truth is known.
//
// The protocol is the training one (training/inpaint_data.py, the paper's "Multiplane
// image inpainting"): slice each photo with our depth network; for every plane but the
// nearest, take it with every plane behind it, erode that region with a 3x3 element k
// times, and ask each method to fill the removed border from the eroded region alone
// (everything outside it is unknown to every method). PSNR and SSIM are measured over the
// removed pixels against the photo, per (photo, plane) sample, and averaged.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "slicing/adaptive.h"

namespace ampi {

// One sample: the photo (BGR), the pixels a method may read, the pixels it must fill.
struct MarginSample {
  cv::Mat bgr;      // CV_8UC3, the truth everywhere
  cv::Mat known;    // CV_8UC1, 255 = visible to the method
  cv::Mat removed;  // CV_8UC1, 255 = to fill and to score (a subset of ~known)
};

// Returns the BGR image with the removed pixels filled. It receives the photo with
// every unknown pixel set to 0, so no method can read what it must not.
using MarginFiller = std::function<cv::Mat(const cv::Mat& bgr_known_only, const MarginSample& s)>;

struct NamedFiller {
  std::string name;
  MarginFiller fill;
};

// Plane index per pixel (0 = farthest) from disparity, as the slicer assigned them.
cv::Mat plane_labels(const cv::Mat& disparity, const std::vector<Plane>& planes);

// The samples of one photo: one per plane but the nearest whose eroded border keeps at
// least min_removed pixels.
std::vector<MarginSample> margin_samples(const cv::Mat& bgr, const cv::Mat& labels, int planes,
                                         int erode_iterations, int min_removed = 64);

// PSNR (dB, 8-bit peak) and mean SSIM (Wang et al. 2004: 11x11 Gaussian window, sigma
// 1.5, averaged over the three channels) of `filled` against `truth`, over the pixels
// where mask != 0. SSIM windows also see the unmasked pixels around the hole, which are
// equal in both images, as usual for masked SSIM.
double masked_psnr(const cv::Mat& filled, const cv::Mat& truth, const cv::Mat& mask);
double masked_ssim(const cv::Mat& filled, const cv::Mat& truth, const cv::Mat& mask);

struct MethodScore {
  std::string name;
  double psnr = 0, ssim = 0;  // means over the samples
  double seconds = 0;         // total fill time
  int samples = 0;
};

// Accumulates the per-sample scores of every method.
class InpaintEvaluator {
 public:
  explicit InpaintEvaluator(std::vector<NamedFiller> methods);
  void add(const MarginSample& sample);
  std::vector<MethodScore> scores() const;

 private:
  std::vector<NamedFiller> methods_;
  std::vector<MethodScore> sums_;
};

// The classic fillers: OpenCV's cv::inpaint (Telea, Navier-Stokes) with `radius`,
// push-pull (inpaint/push_pull.h) and the harmonic fill (inpaint/harmonic_fill.h), the
// two prefills a network may refine.
MarginFiller telea_filler(double radius);
MarginFiller navier_stokes_filler(double radius);
MarginFiller push_pull_margin_filler();
MarginFiller harmonic_margin_filler();

}  // namespace ampi
