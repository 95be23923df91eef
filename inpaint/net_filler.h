// The inpainting network as an MPI layer filler: it runs the network (nets/inpaint_net.h)
// window by window over the pixels to fill, so memory stays bounded whatever the photo's
// size.
#pragma once
#include <memory>

#include <opencv2/core.hpp>

#include "engine/thread_pool.h"
#include "inpaint/mpi_inpaint.h"
#include "nets/inpaint_net.h"

namespace ampi {

// How the filler cuts a layer into network runs: square cores of `core` pixels over the
// bounding box of the pixels to fill, each run on the core plus `halo` pixels of context
// on every side (clipped to the image), so memory stays bounded by one window whatever
// the photo's size. Cores without a pixel to fill are skipped. The defaults keep the
// halo's extra work near a third of a core (448^2 / 384^2) and one window's activations
// near 30 MB; 32 px of context is a quarter of the 128 px crops the network trained on.
struct InpaintTiling {
  int core = 384;
  int halo = 32;
};

// Fills `fill` pixels of a BGRA layer with the network's prediction from the `known`
// pixels (everything not known is the network's hole); every other pixel is unchanged.
// For a version-2 network, its prefill first fills every unknown pixel of the whole image
// (one pass, like push_pull_filler), then the windows read from that.
cv::Mat inpaint_layer(const InpaintNet& net, const cv::Mat& image, const cv::Mat& known,
                      const cv::Mat& fill, const InpaintTiling& tiling = {},
                      ThreadPool& pool = default_pool());

// inpaint_layer as a LayerFiller (inpaint/mpi_inpaint.h); shares the network.
LayerFiller inpaint_net_filler(std::shared_ptr<const InpaintNet> net, InpaintTiling tiling = {});

}  // namespace ampi
