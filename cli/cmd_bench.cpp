// ampi bench WHAT: latency benchmarks. Each benchmark lives in bench/ and writes its
// table into the repository (bench/RESULTS-*.md) as well as to stdout.
#include <cstdio>
#include <cstring>

#include "bench/bench.h"
#include "cli/commands.h"

namespace ampi::cli {
namespace {

struct Benchmark {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};

const Benchmark kBenchmarks[] = {
    {"kernels", bench::kernels_benchmark, "convolution kernels vs the machine's FMA peak and memory bandwidth"},
    {"render", bench::render_benchmark, "MPI renderer frames/s vs the naive compositor (1024x768, 8 planes)"},
    {"pipeline", bench::pipeline_benchmark, "ampi run stage by stage, peak memory (1024x768 and 4K)"},
    {"network", bench::network_benchmark, "the depth network alone on an .npy image (bench/peers/run.sh: vs its peers)"},
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
