// The operators a vision transformer and its DPT head need beyond convolutions: patch
// embedding, the position embedding's bicubic resize, LayerNorm over tokens, multi-head
// self-attention, transposed convolutions whose kernel equals their stride, and bilinear
// resizes to any size. Every matrix product goes through the GEMM op (kernels/gemm.h);
// the per-row work through the table's transformer row kernels (layer_norm_row,
// softmax_block_row, bilinear_row).
//
// Layouts as everywhere else: maps are NHWC with batch 1, and a token sequence is a
// row-major [tokens][dim] matrix (the patch tokens of a rows x cols grid are exactly an
// NHWC [rows][cols][dim] map). Bad sizes throw std::runtime_error. Every output value is
// computed by the same code in the same order whatever the thread count.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/thread_pool.h"
#include "kernels/gemm.h"
#include "kernels/kernel_table.h"

namespace ampi {

// ---- resampling -----------------------------------------------------------------------

// One axis of a bicubic resize as PyTorch (and OpenCV's INTER_CUBIC) computes it: the
// cubic convolution kernel with a = -0.75, half-pixel centres (align_corners=False), no
// antialias, source indices clamped to the edge. Output i samples the input at
// (i + 0.5) * src_per_dst - 0.5 from its four neighbours.
struct CubicAxis {
  std::vector<int32_t> index;  // [n_out][4] input indices, clamped
  std::vector<float> weight;   // [n_out][4]
};
CubicAxis cubic_axis(int n_out, int n_in, double src_per_dst);

// in [h][w][c] -> out [out_h][out_w][c], bicubic as above with the given steps between
// sample positions (the inverse scale factors; in / out for a resize to a size).
void resize_bicubic(const float* in, int h, int w, int c, int out_h, int out_w, double src_per_dst_y,
                    double src_per_dst_x, float* out, ThreadPool& pool = default_pool());

// in [h][w][c] -> out [out_h][out_w][c], bilinear with align_corners=True (PyTorch's
// interpolate(size=..., mode='bilinear', align_corners=True)): the corners of input and
// output coincide. Any sizes, up or down.
void resize_bilinear_corners(const float* in, int h, int w, int c, int out_h, int out_w, float* out,
                             ThreadPool& pool = default_pool(), const KernelTable& k = kernels());
// Rows [row_begin, row_end) of that resize only, into out [row_end - row_begin][out_w][c].
void resize_bilinear_corners_rows(const float* in, int h, int w, int c, int out_h, int out_w, int row_begin,
                                  int row_end, float* out, ThreadPool& pool = default_pool(),
                                  const KernelTable& k = kernels());

// DINOv2's position embedding for a rows x cols patch grid, from the pretrained one for a
// grid x grid: pos [1 + grid*grid][dim] (row 0 the class token's) -> [1 + rows*cols][dim].
// The class token's row is kept; the grid is resized bicubically with the scale factors
// (rows + offset) / grid and (cols + offset) / grid, so the output is rows x cols but the
// sample positions follow the offset scale. A grid equal to the pretrained one is copied
// unchanged.
std::vector<float> interpolate_pos_embed(const float* pos, int grid, int dim, int rows, int cols, double offset);

// ---- token ops --------------------------------------------------------------------------

// out[t] = LayerNorm(in[t]) for each of `tokens` rows of c channels; rows in_stride and
// out_stride floats apart. out may alias in.
void layer_norm(const float* in, int64_t in_stride, int64_t tokens, int c, const float* gamma,
                const float* beta, float eps, float* out, int64_t out_stride,
                ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

// A patch x patch convolution with stride patch and 3 input channels (the ViT's patch
// embedding), as im2col + the GEMM op. Weights OHWI [dim][patch][patch][3], bias [dim].
class PatchEmbedding {
 public:
  PatchEmbedding() = default;
  PatchEmbedding(int patch, int dim, const float* weights, const float* bias, const KernelTable& k = kernels());

  // image [h][w][3], h and w multiples of the patch -> out: (h/patch)*(w/patch) token
  // rows of dim floats, out_stride apart, row-major over the patch grid;
  // out = embed + residual where residual (nullptr, or laid out like out) is given.
  void run(const float* image, int h, int w, float* out, int64_t out_stride, const float* residual,
           ThreadPool& pool = default_pool()) const;

  int patch() const { return patch_; }
  int dim() const { return weights_.n(); }

 private:
  int patch_ = 0;
  GemmWeights weights_;
};

// Multi-head self-attention on the output of the qkv projection: qkv is [tokens][3 dim],
// each row q (head after head, head_dim each), then k, then v. For each head,
// out[:, head] = softmax(scale * q k^T) v, written to out [tokens][dim] (out_stride
// apart). Streamed over blocks of keys with an online softmax (softmax_block_row), so the
// scratch memory is a block of scores per thread, not tokens^2.
void self_attention(const float* qkv, int tokens, int dim, int heads, float scale, float* out,
                    int64_t out_stride, ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

// ---- convolutions the Conv2d op does not cover -------------------------------------------

// A transposed convolution whose kernel equals its stride (no overlap, no padding): every
// input pixel becomes a stride x stride block of the output,
//   out[y*s + ky][x*s + kx][o] = bias[o] + sum_i in[y][x][i] * w[ky][kx][o][i].
// A GEMM over the input channels per kernel row ky, whose output rows (one per input
// pixel, s*out_c values: kx then o) land straight at their place in output row y*s + ky.
class StridedTransposedConv {
 public:
  StridedTransposedConv() = default;
  // weights [s][s][out_c][in_c] (the importer's layout), bias [out_c].
  StridedTransposedConv(int stride, int in_c, int out_c, const float* weights, const float* bias,
                        const KernelTable& k = kernels());
  // in [h][w][in_c] -> out [h*s][w*s][out_c].
  void run(const float* in, int h, int w, float* out, ThreadPool& pool = default_pool()) const;

  int stride() const { return stride_; }
  int out_c() const { return out_c_; }

 private:
  int stride_ = 0, in_c_ = 0, out_c_ = 0;
  std::vector<GemmWeights> rows_;  // one per ky: s*out_c columns over in_c
};

}  // namespace ampi
