#include "bench/machine_limits.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdint>
#include <numeric>
#include <vector>

#include "bench/bench.h"
#include "bench/fma_loop.h"
#include "engine/tensor.h"

namespace ampi::bench {
namespace {

// Loop iterations per thread per timed run: 480M FMAs, a tenth of a second or so.
constexpr int64_t kIterations = 40'000'000;

// Returns a value that depends on every chain, so no work can be dropped. It must stay
// scalar: that is what the scalar table's code can use.
__attribute__((optimize("no-tree-vectorize"))) float scalar_fma_loop(int64_t iterations, float start) {
  float acc[kFmaChains];
  for (int j = 0; j < kFmaChains; ++j) acc[j] = start + 0.01f * j;
  for (int64_t i = 0; i < iterations; ++i)
    for (int j = 0; j < kFmaChains; ++j) acc[j] = acc[j] * kFmaMul + kFmaAdd;
  return std::accumulate(acc, acc + kFmaChains, 0.0f);
}

struct FmaLoop {
  float (*run)(int64_t iterations, float start);
  int lanes;
};

FmaLoop fma_loop_for(Isa isa) {
  switch (isa) {
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2: return {avx2::fma_loop, 8};
    case Isa::Avx512: return {avx512::fma_loop, 16};
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon: return {neon::fma_loop, 4};
#endif
    default: return {scalar_fma_loop, 1};
  }
}

// Keeps the loops' results observable.
volatile float g_sink;
// The chains' start, read at run time so the compiler cannot fold the loops (fma_loop.h).
volatile float g_fma_start = 1.0f;

}  // namespace

const char* clock_name(Clock clock) { return clock == Clock::Wall ? "wall" : "cpu"; }

Stopwatch::Stopwatch(Clock clock, int threads) : clock_(clock), threads_(threads), start_(now(clock)) {}

double Stopwatch::seconds() const {
  const double elapsed = now(clock_) - start_;
  return clock_ == Clock::Wall ? elapsed : elapsed / threads_;
}

double Stopwatch::now(Clock clock) {
  if (clock == Clock::Wall)
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double fma_peak_gflops(Isa isa, ThreadPool& pool, int runs, Clock clock) {
  const FmaLoop loop = fma_loop_for(isa);
  const int threads = pool.size();
  std::vector<float> results(threads);
  std::vector<double> rates;
  for (int r = 0; r < runs; ++r) {
    const Stopwatch watch(clock, pool.size());
    // One index per thread: each runs the loop once.
    pool.parallel_for(threads, 1, [&](int64_t first, int64_t last) {
      for (int64_t t = first; t < last; ++t) results[t] = loop.run(kIterations, g_fma_start);
    });
    const double flops = 2.0 * kIterations * kFmaChains * loop.lanes * threads;
    rates.push_back(flops / watch.seconds() * 1e-9);
    g_sink = std::accumulate(results.begin(), results.end(), 0.0f);
  }
  return median(rates);
}

double memory_bandwidth_gbs(ThreadPool& pool, size_t array_bytes, int runs, Clock clock) {
  const int64_t n = static_cast<int64_t>(array_bytes / sizeof(float));
  AlignedBuffer a_buf = aligned_alloc64(array_bytes), b_buf = aligned_alloc64(array_bytes),
                c_buf = aligned_alloc64(array_bytes);
  float* a = static_cast<float*>(a_buf.get());
  float* b = static_cast<float*>(b_buf.get());
  float* c = static_cast<float*>(c_buf.get());
  // Touch every page before timing, on the threads that will stream it.
  pool.parallel_for(n, 1 << 16, [&](int64_t first, int64_t last) {
    std::fill(a + first, a + last, 0.0f);
    std::fill(b + first, b + last, 1.0f);
    std::fill(c + first, c + last, 2.0f);
  });
  std::vector<double> rates;
  for (int r = 0; r < runs; ++r) {
    const Stopwatch watch(clock, pool.size());
    pool.parallel_for(n, 1 << 16, [&](int64_t first, int64_t last) {
      for (int64_t i = first; i < last; ++i) a[i] = b[i] + 0.5f * c[i];
    });
    rates.push_back(3.0 * static_cast<double>(array_bytes) / watch.seconds() * 1e-9);
  }
  g_sink = a[n / 2];
  return median(rates);
}

}  // namespace ampi::bench
