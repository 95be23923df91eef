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

}  // namespace ampi
