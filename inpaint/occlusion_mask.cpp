#include "inpaint/occlusion_mask.h"

#include <opencv2/imgproc.hpp>

namespace ampi {

std::vector<cv::Mat> occlusion_masks(const std::vector<cv::Mat>& layers,
                                     const OcclusionMaskParams& params) {
  const size_t n = layers.size();
  std::vector<cv::Mat> masks(n);
  if (n == 0) return masks;
  // k iterations of a 3x3 dilation equal one dilation by a (2k+1)-square, which
  // OpenCV runs as two cheap 1-D passes.
  const int side = 2 * params.dilate_iterations + 1;
  const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, {side, side});
  cv::Mat hidden_by_nearer(layers[0].size(), CV_8UC1, cv::Scalar(0));
  for (size_t j = n; j-- > 0;) {  // front to back, accumulating nearer coverage
    cv::Mat coverage;
    cv::extractChannel(layers[j], coverage, 3);
    cv::threshold(coverage, coverage, 0, 255, cv::THRESH_BINARY);
    cv::Mat grown;
    cv::dilate(coverage, grown, square);
    masks[j] = grown & ~coverage & hidden_by_nearer;
    hidden_by_nearer |= coverage;
  }
  return masks;
}

}  // namespace ampi
