// Benchmarks behind `ampi bench WHAT`. Each takes its own argv (argv[0] = WHAT),
// prints a table and writes it to bench/RESULTS-WHAT.md.
#pragma once

namespace ampi::bench {

}  // namespace ampi::bench
