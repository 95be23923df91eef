#include "kernels/conv.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/cpu_caches.h"
#include "engine/tensor.h"
#include "kernels/output_streaming.h"
#include "kernels/winograd.h"

namespace ampi {
namespace {

// General path: output pixels per im2col tile, in gemm tiles. Eight tiles amortise the
// per-tile loop while the scratch (tile pixels x kernel_h*kernel_w*in_c/groups floats:
// 48 x 1152 floats = 216 KiB for a 3x3 conv over 128 channels on AVX2) stays in L2.
constexpr int kGemmTilesPerIm2colTile = 8;
// Taps path: convolutions with at most this many outputs (one NEON vector).
constexpr int kTapsMaxOutputs = 4;
// Taps path: row bands per thread, so uneven bands even out; each band computes the
// kernel's extra rows above and below it again, so bands are at least this many times
// taller than that.
constexpr int kTapsBandsPerThread = 4;
constexpr int kTapsMinBandSeams = 4;

// Winograd path: the fewest input channels it takes. On a 128x96 map, 1 thread, against
// the path taken before (this AMD EPYC, Zen 5; a one-off harness timing Conv2d::run):
// 3->16 1.01x (AVX-512) and 1.03x (AVX2), 4->16 1.08x, 8->16 1.13x and 1.38x, 12->16
// 1.40x and 1.38x, 16->16 1.59x and 1.81x, 64->64 2.39x and 2.26x.
constexpr int kWinogradMinInputs = 8;
// Winograd path: a chunk's transformed windows and products ([36][tiles][in_c + out_c]
// floats) take at most this share of the L2 cache, so they stay there between the
// transforms and the products, beside one position's filters.
constexpr int64_t kWinogradL2Share = 2;
constexpr size_t kDefaultL2Bytes = size_t{512} << 10;  // when the machine does not say

// Rows path: a gemm call reads a run of at least this many contiguous input floats
// (kernel_w * in_c, or in_c when the taps are dilated across the row); shorter runs would
// spend more on reloading the output tile between calls than im2col's copies cost.
constexpr int kRowsMinRun = 16;

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error("conv: " + what); }

std::shared_ptr<float> allocate_floats(int64_t n) {
  AlignedBuffer buffer = aligned_alloc64(static_cast<size_t>(n) * sizeof(float));
  return std::shared_ptr<float>(static_cast<float*>(buffer.release()), AlignedDeleter{});
}

// Output size along one axis; 0 when the dilated kernel does not fit (the numerator is
// negative and C++ division would round it towards zero).
int out_size(int in, int pad_before, int pad_after, int kernel, int dilation, int stride) {
  const int span = in + pad_before + pad_after - dilation * (kernel - 1) - 1;
  return span < 0 ? 0 : span / stride + 1;
}

// Rows path: the taps one gemm call covers. Without dilation across the row, a kernel
// row's taps read one contiguous run of the (padded) input row; with it, each tap is its
// own run.
int rows_run_taps(const ConvParams& p) { return p.dilation_w == 1 ? p.kernel_w : 1; }

Conv2d::Path choose_path(const ConvParams& p) {
  const bool no_padding = p.pad_top == 0 && p.pad_left == 0 && p.pad_bottom == 0 && p.pad_right == 0;
  if (p.groups == 1 && p.kernel_h == 1 && p.kernel_w == 1 && p.stride_h == 1 && p.stride_w == 1 &&
      no_padding)
    return Conv2d::Path::Pointwise;
  if (p.groups == p.in_c && p.in_c == p.out_c && p.kernel_h <= kMaxDepthwiseKernelH)  // taller: general path
    return Conv2d::Path::Depthwise;
  if (p.groups == 1 && p.out_c <= kTapsMaxOutputs && p.stride_h == 1 && p.stride_w == 1 &&
      p.kernel_h * p.kernel_w > 1)
    return Conv2d::Path::Taps;
  if (p.groups == 1 && p.kernel_h == 3 && p.kernel_w == 3 && p.stride_h == 1 && p.stride_w == 1 &&
      p.dilation_h == 1 && p.dilation_w == 1 && p.in_c >= kWinogradMinInputs)
    return Conv2d::Path::Winograd;
  if (p.groups == 1 && rows_run_taps(p) * p.in_c >= kRowsMinRun) return Conv2d::Path::Rows;
  return Conv2d::Path::General;
}

// Output columns whose kernel_w taps all fall inside the input row:
// x*stride - pad_left >= 0 and x*stride - pad_left + (kernel_w-1)*dilation <= in_w - 1.
void interior_columns(const ConvParams& p, int in_w, int out_w, int& begin, int& end) {
  begin = std::min(out_w, (p.pad_left + p.stride_w - 1) / p.stride_w);
  const int last_start = in_w - 1 - (p.kernel_w - 1) * p.dilation_w + p.pad_left;
  end = last_start < 0 ? 0 : std::min(out_w, last_start / p.stride_w + 1);
  end = std::max(begin, end);
}

// Gathers the receptive fields of output pixels [first, first + count) for one group:
// row i holds the kernel_h x kernel_w x in_c/groups inputs of pixel first + i in OHWI
// order, so it lines up with a packed filter; taps in the padding are zeros.
void im2col(const ConvParams& p, const float* in, int in_h, int in_w, int out_w, int group,
            int64_t first, int count, float* cols) {
  const int cin_g = p.in_c / p.groups;
  const size_t tap_bytes = static_cast<size_t>(cin_g) * sizeof(float);
  // With one group and no dilation across the row, a kernel row's taps are one contiguous
  // run of the input row: one copy instead of kernel_w.
  const bool whole_runs = p.groups == 1 && p.dilation_w == 1;
  for (int i = 0; i < count; ++i) {
    const int oy = static_cast<int>((first + i) / out_w), ox = static_cast<int>((first + i) % out_w);
    const int ix0 = ox * p.stride_w - p.pad_left;
    const bool row_inside = whole_runs && ix0 >= 0 && ix0 + p.kernel_w <= in_w;
    for (int ky = 0; ky < p.kernel_h; ++ky) {
      const int iy = oy * p.stride_h - p.pad_top + ky * p.dilation_h;
      const bool iy_inside = iy >= 0 && iy < in_h;
      const float* in_row = iy_inside ? in + static_cast<int64_t>(iy) * in_w * p.in_c : nullptr;
      if (row_inside && iy_inside) {
        std::memcpy(cols, in_row + static_cast<int64_t>(ix0) * p.in_c, p.kernel_w * tap_bytes);
        cols += p.kernel_w * cin_g;
        continue;
      }
      for (int kx = 0; kx < p.kernel_w; ++kx, cols += cin_g) {
        const int ix = ix0 + kx * p.dilation_w;
        if (!iy_inside || ix < 0 || ix >= in_w)
          std::memset(cols, 0, tap_bytes);
        else
          std::memcpy(cols, in_row + static_cast<int64_t>(ix) * p.in_c + group * cin_g, tap_bytes);
      }
    }
  }
}

// out[x][j] += tap[(x + shift) * stride + j] for x in [x0, x1), j < c: one tap's
// contributions (a row of the taps path's ring) added to an output row, with the channel
// count a constant for the compiler.
template <int kChannels>
void add_tap_fixed(const float* tap, int64_t stride, int shift, int x0, int x1, float* out) {
  for (int x = x0; x < x1; ++x)
    for (int j = 0; j < kChannels; ++j) out[x * kChannels + j] += tap[(x + shift) * stride + j];
}

void add_tap(const float* tap, int64_t stride, int shift, int c, int x0, int x1, float* out) {
  switch (c) {
    case 1: return add_tap_fixed<1>(tap, stride, shift, x0, x1, out);
    case 2: return add_tap_fixed<2>(tap, stride, shift, x0, x1, out);
    case 3: return add_tap_fixed<3>(tap, stride, shift, x0, x1, out);
    case 4: return add_tap_fixed<4>(tap, stride, shift, x0, x1, out);
  }
  for (int x = x0; x < x1; ++x)
    for (int j = 0; j < c; ++j) out[x * c + j] += tap[(x + shift) * stride + j];
}

// The general path's per-thread im2col buffer. It grows to the largest tile a convolution
// on this thread has needed (bound: kGemmTilesPerIm2colTile * gemm_mr pixels times
// kernel_h*kernel_w*in_c/groups floats) and is reused, never shrunk.
float* im2col_scratch(size_t floats) {
  thread_local std::vector<float> buffer;
  if (buffer.size() < floats) buffer.resize(floats);
  return buffer.data();
}

// Winograd path: the filters transformed, U = G g G^T at each of the 36 positions (in
// double, then rounded once), each position's [out_c][in_c] packed as a bias-free GEMM
// block; the bias after the last block. `stride` gets the blocks' spacing.
std::shared_ptr<float> pack_winograd_filters(const ConvParams& p, const float* weights, const float* bias,
                                             int nr, int64_t& stride) {
  using winograd::kFilter;
  const int in_c = p.in_c, out_c = p.out_c;
  stride = gemm_packed_size(out_c, in_c, nr);
  std::shared_ptr<float> packed = allocate_floats(stride * winograd::kPositions + out_c);
  std::vector<float> position(static_cast<size_t>(out_c) * in_c);
  for (int i = 0; i < winograd::kWindow; ++i)
    for (int j = 0; j < winograd::kWindow; ++j) {
      for (int o = 0; o < out_c; ++o)
        for (int c = 0; c < in_c; ++c) {
          const float* g = weights + static_cast<int64_t>(o) * 9 * in_c + c;  // OHWI: tap t at g[t * in_c]
          double u = 0.0;
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) u += kFilter[i][a] * g[(a * 3 + b) * in_c] * kFilter[j][b];
          position[static_cast<size_t>(o) * in_c + c] = static_cast<float>(u);
        }
      pack_gemm_weights(position.data(), nullptr, out_c, in_c, nr,
                        packed.get() + (i * winograd::kWindow + j) * stride);
    }
  for (int o = 0; o < out_c; ++o) packed.get()[stride * winograd::kPositions + o] = bias ? bias[o] : 0.0f;
  return packed;
}

