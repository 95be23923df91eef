// Benchmarks behind `ampi bench WHAT`. Each takes its own argv (argv[0] = WHAT),
// prints a table and writes it to bench/RESULTS-WHAT.md.
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

// ampi bench kernels [--threads N] [--runs N] [--clock wall|cpu] [--out FILE]: convolution
// kernels of every runnable ISA against the machine's FMA peak and memory bandwidth
// (kernels_bench.cpp).
int kernels_benchmark(int argc, char** argv);

// ampi bench render [--frames N] [--naive-frames N] [--size WxH] [--planes N] [--out FILE]:
// the tiled compositor against the naive one, 2 threads and 1 (render_bench.cpp).
int render_benchmark(int argc, char** argv);

// ampi bench pipeline [--photo FILE] [--runs N] [--threads N] [--frames N] [--out FILE]:
// per-stage times of `ampi run` and peak memory at 1024x768 and 4K (pipeline_bench.cpp).
int pipeline_benchmark(int argc, char** argv);

// ampi bench network --input RGB.npy [--model NAME] [--threads LIST] [--runs N]
// [--save PREFIX]: DepthModel::run alone, one JSON line per thread count; the ampi side of
// the peer benchmark, bench/peers/run.sh (network_bench.cpp).
int network_benchmark(int argc, char** argv);

}  // namespace ampi::bench
