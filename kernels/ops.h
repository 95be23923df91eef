// The operators the networks call. Each splits its work over a thread pool and runs the
// micro-kernels of one dispatch table (default: the active ISA; tests pass each table).
//
// Data layout (see engine/tensor.h): activations are NHWC with batch 1, i.e. a plain
// H x W x C float array, channels innermost. Convolution weights are OHWI:
// [out_c][kernel_h][kernel_w][in_c / groups], which is PyTorch's OIHW transposed.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/thread_pool.h"
#include "kernels/conv.h"
#include "kernels/kernel_table.h"

namespace ampi {

// out[i] = act(a[i] + b[i]); out may alias a or b.
void add(const float* a, const float* b, int64_t n, float* out, ActivationSpec act = {},
         ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

// x[i] = act(x[i]).
void activate(float* x, int64_t n, ActivationSpec act, ThreadPool& pool = default_pool(),
              const KernelTable& k = kernels());

// The ops below are batch-1 NHWC like the rest; their outputs must not overlap their
// inputs unless a comment says otherwise, and bad sizes throw std::runtime_error.

// Gated convolution output (Yu et al. 2019): in is [pixels][2c], the first c channels the
// feature, the last c the gate: out[p][j] = act(feature) * sigmoid(gate).
void gated_output(const float* in, int64_t pixels, int c, ActivationSpec feature_act, float* out,
                  ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

// out [pixels][ca + cb] = a [pixels][ca] ++ b [pixels][cb].
void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out,
                     ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

// Squeeze-excite as in MobileNetV3: global average pool over h*w, fc1 (reduced x channels,
// + b1) -> ReLU, fc2 (channels x reduced, + b2) -> hard-sigmoid, then
// out[p][j] = in[p][j] * gate[j]. out may alias in. The weights are copied at
// construction. The pooled mean is summed row by row in a fixed order, so the result does
// not depend on the thread count.
class SqueezeExcite {
 public:
  SqueezeExcite() = default;
  SqueezeExcite(int channels, int reduced, const float* w1, const float* b1, const float* w2,
                const float* b2, const KernelTable& k = kernels());
  void run(const float* in, int h, int w, float* out, ThreadPool& pool = default_pool()) const;
  // The per-channel scale run() multiplies `in` by: a consumer that is linear in its input
  // (a 1x1 convolution, Conv2d::run_scaled_input) can fold it into its weights instead of
  // making a pass over the whole map.
  std::vector<float> gate(const float* in, int h, int w, ThreadPool& pool = default_pool()) const;

  int channels() const { return channels_; }
  int reduced() const { return reduced_; }

 private:
  int channels_ = 0, reduced_ = 0;
  std::vector<float> w1_, b1_, w2_, b2_;
  const KernelTable* k_ = nullptr;
};

// Haar DWT: in [h][w][c] (h, w even) -> out [h/2][w/2][4c], channel blocks
// [LL | LH | HL | HH], each c wide. For the 2x2 block x00 x01 / x10 x11:
//   LL = (x00 + x01 + x10 + x11) / 2     LH = (x00 - x01 + x10 - x11) / 2
//   HL = (x00 + x01 - x10 - x11) / 2     HH = (x00 - x01 - x10 + x11) / 2
// (orthonormal, so haar_idwt inverts it exactly up to rounding).
void haar_dwt(const float* in, int h, int w, int c, float* out, ThreadPool& pool = default_pool(),
              const KernelTable& k = kernels());
// Inverse: in [h][w][4c] -> out [2h][2w][c]:
//   x00 = (LL + LH + HL + HH) / 2   x01 = (LL - LH + HL - HH) / 2
//   x10 = (LL + LH - HL - HH) / 2   x11 = (LL - LH - HL + HH) / 2
void haar_idwt(const float* in, int h, int w, int c, float* out, ThreadPool& pool = default_pool(),
               const KernelTable& k = kernels());

// in [h][w][c] -> out [2h][2w][c], each input pixel repeated 2x2.
void resize2x_nearest(const float* in, int h, int w, int c, float* out,
                      ThreadPool& pool = default_pool(), const KernelTable& k = kernels());
// Bilinear x2 with half-pixel centres, as PyTorch's interpolate(scale_factor=2,
// mode='bilinear', align_corners=False); edges clamped.
void resize2x_bilinear(const float* in, int h, int w, int c, float* out,
                       ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

}  // namespace ampi
