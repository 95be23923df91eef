#include "kernels/inverted_residual.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/cpu_caches.h"

namespace ampi {
namespace {

// What one task keeps in cache: the ring of expanded rows and the depthwise row, in half
// of the core's L2 (so the input rows and the packed weights fit beside it), at least
// kMinTileCacheBytes. Larger tiles mean wider strips: fewer halo columns expanded twice
// and fewer depthwise border blocks; on a core with a 2 MiB L2, a 1 MiB budget ran the
// lite network's widest block faster than 256 KiB did.
constexpr int64_t kMinTileCacheBytes = 256 * 1024;
constexpr size_t kDefaultL2Bytes = 512 * 1024;  // when the system does not say

int64_t tile_cache_bytes() {
  return std::max<int64_t>(kMinTileCacheBytes, int64_t(cache_bytes(2, kDefaultL2Bytes) / 2));
}
// Tiles per thread: two, so a thread that starts late or runs slower is partly made up
// for by the other, but no more: every tile expands the rows and columns at its seams
// again, which on the small maps of the deep levels cost more than the balance gained
// (lite's 160->320->80 block at 64x48 on 2 threads ran about a third faster with 2 tiles
// per thread than with 8).
constexpr int kTilesPerThread = 2;
// Bands at least this many times as tall as the rows their seams compute twice.
constexpr int kMinBandSeams = 8;

[[noreturn]] void reject(const std::string& why) {
  throw std::invalid_argument("InvertedResidual: " + why);
}

void check_chain(const std::optional<Conv2d>& expand, const Conv2d& dw, const Conv2d& project) {
  const ConvParams& d = dw.params();
  if (dw.path() != Conv2d::Path::Depthwise) reject("the middle convolution is not depthwise");
  if (d.stride_h != 1 || d.stride_w != 1) reject("the depthwise stride is not 1");
  if (d.pad_top + d.pad_bottom != (d.kernel_h - 1) * d.dilation_h ||
      d.pad_left + d.pad_right != (d.kernel_w - 1) * d.dilation_w)
    reject("the depthwise padding does not keep the size");
  if (d.kernel_h > kMaxDepthwiseKernelH) reject("the depthwise kernel is taller than 16");
  if (project.path() != Conv2d::Path::Pointwise) reject("the projection is not pointwise");
  if (project.params().in_c != d.in_c) reject("the projection does not read the depthwise output");
  if (&project.table() != &dw.table()) reject("the convolutions are packed for different tables");
  if (!expand) return;
  if (expand->path() != Conv2d::Path::Pointwise) reject("the expansion is not pointwise");
  if (expand->params().out_c != d.in_c) reject("the depthwise does not read the expansion");
  if (&expand->table() != &dw.table()) reject("the convolutions are packed for different tables");
}

// A pointwise convolution of `pixels` contiguous pixels through the table's gemm tile: a
// holds in_c floats per pixel, c receives out_c. A tile's rows do not interact, so each
// pixel gets the bits Conv2d::run_pointwise gives it, wherever the tiles start.
void pointwise_rows(const Conv2d& conv, const float* a, int64_t pixels, float* c, const float* residual) {
  const KernelTable& k = conv.table();
  GemmArgs g = conv.pointwise_gemm_args();
  for (int64_t row = 0; row < pixels; row += k.gemm_mr) {
    g.m = static_cast<int>(std::min<int64_t>(k.gemm_mr, pixels - row));
    g.a = a + row * g.k;
    g.c = c + row * g.n;
    g.residual = residual ? residual + row * g.n : nullptr;
    k.gemm(g);
  }
}

}  // namespace

struct InvertedResidual::Scratch {
  std::vector<float> ring, dw_row;
  std::vector<float> input_row, residual_row;  // concatenated input pixels (run_concat)
};

InvertedResidual::InvertedResidual(std::optional<Conv2d> expand, Conv2d dw, Conv2d project)
    : expand_(std::move(expand)), dw_(std::move(dw)), project_(std::move(project)) {
  check_chain(expand_, dw_, project_);
  expanded_ = dw_.params().in_c;
  in_c_ = expand_ ? expand_->params().in_c : expanded_;
  out_c_ = project_.params().out_c;
}

void InvertedResidual::run(const float* in, int h, int w, float* out, const float* residual,
                           ThreadPool& pool) const {
  run_input({in, in_c_}, h, w, out, residual, false, pool);
}

void InvertedResidual::run_concat(const float* first, int first_c, const float* second, int second_c, int h,
                                  int w, float* out, bool add_input, ThreadPool& pool) const {
  if (first_c <= 0 || second_c <= 0 || first_c + second_c != in_c_)
    reject("run_concat: " + std::to_string(first_c) + " + " + std::to_string(second_c) +
           " channels are not the block's " + std::to_string(in_c_));
  if (!expand_) reject("run_concat needs an expansion");
  if (add_input && in_c_ != out_c_) reject("run_concat: the input cannot be added to an output of other width");
  run_input({first, first_c, second, second_c}, h, w, out, nullptr, add_input, pool);
}

void InvertedResidual::run_input(const Input& in, int h, int w, float* out, const float* residual,
                                 bool add_input, ThreadPool& pool) const {
  if (h <= 0 || w <= 0) throw std::invalid_argument("InvertedResidual: empty input");
  const ConvParams& d = dw_.params();
  const int span = (d.kernel_h - 1) * d.dilation_h + 1;  // input rows one output row reads
  const int halo = (d.kernel_w - 1) * d.dilation_w;      // extra input columns of a strip
  // Strips as wide as the cache allows for the ring (span rows) plus the depthwise row,
  // and bands; more strips where the map is too short for enough bands (the small maps
  // of the deep levels), so every thread still gets its tiles.
  const int64_t pixel_bytes = int64_t(expanded_) * sizeof(float);
  const int fit = int(std::max<int64_t>(8, tile_cache_bytes() / ((span + 1) * pixel_bytes) - halo));
  const int wanted_tiles = kTilesPerThread * pool.size();
  const int max_bands = std::clamp(h / std::max(1, kMinBandSeams * (span - 1)), 1, h);
  const int max_strips = std::clamp(w / std::max(1, kMinBandSeams * halo), 1, w);
  const int strips = std::max((w + fit - 1) / fit, std::min(max_strips, (wanted_tiles + max_bands - 1) / max_bands));
  const int strip_w = (w + strips - 1) / strips;
  const int bands = std::min(max_bands, (wanted_tiles + strips - 1) / strips);
  const int band_h = (h + bands - 1) / bands;
  const int ring_w = std::min(w, strip_w + halo);
  pool.parallel_for(int64_t(bands) * strips, 1, [&](int64_t first, int64_t last) {
    thread_local Scratch scratch;
    for (int64_t i = first; i < last; ++i) {
      const int band = int(i / strips), strip = int(i % strips);
      const Tile t{band * band_h, std::min(h, (band + 1) * band_h), strip * strip_w,
                   std::min(w, (strip + 1) * strip_w)};
      if (t.y0 < t.y1 && t.x0 < t.x1) run_tile(t, in, h, w, out, residual, add_input, ring_w, scratch);
    }
  });
}

void InvertedResidual::run_tile(const Tile& t, const Input& in, int h, int w, float* out,
                                const float* residual, bool add_input, int ring_w, Scratch& s) const {
  const ConvParams& d = dw_.params();
  const int span = (d.kernel_h - 1) * d.dilation_h + 1;
  // The input columns the strip reads, and the depthwise arguments for a row of them: the
  // strip's first output column reads column x0 - pad_left + kx * dilation.
  const int cx0 = std::max(0, t.x0 - d.pad_left);
  const int cx1 = std::min(w, t.x1 - 1 - d.pad_left + (d.kernel_w - 1) * d.dilation_w + 1);
  const int cols = cx1 - cx0, out_w = t.x1 - t.x0;
  DepthwiseRowArgs a = dw_.depthwise_row_args(cols, out_w, cx0 - t.x0 + d.pad_left);

  const int64_t ring_row = int64_t(ring_w) * expanded_;
  if (expand_ && s.ring.size() < size_t(span * ring_row)) s.ring.resize(size_t(span * ring_row));
  if (s.dw_row.size() < size_t(out_w) * expanded_) s.dw_row.resize(size_t(out_w) * expanded_);
  // `count` input pixels from pixel `first` on: the map itself, or a concatenated input's
  // pixels gathered into `buffer`.
  const auto input_pixels = [&](int64_t first, int count, std::vector<float>& buffer) -> const float* {
    if (!in.second) return in.first + first * in_c_;
    if (buffer.size() < size_t(count) * in_c_) buffer.resize(size_t(count) * in_c_);
    dw_.table().concat_channels(in.first + first * in.first_c, in.first_c, in.second + first * in.second_c,
                                in.second_c, count, buffer.data());
    return buffer.data();
  };
  // Input row r's columns [cx0, cx1) after the expansion: its ring slot, or the input
  // itself when there is no expansion (a concatenated input always has one).
  const auto ring_slot = [&](int r) { return s.ring.data() + (r % span) * ring_row; };
  const auto expanded_row = [&](int r) -> const float* {
    return expand_ ? ring_slot(r) : in.first + (int64_t(r) * w + cx0) * in_c_;
  };
  int next_row = std::max(0, t.y0 - d.pad_top);  // the first row not yet expanded
  std::array<const float*, kMaxDepthwiseKernelH> rows;
  a.in_rows = rows.data();
  for (int y = t.y0; y < t.y1; ++y) {
    const int top = y - d.pad_top;
    for (const int last = std::min(h, top + span); expand_ && next_row < last; ++next_row)
      pointwise_rows(*expand_, input_pixels(int64_t(next_row) * w + cx0, cols, s.input_row), cols,
                     ring_slot(next_row), nullptr);
    for (int ky = 0; ky < d.kernel_h; ++ky) {
      const int iy = top + ky * d.dilation_h;
      rows[ky] = iy >= 0 && iy < h ? expanded_row(iy) : nullptr;
    }
    a.out = s.dw_row.data();
    dw_.table().depthwise_row(a);
    const int64_t first = int64_t(y) * w + t.x0;
    const float* row_residual = add_input  ? input_pixels(first, out_w, s.residual_row)
                                : residual ? residual + first * out_c_
                                           : nullptr;
    pointwise_rows(project_, s.dw_row.data(), out_w, out + first * out_c_, row_residual);
  }
}

}  // namespace ampi
