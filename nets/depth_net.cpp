#include "nets/depth_net.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <stdexcept>

#include "kernels/conv.h"
#include "kernels/inverted_residual.h"
#include "kernels/ops.h"
#include "nets/architectures.h"
#include "nets/plan.h"
#include "weights_format/weight_file.h"

namespace ampi {
namespace {

constexpr int64_t kFormatVersion = 1;
constexpr int kFieldsPerBlock = 6;  // kind, out, expanded, kernel, se_reduced, activation
constexpr int kMaxLevels = 8;
constexpr int kDefaultWorkingLongSide = 1024;
constexpr int kMaxWorkingSize = 16384;

enum class BlockKind { Conv = 0, MobileNetV3 = 1 };

struct BlockSpec {
  BlockKind kind;
  int out_c, expanded, kernel, se_reduced;
  Activation act;
};

// One block with its weights packed. A plain block uses `conv` only; a MobileNetV3 block
// uses expand (absent when expanded == in_c), dw, se (when se_reduced > 0) and project;
// without squeeze-excite the three convolutions run as one op (`fused`).
struct Block {
  BlockSpec spec;
  int in_c = 0;
  Conv2d conv, expand, dw, project;
  bool has_expand = false, has_se = false, residual = false;
  SqueezeExcite se;
  std::optional<InvertedResidual> fused;
};

using Stage = std::vector<Block>;

// The network's input step: the caller's rgb_h x rgb_w image normalised per channel,
// its last row and column replicated out to h x w (so the network sees no artificial
// edge), then one Haar DWT with haar_dwt's arithmetic, into out [h/2][w/2][12]. One
// pass: the normalised full-resolution image is never stored, and its three channels
// never go through a vector kernel that would fill 3 lanes.
void normalise_and_dwt(const float* rgb, int rgb_h, int rgb_w, int h, int w, const float* mean,
                       const float* inv_std, float* out, ThreadPool& pool) {
  const int out_w = w / 2;
  pool.parallel_for(h / 2, 4, [&](int64_t y0, int64_t y1) {
    for (int64_t y = y0; y < y1; ++y) {
      const float* top = rgb + std::min<int64_t>(2 * y, rgb_h - 1) * rgb_w * 3;
      const float* bottom = rgb + std::min<int64_t>(2 * y + 1, rgb_h - 1) * rgb_w * 3;
      float* dst = out + y * out_w * 12;
      for (int x = 0; x < out_w; ++x, dst += 12) {
        const int left = std::min(2 * x, rgb_w - 1) * 3, right = std::min(2 * x + 1, rgb_w - 1) * 3;
        for (int j = 0; j < 3; ++j) {
          const auto at = [&](const float* row, int column) { return (row[column + j] - mean[j]) * inv_std[j]; };
          const float x00 = at(top, left), x01 = at(top, right), x10 = at(bottom, left), x11 = at(bottom, right);
          const float top_sum = x00 + x01, top_diff = x00 - x01;
          const float bottom_sum = x10 + x11, bottom_diff = x10 - x11;
          dst[j] = (top_sum + bottom_sum) * 0.5f;
          dst[3 + j] = (top_diff + bottom_diff) * 0.5f;
          dst[6 + j] = (top_sum - bottom_sum) * 0.5f;
          dst[9 + j] = (top_diff - bottom_diff) * 0.5f;
        }
      }
    }
  });
}

[[noreturn]] void fail(const WeightFile& f, const std::string& problem) {
  throw std::runtime_error(f.path() + ": " + problem);
}

Activation activation_from_code(const WeightFile& f, const std::string& where, int64_t code) {
  switch (code) {
    case 0: return Activation::None;
    case 1: return Activation::ReLU;
    case 2: return Activation::HardSwish;
  }
  fail(f, where + ": unknown activation code " + std::to_string(code));
}

std::vector<BlockSpec> parse_stage(const WeightFile& f, const std::string& key) {
  const std::vector<int64_t> v = f.get_ints(key);
  if (v.empty() || v.size() % kFieldsPerBlock)
    fail(f, key + ": " + std::to_string(v.size()) + " values, not a non-empty multiple of " +
                std::to_string(kFieldsPerBlock));
  std::vector<BlockSpec> specs;
  for (size_t i = 0; i < v.size(); i += kFieldsPerBlock) {
    const std::string where = key + " block " + std::to_string(i / kFieldsPerBlock);
    if (v[i] != 0 && v[i] != 1) fail(f, where + ": unknown block kind " + std::to_string(v[i]));
    const auto kind = static_cast<BlockKind>(v[i]);
    const int64_t out_c = v[i + 1], expanded = v[i + 2], kernel = v[i + 3], reduced = v[i + 4];
    if (out_c <= 0 || out_c > 65536) fail(f, where + ": bad output channel count " + std::to_string(out_c));
    if (kernel <= 0 || kernel % 2 == 0 || kernel > 15) fail(f, where + ": kernel " + std::to_string(kernel) + " is not odd in 1..15");
    if (kind == BlockKind::MobileNetV3 && (expanded <= 0 || expanded > 65536))
      fail(f, where + ": bad expanded channel count " + std::to_string(expanded));
    if (reduced < 0 || reduced > 65536 || (reduced > 0 && kind != BlockKind::MobileNetV3))
      fail(f, where + ": bad squeeze-excite width " + std::to_string(reduced));
    specs.push_back({kind, int(out_c), int(expanded), int(kernel), int(reduced),
                     activation_from_code(f, where, v[i + 5])});
  }
  return specs;
}

// A stride-1 convolution with 'same' padding, weights checked by name and packed.
Conv2d load_conv(const WeightFile& f, const std::string& name, int in_c, int out_c, int kernel,
                 int groups, Activation act, const KernelTable& table, int64_t& params) {
  const Tensor w = f.tensor(name + ".weight", {out_c, kernel, kernel, in_c / groups});
  const Tensor b = f.tensor(name + ".bias", {out_c});
  params += w.numel() + b.numel();
  ConvParams p;
  p.in_c = in_c;
  p.out_c = out_c;
  p.kernel_h = p.kernel_w = kernel;
  p.pad_top = p.pad_left = p.pad_bottom = p.pad_right = kernel / 2;
  p.groups = groups;
  p.act = {act};
  return Conv2d(p, w.f32(), b.f32(), table);
}

Block load_block(const WeightFile& f, const std::string& prefix, const BlockSpec& s, int in_c,
                 const KernelTable& table, int64_t& params) {
  Block b;
  b.spec = s;
  b.in_c = in_c;
  if (s.kind == BlockKind::Conv) {
    b.conv = load_conv(f, prefix + ".conv", in_c, s.out_c, s.kernel, 1, s.act, table, params);
    return b;
  }
  b.has_expand = s.expanded != in_c;
  if (b.has_expand)
    b.expand = load_conv(f, prefix + ".expand", in_c, s.expanded, 1, 1, s.act, table, params);
  b.dw = load_conv(f, prefix + ".dw", s.expanded, s.expanded, s.kernel, s.expanded, s.act, table, params);
  b.has_se = s.se_reduced > 0;
  if (b.has_se) {
    const Tensor w1 = f.tensor(prefix + ".se.fc1.weight", {s.se_reduced, s.expanded});
    const Tensor b1 = f.tensor(prefix + ".se.fc1.bias", {s.se_reduced});
    const Tensor w2 = f.tensor(prefix + ".se.fc2.weight", {s.expanded, s.se_reduced});
    const Tensor b2 = f.tensor(prefix + ".se.fc2.bias", {s.expanded});
    params += w1.numel() + b1.numel() + w2.numel() + b2.numel();
    b.se = SqueezeExcite(s.expanded, s.se_reduced, w1.f32(), b1.f32(), w2.f32(), b2.f32(), table);
  }
  b.project = load_conv(f, prefix + ".project", s.expanded, s.out_c, 1, 1, Activation::None, table, params);
  b.residual = in_c == s.out_c;
  if (!b.has_se)  // with squeeze-excite the projection waits for the whole depthwise output
    b.fused.emplace(b.has_expand ? std::optional<Conv2d>(b.expand) : std::nullopt, b.dw, b.project);
  return b;
}

Stage load_stage(const WeightFile& f, const std::string& key, const std::string& prefix, int in_c,
                 const KernelTable& table, int64_t& params) {
  Stage stage;
  for (const BlockSpec& s : parse_stage(f, key)) {
    stage.push_back(load_block(f, prefix + "." + std::to_string(stage.size()), s, in_c, table, params));
    in_c = s.out_c;
  }
  return stage;
}

int out_channels(const Stage& s) { return s.back().spec.out_c; }

}  // namespace

struct DepthNet::Impl {
  std::string variant;
  int levels = 0;
  int working_long_side = kDefaultWorkingLongSide;
  float mean[3], inv_std[3];
  std::vector<Stage> encoder, decoder;  // decoder[l] works at level l + 1
  Conv2d head;                          // on decoder level 1: the Haar coefficients of the output
  int64_t params = 0;
  const KernelTable* table = nullptr;
  std::unique_ptr<Plan> plan;
  int plan_h = 0, plan_w = 0;
  int plan_output = -1;  // the value holding the padded full-resolution disparity
  // What the plan's first step reads: the caller's image, set before every execute().
  const float* rgb = nullptr;
  int rgb_h = 0, rgb_w = 0;

