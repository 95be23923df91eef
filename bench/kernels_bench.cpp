// ampi bench kernels: every kernel of every runnable ISA side by side, judged against
// the machine's limits measured in the same run (the FP32 FMA peak for compute-bound
// work, the memory bandwidth for memory-bound work):
// - the convolutions on the layer shapes of the lite depth network at 1024x768;
// - the GEMM op (kernels/gemm.h) on the products of a ViT-S/14 encoder at 518x518: its
//   linear layers with packed weights, attention's two products on strided views;
// - one workload for every family of the kernel lists (kernels/kernel_list.def,
//   slicing/row_kernel_list.def), naming the ISA whose code each table runs for it;
// then the whole lite network with 1 and with 2 threads.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bench/bench.h"
#include "bench/machine_limits.h"
#include "engine/tensor.h"
#include "kernels/conv.h"
#include "kernels/gemm.h"
#include "kernels/ops.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "slicing/bilateral.h"
#include "slicing/row_kernels.h"

namespace ampi::bench {
namespace {

constexpr size_t kBandwidthArrayBytes = size_t{128} << 20;  // x3, far beyond any L3 here
constexpr int kLimitRuns = 5;
// The whole-network scaling row: the bundled lite depth network on a 1024x768 photo.
constexpr int kNetworkW = 1024, kNetworkH = 768;
constexpr double kScalingTarget = 1.7;  // 2 threads against 1

struct Layer {
  std::string name;
  ConvParams p;
  int in_h = 0, in_w = 0;
  bool memory_bound() const { return p.groups > 1 && p.groups == p.in_c && p.in_c == p.out_c; }
};

Layer pointwise(int in_c, int out_c, int h, int w, Activation act) {
  Layer l;
  l.name = "1x1 " + std::to_string(in_c) + "->" + std::to_string(out_c);
  l.p.in_c = in_c;
  l.p.out_c = out_c;
  l.p.act = {act};
  l.in_h = h;
  l.in_w = w;
  return l;
}

Layer depthwise(int c, int kernel, int stride, int h, int w) {
  Layer l;
  l.name = "dw " + std::to_string(kernel) + "x" + std::to_string(kernel) + " s" + std::to_string(stride) +
           " " + std::to_string(c);
  l.p.in_c = l.p.out_c = l.p.groups = c;
  l.p.kernel_h = l.p.kernel_w = kernel;
  l.p.stride_h = l.p.stride_w = stride;
  l.p.pad_top = l.p.pad_left = l.p.pad_bottom = l.p.pad_right = kernel / 2;
  l.p.act = {Activation::HardSwish};
  l.in_h = h;
  l.in_w = w;
  return l;
}

Layer general3x3(int in_c, int out_c, int dilation, int h, int w) {
  Layer l;
  l.name = "3x3 " + std::to_string(in_c) + "->" + std::to_string(out_c) +
           (dilation > 1 ? " d" + std::to_string(dilation) : "");
  l.p.in_c = in_c;
  l.p.out_c = out_c;
  l.p.kernel_h = l.p.kernel_w = 3;
  l.p.dilation_h = l.p.dilation_w = dilation;
  l.p.pad_top = l.p.pad_left = l.p.pad_bottom = l.p.pad_right = dilation;
  l.p.act = {Activation::ReLU};
  l.in_h = h;
  l.in_w = w;
  return l;
}

// A MobileNetV3-style encoder on a 1024x768 photo: the Haar DWT halves it to 512x384x12,
// inverted-residual blocks (1x1 expansion with hard-swish, depthwise 3x3/5x5, 1x1
// projection) run at 512x384, 256x192 and 128x96; the inpainting generator adds dilated
// 3x3 convolutions; the last row is a 3x3 fusion convolution of Depth Anything V2
// ViT-S's DPT head at 518x518.
std::vector<Layer> network_layers() {
  return {
      general3x3(12, 32, 1, 384, 512),
      pointwise(16, 64, 384, 512, Activation::HardSwish),
      pointwise(64, 16, 384, 512, Activation::None),
      pointwise(24, 96, 192, 256, Activation::HardSwish),
      pointwise(96, 24, 192, 256, Activation::None),
      pointwise(64, 64, 192, 256, Activation::HardSwish),
      pointwise(144, 32, 96, 128, Activation::None),
      pointwise(128, 128, 96, 128, Activation::HardSwish),
      depthwise(64, 3, 1, 384, 512),
      depthwise(64, 3, 2, 384, 512),
      depthwise(96, 5, 1, 192, 256),
      depthwise(96, 5, 2, 192, 256),
      depthwise(144, 3, 1, 96, 128),
      depthwise(144, 5, 1, 96, 128),
      general3x3(32, 32, 2, 192, 256),
      general3x3(64, 64, 1, 148, 148),
  };
}

struct Options {
  int threads = 1;
  int runs = 5;
  Clock clock = Clock::Wall;
  std::string out = "bench/RESULTS-kernels.md";
};

const char* const kUsage =
    "usage: ampi bench kernels [--threads N] [--runs N] [--clock wall|cpu] [--out FILE]\n"
    "  Times every kernel of every runnable ISA and compares with the FMA peak and memory\n"
    "  bandwidth measured in the same run: the convolutions on the lite depth network's\n"
    "  layer shapes at 1024x768, the GEMM op on a ViT-S/14 encoder's products at 518x518,\n"
    "  and one workload for every kernel family of the dispatch lists, naming the ISA whose\n"
    "  code each table runs for it; then the whole lite network (bundled weights) at\n"
    "  1024x768 with 1 and with 2 threads, and prints each target's fraction and verdict.\n"
    "  --threads: pool size for the kernels (default 1; the network always runs 1 and 2);\n"
    "  --runs: timed runs per kernel and per network thread count, the median is reported\n"
    "  (default 5); --clock: wall time (default) or the process's CPU time per thread,\n"
    "  steadier on a machine loaded by other processes but blind to idle threads (the\n"
    "  network scaling is always wall time); --out: the table (default bench/RESULTS-kernels.md).\n";

int positive_int(const char* flag, const char* value) {
  char* end = nullptr;
  const long v = std::strtol(value, &end, 10);
  if (*value == '\0' || *end != '\0' || v <= 0 || v > 1024)
    throw std::runtime_error(std::string("kernels: ") + flag + " expects a positive number, got '" + value + "'");
  return static_cast<int>(v);
}

// Returns false when --help was asked for.
bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") return false;
    if (flag != "--threads" && flag != "--runs" && flag != "--out" && flag != "--clock")
      throw std::runtime_error("kernels: unknown option '" + flag + "' (see --help)");
    if (i + 1 >= argc) throw std::runtime_error("kernels: " + flag + " needs a value");
    const char* value = argv[++i];
    if (flag == "--threads") o.threads = positive_int("--threads", value);
    else if (flag == "--runs") o.runs = positive_int("--runs", value);
    else if (flag == "--out") o.out = value;
    else if (std::strcmp(value, "wall") == 0 || std::strcmp(value, "cpu") == 0)
      o.clock = std::strcmp(value, "wall") == 0 ? Clock::Wall : Clock::Cpu;
    else throw std::runtime_error(std::string("kernels: --clock expects wall or cpu, got '") + value + "'");
  }
  return true;
}