// Winograd path: the 6x6 window of in_c channels whose top-left input pixel is (y0, x0),
// zeros where it reaches past the input, into window [6][6][in_c].
void copy_window(const float* in, int in_h, int in_w, int in_c, int y0, int x0, float* window) {
  for (int a = 0; a < winograd::kWindow; ++a)
    for (int b = 0; b < winograd::kWindow; ++b) {
      float* dst = window + static_cast<int64_t>(a * winograd::kWindow + b) * in_c;
      const int y = y0 + a, x = x0 + b;
      if (y < 0 || y >= in_h || x < 0 || x >= in_w)
        std::fill_n(dst, in_c, 0.0f);
      else
        std::copy_n(in + (static_cast<int64_t>(y) * in_w + x) * in_c, in_c, dst);
    }
}

// The input rows one rows-path task reads. With horizontal padding each is copied once
// between zero columns, into a ring of `span` rows (input row iy in slot iy % span) that
// consecutive output rows share; without it, the input rows themselves.
class PaddedRows {
 public:
  PaddedRows(const ConvParams& p, const float* in, int in_w, int span)
      : in_(in), row_floats_(static_cast<int64_t>(in_w) * p.in_c), left_(static_cast<int64_t>(p.pad_left) * p.in_c),
        right_(static_cast<int64_t>(p.pad_right) * p.in_c), held_(span, -1) {
    if (left_ > 0 || right_ > 0) ring_ = im2col_scratch(static_cast<size_t>(span * (left_ + row_floats_ + right_)));
  }

