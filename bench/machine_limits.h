// The machine's limits the kernel benchmark is judged against, measured in the same run
// as the kernels: the FP32 FMA peak (what a 1x1 convolution can reach) and the streaming
// memory bandwidth (what bounds a depthwise convolution).
#pragma once
#include <cstddef>

#include "engine/isa.h"
#include "engine/thread_pool.h"

namespace ampi::bench {

// What the benchmarks' seconds are. Wall: elapsed time, what a user waits for. Cpu: the
// process's CPU time divided by the pool's threads; on a shared, loaded machine it leaves
// out the time other processes held the cores, but it also leaves out threads waiting
// idle, so judge thread scaling with wall time.
enum class Clock { Wall, Cpu };
const char* clock_name(Clock clock);

// Starts at construction.
class Stopwatch {
 public:
  Stopwatch(Clock clock, int threads);
  double seconds() const;

 private:
  static double now(Clock clock);
  Clock clock_;
  int threads_;
  double start_;
};

// FP32 FMA peak in GFLOP/s (an FMA counts 2 FLOPs per lane) of the pool's threads all
// running isa's widest FMA on independent register-resident chains, never touching
// memory. Median of `runs` timings. Scalar counts one float per FMA.
double fma_peak_gflops(Isa isa, ThreadPool& pool, int runs, Clock clock);

// Streaming bandwidth in GB/s (bytes read plus bytes written per second, the STREAM
// convention) of the triad a[i] = b[i] + s * c[i] on the pool's threads, over three
// arrays of `array_bytes` each, far larger than the last-level cache. Median of `runs`.
double memory_bandwidth_gbs(ThreadPool& pool, size_t array_bytes, int runs, Clock clock);

}  // namespace ampi::bench
