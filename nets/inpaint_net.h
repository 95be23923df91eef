// The inpainting generator (training/inpaint_model.py) on ampi's kernels, and the
// LayerFiller that runs it over an MPI layer's margin in bounded memory.
//
// The graph is read from the weight file (training/export_inpaint.py writes it): a list
// of convolutions, each reading an earlier layer's output (or the network input),
// optionally up-sampled 2x nearest and concatenated on channels with a second earlier
// output. Gated layers compute 2c channels and output ELU(feature) * sigmoid(gate); the
// last layer is a plain convolution with tanh.
//
// Two input/output conventions, by the file's inpaint.version:
//   1  input [rgb with the hole zeroed, hole], output tanh(last): the fill itself;
//   2  the hole arrives pre-filled by the classic fill named in inpaint.prefill (the one
//      the network trained on): "push-pull" (inpaint/push_pull.h) or "harmonic"
//      (inpaint/harmonic_fill.h); input [rgb, hole], output rgb + hole * tanh(last): a
//      learned correction of that fill inside the hole. inpaint_layer does the pre-fill.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "engine/thread_pool.h"
#include "inpaint/mpi_inpaint.h"
#include "kernels/conv.h"
#include "kernels/kernel_table.h"
#include "weights_format/weight_file.h"

namespace ampi {

struct InpaintLayer {
  static constexpr int kInput = -1;   // source/skip: the network input
  static constexpr int kNoSkip = -2;  // skip: none
  std::string name;
  int source = kInput;
  bool upsample = false;
  int skip = kNoSkip;
  int in_c = 0, out_c = 0;
  int kernel = 3, stride = 1, dilation = 1;
  bool gated = true;
  int scale_log2 = 0;  // its output is 1 / 2^scale_log2 of the input's size
};

// What fills the hole before the network sees it.
enum class Prefill { None, PushPull, Harmonic };

class InpaintNet {
 public:
  static constexpr int kInChannels = 4;  // rgb with the hole zeroed, hole
  static constexpr int kOutChannels = 3;

  // Reads and checks the graph and every tensor's shape; throws std::runtime_error
  // "PATH: problem".
  static InpaintNet load(const std::string& path, const KernelTable& k = kernels());
  static InpaintNet from_file(const WeightFile& file, const KernelTable& k = kernels());

  // rgb [h][w][3] in [-1, 1] (the prefill in the hole unless prefill() is None), hole
  // [h][w] (1 = unknown, 0 = known); h and w multiples of multiple(). out [h][w][3]: the
  // prediction at every pixel (the caller keeps its known pixels). Scratch memory: a few
  // dozen floats per pixel, freed on return.
  void run(const float* rgb, const float* hole, int h, int w, float* out,
           ThreadPool& pool = default_pool()) const;

  int multiple() const { return multiple_; }
  // Version 2: the hole must hold this fill, and the output is a residual on it.
  Prefill prefill() const { return prefill_; }
  const std::vector<InpaintLayer>& layers() const { return layers_; }
  // Multiply-adds per input pixel (for benchmarks and the model card).
  double macs_per_pixel() const;

 private:
  InpaintNet() = default;
  const float* layer_input(int i, const std::vector<std::vector<float>>& outs,
                           const std::vector<float>& x, int h, int w, std::vector<float>& scratch,
                           ThreadPool& pool) const;

  std::vector<InpaintLayer> layers_;
  std::vector<Conv2d> convs_;
  std::vector<int> last_use_;  // index of the last layer reading each layer's output
  ActivationSpec feature_act_;
  int multiple_ = 4;
  Prefill prefill_ = Prefill::None;  // None: version 1, the hole zeroed
  const KernelTable* k_ = nullptr;
};

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
