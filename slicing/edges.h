// The slicer's edge steps, our own: Canny edges of the filtered 8-bit levels and the band
// that widens them. Each equals its OpenCV counterpart pixel for pixel (tested) and keeps
// only a few rows of gradients or window counts beside its image-sized buffers. OpenCV's
// were among the slicer's largest steps at the depth network's working size, where the
// whole slicing step may take 5% of the network's time (`ampi bench pipeline`).
#pragma once
#include <opencv2/core.hpp>

namespace ampi {

// levels: CV_8UC1, not empty; 0 <= low <= high. Returns CV_8UC1, 255 on edge pixels:
// local maxima of |dx| + |dy| along the gradient's direction (four directions) above
// floor(low), 8-connected through such pixels to one above floor(high).
// As cv::Canny(levels, edges, low, high, 3, false).
cv::Mat canny_edges(const cv::Mat& levels, double low, double high);

// mask: CV_8UC1 of 0 and 255. Returns 255 wherever a size x size square centred as
// OpenCV centres it (anchor size / 2) holds a nonzero pixel of the mask: as cv::dilate
// with a MORPH_RECT element of that size and its default border (none outside).
cv::Mat widen_edges(const cv::Mat& mask, int size);

}  // namespace ampi
