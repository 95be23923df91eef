#include "inpaint/inpaint_net.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "inpaint/harmonic_fill.h"
#include "inpaint/push_pull.h"
#include "kernels/ops.h"

namespace ampi {
namespace {

const char* const kModelName = "ampi-inpaint";
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

InpaintNet InpaintNet::load(const std::string& path, const KernelTable& k) {
  return from_file(WeightFile::open(path), k);
}

InpaintNet InpaintNet::from_file(const WeightFile& f, const KernelTable& k) {
  if (!f.has("model") || f.get_string("model") != kModelName)
    fail(f, std::string("not an inpainting network (metadata 'model' is not '") + kModelName + "')");
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
  net.last_use_.assign(net.layers_.size(), -1);
  for (size_t i = 0; i < net.layers_.size(); ++i)
    for (int ref : {net.layers_[i].source, net.layers_[i].skip})
      if (ref >= 0) net.last_use_[ref] = int(i);
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
  std::vector<float> x(pixels * kInChannels);
  for (int64_t p = 0; p < pixels; ++p) {
    const float keep = prefill_ != Prefill::None ? 1.0f : 1.0f - hole[p];
    for (int c = 0; c < 3; ++c) x[p * kInChannels + c] = rgb[p * 3 + c] * keep;
    x[p * kInChannels + 3] = hole[p];
  }
  std::vector<std::vector<float>> outs(layers_.size());
  for (size_t i = 0; i < layers_.size(); ++i) {
    const InpaintLayer& l = layers_[i];
    std::vector<float> scratch;
    const float* in = layer_input(int(i), outs, x, h, w, scratch, pool);
    const int in_h = h >> (l.scale_log2 - (l.stride == 2 ? 1 : 0));
    const int in_w = w >> (l.scale_log2 - (l.stride == 2 ? 1 : 0));
    const int64_t out_pixels = int64_t(h >> l.scale_log2) * (w >> l.scale_log2);
    const bool last = i + 1 == layers_.size();
    if (l.gated) {
      std::vector<float> raw(out_pixels * 2 * l.out_c);
      convs_[i].run(in, in_h, in_w, raw.data(), nullptr, pool);
      outs[i].resize(out_pixels * l.out_c);
      gated_output(raw.data(), out_pixels, l.out_c, feature_act_, outs[i].data(), pool, *k_);
    } else if (last) {
      convs_[i].run(in, in_h, in_w, out, nullptr, pool);
    } else {
      outs[i].resize(out_pixels * l.out_c);
      convs_[i].run(in, in_h, in_w, outs[i].data(), nullptr, pool);
    }
    // free what no later layer reads, so the peak is a few layers, not the whole net
    for (int ref : {l.source, l.skip})
      if (ref >= 0 && last_use_[ref] == int(i)) std::vector<float>().swap(outs[ref]);
  }
  if (prefill_ != Prefill::None)  // the tanh output is a correction of the pre-filled hole
    for (int64_t p = 0; p < pixels; ++p)
      for (int c = 0; c < 3; ++c) out[p * 3 + c] = rgb[p * 3 + c] + hole[p] * out[p * 3 + c];
}

// Layer i's convolution input: its source, up-sampled when asked, then its skip beside
// it. Points into outs or x when neither applies, else into `scratch`.
const float* InpaintNet::layer_input(int i, const std::vector<std::vector<float>>& outs,
                                     const std::vector<float>& x, int h, int w,
                                     std::vector<float>& scratch, ThreadPool& pool) const {
  const InpaintLayer& l = layers_[i];
  const auto data = [&](int ref) { return ref == InpaintLayer::kInput ? x.data() : outs[ref].data(); };
  const auto channels = [&](int ref) { return ref == InpaintLayer::kInput ? kInChannels : layers_[ref].out_c; };
  const int src_scale = l.source == InpaintLayer::kInput ? 0 : layers_[l.source].scale_log2;
  const int in_scale = src_scale - (l.upsample ? 1 : 0);
  const int64_t pixels = int64_t(h >> in_scale) * (w >> in_scale);
  const int ca = channels(l.source);
  const float* in = data(l.source);
  std::vector<float> up;
  if (l.upsample) {
    up.resize(pixels * ca);
    resize2x_nearest(in, h >> src_scale, w >> src_scale, ca, up.data(), pool, *k_);
    in = up.data();
  }
  if (l.skip == InpaintLayer::kNoSkip) {
    if (l.upsample) scratch.swap(up);
    return l.upsample ? scratch.data() : in;
  }
  const int cb = channels(l.skip);
  scratch.resize(pixels * (ca + cb));
  concat_channels(in, ca, data(l.skip), cb, pixels, scratch.data(), pool, *k_);
  return scratch.data();
}

// ---- the filler -----------------------------------------------------------------------------

namespace {

int round_up(int v, int m) { return (v + m - 1) / m * m; }

// Grows [lo, lo + len) to a multiple of m inside [0, limit): to the right first, then to
// the left. Returns the padded length (>= the grown one when limit is too small).
int fit_span(int& lo, int& len, int limit, int m) {
  const int want = round_up(len, m);
  const int right = std::min(want - len, limit - (lo + len));
  len += right;
  const int left = std::min(want - len, lo);
  lo -= left;
  len += left;
  return want;
}

// The window's network input: rgb in [-1, 1] and hole (1 where not known or padding).
void window_input(const cv::Mat& image, const cv::Mat& known, const cv::Rect& win, int ph, int pw,
                  std::vector<float>& rgb, std::vector<float>& hole) {
  rgb.assign(size_t(ph) * pw * 3, 0.0f);
  hole.assign(size_t(ph) * pw, 1.0f);
  for (int y = 0; y < win.height; ++y) {
    const cv::Vec4b* px = image.ptr<cv::Vec4b>(win.y + y) + win.x;
    const uint8_t* kn = known.ptr<uint8_t>(win.y + y) + win.x;
    for (int x = 0; x < win.width; ++x) {
      const size_t p = size_t(y) * pw + x;
      for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = px[x][2 - c] / 127.5f - 1.0f;  // BGR -> RGB
      hole[p] = kn[x] ? 0.0f : 1.0f;
    }
  }
}

uint8_t to_byte(float v) { return cv::saturate_cast<uint8_t>(std::lround((v + 1.0f) * 127.5f)); }

void fill_core(const InpaintNet& net, const cv::Mat& image, const cv::Mat& known,
               const cv::Mat& fill, const cv::Rect& core, int halo, cv::Mat& result,
               ThreadPool& pool) {
  cv::Rect win = cv::Rect(core.x - halo, core.y - halo, core.width + 2 * halo, core.height + 2 * halo) &
                 cv::Rect(0, 0, image.cols, image.rows);
  const int m = net.multiple();
  const int pw = fit_span(win.x, win.width, image.cols, m);
  const int ph = fit_span(win.y, win.height, image.rows, m);
  std::vector<float> rgb, hole, out(size_t(ph) * pw * 3);
  window_input(image, known, win, ph, pw, rgb, hole);
  net.run(rgb.data(), hole.data(), ph, pw, out.data(), pool);
  for (int y = core.y; y < core.y + core.height; ++y) {
    const uint8_t* f = fill.ptr<uint8_t>(y);
    cv::Vec4b* dst = result.ptr<cv::Vec4b>(y);
    for (int x = core.x; x < core.x + core.width; ++x) {
      if (!f[x]) continue;
      const float* o = &out[(size_t(y - win.y) * pw + (x - win.x)) * 3];
      for (int c = 0; c < 3; ++c) dst[x][2 - c] = to_byte(o[c]);
    }
  }
}

// The network's input colour: its prefill in every unknown pixel.
cv::Mat prefilled(Prefill prefill, const cv::Mat& image, const cv::Mat& known, ThreadPool& pool) {
  switch (prefill) {
    case Prefill::PushPull: return push_pull_fill(image, known, known == 0);
    case Prefill::Harmonic: return harmonic_fill(image, known, known == 0, {}, pool);
    case Prefill::None: break;
  }
  return image;
}

}  // namespace

cv::Mat inpaint_layer(const InpaintNet& net, const cv::Mat& image, const cv::Mat& known,
                      const cv::Mat& fill, const InpaintTiling& tiling, ThreadPool& pool) {
  if (image.type() != CV_8UC4 || known.type() != CV_8UC1 || fill.type() != CV_8UC1 ||
      known.size() != image.size() || fill.size() != image.size())
    throw std::invalid_argument("inpaint_layer: needs a CV_8UC4 image and CV_8UC1 masks of its size");
  if (tiling.core < net.multiple() || tiling.halo < 0)
    throw std::invalid_argument("inpaint_layer: tile core must be at least the net's multiple, halo >= 0");
  cv::Mat result = image.clone();
  std::vector<cv::Point> points;
  cv::findNonZero(fill, points);
  if (points.empty()) return result;
  const cv::Mat source = prefilled(net.prefill(), image, known, pool);
  const cv::Rect box = cv::boundingRect(points);
  for (int y = box.y; y < box.br().y; y += tiling.core)
    for (int x = box.x; x < box.br().x; x += tiling.core) {
      const cv::Rect cell = cv::Rect(x, y, tiling.core, tiling.core) & box;
      std::vector<cv::Point> in_cell;
      cv::findNonZero(fill(cell), in_cell);
      if (in_cell.empty()) continue;
      // run on the fill's own box within the cell: sparse cells cost a small window
      const cv::Rect core = cv::boundingRect(in_cell) + cell.tl();
      fill_core(net, source, known, fill, core, tiling.halo, result, pool);
    }
  return result;
}

LayerFiller inpaint_net_filler(std::shared_ptr<const InpaintNet> net, InpaintTiling tiling) {
  if (!net) throw std::invalid_argument("inpaint_net_filler: no network");
  return [net, tiling](const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill) {
    return inpaint_layer(*net, image, known, fill, tiling);
  };
}

}  // namespace ampi
