#include "kernels/transformer_ops.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/tensor.h"

namespace ampi {
namespace {

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error(what); }

// Queries per attention task and keys per streamed block. 96 queries are 8 whole row
// tiles of the AVX-512 GEMM (12 rows; 64 left a third of its last tile idle), and 1,536
// keys take a ViT-S at 518 x 518 (1,370 tokens) in one block, so its products run whole
// and no output is rescaled; a task's scores (96 x 1,536 floats, 576 KiB) still fit a
// 1 MiB L2 beside a block of packed K and V, and the 6 heads make 90 tasks. ViT-S at
// 518 x 518 on this AMD EPYC (Zen 5), medians of 5 on 2 threads: 64 x 256 311-316 ms,
// 96 x 256 324, 96 x 768 307-316, 96 x 1,536 298-303, 48, 72 or 120 x 1,536 307-312.
constexpr int kQueryBlock = 96;
constexpr int kKeyBlock = 1536;

// PyTorch's cubic convolution kernel, a = -0.75: `near` for |t| <= 1, `far` for 1 < |t| < 2.
double cubic_near(double t, double a) { return ((a + 2) * t - (a + 3)) * t * t + 1; }
double cubic_far(double t, double a) { return ((a * t - 5 * a) * t + 8 * a) * t - 4 * a; }

// out[x] = sum_tap weight[x][tap] * row[index[x][tap]], c channels per pixel.
void cubic_row(const float* row, int c, const CubicAxis& ax, int out_w, float* out) {
  for (int x = 0; x < out_w; ++x) {
    const int32_t* i = &ax.index[size_t(x) * 4];
    const float* wt = &ax.weight[size_t(x) * 4];
    for (int ch = 0; ch < c; ++ch)
      out[size_t(x) * c + ch] = row[size_t(i[0]) * c + ch] * wt[0] + row[size_t(i[1]) * c + ch] * wt[1] +
                                row[size_t(i[2]) * c + ch] * wt[2] + row[size_t(i[3]) * c + ch] * wt[3];
  }
}

// Source positions of align_corners=True in single precision, as PyTorch computes them
// for float maps: position = x * (in - 1) / (out - 1).
struct LinearAxis {
  std::vector<int32_t> lo, hi;
  std::vector<float> weight;
};

LinearAxis linear_corners_axis(int n_out, int n_in) {
  LinearAxis ax;
  ax.lo.resize(n_out);
  ax.hi.resize(n_out);
  ax.weight.resize(n_out);
  const float step = n_out > 1 ? float(n_in - 1) / float(n_out - 1) : 0.0f;
  for (int i = 0; i < n_out; ++i) {
    const float src = step * float(i);
    const int lo = std::min(int(src), n_in - 1);
    ax.lo[i] = lo;
    ax.hi[i] = lo < n_in - 1 ? lo + 1 : lo;
    ax.weight[i] = src - float(lo);
  }
  return ax;
}

void require_positive(const char* op, std::initializer_list<int> sizes) {
  for (int s : sizes)
    if (s <= 0) fail(std::string(op) + ": sizes must be positive");
}

}  // namespace

// ---- resampling -----------------------------------------------------------------------

CubicAxis cubic_axis(int n_out, int n_in, double src_per_dst) {
  constexpr double a = -0.75;
  CubicAxis ax;
  ax.index.resize(size_t(n_out) * 4);
  ax.weight.resize(size_t(n_out) * 4);
  for (int i = 0; i < n_out; ++i) {
    const double src = (i + 0.5) * src_per_dst - 0.5;
    const double base = std::floor(src), t = src - base;
    const double w[4] = {cubic_far(t + 1, a), cubic_near(t, a), cubic_near(1 - t, a), cubic_far(2 - t, a)};
    for (int tap = 0; tap < 4; ++tap) {
      ax.index[size_t(i) * 4 + tap] = int32_t(std::clamp<double>(base - 1 + tap, 0, n_in - 1));
      ax.weight[size_t(i) * 4 + tap] = float(w[tap]);
    }
  }
  return ax;
}

