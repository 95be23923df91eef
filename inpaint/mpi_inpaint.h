// Filling each MPI layer's occluded margin before rendering, so rendering never has to
// invent pixels. The filler is pluggable: the inpainting network, the harmonic fill or
// push-pull.
#pragma once
#include <functional>
#include <string>

#include "inpaint/occlusion_mask.h"
#include "mpi/mpi.h"

namespace ampi {

// Fills the colour of `image` (CV_8UC4) where `fill` != 0, from the pixels where
// `known` != 0. Must leave every other pixel unchanged.
using LayerFiller =
    std::function<cv::Mat(const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill)>;

// The classic fillers: push-pull (inpaint/push_pull.h) and the harmonic fill
// (inpaint/harmonic_fill.h), slower and closer to the truth.
LayerFiller push_pull_filler();
LayerFiller harmonic_filler();

// The fillers a user picks by name (--inpainter): the network (inpaint/net_filler.h),
// "harmonic" or "push-pull".
enum class Inpainter { Network, Harmonic, PushPull };
// Throws std::runtime_error "--inpainter: 'NAME' is not network, harmonic or push-pull".
Inpainter parse_inpainter(const std::string& name);
const char* inpainter_name(Inpainter kind);

// For every layer: computes its occlusion mask, fills those pixels with `filler` from
// the layer's own pixels, and makes them opaque. Pixels outside the masks are untouched,
// so transparent regions stay transparent. Returns the number of pixels filled; with
// `fill_masks`, also each layer's mask of them (evaluations trace what was invented).
int64_t inpaint_mpi(Mpi& mpi, const LayerFiller& filler, const OcclusionMaskParams& params = {},
                    std::vector<cv::Mat>* fill_masks = nullptr);

}  // namespace ampi