  int multiple() const { return 1 << levels; }
  std::unique_ptr<Plan> build_plan(int h, int w);  // sets plan_output
  int add_stage(Plan& p, const Stage& stage, int x, int h, int w) const;
  int add_block(Plan& p, const Block& b, int x, int h, int w) const;
  // Block b on the channel concatenation of the maps up and skip (a decoder's first block).
  int add_concat_block(Plan& p, const Block& b, int up, int skip, int h, int w) const;
};

// Checks everything the metadata promises before any weight is packed.
DepthNet DepthNet::from_file(const WeightFile& f, const KernelTable& table) {
  if (f.get_string("arch") != arch::kDepthDwtMobileNetV3)
    fail(f, "architecture '" + f.get_string("arch") + "' is not " + arch::kDepthDwtMobileNetV3);
  if (f.get_int("depth.format_version") != kFormatVersion)
    fail(f, "depth.format_version " + std::to_string(f.get_int("depth.format_version")) +
                " is not supported (this build reads " + std::to_string(kFormatVersion) + ")");
  auto impl = std::make_unique<Impl>();
  impl->table = &table;
  impl->variant = f.get_string("depth.variant");
  const int64_t levels = f.get_int("depth.levels");
  if (levels < 2 || levels > kMaxLevels) fail(f, "depth.levels " + std::to_string(levels) + " is not in 2..8");
  impl->levels = int(levels);
  if (f.get_int("depth.multiple") != impl->multiple())
    fail(f, "depth.multiple disagrees with 2^depth.levels");
  if (f.has("depth.working_long_side")) {
    const int64_t side = f.get_int("depth.working_long_side");
    if (side < impl->multiple() || side > kMaxWorkingSize)
      fail(f, "depth.working_long_side " + std::to_string(side) + " is not in " +
                  std::to_string(impl->multiple()) + "..16384");
    impl->working_long_side = int(side);
  }
  const std::vector<double> mean = f.get_floats("depth.input_mean"), stdev = f.get_floats("depth.input_std");
  if (mean.size() != 3 || stdev.size() != 3) fail(f, "depth.input_mean and depth.input_std need 3 values");
  for (int c = 0; c < 3; ++c) {
    if (!(stdev[c] > 0)) fail(f, "depth.input_std must be positive");
    impl->mean[c] = float(mean[c]);
    impl->inv_std[c] = float(1.0 / stdev[c]);
  }

  std::vector<int> enc_c;
  int in_c = 3;
  for (int l = 1; l <= impl->levels; ++l) {
    const std::string n = std::to_string(l);
    impl->encoder.push_back(load_stage(f, "depth.encoder." + n, "enc" + n, 4 * in_c, table, impl->params));
    in_c = out_channels(impl->encoder.back());
    enc_c.push_back(in_c);
  }
  impl->decoder.resize(impl->levels - 1);
  int below = enc_c.back();
  for (int l = impl->levels - 1; l >= 1; --l) {
    if (below % 4) fail(f, "level " + std::to_string(l + 1) + " has " + std::to_string(below) +
                               " channels, not a multiple of 4 for the inverse DWT");
    const std::string n = std::to_string(l);
    impl->decoder[l - 1] = load_stage(f, "depth.decoder." + n, "dec" + n, below / 4 + enc_c[l - 1], table, impl->params);
    below = out_channels(impl->decoder[l - 1]);
  }
  const int64_t head_kernel = f.get_int("depth.head_kernel");
  if (head_kernel <= 0 || head_kernel % 2 == 0 || head_kernel > 15) fail(f, "depth.head_kernel must be odd in 1..15");
  impl->head = load_conv(f, "head1", below, 4, int(head_kernel), 1, Activation::None, table, impl->params);
  return DepthNet(std::move(impl));
}

int DepthNet::Impl::add_block(Plan& p, const Block& b, int x, int h, int w) const {
  if (b.spec.kind == BlockKind::Conv) {
    const int y = p.produce(h, w, b.spec.out_c);
    p.consume(x);
    p.push([&b, x, y, h, w](Plan& pl, ThreadPool& pool) { b.conv.run(pl.data(x), h, w, pl.data(y), nullptr, pool); });
    return y;
  }
  if (b.fused) {
    const int y = p.produce(h, w, b.spec.out_c);
    p.consume(x);
    p.push([&b, x, y, h, w](Plan& pl, ThreadPool& pool) {
      b.fused->run(pl.data(x), h, w, pl.data(y), b.residual ? pl.data(x) : nullptr, pool);
    });
    return y;
  }
  int t = x;
  if (b.has_expand) {
    const int e = p.produce(h, w, b.spec.expanded);
    p.consume(t);
    p.push([&b, t, e, h, w](Plan& pl, ThreadPool& pool) { b.expand.run(pl.data(t), h, w, pl.data(e), nullptr, pool); });
    t = e;
  }
  const int d = p.produce(h, w, b.spec.expanded);
  p.consume(t);
  p.push([&b, t, d, h, w](Plan& pl, ThreadPool& pool) { b.dw.run(pl.data(t), h, w, pl.data(d), nullptr, pool); });
  t = d;
  // Only blocks with squeeze-excite get here (the others are fused). Its gate scales the
  // depthwise output's channels, which the projection folds into its weights.
  auto gate = std::make_shared<std::vector<float>>();
  p.consume(t);
  p.push([&b, t, h, w, gate](Plan& pl, ThreadPool& pool) { *gate = b.se.gate(pl.data(t), h, w, pool); });
  const int y = p.produce(h, w, b.spec.out_c);
  p.consume(t);
  if (b.residual) p.consume(x);
  const bool residual = b.residual;
  p.push([&b, t, x, y, h, w, residual, gate](Plan& pl, ThreadPool& pool) {
    b.project.run_scaled_input(pl.data(t), h, w, gate->data(), pl.data(y), residual ? pl.data(x) : nullptr, pool);
  });
  return y;
}

int DepthNet::Impl::add_concat_block(Plan& p, const Block& b, int up, int skip, int h, int w) const {
  const int up_c = p.value(up).c, skip_c = p.value(skip).c;
  if (!b.fused) {  // the concatenated map, then the block on it
    const int cat = p.produce(h, w, up_c + skip_c);
    p.consume(up);
    p.consume(skip);
    const int64_t pixels = int64_t(h) * w;
    p.push([this, up, skip, cat, up_c, skip_c, pixels](Plan& pl, ThreadPool& pool) {
      concat_channels(pl.data(up), up_c, pl.data(skip), skip_c, pixels, pl.data(cat), pool, *table);
    });
    return add_block(p, b, cat, h, w);
  }
  // A fused block concatenates the rows it expands itself: the concatenated map (the
  // widest map of the level, read back at once) is never written.
  const int y = p.produce(h, w, b.spec.out_c);
  p.consume(up);
  p.consume(skip);
  p.push([&b, up, skip, y, up_c, skip_c, h, w](Plan& pl, ThreadPool& pool) {
    b.fused->run_concat(pl.data(up), up_c, pl.data(skip), skip_c, h, w, pl.data(y), b.residual, pool);
  });
  return y;
}

int DepthNet::Impl::add_stage(Plan& p, const Stage& stage, int x, int h, int w) const {
  for (const Block& b : stage) x = add_block(p, b, x, h, w);
  return x;
}

std::unique_ptr<Plan> DepthNet::Impl::build_plan(int h, int w) {
  auto p = std::make_unique<Plan>();
  const KernelTable& k = *table;
  // The encoder: per stage a Haar DWT, then its blocks. The first DWT reads the caller's
  // image itself (normalise_and_dwt); until then there is no map x.
  int c = 3, lh = h, lw = w;
  int x = -1;
  std::vector<int> skips;
  for (const Stage& stage : encoder) {
    const int d = p->produce(lh / 2, lw / 2, 4 * c);
    if (x < 0) {
      p->push([this, d, h, w](Plan& pl, ThreadPool& pool) {
        normalise_and_dwt(rgb, rgb_h, rgb_w, h, w, mean, inv_std, pl.data(d), pool);
      });
    } else {
      p->consume(x);
      p->push([&k, x, d, lh, lw, c](Plan& pl, ThreadPool& pool) { haar_dwt(pl.data(x), lh, lw, c, pl.data(d), pool, k); });
    }
    lh /= 2;
    lw /= 2;
    x = add_stage(*p, stage, d, lh, lw);
    c = out_channels(stage);
    skips.push_back(x);
  }
  for (int l = levels - 1; l >= 1; --l) {
    const int skip = skips[l - 1], up_c = c / 4;
    const int u = p->produce(2 * lh, 2 * lw, up_c);
    p->consume(x);
    p->push([&k, x, u, lh, lw, up_c](Plan& pl, ThreadPool& pool) { haar_idwt(pl.data(x), lh, lw, up_c, pl.data(u), pool, k); });
    lh *= 2;
    lw *= 2;
    const Stage& stage = decoder[l - 1];
    x = add_concat_block(*p, stage.front(), u, skip, lh, lw);
    for (size_t i = 1; i < stage.size(); ++i) x = add_block(*p, stage[i], x, lh, lw);
    c = out_channels(stage);
  }
  const int coeffs = p->produce(lh, lw, 4);
  p->consume(x);
  p->push([this, x, coeffs, lh, lw](Plan& pl, ThreadPool& pool) { head.run(pl.data(x), lh, lw, pl.data(coeffs), nullptr, pool); });
  const int out = p->produce(h, w, 1);
  p->consume(coeffs);
  p->push([&k, coeffs, out, lh, lw](Plan& pl, ThreadPool& pool) { haar_idwt(pl.data(coeffs), lh, lw, 1, pl.data(out), pool, k); });
  plan_output = out;
  p->allocate("depth network (" + variant + ") at " + std::to_string(w) + "x" + std::to_string(h));
  return p;
}

Tensor DepthNet::run(const float* rgb, int h, int w, ThreadPool& pool) {
  if (!rgb || h <= 0 || w <= 0) throw std::invalid_argument("DepthNet::run: empty image");
  Impl& m = *impl_;
  const int ph = (h + m.multiple() - 1) / m.multiple() * m.multiple();
  const int pw = (w + m.multiple() - 1) / m.multiple() * m.multiple();
  if (!m.plan || m.plan_h != ph || m.plan_w != pw) {
    m.plan = m.build_plan(ph, pw);
    m.plan_h = ph;
    m.plan_w = pw;
  }
  m.rgb = rgb;
  m.rgb_h = h;
  m.rgb_w = w;
  m.plan->execute(pool);
  const float* full = m.plan->data(m.plan_output);  // crop the padding away
  Tensor out = Tensor::empty({h, w});
  for (int y = 0; y < h; ++y) std::copy(full + size_t(y) * pw, full + size_t(y) * pw + w, out.f32() + size_t(y) * w);
  return out;
}

DepthNet::DepthNet(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DepthNet::DepthNet(DepthNet&&) noexcept = default;
DepthNet& DepthNet::operator=(DepthNet&&) noexcept = default;
DepthNet::~DepthNet() = default;

const std::string& DepthNet::architecture() const {
  static const std::string name = arch::kDepthDwtMobileNetV3;
  return name;
}
const std::string& DepthNet::variant() const { return impl_->variant; }
int DepthNet::multiple() const { return impl_->multiple(); }
int DepthNet::working_size() const { return impl_->working_long_side; }
void DepthNet::set_working_size(int size) {
  if (size < 1 || size > kMaxWorkingSize)  // any size: run() pads to the multiple
    throw std::invalid_argument("working size " + std::to_string(size) + " is not in 1.." +
                                std::to_string(kMaxWorkingSize));
  impl_->working_long_side = size;
}
ImageSize DepthNet::input_size(int height, int width) const {
  return depth_working_size(height, width, impl_->working_long_side);
}
int64_t DepthNet::parameter_count() const { return impl_->params; }
size_t DepthNet::arena_bytes() const { return impl_->plan ? impl_->plan->arena_bytes() : 0; }

}  // namespace ampi
