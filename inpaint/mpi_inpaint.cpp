#include "inpaint/mpi_inpaint.h"

#include <opencv2/imgproc.hpp>

#include "inpaint/push_pull.h"

namespace ampi {

LayerFiller push_pull_filler() { return push_pull_fill; }

int64_t inpaint_mpi(Mpi& mpi, const LayerFiller& filler, const OcclusionMaskParams& params) {
  const std::vector<cv::Mat> masks = occlusion_masks(mpi.layers, params);
  int64_t filled = 0;
  for (size_t j = 0; j < mpi.layers.size(); ++j) {
    const int count = cv::countNonZero(masks[j]);
    if (count == 0) continue;
    cv::Mat& layer = mpi.layers[j];
    cv::Mat known;
    cv::extractChannel(layer, known, 3);
    cv::threshold(known, known, 0, 255, cv::THRESH_BINARY);
    layer = filler(layer, known, masks[j]);
    cv::Mat alpha;
    cv::extractChannel(layer, alpha, 3);
    alpha.setTo(255, masks[j]);
    cv::insertChannel(alpha, layer, 3);
    filled += count;
  }
  return filled;
}

}  // namespace ampi
