// Which pixels of each MPI layer must be invented before rendering: the margin behind
// nearer layers that a moving camera can uncover (DESIGN.md, "Inpainting": the layer's
// border dilated with a 3x3 element 40 times, restricted to pixels hidden by nearer
// layers).
#pragma once
#include <opencv2/core.hpp>
#include <vector>

namespace ampi {

struct OcclusionMaskParams {
  int dilate_iterations = 40;  // of a 3x3 element: a margin of about 40 px
};

// layers: back to front, CV_8UC4 with alpha in channel 3. Returns one CV_8UC1 mask per
// layer (255 = to fill): dilated coverage of the layer, minus the layer itself, within
// the union of the nearer layers' coverage. The nearest layer's mask is empty.
std::vector<cv::Mat> occlusion_masks(const std::vector<cv::Mat>& layers,
                                     const OcclusionMaskParams& params = {});

// The margin ampi run fills for a photo of this size: the paper's 40 px at a 1024 px
// long side, scaled with the photo, at least a quarter of that; plus `feathered`, the
// border pixels feathering moved from the farther layers (feather_depth_edges), so the
// margin still reaches as far past their remaining pixels.
OcclusionMaskParams margin_for_photo(const cv::Size& size, int feathered = 0);

}  // namespace ampi
