#include "nets/depth_anything_net.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kernels/conv.h"
#include "kernels/gemm.h"
#include "kernels/ops.h"
#include "kernels/transformer_ops.h"
#include "nets/architectures.h"
#include "nets/plan.h"

namespace ampi {
namespace {

constexpr int64_t kFormatVersion = 1;
constexpr int kTaps = 4;  // the DPT head reads four blocks
constexpr int kMaxWorkingSize = 16384;
// Rows per band of the output head (add_output_head): a multiple of Winograd's 4-row
// tiles, so the bands tile the map as its whole convolution does.
constexpr int kOutputBand = 4;

[[noreturn]] void fail(const WeightFile& f, const std::string& problem) {
  throw std::runtime_error(f.path() + ": " + problem);
}

int positive_int(const WeightFile& f, const std::string& key, int64_t most = 65536) {
  const int64_t v = f.get_int(key);
  if (v <= 0 || v > most) fail(f, key + " " + std::to_string(v) + " is not in 1.." + std::to_string(most));
  return int(v);
}

std::vector<int> int_list(const WeightFile& f, const std::string& key, size_t count) {
  const std::vector<int64_t> v = f.get_ints(key);
  if (v.size() != count)
    fail(f, key + ": " + std::to_string(v.size()) + " values, not " + std::to_string(count));
  return std::vector<int>(v.begin(), v.end());
}

// The dimensions of the file (dav2.* metadata), checked against each other.
struct Dims {
  int dim = 0, depth = 0, heads = 0, mlp = 0, patch = 0, pos_grid = 0, features = 0, head_hidden = 0;
  double pos_offset = 0, eps = 0;
  std::vector<int> layers, out_channels;
};

Dims read_dims(const WeightFile& f) {
  Dims d;
  d.dim = positive_int(f, "dav2.embed_dim");
  d.depth = positive_int(f, "dav2.depth", 256);
  d.heads = positive_int(f, "dav2.heads", 1024);
  if (d.dim % d.heads) fail(f, "dav2.heads " + std::to_string(d.heads) + " does not divide dav2.embed_dim");
  d.mlp = positive_int(f, "dav2.mlp_hidden");
  d.patch = positive_int(f, "dav2.patch_size", 256);
  d.pos_grid = positive_int(f, "dav2.pos_grid", 1024);
  d.pos_offset = f.get_float("dav2.pos_offset");
  d.eps = f.get_float("dav2.norm_eps");
  if (!(d.eps > 0)) fail(f, "dav2.norm_eps must be positive");
  d.layers = int_list(f, "dav2.layers", kTaps);
  for (int k = 0; k < kTaps; ++k)
    if (d.layers[k] < 0 || d.layers[k] >= d.depth || (k && d.layers[k] <= d.layers[k - 1]))
      fail(f, "dav2.layers must be 4 increasing block indices below dav2.depth");
  d.features = positive_int(f, "dav2.features");
  if (d.features % 2) fail(f, "dav2.features " + std::to_string(d.features) + " is odd (the head halves it)");
  d.out_channels = int_list(f, "dav2.out_channels", kTaps);
  for (int c : d.out_channels)
    if (c <= 0 || c > 65536) fail(f, "dav2.out_channels must be positive");
  d.head_hidden = positive_int(f, "dav2.head_hidden");
  return d;
}

// One transformer block, LayerScale folded into proj and fc2 by the importer.
struct Block {
  Tensor norm1_w, norm1_b, norm2_w, norm2_b;
  GemmWeights qkv, proj, fc1, fc2;
};

struct ResidualUnit {
  Conv2d conv1, conv2;  // conv1 ends in the ReLU conv2 reads
};

struct Fusion {
  ResidualUnit skip_unit, unit;  // skip_unit unused by the coarsest block
  Conv2d out_conv;
};

// One convolution with 'same' padding, run on a band of rows of its input that carries
// kernel / 2 rows of context above and below: vertical padding only where the band
// touches the map's top or bottom edge, so each band gives exactly the rows that the
// whole map's convolution would (bitwise: the other paths, and Winograd's 4-row tiles
// when bands start on multiples of 4, compute each output the same way).
struct BandConvs {
  static constexpr int kTop = 1, kBottom = 2;
  Conv2d at_place[4];  // indexed by kTop | kBottom where the band touches that edge
  const Conv2d& for_band(bool top, bool bottom) const { return at_place[(top ? kTop : 0) | (bottom ? kBottom : 0)]; }
};

ConvParams square_params(int in, int out, int kernel, Activation act, int stride) {
  ConvParams p;
  p.in_c = in;
  p.out_c = out;
  p.kernel_h = p.kernel_w = kernel;
  p.stride_h = p.stride_w = stride;
  p.pad_top = p.pad_left = p.pad_bottom = p.pad_right = kernel / 2;
  p.act = {act};
  return p;
}

// Weights are read by name with their shapes checked, and counted.
class Reader {
 public:
  Reader(const WeightFile& f, const KernelTable& t) : f_(f), t_(t) {}

