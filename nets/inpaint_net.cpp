#include "nets/inpaint_net.h"

#include <sstream>
#include <stdexcept>

#include "kernels/ops.h"
#include "nets/architectures.h"

namespace ampi {
namespace {

constexpr int64_t kPlainVersion = 1;     // hole zeroed, output = tanh(last)
constexpr int64_t kResidualVersion = 2;  // hole pre-filled (inpaint.prefill), output = rgb + hole * tanh(last)

[[noreturn]] void fail(const WeightFile& f, const std::string& problem) {
  throw std::runtime_error(f.path() + ": " + problem);
}

std::vector<std::string> split_names(const std::string& joined) {
  std::vector<std::string> names;
  std::stringstream in(joined);
  for (std::string name; std::getline(in, name, ',');) names.push_back(name);
  return names;
}

// PyTorch's default parameter for the activations that take one.
ActivationSpec activation_from_name(const WeightFile& f, const std::string& key) {
  const std::string name = f.get_string(key);
  try {
    const Activation kind = parse_activation(name.c_str());
    const float alpha = kind == Activation::ELU ? 1.0f : kind == Activation::LeakyReLU ? 0.01f : 0.0f;
    return {kind, alpha};
  } catch (const std::invalid_argument&) {
    fail(f, key + ": unknown activation '" + name + "'");
  }
}

// Far above any real layer's channels, kernel or dilation, and small enough that the int
// arithmetic on them (padding = dilation * (kernel - 1) / 2, summed and gated channel
// counts) cannot overflow whatever a damaged file holds.
constexpr int64_t kMaxGraphValue = 1 << 14;

// The graph as written by training/export_inpaint.py: one entry per layer in each array.
std::vector<InpaintLayer> read_graph(const WeightFile& f) {
  static const char* const kArrays[] = {"source", "upsample", "skip", "in_channels", "out_channels",
                                        "kernel", "stride", "dilation", "gated"};
  std::vector<std::vector<int64_t>> cols;
  for (const char* a : kArrays) cols.push_back(f.get_ints(std::string("inpaint.") + a));
  const std::vector<std::string> names = split_names(f.get_string("inpaint.layer_names"));
  const size_t n = names.size();
  for (size_t a = 0; a < cols.size(); ++a)
    if (cols[a].size() != n)
      fail(f, std::string("inpaint.") + kArrays[a] + " has " + std::to_string(cols[a].size()) +
                  " entries for " + std::to_string(n) + " layers");
  for (size_t a = 0; a < cols.size(); ++a)
    for (int64_t v : cols[a])
      if (v < InpaintLayer::kNoSkip || v > kMaxGraphValue)
        fail(f, std::string("inpaint.") + kArrays[a] + " holds " + std::to_string(v) + ", outside " +
                    std::to_string(InpaintLayer::kNoSkip) + ".." + std::to_string(kMaxGraphValue));
  std::vector<InpaintLayer> layers(n);
  for (size_t i = 0; i < n; ++i) {
    InpaintLayer& l = layers[i];
    l.name = names[i];
    l.source = int(cols[0][i]);
    l.upsample = cols[1][i] != 0;
    l.skip = int(cols[2][i]);
    l.in_c = int(cols[3][i]);
    l.out_c = int(cols[4][i]);
    l.kernel = int(cols[5][i]);
    l.stride = int(cols[6][i]);
    l.dilation = int(cols[7][i]);
    l.gated = cols[8][i] != 0;
  }
  return layers;
}

Prefill prefill_from_name(const WeightFile& f) {
  const std::string name = f.get_string("inpaint.prefill");
  if (name == "push-pull") return Prefill::PushPull;
  if (name == "harmonic") return Prefill::Harmonic;
  fail(f, "inpaint.prefill '" + name + "' is not 'push-pull' or 'harmonic'");
}

bool refers_back(int ref, size_t i, bool may_be_none) {
  return ref == InpaintLayer::kInput || (may_be_none && ref == InpaintLayer::kNoSkip) ||
         (ref >= 0 && size_t(ref) < i);
}

// Fills scale_log2 and checks what run() relies on: references to earlier layers, channel
// counts that add up, matching resolutions, a plain full-resolution output layer.
void check_graph(const WeightFile& f, std::vector<InpaintLayer>& layers, int multiple) {
  if (layers.empty()) fail(f, "the inpainting graph has no layer");
  for (size_t i = 0; i < layers.size(); ++i) {
    InpaintLayer& l = layers[i];
    const std::string where = "layer " + l.name + ": ";
    if (!refers_back(l.source, i, false)) fail(f, where + "source is not an earlier layer");
    if (!refers_back(l.skip, i, true)) fail(f, where + "skip is not an earlier layer");
    if (l.kernel < 1 || l.kernel % 2 == 0 || (l.stride != 1 && l.stride != 2) || l.dilation < 1 ||
        l.out_c < 1)
      fail(f, where + "needs an odd kernel, stride 1 or 2, dilation >= 1 and outputs");
    const auto channels = [&](int ref) { return ref == InpaintLayer::kInput ? InpaintNet::kInChannels : layers[ref].out_c; };
    const auto scale = [&](int ref) { return ref == InpaintLayer::kInput ? 0 : layers[ref].scale_log2; };
    int in_c = channels(l.source);
    const int in_scale = scale(l.source) - (l.upsample ? 1 : 0);
    if (in_scale < 0) fail(f, where + "up-samples beyond the input's resolution");
    if (l.skip != InpaintLayer::kNoSkip) {
      if (scale(l.skip) != in_scale) fail(f, where + "skip has another resolution");
      in_c += channels(l.skip);
    }
    if (in_c != l.in_c)
      fail(f, where + "in_channels is " + std::to_string(l.in_c) + " but its inputs have " + std::to_string(in_c));
    l.scale_log2 = in_scale + (l.stride == 2 ? 1 : 0);
    if ((1 << l.scale_log2) > multiple) fail(f, where + "down-scales by more than inpaint.multiple");
  }
  const InpaintLayer& last = layers.back();
  if (last.gated || last.scale_log2 != 0 || last.out_c != InpaintNet::kOutChannels)
    fail(f, "the last layer must be a plain convolution to 3 channels at full resolution");
}

ConvParams conv_params(const InpaintLayer& l, ActivationSpec act) {
  ConvParams p;
  p.in_c = l.in_c;
  p.out_c = l.gated ? 2 * l.out_c : l.out_c;
  p.kernel_h = p.kernel_w = l.kernel;
  p.stride_h = p.stride_w = l.stride;
  p.pad_top = p.pad_left = p.pad_bottom = p.pad_right = l.dilation * (l.kernel - 1) / 2;
  p.dilation_h = p.dilation_w = l.dilation;
  p.act = act;
  return p;
}

}  // namespace

InpaintNet InpaintNet::from_file(const WeightFile& f, const KernelTable& k) {
  if (f.get_string("arch") != arch::kInpaintGatedConv)
    fail(f, "architecture '" + f.get_string("arch") + "' is not " + arch::kInpaintGatedConv);
  const int64_t version = f.get_int("inpaint.version");
  if (version != kPlainVersion && version != kResidualVersion)
    fail(f, "inpaint.version " + std::to_string(version) + " is not supported");
  InpaintNet net;
  if (version == kResidualVersion) net.prefill_ = prefill_from_name(f);
  net.k_ = &k;
  net.multiple_ = int(f.get_int("inpaint.multiple"));
  if (net.multiple_ < 1 || net.multiple_ > 64 || (net.multiple_ & (net.multiple_ - 1)))
    fail(f, "inpaint.multiple must be a power of two up to 64");
  net.layers_ = read_graph(f);
  check_graph(f, net.layers_, net.multiple_);
  net.feature_act_ = activation_from_name(f, "inpaint.feature_activation");
  const ActivationSpec output_act = activation_from_name(f, "inpaint.output_activation");
  for (size_t i = 0; i < net.layers_.size(); ++i) {
    const InpaintLayer& l = net.layers_[i];
    const ConvParams p = conv_params(l, l.gated ? ActivationSpec{} : output_act);
    const Tensor w = f.tensor(l.name + ".weight", {p.out_c, l.kernel, l.kernel, l.in_c});
    const Tensor b = f.tensor(l.name + ".bias", {p.out_c});
    net.convs_.emplace_back(p, w.f32(), b.f32(), k);
  }
  return net;
}

double InpaintNet::macs_per_pixel() const {
  double total = 0;
  for (const InpaintLayer& l : layers_)
    total += double(l.kernel) * l.kernel * l.in_c * (l.gated ? 2 : 1) * l.out_c /
             double(1 << (2 * l.scale_log2));
  return total;
}

void InpaintNet::run(const float* rgb, const float* hole, int h, int w, float* out,
                     ThreadPool& pool) const {
  if (h <= 0 || w <= 0 || h % multiple_ || w % multiple_)
    throw std::invalid_argument("inpaint net: input " + std::to_string(h) + "x" + std::to_string(w) +
                                " is not a positive multiple of " + std::to_string(multiple_));
  const int64_t pixels = int64_t(h) * w;
  const bool residual = prefill_ != Prefill::None;
  Plan plan;
  const int input = plan.produce(h, w, kInChannels);
  plan.push([=](Plan& pl, ThreadPool&) {
    float* x = pl.data(input);
    for (int64_t p = 0; p < pixels; ++p) {
      const float keep = residual ? 1.0f : 1.0f - hole[p];
      for (int c = 0; c < 3; ++c) x[p * kInChannels + c] = rgb[p * 3 + c] * keep;
      x[p * kInChannels + 3] = hole[p];
    }
  });
  std::vector<int> outs(layers_.size(), -1);
  for (size_t i = 0; i < layers_.size(); ++i) {
    const InpaintLayer& l = layers_[i];
    const Conv2d& conv = convs_[i];
    const int in = add_layer_input(plan, int(i), outs, input);
    const int in_h = plan.value(in).h, in_w = plan.value(in).w;
    const int out_h = h >> l.scale_log2, out_w = w >> l.scale_log2;
    plan.consume(in);
    if (i + 1 == layers_.size()) {  // check_graph: a plain full-resolution layer
      plan.push([&conv, in, in_h, in_w, out](Plan& pl, ThreadPool& tp) { conv.run(pl.data(in), in_h, in_w, out, nullptr, tp); });
    } else if (l.gated) {
      const int raw = plan.produce(out_h, out_w, 2 * l.out_c);
      plan.push([&conv, in, in_h, in_w, raw](Plan& pl, ThreadPool& tp) { conv.run(pl.data(in), in_h, in_w, pl.data(raw), nullptr, tp); });
      outs[i] = plan.produce(out_h, out_w, l.out_c);
      plan.consume(raw);
      const int64_t out_pixels = int64_t(out_h) * out_w;
      plan.push([this, raw, out_pixels, c = l.out_c, y = outs[i]](Plan& pl, ThreadPool& tp) {
        gated_output(pl.data(raw), out_pixels, c, feature_act_, pl.data(y), tp, *k_);
      });
    } else {
      outs[i] = plan.produce(out_h, out_w, l.out_c);
      plan.push([&conv, in, in_h, in_w, y = outs[i]](Plan& pl, ThreadPool& tp) { conv.run(pl.data(in), in_h, in_w, pl.data(y), nullptr, tp); });
    }
  }
  plan.allocate("inpainting network at " + std::to_string(w) + "x" + std::to_string(h));
  plan.execute(pool);
  if (residual)  // the tanh output is a correction of the pre-filled hole
    for (int64_t p = 0; p < pixels; ++p)
      for (int c = 0; c < 3; ++c) out[p * 3 + c] = rgb[p * 3 + c] + hole[p] * out[p * 3 + c];
}

int InpaintNet::add_layer_input(Plan& plan, int i, const std::vector<int>& outs, int input) const {
  const InpaintLayer& l = layers_[i];
  const auto value_of = [&](int ref) { return ref == InpaintLayer::kInput ? input : outs[ref]; };
  int in = value_of(l.source);
  if (l.upsample) {
    const Plan::Value src = plan.value(in);
    const int up = plan.produce(2 * src.h, 2 * src.w, src.c);
    plan.consume(in);
    plan.push([this, in, up, src](Plan& pl, ThreadPool& tp) {
      resize2x_nearest(pl.data(in), src.h, src.w, src.c, pl.data(up), tp, *k_);
    });
    in = up;
  }
  if (l.skip == InpaintLayer::kNoSkip) return in;
  const int skip = value_of(l.skip);
  const Plan::Value a = plan.value(in), b = plan.value(skip);
  const int cat = plan.produce(a.h, a.w, a.c + b.c);
  plan.consume(in);
  plan.consume(skip);
  plan.push([this, in, skip, cat, a, b](Plan& pl, ThreadPool& tp) {
    concat_channels(pl.data(in), a.c, pl.data(skip), b.c, int64_t(a.h) * a.w, pl.data(cat), tp, *k_);
  });
  return cat;
}

}  // namespace ampi
