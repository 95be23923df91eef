// Canny edges of the slicer's filtered 8-bit levels, our own: OpenCV's cv::Canny with a
// 3x3 Sobel and the L1 gradient norm, pixel for pixel (tested against it), in one pass
// over the rows with three rows of gradients, no whole-image buffers but the output.
// cv::Canny was the slicer's largest step on real disparity maps at the depth network's
// working size (110 us of about 300 at 256x192).
#pragma once
#include <opencv2/core.hpp>

namespace ampi {

// levels: CV_8UC1, not empty; 0 <= low <= high. Returns CV_8UC1, 255 on edge pixels:
// local maxima of |dx| + |dy| along the gradient's direction (four directions) above
// floor(low), 8-connected through such pixels to one above floor(high).
cv::Mat canny_edges(const cv::Mat& levels, double low, double high);

}  // namespace ampi
