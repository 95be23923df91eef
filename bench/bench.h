// Benchmarks behind `ampi bench WHAT`. Each takes its own argv (argv[0] = WHAT),
// prints a table and writes it to bench/RESULTS-WHAT.md.
#pragma once

namespace ampi::bench {

// ampi bench render [--frames N] [--naive-frames N] [--size WxH] [--planes N] [--out FILE]:
// the tiled compositor against the naive one, 2 threads and 1 (render_bench.cpp).
int render_benchmark(int argc, char** argv);

}  // namespace ampi::bench