std::vector<float> random_floats(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(-1.0f, 1.0f);
  std::vector<float> v(n);
  for (float& x : v) x = dist(rng);
  return v;
}

struct Timing {
  double ms = 0, gflops = 0, gbs = 0;
};

// The median of o.runs timed calls of f, after one untimed call (pages, caches), as a
// Timing of that many floating-point operations and bytes moved.
Timing time_calls(const std::function<void()>& f, double flops, double bytes, int threads, const Options& o) {
  f();
  std::vector<double> seconds;
  for (int r = 0; r < o.runs; ++r) {
    const Stopwatch watch(o.clock, threads);
    f();
    seconds.push_back(watch.seconds());
  }
  const double s = median(seconds);
  return {s * 1e3, flops / s * 1e-9, bytes / s * 1e-9};
}

// The activations live in 64-byte-aligned tensors, as the networks' do (their arena is
// 64-byte aligned and rounds every buffer to 64 bytes). A std::vector of this size comes
// from mmap 16 bytes past a page start, so every AVX-512 load of it would straddle two
// cache lines: the kernels measured 1.5-3.5x slower on such buffers than in the network.
Tensor random_tensor(const Shape& shape, uint32_t seed, float lo = -1.0f, float hi = 1.0f) {
  Tensor t = Tensor::empty(shape);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  std::generate(t.f32(), t.f32() + t.numel(), [&] { return dist(rng); });
  return t;
}

struct LayerData {
  Tensor in, out;
  std::vector<float> weights, bias;
  explicit LayerData(const Layer& l) {
    const ConvParams& p = l.p;
    in = random_tensor({l.in_h, l.in_w, p.in_c}, 1);
    weights = random_floats(static_cast<size_t>(p.out_c) * p.kernel_h * p.kernel_w * (p.in_c / p.groups), 2);
    bias = random_floats(p.out_c, 3);
    out = Tensor::zeros({p.out_h(l.in_h), p.out_w(l.in_w), p.out_c});
  }
};

Timing time_layer(const Layer& l, const LayerData& d, const KernelTable& k, ThreadPool& pool,
                  const Options& o) {
  const Conv2d conv(l.p, d.weights.data(), d.bias.data(), k);
  float* out = const_cast<float*>(d.out.f32());
  const double macs = static_cast<double>(d.out.numel()) * l.p.kernel_h * l.p.kernel_w * (l.p.in_c / l.p.groups);
  const double bytes = 4.0 * static_cast<double>(d.in.numel() + d.out.numel() + d.weights.size() + d.bias.size());
  return time_calls([&] { conv.run(d.in.f32(), l.in_h, l.in_w, out, nullptr, pool); }, 2.0 * macs, bytes,
                    pool.size(), o);
}

std::string cpu_name() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos)
      return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

struct Limits {
  Isa isa;
  double peak_gflops = 0, bandwidth_gbs = 0;
  double fraction(bool memory_bound, const Timing& t) const {
    return memory_bound ? t.gbs / bandwidth_gbs : t.gflops / peak_gflops;
  }
};

// The first columns of a row of the convolution and GEMM tables.
struct RowLabel {
  std::string name, input, output;
  bool memory_bound = false;
};

RowLabel label(const Layer& l) {
  return {l.name, std::to_string(l.in_w) + "x" + std::to_string(l.in_h),
          std::to_string(l.p.out_w(l.in_w)) + "x" + std::to_string(l.p.out_h(l.in_h)), l.memory_bound()};
}

std::string header(const Options& o, const Limits& lim) {
  std::ostringstream s;
  s << "# Kernels vs the machine's limits (`ampi bench kernels`)\n\n"
    << "CPU: " << cpu_name() << "; " << o.threads << " thread(s); median of " << o.runs
    << " runs per kernel; " << clock_name(o.clock) << " clock"
    << (o.clock == Clock::Cpu ? " (process CPU time per thread: other processes' share of the cores left out)" : "")
    << ".\n\n"
    << "Limits measured in the same run, on the same threads:\n"
    << "- FP32 FMA peak (" << isa_name(lim.isa) << ", register-resident FMA loop): "
    << format("%.1f", lim.peak_gflops) << " GFLOP/s\n"
    << "- memory bandwidth (triad a = b + s*c, 3 arrays of " << (kBandwidthArrayBytes >> 20)
    << " MiB): " << format("%.1f", lim.bandwidth_gbs) << " GB/s\n\n";
  return s.str();
}

// The head of a table whose rows have the columns `first` and, per ISA, time, GFLOP/s,
// GB/s and the fraction of the limit.
std::string limits_table_head(const std::string& first, const std::vector<Isa>& isas) {
  std::ostringstream s;
  s << "| " << first << " |";
  for (Isa isa : isas) s << ' ' << isa_name(isa) << " ms | GFLOP/s | GB/s | of limit |";
  s << "\n|---|---|---|";
  for (size_t i = 0; i < isas.size(); ++i) s << "---:|---:|---:|---:|";
  s << "\n";
  return s.str();
}

