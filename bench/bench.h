// Benchmarks behind `ampi bench WHAT` (cli/cmd_bench.cpp) and the timing helpers they
// share. Each prints its results and writes its table into the repository (bench/).
// bench/ never includes cli/: the network and pipeline benchmarks take their options as
// structs (network_bench.h, pipeline_bench.h) that cli/cmd_bench.cpp parses the way the
// other subcommands parse theirs (--model, --weights, --inpainter, --working-size as in
// ampi depth and ampi run); kernels and render read their own few options from argv
// (argv[0] = WHAT).
#pragma once
#include <algorithm>
#include <chrono>
#include <vector>

namespace ampi::bench {

// The median of timed runs (the upper one of an even count); 0 for none.
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// Wall-clock milliseconds of one call of f.
template <class F>
double time_ms(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// ampi bench kernels [--threads N] [--runs N] [--clock wall|cpu] [--out FILE]: every
// kernel family of every runnable ISA, the convolutions and the GEMM op included, against
// the machine's FMA peak and memory bandwidth (kernels_bench.cpp).
int kernels_benchmark(int argc, char** argv);

// ampi bench render [--frames N] [--naive-frames N] [--size WxH] [--planes N] [--out FILE]:
// the tiled compositor against the naive one, 2 threads and 1 (render_bench.cpp).
int render_benchmark(int argc, char** argv);

}  // namespace ampi::bench
