#include "bench/network_bench.h"

#include <cstdio>
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

}  // namespace

int network_benchmark(const NetworkBenchOptions& o) {
  const Tensor rgb = read_rgb(o.input);
  const std::unique_ptr<DepthModel> net = load_depth_model(depth_weights_path(o.weights, o.model));
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