std::string convolution_section(const std::vector<Isa>& isas) {
  return "Layers: a MobileNetV3-style depth network on a 1024x768 photo (Haar DWT to 512x384x12, "
         "then 512x384, 256x192, 128x96), plus the inpainting generator's dilated 3x3 and a "
         "fusion convolution of Depth Anything V2 ViT-S's DPT head (64->64 at 148x148). "
         "\"of limit\" is GFLOP/s over the FMA peak for 1x1 and general convolutions, GB/s "
         "over the bandwidth for depthwise ones; bytes count the input and output once and "
         "the weights. GFLOP/s counts a direct convolution's multiply-adds: the undilated 3x3 "
         "layers take Conv2d's Winograd path (kernels/winograd.h), which does a quarter of "
         "them, so they can pass 100%. Every ISA is compared with the same limits (the "
         "active ISA's peak).\n\n" +
         limits_table_head("layer | input | output", isas);
}

std::string row(const RowLabel& l, const std::vector<Timing>& timings, const Limits& lim) {
  std::ostringstream s;
  s << "| " << l.name << " | " << l.input << " | " << l.output << " |";
  for (const Timing& t : timings)
    s << ' ' << format("%.2f", t.ms) << " | " << format("%.1f", t.gflops) << " | " << format("%.1f", t.gbs)
      << " | " << format("%.0f%%", 100.0 * lim.fraction(l.memory_bound, t)) << " |";
  return s.str() + "\n";
}

// Prints a line or section as it comes and keeps it for the file.
struct Report {
  std::string text;
  void add(const std::string& part) {
    std::fputs(part.c_str(), stdout);
    std::fflush(stdout);
    text += part;
  }
};

// ---- the GEMM op on a ViT encoder's products ----------------------------------------------
// Depth Anything V2 Small's encoder (ViT-S/14) on a 518x518 image: 37x37 patches and a
// class token, embedding 384, 6 heads of 64, MLP 1536.
constexpr int kTokens = 37 * 37 + 1, kDim = 384, kHeads = 6, kHeadDim = kDim / kHeads, kMlp = 4 * kDim;

// How the product's B reaches the op.
enum class BForm { Packed, Transposed, Strided };

struct Product {
  std::string name;
  int m, n, k;
  BForm b = BForm::Packed;
  int heads = 1;  // one product per attention head in each timed run
  bool residual = false;
};

// Linear layers take packed weights; attention's products take views of the [tokens][3
// dim] qkv buffer: K^T (transposed) for the scores, V (row-major) for the mix.
std::vector<Product> vit_products() {
  return {
      {"qkv 384->1152", kTokens, 3 * kDim, kDim},
      {"Q K^T, 6 heads", kTokens, kTokens, kHeadDim, BForm::Transposed, kHeads},
      {"P V, 6 heads", kTokens, kHeadDim, kTokens, BForm::Strided, kHeads},
      {"proj 384->384 + residual", kTokens, kDim, kDim, BForm::Packed, 1, true},
      {"fc1 384->1536", kTokens, kMlp, kDim},
      {"fc2 1536->384 + residual", kTokens, kDim, kMlp, BForm::Packed, 1, true},
  };
}

// The operands of one product. Attention's are views of qkv ([tokens][3 dim]: each
// head's Q, K and V are column ranges of it); P V's A is a [tokens][tokens] map of
// probabilities, one for every head.
struct ProductData {
  Tensor a, qkv, c, residual;
  std::vector<float> w, bias;  // packed B's source, [n][k], and its bias
  explicit ProductData(const Product& p) {
    if (p.b != BForm::Transposed)
      a = p.b == BForm::Packed ? random_tensor({p.m, p.k}, 11) : random_tensor({p.m, p.k}, 11, 0.0f, 2.0f / p.k);
    if (p.b != BForm::Packed) qkv = random_tensor({kTokens, 3 * kDim}, 12);
    if (p.b == BForm::Packed) {
      w = random_floats(static_cast<size_t>(p.n) * p.k, 13);
      bias = random_floats(p.n, 14);
    }
    c = Tensor::zeros({p.m, p.b == BForm::Strided ? kDim : p.n});  // P V: the heads side by side
    if (p.residual) residual = random_tensor({p.m, p.n}, 15);
  }
};

// One timed call: the product on one table, for every head. Packing the weights is not
// timed (it happens once, at load); packing a strided B is (it happens on every call).
std::function<void()> product_call(const Product& p, ProductData& d, const KernelTable& table, ThreadPool& pool) {
  GemmProblem g;
  g.m = p.m, g.n = p.n, g.k = p.k;
  g.c = d.c.f32();
  g.c_stride = d.c.shape()[1];
  g.residual = p.residual ? d.residual.f32() : nullptr;
  if (p.b == BForm::Packed) {
    g.a = d.a.f32();
    g.a_stride = p.k;
    auto weights = std::make_shared<const GemmWeights>(d.w.data(), d.bias.data(), p.n, p.k, table);
    return [g, weights, &pool] { gemm(g, *weights, pool); };
  }
  const float* qkv = d.qkv.f32();
  const int heads = p.heads;
  if (p.b == BForm::Transposed)  // scores = Q_h K_h^T, into one [tokens][tokens] map
    return [g, qkv, heads, &table, &pool] {
      for (int h = 0; h < heads; ++h) {
        GemmProblem head = g;
        head.a = qkv + h * kHeadDim;
        head.a_stride = 3 * kDim;
        gemm(head, {qkv + kDim + h * kHeadDim, 3 * kDim, true}, nullptr, pool, table);
      }
    };
  const float* probabilities = d.a.f32();
  return [g, qkv, probabilities, heads, &table, &pool] {  // head h's columns of the output = P V_h
    for (int h = 0; h < heads; ++h) {
      GemmProblem head = g;
      head.a = probabilities;
      head.a_stride = kTokens;
      head.c = g.c + h * kHeadDim;
      gemm(head, {qkv + 2 * kDim + h * kHeadDim, 3 * kDim, false}, nullptr, pool, table);
    }
  };
}