  const float* row(int iy) {
    const float* src = in_ + iy * row_floats_;
    if (!ring_) return src;
    const size_t slot = static_cast<size_t>(iy) % held_.size();
    float* row = ring_ + static_cast<int64_t>(slot) * (left_ + row_floats_ + right_);
    if (held_[slot] != iy) {
      std::fill_n(row, left_, 0.0f);
      std::copy_n(src, row_floats_, row + left_);
      std::fill_n(row + left_ + row_floats_, right_, 0.0f);
      held_[slot] = iy;
    }
    return row;
  }

 private:
  const float* in_;
  int64_t row_floats_, left_, right_;
  std::vector<int> held_;
  float* ring_ = nullptr;
};

}  // namespace

int ConvParams::out_h(int in_h) const {
  return out_size(in_h, pad_top, pad_bottom, kernel_h, dilation_h, stride_h);
}

int ConvParams::out_w(int in_w) const {
  return out_size(in_w, pad_left, pad_right, kernel_w, dilation_w, stride_w);
}

void validate(const ConvParams& p) {
  const auto positive = [](const char* name, int v) {
    if (v <= 0) fail(std::string(name) + " must be positive (got " + std::to_string(v) + ")");
  };
  positive("in_c", p.in_c);
  positive("out_c", p.out_c);
  positive("kernel_h", p.kernel_h);
  positive("kernel_w", p.kernel_w);
  positive("stride_h", p.stride_h);
  positive("stride_w", p.stride_w);
  positive("dilation_h", p.dilation_h);
  positive("dilation_w", p.dilation_w);
  positive("groups", p.groups);
  if (p.pad_top < 0 || p.pad_left < 0 || p.pad_bottom < 0 || p.pad_right < 0)
    fail("padding must not be negative");
  if (p.in_c % p.groups != 0)
    fail("groups " + std::to_string(p.groups) + " does not divide in_c " + std::to_string(p.in_c));
  if (p.out_c % p.groups != 0)
    fail("groups " + std::to_string(p.groups) + " does not divide out_c " + std::to_string(p.out_c));
}