  Tensor tensor(const std::string& name, const Shape& shape) {
    Tensor v = f_.tensor(name, shape);
    params_ += v.numel();
    return v;
  }
  GemmWeights linear(const std::string& name, int out, int in) {
    const Tensor w = tensor(name + ".weight", {out, in}), b = tensor(name + ".bias", {out});
    return GemmWeights(w.f32(), b.f32(), out, in, t_);
  }
  // A square convolution with 'same' padding (stride 1) or padding 1 at stride 2.
  Conv2d conv(const std::string& name, int in, int out, int kernel, bool bias, Activation act = Activation::None,
              int stride = 1) {
    const Tensor w = tensor(name + ".weight", {out, kernel, kernel, in});
    Tensor b;
    if (bias) b = tensor(name + ".bias", {out});
    return Conv2d(square_params(in, out, kernel, act, stride), w.f32(), bias ? b.f32() : nullptr, t_);
  }
  // The same 'same'-padded convolution for each place of a band of rows (BandConvs).
  BandConvs band_convs(const std::string& name, int in, int out, int kernel, Activation act) {
    const Tensor w = tensor(name + ".weight", {out, kernel, kernel, in}), b = tensor(name + ".bias", {out});
    BandConvs convs;
    for (int place = 0; place < 4; ++place) {
      ConvParams p = square_params(in, out, kernel, act, 1);
      if (!(place & BandConvs::kTop)) p.pad_top = 0;
      if (!(place & BandConvs::kBottom)) p.pad_bottom = 0;
      convs.at_place[place] = Conv2d(p, w.f32(), b.f32(), t_);
    }
    return convs;
  }
  StridedTransposedConv transposed(const std::string& name, int channels, int stride) {
    const Tensor w = tensor(name + ".weight", {stride, stride, channels, channels});
    const Tensor b = tensor(name + ".bias", {channels});
    return StridedTransposedConv(stride, channels, channels, w.f32(), b.f32(), t_);
  }
  ResidualUnit unit(const std::string& name, int f) {
    return {conv(name + ".conv1", f, f, 3, true, Activation::ReLU), conv(name + ".conv2", f, f, 3, true)};
  }
  int64_t params() const { return params_; }

 private:
  const WeightFile& f_;
  const KernelTable& t_;
  int64_t params_ = 0;
};

}  // namespace

ImageSize dav2_working_shape(int height, int width, int size, int multiple) {
  if (height <= 0 || width <= 0 || size <= 0 || multiple <= 0)
    throw std::invalid_argument("dav2_working_shape: sizes must be positive");
  const double scale = std::max(double(size) / height, double(size) / width);
  const auto side = [&](double x) {
    // nearbyint rounds halves to even under the default rounding mode, as Python's round.
    const int y = int(std::nearbyint(x / multiple)) * multiple;
    return y >= size ? y : int(std::ceil(x / multiple)) * multiple;
  };
  return {side(scale * height), side(scale * width)};
}

struct DepthAnythingNet::Impl {
  std::string variant;
  Dims d;
  int working_size = 0;
  float mean[3], inv_std[3];
  Tensor cls, pos;  // [dim], [1 + grid^2][dim]
  PatchEmbedding patch;
  std::vector<Block> blocks;
  Tensor norm_w, norm_b;
  Conv2d project[kTaps], layer_rn[kTaps], downsample;  // downsample: the coarsest level's resize
  StridedTransposedConv upsample4, upsample2;
  Fusion fusion[kTaps];  // fusion[k]: refinenet{k+1}
  Conv2d output_conv1, head_out;
  BandConvs head_hidden;
  int64_t params = 0;
  const KernelTable* table = nullptr;