Timing time_product(const Product& p, const KernelTable& table, ThreadPool& pool, const Options& o) {
  ProductData d(p);
  const std::function<void()> call = product_call(p, d, table, pool);
  const double mnk = static_cast<double>(p.m) * p.n * p.k * p.heads;
  const double bytes = 4.0 * p.heads * (static_cast<double>(p.m) * p.k + static_cast<double>(p.k) * p.n +
                                        static_cast<double>(p.m) * p.n * (p.residual ? 2 : 1));
  return time_calls(call, 2.0 * mnk, bytes, pool.size(), o);
}

std::string gemm_section(const std::vector<Isa>& isas) {
  return "\n## GEMM op (kernels/gemm.h)\n\n"
         "The products of a ViT-S/14 encoder (Depth Anything V2 Small) on a 518x518 image: " +
         std::to_string(kTokens) + " tokens, embedding " + std::to_string(kDim) + ", " + std::to_string(kHeads) +
         " heads of " + std::to_string(kHeadDim) + ", MLP " + std::to_string(kMlp) +
         ". Linear layers take their weights packed once (GemmWeights); attention's products "
         "take views of one [tokens][3 dim] buffer, packed on each call: K^T transposed for "
         "the scores, V row-major for the mix, each head's output into its columns of a "
         "[tokens][dim] map. \"of limit\" is GFLOP/s over the FMA peak; bytes count A, B and "
         "C once per head.\n\n" +
         limits_table_head("product | A | C", isas);
}

RowLabel label(const Product& p) {
  const std::string per_head = p.heads > 1 ? std::to_string(p.heads) + " x " : "";
  return {p.name, per_head + std::to_string(p.m) + "x" + std::to_string(p.k),
          per_head + std::to_string(p.m) + "x" + std::to_string(p.n), false};
}

// ---- every kernel family of the dispatch lists ---------------------------------------------
// Feature maps of the depth network's middle scale: 256x192 pixels of 64 channels.
constexpr int kMapH = 192, kMapW = 256, kMapC = 64;
constexpr int64_t kMapPixels = int64_t{kMapH} * kMapW;
// The slicer works on the photo at the depth network's size.
constexpr int kSliceH = 768, kSliceW = 1024;

// A timed call on one ISA's table (core or slicer's) and a pool.
using FamilyCall = std::function<void(Isa, ThreadPool&)>;

// What `ampi bench kernels` times for one or more families: the op that calls them on a
// network's shape. make() allocates the data and returns the call (only the call is timed).
struct FamilyWorkload {
  std::vector<std::string> families;
  std::string shape;
  double bytes;  // each input and output counted once
  std::function<FamilyCall()> make;
};

std::shared_ptr<Tensor> shared_random(const Shape& shape, uint32_t seed, float lo = -1.0f, float hi = 1.0f) {
  return std::make_shared<Tensor>(random_tensor(shape, seed, lo, hi));
}

std::shared_ptr<Tensor> shared_zeros(const Shape& shape) { return std::make_shared<Tensor>(Tensor::zeros(shape)); }

std::string map_shape(int h, int w, int c) {
  return std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(c);
}

// make(table) for every runnable ISA's table, indexed by the Isa's value (packing, done
// once at load, stays out of the timed calls).
template <class T, class Make>
std::shared_ptr<const std::vector<T>> per_isa(Make make) {
  auto list = std::make_shared<std::vector<T>>(4);
  for (Isa isa : runnable_isas()) (*list)[static_cast<int>(isa)] = make(kernels_for(isa));
  return list;
}

FamilyWorkload gemm_workload() {
  return {{"gemm"}, "GEMM op, 1x1 64->64 over " + map_shape(kMapH, kMapW, kMapC),
          4.0 * (2 * kMapPixels * kMapC + kMapC * kMapC), [] {
            auto in = shared_random({kMapPixels, kMapC}, 21), out = shared_zeros({kMapPixels, kMapC});
            const std::vector<float> w = random_floats(kMapC * kMapC, 22);
            auto weights = per_isa<GemmWeights>(
                [&](const KernelTable& t) { return GemmWeights(w.data(), nullptr, kMapC, kMapC, t); });
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              GemmProblem g;
              g.m = static_cast<int>(kMapPixels), g.n = kMapC, g.k = kMapC;
              g.a = in->f32(), g.a_stride = kMapC;
              g.c = out->f32(), g.c_stride = kMapC;
              gemm(g, (*weights)[static_cast<int>(isa)], pool);
            });
          }};
}

// A workload's make(): Conv2d on layer l, packed once per ISA, run over its map.
std::function<FamilyCall()> conv_layer_call(const Layer& l) {
  return [l] {
    auto d = std::make_shared<LayerData>(l);
    auto convs = per_isa<Conv2d>([&](const KernelTable& t) { return Conv2d(l.p, d->weights.data(), d->bias.data(), t); });
    return FamilyCall([=](Isa isa, ThreadPool& pool) {
      (*convs)[static_cast<int>(isa)].run(d->in.f32(), l.in_h, l.in_w, d->out.f32(), nullptr, pool);
    });
  };
}

FamilyWorkload depthwise_workload() {
  const Layer l = depthwise(kMapC, 3, 1, kMapH, kMapW);
  return {{"depthwise_row"}, "Conv2d, " + l.name + " over " + map_shape(kMapH, kMapW, kMapC),
          4.0 * (2 * kMapPixels * kMapC + 10 * kMapC), conv_layer_call(l)};
}

// The DPT head's 3x3 fusion convolution (Depth Anything V2 ViT-S at 518x518), whose
// Winograd path runs both transforms around the GEMM micro-kernel.
FamilyWorkload winograd_workload() {
  const Layer l = general3x3(64, 64, 1, 148, 148);
  const double pixels = double(l.in_h) * l.in_w;
  return {{"winograd_input", "winograd_output"},
          "Conv2d (winograd path), " + l.name + " over " + map_shape(l.in_h, l.in_w, l.p.in_c),
          4.0 * pixels * (l.p.in_c + l.p.out_c), conv_layer_call(l)};
}

