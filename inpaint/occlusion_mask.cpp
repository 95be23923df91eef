#include "inpaint/occlusion_mask.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace ampi {

std::vector<cv::Mat> occlusion_masks(const std::vector<cv::Mat>& layers,
                                     const OcclusionMaskParams& params) {
  const size_t n = layers.size();
  std::vector<cv::Mat> masks(n);
  if (n == 0) return masks;
  // k iterations of a 3x3 dilation reach exactly the pixels within chessboard distance
  // k of the layer. A distance transform finds them in time independent of k (a direct
  // dilation costs O(k) per pixel: seconds for the wide margins of 4K photos).
  const float reach = static_cast<float>(params.dilate_iterations);
  cv::Mat hidden_by_nearer(layers[0].size(), CV_8UC1, cv::Scalar(0));
  for (size_t j = n; j-- > 0;) {  // front to back, accumulating nearer coverage
    cv::Mat coverage;
    cv::extractChannel(layers[j], coverage, 3);
    cv::threshold(coverage, coverage, 0, 255, cv::THRESH_BINARY);
    cv::Mat distance;
    cv::distanceTransform(~coverage, distance, cv::DIST_C, 3);
    const cv::Mat grown = distance <= reach;
    masks[j] = grown & ~coverage & hidden_by_nearer;
    hidden_by_nearer |= coverage;
  }
  return masks;
}

OcclusionMaskParams margin_for_photo(const cv::Size& size, int feathered) {
  const double scale = std::max(size.width, size.height) / 1024.0;
  OcclusionMaskParams params;
  params.dilate_iterations = std::max(1, static_cast<int>(std::lround(40 * std::max(scale, 0.25)))) + feathered;
  return params;
}

}  // namespace ampi
