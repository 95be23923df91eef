// ampi bench kernels: the convolution kernels on the layer shapes of the lite depth
// network at 1024x768, every runnable ISA side by side, judged against the machine's
// limits measured in the same run: the FMA peak for 1x1 and general convolutions (they
// are compute bound) and the memory bandwidth for depthwise ones (memory bound).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "bench/machine_limits.h"
#include "engine/tensor.h"
#include "kernels/conv.h"
#include "nets/model_loader.h"
#include "nets/bundled_weights.h"

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
// 3x3 convolutions.
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
    "  Times every convolution kernel of every runnable ISA on the lite depth network's\n"
    "  layer shapes at 1024x768 and compares with the FMA peak and memory bandwidth\n"
    "  measured in the same run, then the whole lite network (bundled weights) at 1024x768\n"
    "  with 1 and with 2 threads, and prints each target's fraction and verdict.\n"
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

// The activations live in 64-byte-aligned tensors, as the networks' do (their arena is
// 64-byte aligned and rounds every buffer to 64 bytes). A std::vector of this size comes
// from mmap 16 bytes past a page start, so every AVX-512 load of it would straddle two
// cache lines: the kernels measured 1.5-3.5x slower on such buffers than in the network.
struct LayerData {
  Tensor in, out;
  std::vector<float> weights, bias;
  explicit LayerData(const Layer& l) {
    const ConvParams& p = l.p;
    in = Tensor::empty({l.in_h, l.in_w, p.in_c});
    const std::vector<float> values = random_floats(static_cast<size_t>(in.numel()), 1);
    std::copy(values.begin(), values.end(), in.f32());
    weights = random_floats(static_cast<size_t>(p.out_c) * p.kernel_h * p.kernel_w * (p.in_c / p.groups), 2);
    bias = random_floats(p.out_c, 3);
    out = Tensor::zeros({p.out_h(l.in_h), p.out_w(l.in_w), p.out_c});
  }
};

Timing time_layer(const Layer& l, const LayerData& d, const KernelTable& k, ThreadPool& pool,
                  const Options& o) {
  const Conv2d conv(l.p, d.weights.data(), d.bias.data(), k);
  float* out = const_cast<float*>(d.out.f32());
  conv.run(d.in.f32(), l.in_h, l.in_w, out, nullptr, pool);  // warm-up: pages, caches
  std::vector<double> seconds;
  for (int r = 0; r < o.runs; ++r) {
    const Stopwatch watch(o.clock, pool.size());
    conv.run(d.in.f32(), l.in_h, l.in_w, out, nullptr, pool);
    seconds.push_back(watch.seconds());
  }
  std::sort(seconds.begin(), seconds.end());
  const double s = seconds[seconds.size() / 2];
  const double macs = static_cast<double>(d.out.numel()) * l.p.kernel_h * l.p.kernel_w * (l.p.in_c / l.p.groups);
  const double bytes = 4.0 * static_cast<double>(d.in.numel() + d.out.numel() + d.weights.size() + d.bias.size());
  return {s * 1e3, 2.0 * macs / s * 1e-9, bytes / s * 1e-9};
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
  double fraction(const Layer& l, const Timing& t) const {
    return l.memory_bound() ? t.gbs / bandwidth_gbs : t.gflops / peak_gflops;
  }
};

std::string header(const Options& o, const Limits& lim, const std::vector<Isa>& isas) {
  std::ostringstream s;
  s << "# Convolution kernels vs the machine's limits (`ampi bench kernels`)\n\n"
    << "CPU: " << cpu_name() << "; " << o.threads << " thread(s); median of " << o.runs
    << " runs per kernel; " << clock_name(o.clock) << " clock"
    << (o.clock == Clock::Cpu ? " (process CPU time per thread: other processes' share of the cores left out)" : "")
    << ".\n\n"
    << "Limits measured in the same run, on the same threads:\n"
    << "- FP32 FMA peak (" << isa_name(lim.isa) << ", register-resident FMA loop): "
    << format("%.1f", lim.peak_gflops) << " GFLOP/s\n"
    << "- memory bandwidth (triad a = b + s*c, 3 arrays of " << (kBandwidthArrayBytes >> 20)
    << " MiB): " << format("%.1f", lim.bandwidth_gbs) << " GB/s\n\n"
    << "Layers: a MobileNetV3-style depth network on a 1024x768 photo (Haar DWT to 512x384x12, "
    << "then 512x384, 256x192, 128x96), plus the inpainting generator's dilated 3x3. "
    << "\"of limit\" is GFLOP/s over the FMA peak for 1x1 and general convolutions, GB/s "
    << "over the bandwidth for depthwise ones; bytes count the input and output once and "
    << "the weights. Every ISA is compared with the same limits (the active ISA's peak).\n\n"
    << "| layer | input | output |";
  for (Isa isa : isas) s << ' ' << isa_name(isa) << " ms | GFLOP/s | GB/s | of limit |";
  s << "\n|---|---|---|";
  for (size_t i = 0; i < isas.size(); ++i) s << "---:|---:|---:|---:|";
  s << "\n";
  return s.str();
}

std::string row(const Layer& l, const std::vector<Timing>& timings, const Limits& lim) {
  std::ostringstream s;
  s << "| " << l.name << " | " << l.in_w << "x" << l.in_h << " | " << l.p.out_w(l.in_w) << "x"
    << l.p.out_h(l.in_h) << " |";
  for (const Timing& t : timings)
    s << ' ' << format("%.2f", t.ms) << " | " << format("%.1f", t.gflops) << " | " << format("%.1f", t.gbs)
      << " | " << format("%.0f%%", 100.0 * lim.fraction(l, t)) << " |";
  return s.str() + "\n";
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
    const double f = lim.fraction(l, best[i]);
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
  std::string table = header(o, lim, isas);
  std::fputs(table.c_str(), stdout);
  const std::vector<Layer> layers = network_layers();
  std::vector<Timing> active_timings;
  for (const Layer& l : layers) {
    const LayerData d(l);
    std::vector<Timing> timings;
    for (Isa isa : isas) timings.push_back(time_layer(l, d, kernels_for(isa), pool, o));
    active_timings.push_back(timings[std::find(isas.begin(), isas.end(), lim.isa) - isas.begin()]);
    const std::string line = row(l, timings, lim);
    std::fputs(line.c_str(), stdout);
    std::fflush(stdout);
    table += line;
  }
  const std::string weights = depth_weights_path({}, "lite");
  const Scaling scaling = network_scaling(weights, o.runs);
  const std::string network = scaling_section(weights, scaling, o.runs);
  std::fputs(network.c_str(), stdout);
  table += network;
  const std::string summary = targets(layers, active_timings, lim, lim.isa) + scaling_target(scaling);
  std::fputs(summary.c_str(), stdout);
  table += summary;
  std::ofstream file(o.out);
  if (!(file << table))
    throw std::runtime_error(o.out + ": cannot write the results table");
  std::printf("\nwrote %s\n", o.out.c_str());
  return 0;
}

}  // namespace ampi::bench