FamilyWorkload add_workload() {
  const int64_t n = kMapPixels * kMapC;
  return {{"add"}, "add, " + map_shape(kMapH, kMapW, kMapC), 12.0 * n, [n] {
            auto a = shared_random({n}, 31), b = shared_random({n}, 32), out = shared_zeros({n});
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              add(a->f32(), b->f32(), n, out->f32(), {}, pool, kernels_for(isa));
            });
          }};
}

FamilyWorkload activate_workload() {
  const int64_t n = kMapPixels * kMapC;
  return {{"activate"}, "activate (hard-swish) in place, " + map_shape(kMapH, kMapW, kMapC), 8.0 * n, [n] {
            auto x = shared_random({n}, 33);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              activate(x->f32(), n, {Activation::HardSwish}, pool, kernels_for(isa));
            });
          }};
}

FamilyWorkload gated_output_workload() {
  const int c = kMapC / 2;
  return {{"gated_output"}, "gated output (ELU feature), " + map_shape(kMapH, kMapW, 2 * c) + " -> " + std::to_string(c),
          4.0 * kMapPixels * 3 * c, [c] {
            auto in = shared_random({kMapPixels, 2 * c}, 34), out = shared_zeros({kMapPixels, c});
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              gated_output(in->f32(), kMapPixels, c, {Activation::ELU, 1.0f}, out->f32(), pool, kernels_for(isa));
            });
          }};
}

FamilyWorkload concat_workload() {
  const int c = kMapC / 2;
  return {{"concat_channels"}, "concat, 2 x " + map_shape(kMapH, kMapW, c), 4.0 * kMapPixels * 4 * c, [c] {
            auto a = shared_random({kMapPixels, c}, 35), b = shared_random({kMapPixels, c}, 36);
            auto out = shared_zeros({kMapPixels, 2 * c});
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              concat_channels(a->f32(), c, b->f32(), c, kMapPixels, out->f32(), pool, kernels_for(isa));
            });
          }};
}

// Squeeze-excite's two channel kernels, called as SqueezeExcite calls them: a sum per row,
// a scale per chunk of pixels.
FamilyWorkload channel_sum_workload() {
  return {{"channel_sum"}, "a sum per row (squeeze-excite), " + map_shape(kMapH, kMapW, kMapC),
          4.0 * kMapPixels * kMapC, [] {
            auto in = shared_random({kMapPixels, kMapC}, 37), sums = shared_zeros({kMapH, kMapC});
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const KernelTable& k = kernels_for(isa);
              pool.parallel_for(kMapH, 1, [&](int64_t begin, int64_t end) {
                for (int64_t y = begin; y < end; ++y)
                  k.channel_sum(in->f32() + y * kMapW * kMapC, kMapW, kMapC, sums->f32() + y * kMapC);
              });
            });
          }};
}

FamilyWorkload channel_scale_workload() {
  return {{"channel_scale"}, "scale per channel (squeeze-excite), " + map_shape(kMapH, kMapW, kMapC),
          8.0 * kMapPixels * kMapC, [] {
            auto in = shared_random({kMapPixels, kMapC}, 38), out = shared_zeros({kMapPixels, kMapC});
            auto scale = shared_random({kMapC}, 39, 0.0f, 1.0f);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const KernelTable& k = kernels_for(isa);
              pool.parallel_for(kMapH, 1, [&](int64_t begin, int64_t end) {
                k.channel_scale(in->f32() + begin * kMapW * kMapC, (end - begin) * kMapW, kMapC, scale->f32(),
                                out->f32() + begin * kMapW * kMapC);
              });
            });
          }};
}

// A fully connected layer whose weights (4 MiB) overflow L2: bound by reading them.
FamilyWorkload dense_workload() {
  constexpr int kRows = 1024, kCols = 1024;
  return {{"dense"}, "dense, 1024x1024 weights", 4.0 * (int64_t{kRows} * kCols + kRows + kCols), [] {
            auto w = shared_random({kRows, kCols}, 40), x = shared_random({kCols}, 41), y = shared_zeros({kRows});
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const KernelTable& k = kernels_for(isa);
              pool.parallel_for(kRows, 64, [&](int64_t begin, int64_t end) {
                k.dense(w->f32() + begin * kCols, nullptr, static_cast<int>(end - begin), kCols, x->f32(), {},
                        y->f32() + begin);
              });
            });
          }};
}

// A 2x resampling op: (in, h, w, c) as kernels/ops.h takes them; in_c is the input's
// channel count (4c for the inverse DWT).
using ResampleOp = void (*)(const float*, int, int, int, float*, ThreadPool&, const KernelTable&);

// out_per_in: output floats per input float.
FamilyWorkload resample_workload(const char* family, ResampleOp op, int h, int w, int c, int in_c, int out_per_in) {
  const int64_t in_floats = int64_t{h} * w * in_c;
  return {{family}, std::string(family) + ", " + map_shape(h, w, in_c) + " in", 4.0 * in_floats * (1 + out_per_in), [=] {
            auto in = shared_random({in_floats}, 42), out = shared_zeros({in_floats * out_per_in});
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              op(in->f32(), h, w, c, out->f32(), pool, kernels_for(isa));
            });
          }};
}

// The slicer's row kernels on a photo at the depth network's size, row by row over the
// pool as slicing/ calls them.
std::shared_ptr<Tensor> slice_plane(uint32_t seed, float lo = 0.0f, float hi = 1.0f) {
  return shared_random({kSliceH, kSliceW}, seed, lo, hi);
}

void for_each_slice_row(ThreadPool& pool, const std::function<void(int64_t)>& row) {
  pool.parallel_for(kSliceH, 16, [&](int64_t begin, int64_t end) {
    for (int64_t y = begin; y < end; ++y) row(y);
  });
}

constexpr int64_t kSlicePixels = int64_t{kSliceH} * kSliceW;

FamilyWorkload range_row_workload() {
  return {{"range_row"}, "range of a " + map_shape(kSliceH, kSliceW, 1) + " disparity map", 4.0 * kSlicePixels, [] {
            auto d = slice_plane(50);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const slicing::RangeRowFn range_row = slicing::slicing_kernels(isa).range_row;
              for_each_slice_row(pool, [&](int64_t y) {
                slicing::ValueRange r{d->f32()[y * kSliceW], d->f32()[y * kSliceW], true};
                range_row(d->f32() + y * kSliceW, kSliceW, r);
              });
            });
          }};
}