  std::unique_ptr<Plan> plan;
  ImageSize plan_shape;
  int plan_output = -1;
  const float* rgb = nullptr;  // the caller's photo, set before every execute()
  int rgb_h = 0, rgb_w = 0;

  std::unique_ptr<Plan> build_plan(ImageSize shape);
  int add_input(Plan& p, ImageSize shape) const;
  int add_block(Plan& p, const Block& b, int t, int tokens) const;
  int add_layer_norm(Plan& p, int t, int tokens, const Tensor& w, const Tensor& b) const;
  int add_linear(Plan& p, int x, int tokens, const GemmWeights& w, ActivationSpec act, int residual) const;
  int add_conv(Plan& p, const Conv2d& conv, int x, int h, int w, int residual = -1, int offset = 0) const;
  int add_unit(Plan& p, const ResidualUnit& u, int x, int h, int w) const;
  int add_fusion(Plan& p, const Fusion& fu, int x, int skip, int h, int w, ImageSize to) const;
  int add_resize(Plan& p, int x, int h, int w, ImageSize to) const;
  int add_output_head(Plan& p, int x, ImageSize fine, ImageSize shape) const;
};

DepthAnythingNet DepthAnythingNet::from_file(const WeightFile& f, const KernelTable& table) {
  if (f.get_string("arch") != arch::kDepthDinoV2Dpt)
    fail(f, "architecture '" + f.get_string("arch") + "' is not " + arch::kDepthDinoV2Dpt);
  if (f.get_int("depth.format_version") != kFormatVersion)
    fail(f, "depth.format_version " + std::to_string(f.get_int("depth.format_version")) +
                " is not supported (this build reads " + std::to_string(kFormatVersion) + ")");
  auto m = std::make_unique<Impl>();
  m->table = &table;
  m->variant = f.get_string("depth.variant");
  m->d = read_dims(f);
  const Dims& d = m->d;
  if (f.get_int("depth.multiple") != d.patch) fail(f, "depth.multiple disagrees with dav2.patch_size");
  const int64_t size = f.get_int("depth.working_size");
  if (size < d.patch || size > kMaxWorkingSize)
    fail(f, "depth.working_size " + std::to_string(size) + " is not in " + std::to_string(d.patch) + ".." +
                std::to_string(kMaxWorkingSize));
  m->working_size = int(size);
  const std::vector<double> mean = f.get_floats("depth.input_mean"), stdev = f.get_floats("depth.input_std");
  if (mean.size() != 3 || stdev.size() != 3) fail(f, "depth.input_mean and depth.input_std need 3 values");
  for (int c = 0; c < 3; ++c) {
    if (!(stdev[c] > 0)) fail(f, "depth.input_std must be positive");
    m->mean[c] = float(mean[c]);
    m->inv_std[c] = float(1.0 / stdev[c]);
  }

  Reader r(f, table);
  const std::string vit = "pretrained.", head = "depth_head.", s = "depth_head.scratch.";
  {
    const Tensor w = r.tensor(vit + "patch_embed.proj.weight", {d.dim, d.patch, d.patch, 3});
    const Tensor b = r.tensor(vit + "patch_embed.proj.bias", {d.dim});
    m->patch = PatchEmbedding(d.patch, d.dim, w.f32(), b.f32(), table);
  }
  m->cls = r.tensor(vit + "cls_token", {d.dim});
  m->pos = r.tensor(vit + "pos_embed", {1 + int64_t(d.pos_grid) * d.pos_grid, d.dim});
  for (int i = 0; i <= d.layers.back(); ++i) {  // blocks past the last tap never run
    const std::string n = vit + "blocks." + std::to_string(i) + ".";
    Block b;
    b.norm1_w = r.tensor(n + "norm1.weight", {d.dim});
    b.norm1_b = r.tensor(n + "norm1.bias", {d.dim});
    b.qkv = r.linear(n + "attn.qkv", 3 * d.dim, d.dim);
    b.proj = r.linear(n + "attn.proj", d.dim, d.dim);
    b.norm2_w = r.tensor(n + "norm2.weight", {d.dim});
    b.norm2_b = r.tensor(n + "norm2.bias", {d.dim});
    b.fc1 = r.linear(n + "mlp.fc1", d.mlp, d.dim);
    b.fc2 = r.linear(n + "mlp.fc2", d.dim, d.mlp);
    m->blocks.push_back(std::move(b));
  }
  m->norm_w = r.tensor(vit + "norm.weight", {d.dim});
  m->norm_b = r.tensor(vit + "norm.bias", {d.dim});
  for (int k = 0; k < kTaps; ++k) {
    const int c = d.out_channels[k];
    m->project[k] = r.conv(head + "projects." + std::to_string(k), d.dim, c, 1, true);
    m->layer_rn[k] = r.conv(s + "layer" + std::to_string(k + 1) + "_rn", c, d.features, 3, false);
    const std::string fu = s + "refinenet" + std::to_string(k + 1) + ".";
    if (k < kTaps - 1) m->fusion[k].skip_unit = r.unit(fu + "resConfUnit1", d.features);
    m->fusion[k].unit = r.unit(fu + "resConfUnit2", d.features);
    m->fusion[k].out_conv = r.conv(fu + "out_conv", d.features, d.features, 1, true);
  }
  m->upsample4 = r.transposed(head + "resize_layers.0", d.out_channels[0], 4);
  m->upsample2 = r.transposed(head + "resize_layers.1", d.out_channels[1], 2);
  m->downsample = r.conv(head + "resize_layers.3", d.out_channels[3], d.out_channels[3], 3, true, Activation::None, 2);
  const int half = d.features / 2;
  m->output_conv1 = r.conv(s + "output_conv1", d.features, half, 3, true);
  m->head_hidden = r.band_convs(s + "output_conv2.0", half, d.head_hidden, 3, Activation::ReLU);
  m->head_out = r.conv(s + "output_conv2.2", d.head_hidden, 1, 1, true, Activation::ReLU);
  m->params = r.params();
  return DepthAnythingNet(std::move(m));
}

// ---- the plan ---------------------------------------------------------------------------

// The normalised network input [H][W][3]: the caller's photo resized bicubically to the
// working shape (or taken as it is when it already has it).
int DepthAnythingNet::Impl::add_input(Plan& p, ImageSize shape) const {
  const int img = p.produce(shape.height, shape.width, 3);
  p.push([this, img, shape](Plan& pl, ThreadPool& pool) {
    float* x = pl.data(img);
    const int64_t pixels = int64_t(shape.height) * shape.width;
    if (rgb_h == shape.height && rgb_w == shape.width)
      std::copy(rgb, rgb + pixels * 3, x);
    else
      resize_bicubic(rgb, rgb_h, rgb_w, 3, shape.height, shape.width, double(rgb_h) / shape.height,
                     double(rgb_w) / shape.width, x, pool);
    pool.parallel_for(pixels, 4096, [&](int64_t i0, int64_t i1) {
      for (int64_t i = i0; i < i1; ++i)
        for (int c = 0; c < 3; ++c) x[i * 3 + c] = (x[i * 3 + c] - mean[c]) * inv_std[c];
    });
  });
  return img;
}

int DepthAnythingNet::Impl::add_layer_norm(Plan& p, int t, int tokens, const Tensor& w, const Tensor& b) const {
  const int dim = d.dim;
  const int y = p.produce(tokens, 1, dim);
  p.consume(t);
  const float eps = float(d.eps);
  p.push([this, t, y, tokens, dim, &w, &b, eps](Plan& pl, ThreadPool& pool) {
    layer_norm(pl.data(t), dim, tokens, dim, w.f32(), b.f32(), eps, pl.data(y), dim, pool, *table);
  });
  return y;
}

int DepthAnythingNet::Impl::add_linear(Plan& p, int x, int tokens, const GemmWeights& w, ActivationSpec act,
                                       int residual) const {
  const int y = p.produce(tokens, 1, w.n());
  p.consume(x);
  if (residual >= 0) p.consume(residual);
  p.push([x, y, tokens, &w, act, residual](Plan& pl, ThreadPool& pool) {
    GemmProblem g;
    g.m = tokens;
    g.n = w.n();
    g.k = w.k();
    g.a = pl.data(x);
    g.a_stride = w.k();
    g.c = pl.data(y);
    g.c_stride = w.n();
    g.residual = residual >= 0 ? pl.data(residual) : nullptr;
    g.act = act;
    gemm(g, w, pool);
  });
  return y;
}

// Pre-norm block: t + proj(attention(norm1 t)), then + fc2(gelu(fc1(norm2 t))).
int DepthAnythingNet::Impl::add_block(Plan& p, const Block& b, int t, int tokens) const {
  const int a = add_layer_norm(p, t, tokens, b.norm1_w, b.norm1_b);
  const int qkv = add_linear(p, a, tokens, b.qkv, {}, -1);
  const int att = p.produce(tokens, 1, d.dim);
  p.consume(qkv);
  const float scale = float(1.0 / std::sqrt(double(d.dim / d.heads)));
  p.push([this, qkv, att, tokens, scale](Plan& pl, ThreadPool& pool) {
    self_attention(pl.data(qkv), tokens, d.dim, d.heads, scale, pl.data(att), d.dim, pool, *table);
  });
  const int t2 = add_linear(p, att, tokens, b.proj, {}, t);
  const int a2 = add_layer_norm(p, t2, tokens, b.norm2_w, b.norm2_b);
  const int hidden = add_linear(p, a2, tokens, b.fc1, {Activation::GELU}, -1);
  return add_linear(p, hidden, tokens, b.fc2, {}, t2);
}

// A convolution of the h x w map x (its data `offset` floats into the value: a token map
// without its class token), with the residual value added when given.
int DepthAnythingNet::Impl::add_conv(Plan& p, const Conv2d& conv, int x, int h, int w, int residual,
                                     int offset) const {
  const ConvParams& cp = conv.params();
  const int y = p.produce(cp.out_h(h), cp.out_w(w), cp.out_c);
  p.consume(x);
  if (residual >= 0) p.consume(residual);
  p.push([&conv, x, y, h, w, residual, offset](Plan& pl, ThreadPool& pool) {
    conv.run(pl.data(x) + offset, h, w, pl.data(y), residual >= 0 ? pl.data(residual) : nullptr, pool);
  });
  return y;
}

// x + conv2(relu(conv1(relu(x)))).
int DepthAnythingNet::Impl::add_unit(Plan& p, const ResidualUnit& u, int x, int h, int w) const {
  const int c = p.value(x).c;
  const int rx = p.produce(h, w, c);
  p.consume(x);
  p.push([this, x, rx, h, w, c](Plan& pl, ThreadPool& pool) {
    const int64_t n = int64_t(h) * w * c;
    std::copy(pl.data(x), pl.data(x) + n, pl.data(rx));
    activate(pl.data(rx), n, {Activation::ReLU}, pool, *table);
  });
  const int c1 = add_conv(p, u.conv1, rx, h, w);
  return add_conv(p, u.conv2, c1, h, w, x);
}

int DepthAnythingNet::Impl::add_resize(Plan& p, int x, int h, int w, ImageSize to) const {
  const int c = p.value(x).c;
  const int y = p.produce(to.height, to.width, c);
  p.consume(x);
  p.push([this, x, y, h, w, c, to](Plan& pl, ThreadPool& pool) {
    resize_bilinear_corners(pl.data(x), h, w, c, to.height, to.width, pl.data(y), pool, *table);
  });
  return y;
}

// DPT fusion: (x + unit1(skip) when there is a skip), unit2, bilinear resize, 1x1 conv.
// The 1x1 convolution runs before the resize instead, on a quarter of the pixels: both
// are linear, and the resize's weights sum to one so the bias passes through, so the
// order changes only the rounding (the fixtures hold either within 1e-4 of the range).
// ViT-S at 518 x 518, 2 threads: the finest block's resize and 1x1 conv 2.4 -> 0.85 ms.
int DepthAnythingNet::Impl::add_fusion(Plan& p, const Fusion& fu, int x, int skip, int h, int w,
                                       ImageSize to) const {
  if (skip >= 0) {
    const int refined = add_unit(p, fu.skip_unit, skip, h, w);
    const int sum = p.produce(h, w, d.features);
    p.consume(x);
    p.consume(refined);
    const int64_t n = int64_t(h) * w * d.features;
    p.push([this, x, refined, sum, n](Plan& pl, ThreadPool& pool) {
      add(pl.data(x), pl.data(refined), n, pl.data(sum), {}, pool, *table);
    });
    x = sum;
  }
  x = add_unit(p, fu.unit, x, h, w);
  x = add_conv(p, fu.out_conv, x, h, w);
  return add_resize(p, x, h, w, to);
}

// The head at the working size: the fine map resized bilinearly to it, a 3x3 convolution
// with ReLU, a 1x1 convolution to one channel with ReLU (the final one too). Run in bands
// of kOutputBand rows, each thread a band at a time, so the two working-size maps of
// head_hidden channels (34 MB each for ViT-S at 518 x 518) only ever exist a band at a
// time, in the thread's cache, instead of crossing memory twice.
int DepthAnythingNet::Impl::add_output_head(Plan& p, int x, ImageSize fine, ImageSize shape) const {
  const int y = p.produce(shape.height, shape.width, 1);
  p.consume(x);
  p.push([this, x, y, fine, shape](Plan& pl, ThreadPool& pool) {
    const int height = shape.height, width = shape.width, c = d.features / 2;
    const int bands = (height + kOutputBand - 1) / kOutputBand;
    pool.parallel_for(bands, 1, [&](int64_t b0, int64_t b1) {  // the ops inside run on this thread
      std::vector<float> resized(size_t(kOutputBand + 2) * width * c), hidden(size_t(kOutputBand) * width * d.head_hidden);
      for (int64_t b = b0; b < b1; ++b) {
        const int y0 = int(b) * kOutputBand, y1 = std::min(height, y0 + kOutputBand);
        const int r0 = std::max(0, y0 - 1), r1 = std::min(height, y1 + 1);  // a row of context each side
        resize_bilinear_corners_rows(pl.data(x), fine.height, fine.width, c, height, width, r0, r1, resized.data(),
                                     pool, *table);
        head_hidden.for_band(y0 == 0, y1 == height).run(resized.data(), r1 - r0, width, hidden.data(), nullptr, pool);
        head_out.run(hidden.data(), y1 - y0, width, pl.data(y) + int64_t(y0) * width, nullptr, pool);
      }
    });
  });
  return y;
}

std::unique_ptr<Plan> DepthAnythingNet::Impl::build_plan(ImageSize shape) {
  auto p = std::make_unique<Plan>();
  const int rows = shape.height / d.patch, cols = shape.width / d.patch;
  const int tokens = 1 + rows * cols, dim = d.dim;
  // The position embedding for this grid, with the class token's vector folded into its
  // row 0: the embedding step adds it as the GEMM's residual.
  auto pos = std::make_shared<std::vector<float>>(
      interpolate_pos_embed(this->pos.f32(), d.pos_grid, dim, rows, cols, d.pos_offset));
  for (int j = 0; j < dim; ++j) (*pos)[j] += cls.f32()[j];

  const int img = add_input(*p, shape);
  int t = p->produce(tokens, 1, dim);
  p->consume(img);
  p->push([this, img, t, shape, pos, dim](Plan& pl, ThreadPool& pool) {
    float* x = pl.data(t);
    std::copy(pos->begin(), pos->begin() + dim, x);
    patch.run(pl.data(img), shape.height, shape.width, x + dim, dim, pos->data() + dim, pool);
  });
  std::vector<int> taps;
  for (size_t i = 0; i < blocks.size(); ++i) {
    t = add_block(*p, blocks[i], t, tokens);
    if (std::find(d.layers.begin(), d.layers.end(), int(i)) != d.layers.end())
      taps.push_back(add_layer_norm(*p, t, tokens, norm_w, norm_b));
  }

  // The pyramid: 4x, 2x, 1x and 1/2x the patch grid, `features` channels each.
  std::vector<int> level(kTaps);
  std::vector<ImageSize> size(kTaps);
  for (int k = 0; k < kTaps; ++k) {
    int x = add_conv(*p, project[k], taps[k], rows, cols, -1, dim);  // the class token's row skipped
    int h = rows, w = cols;
    const int c = d.out_channels[k];
    if (k == 0 || k == 1) {
      const StridedTransposedConv& up = k == 0 ? upsample4 : upsample2;
      const int y = p->produce(h * up.stride(), w * up.stride(), c);
      p->consume(x);
      p->push([&up, x, y, h, w](Plan& pl, ThreadPool& pool) { up.run(pl.data(x), h, w, pl.data(y), pool); });
      x = y;
      h *= up.stride();
      w *= up.stride();
    } else if (k == 3) {
      x = add_conv(*p, downsample, x, h, w);
      h = downsample.params().out_h(h);
      w = downsample.params().out_w(w);
    }
    level[k] = add_conv(*p, layer_rn[k], x, h, w);
    size[k] = {h, w};
  }
  int x = add_fusion(*p, fusion[3], level[3], -1, size[3].height, size[3].width, size[2]);
  for (int k = 2; k >= 0; --k) {
    const ImageSize to = k > 0 ? size[k - 1] : ImageSize{2 * size[0].height, 2 * size[0].width};
    x = add_fusion(*p, fusion[k], x, level[k], size[k].height, size[k].width, to);
  }
  const ImageSize fine{2 * size[0].height, 2 * size[0].width};
  x = add_conv(*p, output_conv1, x, fine.height, fine.width);
  plan_output = add_output_head(*p, x, fine, shape);
  p->allocate("depth network (Depth Anything V2 " + variant + ") at " + std::to_string(shape.width) + "x" +
              std::to_string(shape.height));
  return p;
}

Tensor DepthAnythingNet::run(const float* rgb, int h, int w, ThreadPool& pool) {
  if (!rgb || h <= 0 || w <= 0) throw std::invalid_argument("DepthAnythingNet::run: empty image");
  Impl& m = *impl_;
  const ImageSize shape = dav2_working_shape(h, w, m.working_size, m.d.patch);
  if (!m.plan || m.plan_shape.height != shape.height || m.plan_shape.width != shape.width) {
    m.plan.reset();  // its arena goes before the next one is allocated
    m.plan = m.build_plan(shape);
    m.plan_shape = shape;
  }
  m.rgb = rgb;
  m.rgb_h = h;
  m.rgb_w = w;
  m.plan->execute(pool);
  Tensor out = Tensor::empty({h, w});
  resize_bilinear_corners(m.plan->data(m.plan_output), shape.height, shape.width, 1, h, w, out.f32(), pool,
                          *m.table);
  return out;
}

DepthAnythingNet::DepthAnythingNet(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DepthAnythingNet::DepthAnythingNet(DepthAnythingNet&&) noexcept = default;
DepthAnythingNet& DepthAnythingNet::operator=(DepthAnythingNet&&) noexcept = default;
DepthAnythingNet::~DepthAnythingNet() = default;

const std::string& DepthAnythingNet::architecture() const {
  static const std::string name = arch::kDepthDinoV2Dpt;
  return name;
}
const std::string& DepthAnythingNet::variant() const { return impl_->variant; }
int DepthAnythingNet::working_size() const { return impl_->working_size; }
void DepthAnythingNet::set_working_size(int size) {
  if (size < impl_->d.patch || size > kMaxWorkingSize)
    throw std::invalid_argument("working size " + std::to_string(size) + " is not in " +
                                std::to_string(impl_->d.patch) + ".." + std::to_string(kMaxWorkingSize));
  impl_->working_size = size;
}
int DepthAnythingNet::multiple() const { return impl_->d.patch; }
int64_t DepthAnythingNet::parameter_count() const { return impl_->params; }
size_t DepthAnythingNet::arena_bytes() const { return impl_->plan ? impl_->plan->arena_bytes() : 0; }

}  // namespace ampi
