#include "bench/network_bench.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "engine/isa.h"
#include "engine/thread_pool.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "pipeline/progress.h"
#include "weights_format/npy.h"

namespace ampi::bench {
namespace {

// The image of `path`, checked to be H x W x 3.
Tensor read_rgb(const std::string& path) {
  Tensor rgb = read_npy(path);
  if (rgb.rank() != 3 || rgb.dim(2) != 3 || rgb.dim(0) < 1 || rgb.dim(1) < 1)
    throw std::runtime_error(path + ": expected an H x W x 3 array, got " + shape_str(rgb.shape()));
  return rgb;
}

std::vector<double> time_runs(DepthModel& net, const Tensor& rgb, ThreadPool& pool, int warmup, int runs,
                              Tensor* last_output) {
  const int h = static_cast<int>(rgb.dim(0)), w = static_cast<int>(rgb.dim(1));
  for (int i = 0; i < warmup; ++i) *last_output = net.run(rgb.f32(), h, w, pool);
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) ms.push_back(time_ms([&] { *last_output = net.run(rgb.f32(), h, w, pool); }));
  return ms;
}

std::string json_line(const std::string& variant, int threads, const std::vector<double>& ms) {
  std::ostringstream line;
  line << "{\"engine\": \"ampi\", \"model\": \"" << variant << "\", \"isa\": \"" << isa_name(active_isa())
       << "\", \"threads\": " << threads << ", \"ms\": [";
  for (size_t i = 0; i < ms.size(); ++i) line << (i ? ", " : "") << ms[i];
  line << "]}";
  return line.str();
}

// Loads the model, and tells on stderr how much the load raised the resident peak beside
// the file's size and the float weights' (loading reads the file once and packs its
// weights for the kernels, so the peak should stay within the two together).
std::unique_ptr<DepthModel> load_and_measure(const std::string& path) {
  const bool windowed = reset_peak_rss();
  const double before_mb = peak_rss_mb();
  std::unique_ptr<DepthModel> net = load_depth_model(path);
  if (windowed && before_mb > 0) {
    const double file_mb = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
    const double weights_mb = static_cast<double>(net->parameter_count()) * sizeof(float) / 1e6;
    std::fprintf(stderr, "ampi: loading %s raised the resident peak by %.1f MB (file %.1f MB, weights %.1f MB)\n",
                 path.c_str(), peak_rss_mb() - before_mb, file_mb, weights_mb);
  }
  return net;
}

}  // namespace

int network_benchmark(const NetworkBenchOptions& o) {
  const Tensor rgb = read_rgb(o.input);
  const std::unique_ptr<DepthModel> net = load_and_measure(depth_weights_path(o.weights, o.model));
  for (int threads : o.threads) {
    ThreadPool pool(threads);
    Tensor output;
    const std::vector<double> ms = time_runs(*net, rgb, pool, o.warmup, o.runs, &output);
    std::printf("%s\n", json_line(net->variant(), threads, ms).c_str());
    std::fflush(stdout);
    if (!o.save.empty()) write_npy(o.save + ".t" + std::to_string(threads) + ".npy", output);
  }
  return 0;
}

}  // namespace ampi::bench
