// ampi bench network: DepthModel::run alone, timed on a given input, so that the peer
// benchmark (bench/peers/run.sh) can put ampi beside ONNX Runtime, OpenCV DNN and
// PyTorch running the same network on the same pixels. Prints one JSON line per thread
// count (what bench/peers/run_peers.py reads) and can save the output as .npy.
#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "cli/args.h"
#include "engine/isa.h"
#include "engine/thread_pool.h"
#include "nets/model_loader.h"
#include "nets/bundled_weights.h"
#include "weights_format/npy.h"

namespace ampi::bench {
namespace {

const char kUsage[] =
    "usage: ampi bench network --input RGB.npy [--model NAME | --weights FILE]\n"
    "                          [--threads LIST] [--runs N] [--warmup N] [--save PREFIX]\n"
    "\n"
    "Times DepthModel::run on one image: RGB.npy holds H x W x 3 float32 values in [0, 1]\n"
    "(any H and W; the network pads them to its multiple and crops the output back).\n"
    "For each thread count, runs N times after the warm-up runs and prints one line:\n"
    "  {\"engine\": \"ampi\", \"model\": ..., \"isa\": ..., \"threads\": T, \"ms\": [...]}\n"
    "bench/peers/run.sh uses it to compare ampi with ONNX Runtime, OpenCV DNN and PyTorch.\n"
    "\n"
    "  --model NAME     a bundled depth model by name: lite (default), heavy, ...\n"
    "  --weights FILE   a depth weight file instead\n"
    "  --threads LIST   comma-separated thread counts (default 1,2)\n"
    "  --runs N         timed runs per thread count (default 5)\n"
    "  --warmup N       untimed runs first (default 1; the first plans the arena)\n"
    "  --save PREFIX    writes the output (H x W disparity) to PREFIX.tT.npy per count T\n";

std::vector<int> parse_thread_list(const std::string& text) {
  std::vector<int> counts;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    size_t used = 0;
    int n = 0;
    try {
      n = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || n < 1 || n > 256)
      throw std::runtime_error("--threads: '" + text + "' is not a list of counts 1..256");
    counts.push_back(n);
  }
  if (counts.empty()) throw std::runtime_error("--threads: empty list");
  return counts;
}

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

int network_benchmark(int argc, char** argv) {
  std::string input, model = "lite", weights, threads_text = "1,2", save;
  int runs = 5, warmup = 1;
  cli::ArgParser p("bench network", kUsage);
  p.option("--input", &input);
  p.option("--model", &model);
  p.option("--weights", &weights);
  p.option("--threads", &threads_text);
  p.option("--runs", &runs, 1, 1000);
  p.option("--warmup", &warmup, 0, 1000);
  p.option("--save", &save);
  if (!p.parse(argc, argv)) return 0;
  if (input.empty()) throw std::runtime_error("network: --input RGB.npy is required");
  const std::vector<int> thread_counts = parse_thread_list(threads_text);

  const Tensor rgb = read_rgb(input);
  const std::unique_ptr<DepthModel> net = load_depth_model(depth_weights_path(weights, model));
  for (int threads : thread_counts) {
    ThreadPool pool(threads);
    Tensor output;
    const std::vector<double> ms = time_runs(*net, rgb, pool, warmup, runs, &output);
    std::printf("%s\n", json_line(net->variant(), threads, ms).c_str());
    std::fflush(stdout);
    if (!save.empty()) write_npy(save + ".t" + std::to_string(threads) + ".npy", output);
  }
  return 0;
}

}  // namespace ampi::bench