FamilyWorkload normalize_row_workload() {
  return {{"normalize_row"}, "levels of a " + map_shape(kSliceH, kSliceW, 1) + " disparity map",
          9.0 * kSlicePixels, [] {
            auto d = slice_plane(51), value = shared_zeros({kSliceH, kSliceW});
            auto level = std::make_shared<std::vector<uint8_t>>(kSlicePixels);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const slicing::NormalizeRowFn normalize_row = slicing::slicing_kernels(isa).normalize_row;
              for_each_slice_row(pool, [&](int64_t y) {
                normalize_row(d->f32() + y * kSliceW, kSliceW, 0.0, 255.0, value->f32() + y * kSliceW,
                              level->data() + y * kSliceW);
              });
            });
          }};
}

FamilyWorkload bilateral_workload() {
  return {{"bilateral_weights", "bilateral_combine"},
          "bilateral filter (diameter 5) of " + map_shape(kSliceH, kSliceW, 1) + " levels", 2.0 * kSlicePixels, [] {
            auto levels = std::make_shared<cv::Mat>(kSliceH, kSliceW, CV_8UC1);
            cv::randu(*levels, 0, 256);
            return FamilyCall([=](Isa isa, ThreadPool& pool) { bilateral_filter_levels(*levels, {}, isa, pool); });
          }};
}

FamilyWorkload snap_row_workload() {
  return {{"snap_row"}, "depth-edge snapping of a " + map_shape(kSliceH, kSliceW, 1) + " map", 45.0 * kSlicePixels,
          [] {
            // The disparity, the photo's three channels, the fit's four coefficients, the extremes.
            std::vector<std::shared_ptr<Tensor>> planes;
            for (uint32_t i = 0; i < 10; ++i) planes.push_back(slice_plane(60 + i));
            auto out = shared_zeros({kSliceH, kSliceW});
            auto band = std::make_shared<std::vector<uint8_t>>(kSlicePixels);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const slicing::SnapRowFn snap_row = slicing::slicing_kernels(isa).snap_row;
              for_each_slice_row(pool, [&](int64_t y) {
                const auto row = [&](int i) { return planes[i]->f32() + y * kSliceW; };
                snap_row({row(0), row(1), row(2), row(3), row(4), row(5), row(6), row(7), row(8), row(9)}, kSliceW,
                         0.1f, 0.1f, out->f32() + y * kSliceW, band->data() + y * kSliceW);
              });
            });
          }};
}

// The transformer rows on a ViT-S/14 encoder at 518x518: 1370 tokens (37 x 37 patches and
// the class token) of 384 channels, attention over 1370 keys in blocks of 256.
constexpr int kVitTokens = 1370, kVitDim = 384, kVitKeyBlock = 256;

FamilyWorkload layer_norm_workload() {
  const int64_t n = int64_t{kVitTokens} * kVitDim;
  return {{"layer_norm_row"}, "layer norm, " + std::to_string(kVitTokens) + " tokens x " + std::to_string(kVitDim),
          8.0 * n, [n] {
            auto in = shared_random({n}, 70), out = shared_zeros({n});
            auto gamma = shared_random({kVitDim}, 71), beta = shared_random({kVitDim}, 72);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const KernelTable& k = kernels_for(isa);
              pool.parallel_for(kVitTokens, 16, [&](int64_t begin, int64_t end) {
                for (int64_t t = begin; t < end; ++t)
                  k.layer_norm_row(in->f32() + t * kVitDim, kVitDim, gamma->f32(), beta->f32(), 1e-6f,
                                   out->f32() + t * kVitDim);
              });
            });
          }};
}

// Every query row's scores against all keys, block by block in place, as attention streams
// them (one head: the 1370 x 1370 score matrix).
FamilyWorkload softmax_workload() {
  const int64_t n = int64_t{kVitTokens} * kVitTokens;
  return {{"softmax_block_row"},
          "online softmax, " + std::to_string(kVitTokens) + " queries x " + std::to_string(kVitTokens) +
              " keys in blocks of " + std::to_string(kVitKeyBlock),
          8.0 * n, [n] {
            auto scores = shared_random({n}, 73, -8.0f, 8.0f);
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const KernelTable& k = kernels_for(isa);
              pool.parallel_for(kVitTokens, 16, [&](int64_t begin, int64_t end) {
                for (int64_t q = begin; q < end; ++q) {
                  float running_max = -INFINITY, running_sum = 0.0f;
                  for (int k0 = 0; k0 < kVitTokens; k0 += kVitKeyBlock)
                    k.softmax_block_row(scores->f32() + q * kVitTokens + k0, std::min(kVitKeyBlock, kVitTokens - k0),
                                        0.125f, &running_max, &running_sum);
                }
              });
            });
          }};
}

// The DPT head's 2x resize (align_corners=True) of a 74x74x256 fusion map.
constexpr int kDptIn = 74, kDptOut = 2 * kDptIn, kDptC = 256;

FamilyWorkload bilinear_row_workload() {
  constexpr int kIn = kDptIn, kOut = kDptOut, kC = kDptC;
  const double bytes = 4.0 * (int64_t{kIn} * kIn * kC + int64_t{kOut} * kOut * kC);
  return {{"bilinear_row"}, "bilinear resize (align corners), " + map_shape(kIn, kIn, kC) + " -> " + map_shape(kOut, kOut, kC),
          bytes, [] {
            auto in = shared_random({kIn, kIn, kC}, 74), out = shared_zeros({kOut, kOut, kC});
            auto x0 = std::make_shared<std::vector<int32_t>>(kDptOut);
            auto x1 = std::make_shared<std::vector<int32_t>>(kDptOut);
            auto wx = std::make_shared<std::vector<float>>(kDptOut);
            for (int x = 0; x < kOut; ++x) {
              const float src = static_cast<float>(x) * (kIn - 1) / (kOut - 1);
              (*x0)[x] = std::min(static_cast<int>(src), kIn - 1);
              (*x1)[x] = std::min((*x0)[x] + 1, kIn - 1);
              (*wx)[x] = src - (*x0)[x];
            }
            return FamilyCall([=](Isa isa, ThreadPool& pool) {
              const KernelTable& k = kernels_for(isa);
              const int64_t in_row = int64_t{kIn} * kC;
              pool.parallel_for(kOut, 8, [&](int64_t begin, int64_t end) {
                for (int64_t y = begin; y < end; ++y) {
                  const int64_t sy = (*x0)[y], sy1 = (*x1)[y];  // the same rule down the rows
                  k.bilinear_row(in->f32() + sy * in_row, in->f32() + sy1 * in_row, (*wx)[y], x0->data(),
                                 x1->data(), wx->data(), kOut, kC, out->f32() + y * kOut * kC);
                }
              });
            });
          }};
}