void resize_bicubic(const float* in, int h, int w, int c, int out_h, int out_w, double src_per_dst_y,
                    double src_per_dst_x, float* out, ThreadPool& pool) {
  require_positive("resize_bicubic", {h, w, c, out_h, out_w});
  const CubicAxis ay = cubic_axis(out_h, h, src_per_dst_y), ax = cubic_axis(out_w, w, src_per_dst_x);
  const size_t row_floats = size_t(out_w) * c;
  // Each output row: the four input rows it reads resized across first, then blended, in
  // PyTorch's order (horizontal taps, then vertical).
  pool.parallel_for(out_h, 4, [&](int64_t y0, int64_t y1) {
    std::vector<float> across(4 * row_floats);
    for (int64_t y = y0; y < y1; ++y) {
      for (int tap = 0; tap < 4; ++tap)
        cubic_row(in + size_t(ay.index[y * 4 + tap]) * w * c, c, ax, out_w, &across[tap * row_floats]);
      const float* wt = &ay.weight[y * 4];
      float* dst = out + size_t(y) * row_floats;
      for (size_t i = 0; i < row_floats; ++i)
        dst[i] = across[i] * wt[0] + across[row_floats + i] * wt[1] + across[2 * row_floats + i] * wt[2] +
                 across[3 * row_floats + i] * wt[3];
    }
  });
}

void resize_bilinear_corners(const float* in, int h, int w, int c, int out_h, int out_w, float* out,
                             ThreadPool& pool, const KernelTable& k) {
  resize_bilinear_corners_rows(in, h, w, c, out_h, out_w, 0, out_h, out, pool, k);
}

void resize_bilinear_corners_rows(const float* in, int h, int w, int c, int out_h, int out_w, int row_begin,
                                  int row_end, float* out, ThreadPool& pool, const KernelTable& k) {
  require_positive("resize_bilinear_corners", {h, w, c, out_h, out_w});
  if (row_begin < 0 || row_end > out_h || row_begin >= row_end)
    fail("resize_bilinear_corners: rows " + std::to_string(row_begin) + ".." + std::to_string(row_end) +
         " are not inside 0.." + std::to_string(out_h));
  const LinearAxis ay = linear_corners_axis(out_h, h), ax = linear_corners_axis(out_w, w);
  pool.parallel_for(row_end - row_begin, 4, [&](int64_t r0, int64_t r1) {
    for (int64_t r = r0; r < r1; ++r) {
      const int64_t y = row_begin + r;
      k.bilinear_row(in + size_t(ay.lo[y]) * w * c, in + size_t(ay.hi[y]) * w * c, ay.weight[y], ax.lo.data(),
                     ax.hi.data(), ax.weight.data(), out_w, c, out + size_t(r) * out_w * c);
    }
  });
}

std::vector<float> interpolate_pos_embed(const float* pos, int grid, int dim, int rows, int cols, double offset) {
  require_positive("interpolate_pos_embed", {grid, dim, rows, cols});
  const size_t cells = size_t(rows) * cols;
  std::vector<float> out((1 + cells) * dim);
  std::copy(pos, pos + dim, out.begin());  // the class token's entry
  if (rows == grid && cols == grid) {
    std::copy(pos + dim, pos + size_t(1 + cells) * dim, out.begin() + dim);
    return out;
  }
  // The sample step is 1 / scale factor, with the offset in the factor.
  ThreadPool serial(1);
  resize_bicubic(pos + dim, grid, grid, dim, rows, cols, grid / (rows + offset), grid / (cols + offset),
                 out.data() + dim, serial);
  return out;
}

// ---- token ops --------------------------------------------------------------------------

void layer_norm(const float* in, int64_t in_stride, int64_t tokens, int c, const float* gamma,
                const float* beta, float eps, float* out, int64_t out_stride, ThreadPool& pool,
                const KernelTable& k) {
  if (tokens <= 0 || c <= 0 || in_stride < c || out_stride < c) fail("layer_norm: bad sizes or strides");
  pool.parallel_for(tokens, 16, [&](int64_t t0, int64_t t1) {
    for (int64_t t = t0; t < t1; ++t) k.layer_norm_row(in + t * in_stride, c, gamma, beta, eps, out + t * out_stride);
  });
}

PatchEmbedding::PatchEmbedding(int patch, int dim, const float* weights, const float* bias, const KernelTable& k)
    : patch_(patch), weights_(weights, bias, dim, patch * patch * 3, k) {
  require_positive("PatchEmbedding", {patch, dim});
}

