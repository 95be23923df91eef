// From photo + disparity + planes to the (not yet inpainted) multiplane image.
#pragma once
#include <opencv2/core.hpp>
#include <vector>

#include "mpi/mpi.h"

namespace ampi {

// One BGRA layer per plane (CV_8UC4, straight alpha), back to front like `planes`
// (from slice_adaptive or slice_uniform on the same `disparity`). A pixel belongs to the
// plane whose interval holds its normalised disparity: alpha 255 there and the photo's
// colour; everywhere else alpha 0 and colour 0. As in the paper, the back layer holds
// only its own pixels (it is not made opaque everywhere): what no layer covers
// composites over black, and inpainting is what extends the layers.
//
// soft_alpha > 0 replaces each hard cut between adjacent planes by an alpha ramp
// soft_alpha disparity levels wide, centred on the cut: the nearer layer fades in
// across it while the farther one stays opaque until the ramp's end, so the over
// operator still covers every pixel fully. 0 reproduces the paper's hard cuts.
//
// bgr: CV_8UC3 of the disparity's size; cam: of that size too. Throws
// std::invalid_argument naming the mismatch.
Mpi assemble_mpi(const cv::Mat& bgr, const cv::Mat& disparity, const std::vector<Plane>& planes,
                 const Camera& cam, const DepthRange& range, double soft_alpha = 0);

}  // namespace ampi