std::vector<FamilyWorkload> family_workloads() {
  return {gemm_workload(),
          depthwise_workload(),
          winograd_workload(),
          add_workload(),
          activate_workload(),
          gated_output_workload(),
          concat_workload(),
          channel_sum_workload(),
          channel_scale_workload(),
          dense_workload(),
          // Between the network's two finest scales: 512x384x16 and 256x192x64.
          resample_workload("haar_dwt", haar_dwt, 2 * kMapH, 2 * kMapW, kMapC / 4, kMapC / 4, 1),
          resample_workload("haar_idwt", haar_idwt, kMapH, kMapW, kMapC / 4, kMapC, 1),
          resample_workload("resize2x_nearest", resize2x_nearest, kMapH / 2, kMapW / 2, kMapC, kMapC, 4),
          resample_workload("resize2x_bilinear", resize2x_bilinear, kMapH / 2, kMapW / 2, kMapC, kMapC, 4),
          range_row_workload(),
          normalize_row_workload(),
          bilateral_workload(),
          snap_row_workload(),
          layer_norm_workload(),
          softmax_workload(),
          bilinear_row_workload()};
}

// Every family of both lists, in their order, with the ISA each runnable table runs for it.
struct ListedFamily {
  std::string name;
  std::vector<Isa> provider;  // per runnable ISA
};

std::vector<ListedFamily> listed_families(const std::vector<Isa>& isas) {
  std::vector<ListedFamily> list;
  for (const KernelFamily& f : kernel_families()) list.push_back({f.name, {}});
  for (const KernelFamily& f : slicing::slicing_kernel_families()) list.push_back({f.name, {}});
  for (Isa isa : isas) {
    std::vector<KernelEntry> entries = kernel_entries(kernels_for(isa));
    const std::vector<KernelEntry> rows = slicing::slicing_kernel_entries(slicing::slicing_kernels(isa));
    entries.insert(entries.end(), rows.begin(), rows.end());
    for (size_t i = 0; i < list.size(); ++i) list[i].provider.push_back(entries[i].provider);
  }
  return list;
}

// The workload timing `family`; throws when a family of the lists has none, so a new
// kernel family cannot be left out of the benchmark.
const FamilyWorkload& workload_of(const std::vector<FamilyWorkload>& workloads, const std::string& family) {
  for (const FamilyWorkload& w : workloads)
    if (std::find(w.families.begin(), w.families.end(), family) != w.families.end()) return w;
  throw std::runtime_error("kernels: no benchmark workload for the kernel family '" + family +
                           "' (bench/kernels_bench.cpp, family_workloads)");
}

std::string families_section(const std::vector<Isa>& isas) {
  std::ostringstream s;
  s << "\n## Every kernel family\n\n"
    << "Each family of the kernel lists (kernels/kernel_list.def, then slicing/row_kernel_list.def), "
    << "timed through the op that calls it on a network's shape. \"code\" is the instruction set "
    << "whose code the ISA's table runs for the family: its own variant, or the one it falls back "
    << "to. GB/s counts each input and output once (the GEMM and depthwise rows repeat shapes of "
    << "the tables above).\n\n| family | workload |";
  for (Isa isa : isas) s << ' ' << isa_name(isa) << " code | ms | GB/s |";
  s << "\n|---|---|";
  for (size_t i = 0; i < isas.size(); ++i) s << "---|---:|---:|";
  s << "\n";
  return s.str();
}

// One row for the families a workload times (all of them listed next to each other).
std::string family_row(const std::vector<const ListedFamily*>& families, const FamilyWorkload& w,
                       const std::vector<Timing>& timings) {
  std::ostringstream s;
  s << "|";
  for (size_t i = 0; i < families.size(); ++i) s << (i ? ", " : " ") << families[i]->name;
  s << " | " << w.shape << " |";
  for (size_t t = 0; t < timings.size(); ++t) {
    std::string code;
    for (const ListedFamily* f : families) {
      const std::string name = isa_name(f->provider[t]);
      if (code.find(name) == std::string::npos) code += (code.empty() ? "" : ", ") + name;
    }
    s << ' ' << code << " | " << format("%.3f", timings[t].ms) << " | " << format("%.1f", timings[t].gbs) << " |";
  }
  return s.str() + "\n";
}

// Times every workload once per ISA, in the lists' order of their first family.
void time_families(const std::vector<Isa>& isas, ThreadPool& pool, const Options& o, Report& report) {
  const std::vector<FamilyWorkload> workloads = family_workloads();
  const std::vector<ListedFamily> families = listed_families(isas);
  std::vector<const FamilyWorkload*> done;
  report.add(families_section(isas));
  for (const ListedFamily& family : families) {
    const FamilyWorkload& w = workload_of(workloads, family.name);
    if (std::find(done.begin(), done.end(), &w) != done.end()) continue;
    done.push_back(&w);
    std::vector<const ListedFamily*> covered;
    for (const ListedFamily& f : families)
      if (std::find(w.families.begin(), w.families.end(), f.name) != w.families.end()) covered.push_back(&f);
    const FamilyCall call = w.make();
    std::vector<Timing> timings;
    for (Isa isa : isas) timings.push_back(time_calls([&] { call(isa, pool); }, 0, w.bytes, pool.size(), o));
    report.add(family_row(covered, w, timings));
  }
}