void PatchEmbedding::run(const float* image, int h, int w, float* out, int64_t out_stride,
                         const float* residual, ThreadPool& pool) const {
  if (patch_ <= 0) fail("PatchEmbedding::run: empty op");
  if (h <= 0 || w <= 0 || h % patch_ || w % patch_)
    fail("PatchEmbedding::run: image " + std::to_string(h) + "x" + std::to_string(w) +
         " is not a multiple of the patch size " + std::to_string(patch_));
  const int rows = h / patch_, cols = w / patch_, k = weights_.k();
  const int64_t tokens = int64_t(rows) * cols;
  // im2col: each patch's pixels in the weights' [ky][kx][channel] order, one row per token.
  std::vector<float> patches(size_t(tokens) * k);
  const int run = patch_ * 3;  // one patch row: contiguous in the image
  pool.parallel_for(rows, 1, [&](int64_t r0, int64_t r1) {
    for (int64_t r = r0; r < r1; ++r)
      for (int col = 0; col < cols; ++col)
        for (int ky = 0; ky < patch_; ++ky) {
          const float* src = image + ((r * patch_ + ky) * size_t(w) + size_t(col) * patch_) * 3;
          std::copy(src, src + run, &patches[(size_t(r) * cols + col) * k + size_t(ky) * run]);
        }
  });
  GemmProblem p;
  p.m = int(tokens);
  p.n = weights_.n();
  p.k = k;
  p.a = patches.data();
  p.a_stride = k;
  p.c = out;
  p.c_stride = out_stride;
  p.residual = residual;
  gemm(p, weights_, pool);
}

namespace {

// Where every head's K and V live once packed: per head, per block of keys b, entry 2b
// (K^T of the block, a head_dim x keys B) then 2b + 1 (V, keys x head_dim), each on a
// 64-byte line. Memory linear in tokens: about the size of K and V themselves.
struct PackedKeysValues {
  int tokens = 0, head_dim = 0, blocks = 0;
  std::vector<int64_t> offset;  // [2 * blocks + 1] floats into one head's share
  AlignedBuffer buffer;

  int keys_in(int block) const { return std::min(kKeyBlock, tokens - block * kKeyBlock); }
  const float* at(int head, int entry) const {
    return static_cast<const float*>(buffer.get()) + head * offset.back() + offset[entry];
  }
};

PackedKeysValues pack_keys_values(const float* qkv, int tokens, int dim, int heads, ThreadPool& pool,
                                  const KernelTable& k) {
  PackedKeysValues kv;
  kv.tokens = tokens;
  kv.head_dim = dim / heads;
  kv.blocks = (tokens + kKeyBlock - 1) / kKeyBlock;
  const int nr = k.gemm_nr, head_dim = kv.head_dim;
  const auto lines = [](int64_t floats) { return (floats + 15) / 16 * 16; };
  kv.offset.assign(2 * kv.blocks + 1, 0);
  for (int b = 0; b < kv.blocks; ++b) {
    kv.offset[2 * b + 1] = kv.offset[2 * b] + lines(gemm_packed_size(kv.keys_in(b), head_dim, nr));
    kv.offset[2 * b + 2] = kv.offset[2 * b + 1] + lines(gemm_packed_size(head_dim, kv.keys_in(b), nr));
  }
  kv.buffer = aligned_alloc64(size_t(heads) * kv.offset.back() * sizeof(float));
  const int64_t row = 3 * int64_t(dim), entries = 2 * int64_t(kv.blocks);
  pool.parallel_for(heads * entries, 1, [&](int64_t i0, int64_t i1) {
    for (int64_t i = i0; i < i1; ++i) {
      const int head = int(i / entries), entry = int(i % entries), b = entry / 2, kn = kv.keys_in(b);
      const float* keys = qkv + int64_t(b) * kKeyBlock * row + dim + head * head_dim;
      float* dst = const_cast<float*>(kv.at(head, entry));
      if (entry % 2 == 0)
        pack_gemm_panels(StridedMatrix{keys, row, true}, nullptr, kn, head_dim, nr, 0, (kn + nr - 1) / nr, dst);
      else
        pack_gemm_panels(StridedMatrix{keys + dim, row, false}, nullptr, head_dim, kn, nr, 0,
                         (head_dim + nr - 1) / nr, dst);
    }
  });
  return kv;
}

// out rows [q0, q0 + qn) of one head: softmax(q k^T) v with the softmax in base 2 and
// scale_base2 = scale log2(e) (softmax_block_row), streamed over the blocks of
// keys. scores holds kQueryBlock x kKeyBlock floats.
void attend(const float* q, int64_t q_stride, int qn, const PackedKeysValues& kv, int head, float scale_base2,
            float* o, int64_t out_stride, float* scores, ThreadPool& pool, const KernelTable& k) {
  float running_max[kQueryBlock], running_sum[kQueryBlock];
  std::fill(running_max, running_max + qn, -INFINITY);
  std::fill(running_sum, running_sum + qn, 0.0f);
  for (int b = 0; b < kv.blocks; ++b) {
    const int kn = kv.keys_in(b);
    GemmProblem s;  // scores = Q K^T of this block of keys
    s.m = qn;
    s.n = kn;
    s.k = kv.head_dim;
    s.a = q;
    s.a_stride = q_stride;
    s.c = scores;
    s.c_stride = kKeyBlock;
    gemm_packed(s, kv.at(head, 2 * b), pool, k);
    for (int r = 0; r < qn; ++r) {
      const float factor = k.softmax_block_row(scores + size_t(r) * kKeyBlock, kn, scale_base2, &running_max[r],
                                               &running_sum[r]);
      if (b > 0)
        for (int j = 0; j < kv.head_dim; ++j) o[r * out_stride + j] *= factor;
    }
    GemmProblem pv;  // out += P V of this block (the first block writes out)
    pv.m = qn;
    pv.n = kv.head_dim;
    pv.k = kn;
    pv.a = scores;
    pv.a_stride = kKeyBlock;
    pv.c = o;
    pv.c_stride = out_stride;
    pv.residual = b > 0 ? o : nullptr;
    gemm_packed(pv, kv.at(head, 2 * b + 1), pool, k);
  }
  for (int r = 0; r < qn; ++r) {
    const float inv = 1.0f / running_sum[r];
    for (int j = 0; j < kv.head_dim; ++j) o[r * out_stride + j] *= inv;
  }
}

}  // namespace

