#include "inpaint/mpi_inpaint.h"

#include <opencv2/imgproc.hpp>

#include <stdexcept>

#include "inpaint/harmonic_fill.h"
#include "inpaint/push_pull.h"

namespace ampi {

LayerFiller push_pull_filler() { return push_pull_fill; }

LayerFiller harmonic_filler() {
  return [](const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill) {
    return harmonic_fill(image, known, fill);
  };
}

Inpainter parse_inpainter(const std::string& name) {
  for (Inpainter kind : {Inpainter::Network, Inpainter::Harmonic, Inpainter::PushPull})
    if (name == inpainter_name(kind)) return kind;
  throw std::runtime_error("--inpainter: '" + name + "' is not network, harmonic or push-pull");
}

const char* inpainter_name(Inpainter kind) {
  switch (kind) {
    case Inpainter::Network: return "network";
    case Inpainter::Harmonic: return "harmonic";
    case Inpainter::PushPull: break;
  }
  return "push-pull";
}

namespace {

// The part of the image a filler needs: the pixels to fill and `context` pixels around
// them. Fillers then cost what the margin costs, not what the photo costs.
cv::Rect fill_region(const cv::Mat& fill, int context) {
  const cv::Rect box = cv::boundingRect(fill);
  const cv::Rect grown(box.x - context, box.y - context, box.width + 2 * context,
                       box.height + 2 * context);
  return grown & cv::Rect(0, 0, fill.cols, fill.rows);
}

}  // namespace

int64_t inpaint_mpi(Mpi& mpi, const LayerFiller& filler, const OcclusionMaskParams& params,
                    std::vector<cv::Mat>* fill_masks) {
  const std::vector<cv::Mat> masks = occlusion_masks(mpi.layers, params);
  if (fill_masks) *fill_masks = masks;
  int64_t filled = 0;
  for (size_t j = 0; j < mpi.layers.size(); ++j) {
    const int count = cv::countNonZero(masks[j]);
    if (count == 0) continue;
    const cv::Rect roi = fill_region(masks[j], 2 * params.dilate_iterations);
    cv::Mat layer = mpi.layers[j](roi);
    const cv::Mat fill = masks[j](roi);
    cv::Mat known;
    cv::extractChannel(layer, known, 3);
    cv::threshold(known, known, 0, 255, cv::THRESH_BINARY);
    cv::Mat result = filler(layer, known, fill);
    cv::Mat alpha;
    cv::extractChannel(result, alpha, 3);
    alpha.setTo(255, fill);
    cv::insertChannel(alpha, result, 3);
    result.copyTo(layer);  // back into the full layer through the ROI view
    filled += count;
  }
  return filled;
}

}  // namespace ampi
