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

// Clean layer borders at depth edges, for hard layers (soft_alpha 0) of the map that
// snap_depth_edges made: a pixel of the edge band (its `band`, CV_8UC1 of the photo's
// size, 255 near a depth edge) that lies within `width` pixels (chessboard distance r)
// of a nearer layer's pixel leaves its own layer and joins the nearest such layer with
// the photo's colour and alpha 255 (width + 1 - r) / (width + 1). So the nearer layer
// keeps its whole object with a thin alpha ramp against aliasing, and the farther layer
// loses the border pixels the object's colour may have bled into: they are now hidden
// by the nearer layer, so the inpainter fills them from the farther layer's own pixels
// and no foreground colour is smeared into the background's margin. The photo is
// reproduced in the source view up to that ramp over the filled background.
// Returns the number of pixels moved; width 0 moves none.
int64_t feather_depth_edges(Mpi& mpi, const cv::Mat& bgr, const cv::Mat& band, int width);

}  // namespace ampi