Conv2d::Conv2d(const ConvParams& p, const float* weights, const float* bias, const KernelTable& k)
    : p_(p), path_(Path::General), k_(&k) {
  validate(p);
  if (!weights) fail("weights are missing");
  path_ = choose_path(p);
  const int taps = p.kernel_h * p.kernel_w;
  if (path_ == Path::Depthwise) {
    // OHWI with one input channel per group is [c][tap]; the row kernel wants [tap][c].
    const int c = p.in_c;
    std::shared_ptr<float> packed = allocate_floats(static_cast<int64_t>(taps + 1) * c);
    for (int ch = 0; ch < c; ++ch) {
      for (int t = 0; t < taps; ++t) packed.get()[static_cast<int64_t>(t) * c + ch] = weights[ch * taps + t];
      packed.get()[static_cast<int64_t>(taps) * c + ch] = bias ? bias[ch] : 0.0f;
    }
    packed_ = packed;
    return;
  }
  if (path_ == Path::Taps) {
    // Weights regrouped [tap][out_c][in_c]: gemm column tap * out_c + j is output j's tap.
    const int n = taps * p.out_c;
    std::vector<float> by_tap(static_cast<size_t>(n) * p.in_c);
    for (int j = 0; j < p.out_c; ++j)
      for (int t = 0; t < taps; ++t)
        std::copy_n(weights + (static_cast<int64_t>(j) * taps + t) * p.in_c, p.in_c,
                    by_tap.begin() + (static_cast<int64_t>(t) * p.out_c + j) * p.in_c);
    group_stride_ = gemm_packed_size(n, p.in_c, k.gemm_nr);
    std::shared_ptr<float> packed = allocate_floats(group_stride_ + p.out_c);
    pack_gemm_weights(by_tap.data(), nullptr, n, p.in_c, k.gemm_nr, packed.get());
    for (int j = 0; j < p.out_c; ++j) packed.get()[group_stride_ + j] = bias ? bias[j] : 0.0f;
    packed_ = packed;
    return;
  }
  if (path_ == Path::Winograd) {
    packed_ = pack_winograd_filters(p, weights, bias, k.gemm_nr, group_stride_);
    return;
  }
  if (path_ == Path::Rows) {
    // One bias-free block per run (kernel row ky, taps kx0..kx0+run-1): [out_c][run*in_c]
    // is a contiguous slice of each OHWI filter row.
    const int run = rows_run_taps(p), runs = taps / run, kdim = run * p.in_c;
    group_stride_ = gemm_packed_size(p.out_c, kdim, k.gemm_nr);
    std::shared_ptr<float> packed = allocate_floats(group_stride_ * runs + p.out_c);
    std::vector<float> slice(static_cast<size_t>(p.out_c) * kdim);
    for (int r = 0; r < runs; ++r) {
      for (int j = 0; j < p.out_c; ++j)
        std::copy_n(weights + (static_cast<int64_t>(j) * taps + r * run) * p.in_c, kdim,
                    slice.begin() + static_cast<int64_t>(j) * kdim);
      pack_gemm_weights(slice.data(), nullptr, p.out_c, kdim, k.gemm_nr, packed.get() + r * group_stride_);
    }
    for (int j = 0; j < p.out_c; ++j) packed.get()[group_stride_ * runs + j] = bias ? bias[j] : 0.0f;
    packed_ = packed;
    return;
  }
  const int cout_g = p.out_c / p.groups;
  const int kdim = taps * (p.in_c / p.groups);
  group_stride_ = gemm_packed_size(cout_g, kdim, k.gemm_nr);
  std::shared_ptr<float> packed = allocate_floats(group_stride_ * p.groups);
  for (int g = 0; g < p.groups; ++g)
    pack_gemm_weights(weights + static_cast<int64_t>(g) * cout_g * kdim, bias ? bias + g * cout_g : nullptr,
                      cout_g, kdim, k.gemm_nr, packed.get() + g * group_stride_);
  packed_ = packed;
}

void Conv2d::check_input(const char* method, int in_h, int in_w) const {
  if (!k_) fail(std::string(method) + "() on an empty Conv2d");
  if (in_h <= 0 || in_w <= 0)
    fail("input size " + std::to_string(in_h) + "x" + std::to_string(in_w) + " is empty");
  if (p_.out_h(in_h) <= 0 || p_.out_w(in_w) <= 0)
    fail("input " + std::to_string(in_h) + "x" + std::to_string(in_w) +
         " is smaller than the dilated " + std::to_string(p_.kernel_h) + "x" +
         std::to_string(p_.kernel_w) + " kernel");
}