// The targets, for the best ISA: 1x1 convolutions with >= 64 channels on both
// sides at >= 60% of the FMA peak, depthwise ones at >= 50% of the bandwidth (the
// whole network's 2-thread scaling, scaling_target, follows them).
std::string targets(const std::vector<Layer>& layers, const std::vector<Timing>& best, const Limits& lim,
                    Isa isa) {
  std::ostringstream s;
  s << "\n## Targets (" << isa_name(isa) << ")\n\n";
  for (size_t i = 0; i < layers.size(); ++i) {
    const Layer& l = layers[i];
    const bool pointwise = l.p.kernel_h == 1 && l.p.kernel_w == 1 && l.p.groups == 1;
    double target = 0;
    if (pointwise && std::min(l.p.in_c, l.p.out_c) >= 64) target = 0.6;
    else if (l.memory_bound()) target = 0.5;
    else continue;
    const double f = lim.fraction(l.memory_bound(), best[i]);
    s << "- " << l.name << " at " << l.in_w << "x" << l.in_h << ": " << format("%.0f%%", 100 * f)
      << " of " << (l.memory_bound() ? "bandwidth" : "FMA peak") << " (target "
      << format("%.0f%%", 100 * target) << ") " << (f >= target ? "met" : "NOT met") << "\n";
  }
  return s.str();
}

// The whole lite network (bundled weights) on a 1024x768 image, with 1 and with 2
// threads: median wall-clock latency of each and their ratio. Always wall time: CPU time
// cannot see threads waiting for each other, which is what scaling is about. The 1- and
// 2-thread runs alternate, so a burst of load from other processes lands on both.
struct Scaling {
  double ms1 = 0, ms2 = 0;
  double ratio() const { return ms1 / ms2; }
};

Scaling network_scaling(const std::string& weights, int runs) {
  const std::unique_ptr<DepthModel> net = load_depth_model(weights);
  Tensor rgb = Tensor::empty({kNetworkH, kNetworkW, 3});
  const std::vector<float> values = random_floats(static_cast<size_t>(rgb.numel()), 4);
  // Pixels in [0, 1], as a decoded photo's are.
  std::transform(values.begin(), values.end(), rgb.f32(), [](float v) { return 0.5f + 0.5f * v; });
  ThreadPool one(1), two(2);
  const auto seconds = [&](ThreadPool& pool) {
    const Stopwatch watch(Clock::Wall, pool.size());
    net->run(rgb.f32(), kNetworkH, kNetworkW, pool);
    return watch.seconds();
  };
  seconds(one);  // warm-up: plans the arena, touches its pages
  seconds(two);
  std::vector<double> s1, s2;
  for (int r = 0; r < runs; ++r) {
    s1.push_back(seconds(one));
    s2.push_back(seconds(two));
  }
  return {median(s1) * 1e3, median(s2) * 1e3};
}

std::string scaling_section(const std::string& weights, const Scaling& s, int runs) {
  std::ostringstream out;
  out << "\n## Whole lite network, 2 threads vs 1\n\n"
      << "`" << weights << "` on a " << kNetworkW << "x" << kNetworkH << " image (DepthModel::run, "
      << isa_name(active_isa()) << "), median of " << runs
      << " runs each, 1- and 2-thread runs alternating, wall clock.\n\n"
      << "| threads | ms |\n|---:|---:|\n"
      << "| 1 | " << format("%.1f", s.ms1) << " |\n"
      << "| 2 | " << format("%.1f", s.ms2) << " |\n";
  return out.str();
}

std::string scaling_target(const Scaling& s) {
  return "- lite network at " + std::to_string(kNetworkW) + "x" + std::to_string(kNetworkH) + ", 2 threads vs 1: " +
         format("%.2fx", s.ratio()) + " (target " + format("%.1fx", kScalingTarget) + ") " +
         (s.ratio() >= kScalingTarget ? "met" : "NOT met") + "\n";
}


// The convolution table; returns the active ISA's timing of each layer (for the targets).
std::vector<Timing> time_convolutions(const std::vector<Layer>& layers, const std::vector<Isa>& isas,
                                      const Limits& lim, ThreadPool& pool, const Options& o, Report& report) {
  report.add(convolution_section(isas));
  std::vector<Timing> active;
  for (const Layer& l : layers) {
    const LayerData d(l);
    std::vector<Timing> timings;
    for (Isa isa : isas) timings.push_back(time_layer(l, d, kernels_for(isa), pool, o));
    active.push_back(timings[std::find(isas.begin(), isas.end(), lim.isa) - isas.begin()]);
    report.add(row(label(l), timings, lim));
  }
  return active;
}

void time_products(const std::vector<Isa>& isas, const Limits& lim, ThreadPool& pool, const Options& o,
                   Report& report) {
  report.add(gemm_section(isas));
  for (const Product& p : vit_products()) {
    std::vector<Timing> timings;
    for (Isa isa : isas) timings.push_back(time_product(p, kernels_for(isa), pool, o));
    report.add(row(label(p), timings, lim));
  }
}

}  // namespace

int kernels_benchmark(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  ThreadPool pool(o.threads);
  const std::vector<Isa> isas = runnable_isas();
  Limits lim{active_isa()};
  lim.peak_gflops = fma_peak_gflops(lim.isa, pool, kLimitRuns, o.clock);
  lim.bandwidth_gbs = memory_bandwidth_gbs(pool, kBandwidthArrayBytes, kLimitRuns, o.clock);
  Report report;
  report.add(header(o, lim));
  const std::vector<Layer> layers = network_layers();
  const std::vector<Timing> active_timings = time_convolutions(layers, isas, lim, pool, o, report);
  time_products(isas, lim, pool, o, report);
  time_families(isas, pool, o, report);
  const std::string weights = depth_weights_path({}, "lite");
  const Scaling scaling = network_scaling(weights, o.runs);
  report.add(scaling_section(weights, scaling, o.runs));
  report.add(targets(layers, active_timings, lim, lim.isa) + scaling_target(scaling));
  std::ofstream file(o.out);
  if (!(file << report.text))
    throw std::runtime_error(o.out + ": cannot write the results table");
  std::printf("\nwrote %s\n", o.out.c_str());
  return 0;
}

}  // namespace ampi::bench
