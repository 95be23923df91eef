// ampi bench WHAT: latency benchmarks. Each benchmark lives in bench/ and writes its
// table into the repository (bench/RESULTS-*.md) as well as to stdout. The network and
// pipeline benchmarks' options are parsed here, with the parser of the other subcommands,
// so bench/ needs nothing from cli/.
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "bench/network_bench.h"
#include "bench/pipeline_bench.h"
#include "cli/args.h"
#include "cli/commands.h"
#include "pipeline/photo_io.h"

namespace ampi::cli {
namespace {

const char kNetworkUsage[] =
    "usage: ampi bench network --input RGB.npy [--model NAME | --weights FILE]\n"
    "                          [--threads LIST] [--runs N] [--warmup N] [--save PREFIX]\n"
    "\n"
    "Times DepthModel::run on one image: RGB.npy holds H x W x 3 float32 values in [0, 1]\n"
    "(any H and W; lite and heavy pad them to their multiple and crop the output back,\n"
    "Depth Anything V2 resizes to its working shape and back, as its reference does).\n"
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

int bench_network(int argc, char** argv) {
  bench::NetworkBenchOptions o;
  std::string threads = "1,2";
  ArgParser p("bench network", kNetworkUsage);
  p.option("--input", &o.input);
  p.option("--model", &o.model);
  p.option("--weights", &o.weights);
  p.option("--threads", &threads);
  p.option("--runs", &o.runs, 1, 1000);
  p.option("--warmup", &o.warmup, 0, 1000);
  p.option("--save", &o.save);
  if (!p.parse(argc, argv)) return 0;
  if (o.input.empty()) throw std::runtime_error("network: --input RGB.npy is required");
  o.threads = parse_int_list("--threads", threads, 1, 256, "a thread count");
  return bench::network_benchmark(o);
}

const char kPipelineUsage[] =
    "usage: ampi bench pipeline [--photo FILE] [--runs N] [--threads N] [--frames N] [--sizes LIST]\n"
    "                           [--inpainter network|harmonic|push-pull] [--working-size N] [--out FILE]\n"
    "\n"
    "Times every stage of `ampi run` (decode, depth, depth edges, slicing, assembly,\n"
    "inpainting, MPI write, render + encode of the video) on PHOTO resized to 1024x768 and\n"
    "to 3840x2160, medians of N runs, and each stage's peak resident memory (and the video\n"
    "encoder's, when the ffmpeg program encodes the MP4 in its own process). Also slicing's\n"
    "time as a share of the depth network's (both run at the same working resolution), and\n"
    "photo to MPI with and without depth edges, run by run. Writes the table to\n"
    "bench/RESULTS-pipeline.md.\n"
    "\n"
    "  --photo FILE   default examples/forest_path.jpg\n"
    "  --runs N       runs per size (default 3)\n"
    "  --threads N    worker threads (default 2)\n"
    "  --frames N     video frames rendered and encoded per run (default 30)\n"
    "  --sizes LIST   comma-separated WxH sizes (default 1024x768,3840x2160)\n"
    "  --inpainter NAME      network (default, as ampi run), harmonic or push-pull\n"
    "  --working-size N      the depth network's working size (default: the weight file's)\n"
    "  --out FILE     default bench/RESULTS-pipeline.md\n";

// "1024x768,3840x2160": each side at least kMinPhotoSide.
std::vector<cv::Size> parse_sizes(const std::string& option, const std::string& text) {
  std::vector<cv::Size> sizes;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    int width = 0, height = 0;
    char extra = 0;
    if (std::sscanf(item.c_str(), "%dx%d%c", &width, &height, &extra) != 2 || width < kMinPhotoSide ||
        height < kMinPhotoSide || width > 16384 || height > 16384)
      throw std::runtime_error(option + ": '" + item + "' is not a size WxH with sides from " +
                               std::to_string(kMinPhotoSide) + " to 16384");
    sizes.emplace_back(width, height);
    start = end + 1;
  }
  return sizes;
}

int bench_pipeline(int argc, char** argv) {
  bench::PipelineBenchOptions o;
  ArgParser p("bench pipeline", kPipelineUsage);
  p.option("--photo", &o.photo);
  p.option("--runs", &o.runs, 1, 100);
  p.option("--threads", &o.threads, 1, 256);
  p.option("--frames", &o.frames, 1, 10000);
  p.option("--out", &o.out);
  p.option("--inpainter", [&](const std::string& v) { o.mpi.inpainter = parse_inpainter(v); });
  p.option("--working-size", &o.mpi.working_size, kMinPhotoSide, 16384);
  p.option("--sizes", [&](const std::string& v) { o.sizes = parse_sizes("--sizes", v); });
  if (!p.parse(argc, argv)) return 0;
  return bench::pipeline_benchmark(o);
}

struct Benchmark {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};

const Benchmark kBenchmarks[] = {
    {"kernels", bench::kernels_benchmark, "every kernel family vs the machine's FMA peak and memory bandwidth"},
    {"render", bench::render_benchmark, "MPI renderer frames/s vs the naive compositor (1024x768, 8 planes)"},
    {"pipeline", bench_pipeline, "ampi run stage by stage, peak memory (1024x768 and 4K)"},
    {"network", bench_network, "the depth network alone on an .npy image (bench/peers/run.sh: vs its peers)"},
};

void usage(FILE* out) {
  std::fprintf(out, "usage: ampi bench WHAT [OPTIONS]\n\nbenchmarks:\n");
  for (const Benchmark& b : kBenchmarks)
    std::fprintf(out, "  %-10s %s\n", b.name, b.summary);
}

}  // namespace

int cmd_bench(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (const Benchmark& b : kBenchmarks)
    if (!std::strcmp(argv[1], b.name)) return b.run(argc - 1, argv + 1);
  std::fprintf(stderr, "ampi bench: unknown benchmark '%s'\n", argv[1]);
  usage(stderr);
  return 2;
}

}  // namespace ampi::cli
