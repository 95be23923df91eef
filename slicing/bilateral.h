// The slicer's bilateral filter on 8-bit disparity levels: OpenCV's cv::bilateralFilter
// for CV_8UC1 (the same disk of taps, Gaussian space and colour weights, reflect-101
// border), computed by our row kernels (slicing/row_kernels.h) over the thread
// pool. OpenCV's own was the slicer's largest cost at the depth network's working size,
// where the whole slicing step may take 5% of the network's time (`ampi bench pipeline`).
#pragma once
#include <opencv2/core.hpp>

#include "engine/isa.h"
#include "engine/thread_pool.h"

namespace ampi {

struct BilateralParams {
  int diameter = 5;            // taps within a disk of radius max(1, diameter / 2)
  double sigma_color = 20.0;   // in levels, > 0
  double sigma_space = 3.0;    // in pixels, > 0
};

// levels: CV_8UC1, not empty. Returns the filtered map (CV_8UC1, same size). The scalar
// variant equals cv::bilateralFilter(levels, out, diameter, sigma_color, sigma_space);
// the vector variants may differ from it by one level (slicing/row_kernels.h).
cv::Mat bilateral_filter_levels(const cv::Mat& levels, const BilateralParams& p, Isa isa, ThreadPool& pool);
// The active instruction set on the default pool.
cv::Mat bilateral_filter_levels(const cv::Mat& levels, const BilateralParams& p);

}  // namespace ampi