void Conv2d::run(const float* in, int in_h, int in_w, float* out, const float* residual,
                 ThreadPool& pool) const {
  check_input("run", in_h, in_w);
  switch (path_) {
    case Path::Pointwise:
      run_pointwise(packed_.get(), in, static_cast<int64_t>(in_h) * in_w, out, residual, pool);
      break;
    case Path::Depthwise: run_depthwise(in, in_h, in_w, out, residual, pool); break;
    case Path::Taps: run_taps(in, in_h, in_w, out, residual, pool); break;
    case Path::Winograd: run_winograd(in, in_h, in_w, out, residual, pool); break;
    case Path::Rows: run_rows(in, in_h, in_w, out, residual, pool); break;
    case Path::General: run_general(in, in_h, in_w, out, residual, pool); break;
  }
}

void Conv2d::run_scaled_input(const float* in, int in_h, int in_w, const float* in_scale,
                              float* out, const float* residual, ThreadPool& pool) const {
  check_input("run_scaled_input", in_h, in_w);
  if (path_ != Path::Pointwise) fail("run_scaled_input() needs a pointwise convolution");
  // Each panel is [bias: nr][k][nr]: row kk of every panel takes the scale of input kk.
  const int nr = k_->gemm_nr, kdim = p_.in_c;
  const int64_t size = gemm_packed_size(p_.out_c, kdim, nr);
  AlignedBuffer scaled_buffer = aligned_alloc64(static_cast<size_t>(size) * sizeof(float));
  float* scaled = static_cast<float*>(scaled_buffer.get());
  const float* packed = packed_.get();
  for (int64_t panel = 0; panel < size; panel += static_cast<int64_t>(1 + kdim) * nr) {
    std::copy_n(packed + panel, nr, scaled + panel);
    for (int kk = 0; kk < kdim; ++kk) {
      const int64_t row = panel + static_cast<int64_t>(1 + kk) * nr;
      for (int j = 0; j < nr; ++j) scaled[row + j] = packed[row + j] * in_scale[kk];
    }
  }
  run_pointwise(scaled, in, static_cast<int64_t>(in_h) * in_w, out, residual, pool);
}

GemmArgs Conv2d::pointwise_gemm_args() const {
  GemmArgs g;
  g.n = p_.out_c;
  g.k = p_.in_c;
  g.a_stride = p_.in_c;
  g.packed = packed_.get();
  g.c_stride = p_.out_c;
  g.act = p_.act;
  return g;
}

DepthwiseRowArgs Conv2d::depthwise_row_args(int in_w, int out_w, int pad_left) const {
  DepthwiseRowArgs a;
  a.in_w = in_w;
  a.channels = p_.in_c;
  a.kernel_h = p_.kernel_h;
  a.kernel_w = p_.kernel_w;
  a.stride_w = p_.stride_w;
  a.dilation_w = p_.dilation_w;
  a.pad_left = pad_left;
  a.out_w = out_w;
  ConvParams shifted = p_;
  shifted.pad_left = pad_left;
  interior_columns(shifted, in_w, out_w, a.interior_begin, a.interior_end);
  a.weights = packed_.get();
  a.bias = packed_.get() + static_cast<int64_t>(p_.kernel_h) * p_.kernel_w * p_.in_c;
  a.act = p_.act;
  return a;
}

void Conv2d::run_pointwise(const float* packed, const float* in, int64_t pixels, float* out,
                           const float* residual, ThreadPool& pool) const {
  GemmProblem g;
  g.m = static_cast<int>(pixels);
  g.n = p_.out_c;
  g.k = p_.in_c;
  g.a = in;
  g.a_stride = p_.in_c;
  g.c = out;
  g.c_stride = p_.out_c;
  g.residual = residual;
  g.act = p_.act;
  gemm_packed(g, packed, pool, *k_);
}

