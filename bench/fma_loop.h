// The loops the FMA peak (machine_limits.h) is measured with: one per instruction set,
// each in a file of its own (fma_loop_ISA.cpp) that cmake/isa.cmake compiles with that
// ISA's flags, as it does every kernel. Each runs `iterations` steps of kFmaChains
// independent chains acc = acc * kFmaMul + kFmaAdd, all lanes of the ISA's widest
// register, chain j starting at start + 0.01 j, and returns a value that depends on every
// chain, so no work can be dropped. The caller passes a start the compiler cannot know:
// from constants it could run the chains at compile time (1.0 is a fixed point of the
// step in float) and drop the loop.
#pragma once
#include <cstdint>

namespace ampi::bench {

// More chains than FMA latency x FMA ports (4 x 2 on current cores), so the loop runs at
// FMA throughput, and few enough to stay in registers.
constexpr int kFmaChains = 12;
// Multiplier and addend keep the accumulators finite and normal for any run length.
constexpr float kFmaMul = 0.9999999f, kFmaAdd = 1e-7f;

namespace avx2 {
float fma_loop(int64_t iterations, float start);  // 8 lanes
}
namespace avx512 {
float fma_loop(int64_t iterations, float start);  // 16 lanes
}
namespace neon {
float fma_loop(int64_t iterations, float start);  // 4 lanes
}

}  // namespace ampi::bench