void self_attention(const float* qkv, int tokens, int dim, int heads, float scale, float* out,
                    int64_t out_stride, ThreadPool& pool, const KernelTable& k) {
  if (tokens <= 0 || heads <= 0 || dim <= 0 || dim % heads || out_stride < dim)
    fail("self_attention: bad sizes (dim must split into the heads)");
  const PackedKeysValues kv = pack_keys_values(qkv, tokens, dim, heads, pool, k);
  // softmax_block_row works in base 2: e^(scale s) = 2^(scale log2(e) s).
  const float scale_base2 = float(double(scale) * 1.4426950408889634);
  const int64_t row = 3 * int64_t(dim);
  const int query_blocks = (tokens + kQueryBlock - 1) / kQueryBlock;
  // One task per head and block of queries; its products run on the calling thread (a
  // nested loop of the pool runs inline), so the split never depends on the thread count.
  pool.parallel_for(int64_t(heads) * query_blocks, 1, [&](int64_t u0, int64_t u1) {
    AlignedBuffer scores_buffer = aligned_alloc64(size_t(kQueryBlock) * kKeyBlock * sizeof(float));
    float* scores = static_cast<float*>(scores_buffer.get());
    for (int64_t u = u0; u < u1; ++u) {
      const int head = int(u / query_blocks), q0 = int(u % query_blocks) * kQueryBlock;
      attend(qkv + q0 * row + head * kv.head_dim, row, std::min(kQueryBlock, tokens - q0), kv, head, scale_base2,
             out + q0 * out_stride + head * kv.head_dim, out_stride, scores, pool, k);
    }
  });
}

// ---- transposed convolution -------------------------------------------------------------

StridedTransposedConv::StridedTransposedConv(int stride, int in_c, int out_c, const float* weights,
                                             const float* bias, const KernelTable& k)
    : stride_(stride), in_c_(in_c), out_c_(out_c) {
  require_positive("StridedTransposedConv", {stride, in_c, out_c});
  if (!weights) fail("StridedTransposedConv: no weights");
  // Each kernel row's GEMM has stride * out_c columns (kx, then o), each with o's bias.
  std::vector<float> row_bias(size_t(stride) * out_c, 0.0f);
  for (int kx = 0; kx < stride; ++kx)
    for (int o = 0; o < out_c; ++o) row_bias[size_t(kx) * out_c + o] = bias ? bias[o] : 0.0f;
  const size_t row_floats = size_t(stride) * out_c * in_c;
  for (int ky = 0; ky < stride; ++ky)
    rows_.emplace_back(weights + ky * row_floats, row_bias.data(), stride * out_c, in_c, k);
}

void StridedTransposedConv::run(const float* in, int h, int w, float* out, ThreadPool& pool) const {
  if (stride_ <= 0) fail("StridedTransposedConv::run: empty op");
  require_positive("StridedTransposedConv::run", {h, w});
  const int64_t block = int64_t(stride_) * out_c_;  // the outputs of one input pixel in one output row
  const int64_t out_row = int64_t(w) * block;
  pool.parallel_for(h, 1, [&](int64_t y0, int64_t y1) {
    for (int64_t y = y0; y < y1; ++y)
      for (int ky = 0; ky < stride_; ++ky) {
        GemmProblem p;
        p.m = w;
        p.n = int(block);
        p.k = in_c_;
        p.a = in + y * w * in_c_;
        p.a_stride = in_c_;
        p.c = out + (y * stride_ + ky) * out_row;
        p.c_stride = block;
        gemm(p, rows_[ky], pool);
      }
  });
}

}  // namespace ampi