void Conv2d::run_depthwise(const float* in, int in_h, int in_w, float* out, const float* residual,
                           ThreadPool& pool) const {
  const int out_h = p_.out_h(in_h), out_w = p_.out_w(in_w), c = p_.in_c;
  DepthwiseRowArgs base = depthwise_row_args(in_w, out_w, p_.pad_left);
  const int64_t row_floats = static_cast<int64_t>(out_w) * c;
  base.stream_out = stream_output(out, row_floats * out_h, c);
  pool.parallel_for(out_h, 1, [&](int64_t first, int64_t last) {
    std::array<const float*, kMaxDepthwiseKernelH> rows;
    DepthwiseRowArgs a = base;
    a.in_rows = rows.data();
    for (int64_t y = first; y < last; ++y) {
      for (int ky = 0; ky < p_.kernel_h; ++ky) {
        const int iy = static_cast<int>(y) * p_.stride_h - p_.pad_top + ky * p_.dilation_h;
        rows[ky] = iy >= 0 && iy < in_h ? in + static_cast<int64_t>(iy) * in_w * c : nullptr;
      }
      const int next_iy = static_cast<int>(y + 1) * p_.stride_h - p_.pad_top + (p_.kernel_h - 1) * p_.dilation_h;
      a.prefetch_row = y + 1 < out_h && next_iy < in_h ? in + static_cast<int64_t>(next_iy) * in_w * c : nullptr;
      a.out = out + y * row_floats;
      a.residual = residual ? residual + y * row_floats : nullptr;
      k_->depthwise_row(a);
    }
  });
}

void Conv2d::run_taps(const float* in, int in_h, int in_w, float* out, const float* residual,
                      ThreadPool& pool) const {
  const int out_h = p_.out_h(in_h), out_w = p_.out_w(in_w), out_c = p_.out_c;
  const int taps = p_.kernel_h * p_.kernel_w, columns = taps * out_c;
  const int span = (p_.kernel_h - 1) * p_.dilation_h + 1;  // input rows one output row reads
  const int64_t row_floats = static_cast<int64_t>(in_w) * columns;
  const float* bias = packed_.get() + group_stride_;
  GemmArgs base;
  base.n = columns;
  base.k = p_.in_c;
  base.a_stride = p_.in_c;
  base.packed = packed_.get();
  base.c_stride = columns;
  const int bands = std::clamp(std::min(kTapsBandsPerThread * pool.size(), out_h / (kTapsMinBandSeams * span)), 1, out_h);
  const int band_h = (out_h + bands - 1) / bands;
  pool.parallel_for(bands, 1, [&](int64_t first, int64_t last) {
    // A ring of span rows of tap contributions: input row iy lives in slot iy % span.
    float* ring = im2col_scratch(static_cast<size_t>(span * row_floats));
    GemmArgs g = base;
    for (int64_t band = first; band < last; ++band) {
      const int y0 = static_cast<int>(band) * band_h, y1 = std::min(out_h, y0 + band_h);
      int next_row = std::max(0, y0 - p_.pad_top);  // the first input row not yet in the ring
      for (int y = y0; y < y1; ++y) {
        const int top = y - p_.pad_top;
        for (const int end = std::min(in_h, top + span); next_row < end; ++next_row)
          for (int x = 0; x < in_w; x += k_->gemm_mr) {
            g.m = std::min(k_->gemm_mr, in_w - x);
            g.a = in + (static_cast<int64_t>(next_row) * in_w + x) * p_.in_c;
            g.c = ring + (next_row % span) * row_floats + static_cast<int64_t>(x) * columns;
            k_->gemm(g);
          }
        float* row_out = out + static_cast<int64_t>(y) * out_w * out_c;
        for (int x = 0; x < out_w; ++x) std::copy_n(bias, out_c, row_out + static_cast<int64_t>(x) * out_c);
        for (int ky = 0; ky < p_.kernel_h; ++ky) {
          const int iy = top + ky * p_.dilation_h;
          if (iy < 0 || iy >= in_h) continue;
          for (int kx = 0; kx < p_.kernel_w; ++kx) {
            // Output columns whose tap reads inside the row: x - pad_left + kx*dilation in [0, in_w).
            const int shift = kx * p_.dilation_w - p_.pad_left;
            const int x0 = std::max(0, -shift), x1 = std::min(out_w, in_w - shift);
            const float* tap = ring + (iy % span) * row_floats + (ky * p_.kernel_w + kx) * out_c;
            add_tap(tap, columns, shift, out_c, x0, x1, row_out);
          }
        }
        const int64_t row_values = static_cast<int64_t>(out_w) * out_c;
        k_->activate(row_out, row_values, p_.act);
        if (residual) k_->add(row_out, residual + static_cast<int64_t>(y) * row_values, row_values, {}, row_out);
      }
    }
  });
}

