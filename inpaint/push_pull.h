// A classic, fast hole filler: push-pull (Gortler et al. 1996, "The Lumigraph"). Known
// pixels are averaged down an image pyramid until every coarse cell has a value, then
// pulled back up so each hole pixel takes a smooth blend of its surroundings. Linear
// time, no iterations; the baseline fill of the MPI margin and what ampi uses when no
// inpainting weights are given.
#pragma once
#include <opencv2/core.hpp>

namespace ampi {

// image: CV_8UC3 or CV_8UC4 (the first three channels are filled); known: CV_8UC1,
// non-zero where image holds valid colour. Returns a copy of image whose pixels with
// fill != 0 are replaced by the push-pull estimate; every other pixel is unchanged.
cv::Mat push_pull_fill(const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill);

// Throws std::invalid_argument "WHO: expects 8-bit BGR(A) image and 8-bit masks of its
// size" unless image is CV_8UC3 or CV_8UC4 and known (and fill, unless empty) CV_8UC1 of
// its size: the inputs every filler takes.
void check_fill_inputs(const char* who, const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill = cv::Mat());

// The float estimate behind push_pull_fill: CV_32FC3 at every pixel (the known colour
// where known), from an 8-bit BGR(A) or a CV_32FC3 image. Empty when no pixel is known.
cv::Mat push_pull_estimate(const cv::Mat& image, const cv::Mat& known);

// A copy of image (CV_8UC3 or CV_8UC4) whose colour channels take the 8-bit rounding of
// estimate (CV_32FC3) where fill != 0; alpha and every other pixel are unchanged.
cv::Mat paste_estimate(const cv::Mat& image, const cv::Mat& estimate, const cv::Mat& fill);

}  // namespace ampi
