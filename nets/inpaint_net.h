// The inpainting generator (training/inpaint_model.py) on ampi's kernels. The filler
// that runs it over an MPI layer's margin in bounded memory is inpaint/net_filler.h.
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
//
// run() unrolls the graph for the window's size on the shared executor (nets/plan.h), so
// outputs no later layer reads share memory.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "engine/thread_pool.h"
#include "kernels/conv.h"
#include "kernels/kernel_table.h"
#include "nets/plan.h"
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

  // Checks the architecture (arch::kInpaintGatedConv), the graph and every tensor's
  // shape; throws std::runtime_error "PATH: problem". Programs load it through
  // load_inpaint_net (nets/model_loader.h).
  static InpaintNet from_file(const WeightFile& file, const KernelTable& k = kernels());

  // rgb [h][w][3] in [-1, 1] (the prefill in the hole unless prefill() is None), hole
  // [h][w] (1 = unknown, 0 = known); h and w multiples of multiple(). out [h][w][3]: the
  // prediction at every pixel (the caller keeps its known pixels). Scratch memory: one
  // arena of a few dozen floats per pixel, freed on return.
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
  // Adds the steps that make layer i's convolution input to `plan`: its source,
  // up-sampled when asked, then its skip beside it. `outs` holds the earlier layers'
  // values, `input` the network input's. Returns the value the convolution reads.
  int add_layer_input(Plan& plan, int i, const std::vector<int>& outs, int input) const;

  std::vector<InpaintLayer> layers_;
  std::vector<Conv2d> convs_;
  ActivationSpec feature_act_;
  int multiple_ = 4;
  Prefill prefill_ = Prefill::None;  // None: version 1, the hole zeroed
  const KernelTable* k_ = nullptr;
};

}  // namespace ampi
