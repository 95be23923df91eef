// Downscaling with a tent (triangle) filter stretched by the reduction factor: the filter
// the depth networks' training photos are shrunk with (PIL's antialiased bilinear resize,
// training/ordinal_data.py), so that the engine runs each network on images as soft as
// those it was trained and picked on (training/DEPTH.md, "The input filter").
#pragma once
#include <opencv2/core.hpp>

namespace ampi {

// src: CV_8UC(n) or CV_32FC(n), non-empty; size: positive. Returns CV_32FC(n) of `size`,
// in src's units. Along each axis with factor s = in / out, output sample i (centre
// (i + 0.5) * s in input coordinates) is the average of the input samples j weighted by
// max(0, 1 - |j + 0.5 - centre| / max(s, 1)), the weights normalised to sum 1 (so an
// enlargement is plain bilinear interpolation, edge samples clamped). Throws
// std::invalid_argument on any other input.
cv::Mat resize_tent(const cv::Mat& src, cv::Size size);

}  // namespace ampi