// Winograd path (kernels/winograd.h): the 4x4 output tiles in row-major order, in chunks
// whose transforms fit the L2 share; per chunk, every tile's window transformed, the 36
// position products, every tile's outputs.
void Conv2d::run_winograd(const float* in, int in_h, int in_w, float* out, const float* residual,
                          ThreadPool& pool) const {
  using winograd::kPositions;
  using winograd::kTile;
  using winograd::kWindow;
  const int out_h = p_.out_h(in_h), out_w = p_.out_w(in_w), in_c = p_.in_c, out_c = p_.out_c;
  const int tile_cols = (out_w + kTile - 1) / kTile;
  const int64_t tiles = static_cast<int64_t>((out_h + kTile - 1) / kTile) * tile_cols;
  const int mr = k_->gemm_mr;
  const int64_t tile_bytes = kPositions * static_cast<int64_t>(in_c + out_c) * sizeof(float);
  const int64_t fit = static_cast<int64_t>(cache_bytes(2, kDefaultL2Bytes)) / kWinogradL2Share / tile_bytes;
  const int chunk = static_cast<int>(std::min<int64_t>(tiles, std::max<int64_t>(mr, fit / mr * mr)));
  const int64_t v_stride = static_cast<int64_t>(chunk) * in_c, m_stride = static_cast<int64_t>(chunk) * out_c;
  const int64_t in_row = static_cast<int64_t>(in_w) * in_c, out_row = static_cast<int64_t>(out_w) * out_c;
  const float* bias = packed_.get() + group_stride_ * kPositions;
  pool.parallel_for((tiles + chunk - 1) / chunk, 1, [&](int64_t first, int64_t last) {
    float* v = im2col_scratch(static_cast<size_t>(kPositions * (v_stride + m_stride + in_c)));
    float* m = v + kPositions * v_stride;
    float* window = m + kPositions * m_stride;  // [6][6][in_c], for windows past the input's edge
    for (int64_t item = first; item < last; ++item) {
      const int64_t t0 = item * chunk;
      const int count = static_cast<int>(std::min<int64_t>(chunk, tiles - t0));
      for (int t = 0; t < count; ++t) {
        const int y0 = static_cast<int>((t0 + t) / tile_cols) * kTile - p_.pad_top;
        const int x0 = static_cast<int>((t0 + t) % tile_cols) * kTile - p_.pad_left;
        float* vt = v + static_cast<int64_t>(t) * in_c;
        if (y0 >= 0 && x0 >= 0 && y0 + kWindow <= in_h && x0 + kWindow <= in_w) {
          k_->winograd_input(in + y0 * in_row + static_cast<int64_t>(x0) * in_c, in_row, in_c, vt, v_stride);
        } else {
          copy_window(in, in_h, in_w, in_c, y0, x0, window);
          k_->winograd_input(window, static_cast<int64_t>(kWindow) * in_c, in_c, vt, v_stride);
        }
      }
      GemmArgs g;
      g.n = out_c;
      g.k = in_c;
      g.a_stride = in_c;
      g.c_stride = out_c;
      for (int xi = 0; xi < kPositions; ++xi) {  // one position's filters stay in L1 across the chunk
        g.packed = packed_.get() + xi * group_stride_;
        for (int r = 0; r < count; r += mr) {
          g.m = std::min(mr, count - r);
          g.a = v + xi * v_stride + static_cast<int64_t>(r) * in_c;
          g.c = m + xi * m_stride + static_cast<int64_t>(r) * out_c;
          k_->gemm(g);
        }
      }
      WinogradOutputArgs o;
      o.m_stride = m_stride;
      o.channels = out_c;
      o.bias = bias;
      o.act = p_.act;
      o.row_stride = out_row;
      for (int t = 0; t < count; ++t) {
        const int ty = static_cast<int>((t0 + t) / tile_cols), tx = static_cast<int>((t0 + t) % tile_cols);
        const int64_t at = static_cast<int64_t>(ty) * kTile * out_row + static_cast<int64_t>(tx) * kTile * out_c;
        o.m = m + static_cast<int64_t>(t) * out_c;
        o.out = out + at;
        o.residual = residual ? residual + at : nullptr;
        o.rows = std::min(kTile, out_h - ty * kTile);
        o.cols = std::min(kTile, out_w - tx * kTile);
        k_->winograd_output(o);
      }
    }
  });
}

void Conv2d::run_rows(const float* in, int in_h, int in_w, float* out, const float* residual,
                      ThreadPool& pool) const {
  const int out_h = p_.out_h(in_h), out_w = p_.out_w(in_w), c = p_.in_c, out_c = p_.out_c;
  const int run = rows_run_taps(p_), runs_per_row = p_.kernel_w / run;
  const int span = (p_.kernel_h - 1) * p_.dilation_h + 1;  // input rows one output row reads
  const float* bias = packed_.get() + group_stride_ * p_.kernel_h * runs_per_row;
  const int64_t row_values = static_cast<int64_t>(out_w) * out_c;
  GemmArgs base;
  base.n = out_c;
  base.k = run * c;
  base.a_stride = static_cast<int64_t>(p_.stride_w) * c;
  base.c_stride = out_c;
  pool.parallel_for(out_h, 1, [&](int64_t first, int64_t last) {
    PaddedRows padded(p_, in, in_w, span);
    // The bias repeated along a row: the first run's gemm adds it as its residual.
    std::vector<float> bias_row(static_cast<size_t>(row_values));
    for (int x = 0; x < out_w; ++x) std::copy_n(bias, out_c, bias_row.begin() + static_cast<int64_t>(x) * out_c);
    std::vector<const float*> rows(p_.kernel_h);
    GemmArgs g = base;
    for (int64_t y = first; y < last; ++y) {
      for (int ky = 0; ky < p_.kernel_h; ++ky) {
        const int iy = static_cast<int>(y) * p_.stride_h - p_.pad_top + ky * p_.dilation_h;
        rows[ky] = iy >= 0 && iy < in_h ? padded.row(iy) : nullptr;  // rows in the padding add nothing
      }
      float* row_out = out + y * row_values;
      // Each run's gemm adds its product to the output tile (residual = c after the
      // first), so a tile's accumulators pass through memory once per run; it stays in L1.
      for (int x = 0; x < out_w; x += k_->gemm_mr) {
        g.m = std::min(k_->gemm_mr, out_w - x);
        g.c = row_out + static_cast<int64_t>(x) * out_c;
        g.residual = bias_row.data() + static_cast<int64_t>(x) * out_c;
        for (int ky = 0; ky < p_.kernel_h; ++ky) {
          if (!rows[ky]) continue;
          for (int r = 0; r < runs_per_row; ++r) {
            // Padded column of output x's first tap in this run: x*stride + kx*dilation.
            const int64_t column = static_cast<int64_t>(x) * p_.stride_w + static_cast<int64_t>(r) * run * p_.dilation_w;
            g.a = rows[ky] + column * c;
            g.packed = packed_.get() + (ky * runs_per_row + r) * group_stride_;
            k_->gemm(g);
            g.residual = g.c;
          }
        }
        if (g.residual != g.c)  // every kernel row fell in the padding: the output is the bias
          std::copy_n(g.residual, static_cast<int64_t>(g.m) * out_c, g.c);
      }
      k_->activate(row_out, row_values, p_.act);
      if (residual) k_->add(row_out, residual + y * row_values, row_values, {}, row_out);
    }
  });
}

void Conv2d::run_general(const float* in, int in_h, int in_w, float* out, const float* residual,
                         ThreadPool& pool) const {
  const int out_w = p_.out_w(in_w);
  const int64_t pixels = static_cast<int64_t>(p_.out_h(in_h)) * out_w;
  const int cout_g = p_.out_c / p_.groups;
  const int kdim = p_.kernel_h * p_.kernel_w * (p_.in_c / p_.groups);
  const int mr = k_->gemm_mr;
  const int tile = mr * kGemmTilesPerIm2colTile;
  GemmArgs base;
  base.n = cout_g;
  base.k = kdim;
  base.a_stride = kdim;
  base.c_stride = p_.out_c;
  base.act = p_.act;
  const int64_t tiles = (pixels + tile - 1) / tile;
  pool.parallel_for(tiles, 1, [&](int64_t first, int64_t last) {
    float* cols = im2col_scratch(static_cast<size_t>(tile) * kdim);
    GemmArgs g = base;
    for (int64_t t = first; t < last; ++t) {
      const int64_t p0 = t * tile;
      const int count = static_cast<int>(std::min<int64_t>(tile, pixels - p0));
      for (int group = 0; group < p_.groups; ++group) {
        im2col(p_, in, in_h, in_w, out_w, group, p0, count, cols);
        g.packed = packed_.get() + group * group_stride_;
        for (int r = 0; r < count; r += mr) {
          const int64_t offset = (p0 + r) * p_.out_c + static_cast<int64_t>(group) * cout_g;
          g.m = std::min(mr, count - r);
          g.a = cols + static_cast<int64_t>(r) * kdim;
          g.c = out + offset;
          g.residual = residual ? residual + offset : nullptr;
          k_->gemm(g);
        }
      }
    }
  });
}

}  // namespace ampi
