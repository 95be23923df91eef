// The one sweep harness of the kernel tests (as ncnn's testutil): what every test sweeps
// over and how it checks an output. Channel counts around every vector width (4 for
// NEON, 8 for AVX2, 16 for AVX-512) and panel width, odd lengths and sizes, thread counts,
// every activation, every runnable ISA, fixed seeds (support/random.h) printed on failure.
// AMPI_TEST_SMALL=1 picks a subset that runs in seconds under qemu (about 150x slower on
// float code). The convolution cases (conv_cases.h) and the GEMM test build on it.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "engine/isa.h"
#include "engine/thread_pool.h"
#include "kernels/activation.h"
#include "support/random.h"

namespace ampi::test {

inline bool small_tests() {
  const char* v = std::getenv("AMPI_TEST_SMALL");
  return v && *v && std::strcmp(v, "0") != 0;
}

// Picks the full or the small list.
template <typename T>
std::vector<T> sweep(std::vector<T> full, std::vector<T> small) {
  return small_tests() ? small : full;
}

// Channel counts below, at and above each vector width, and multiples of them.
inline std::vector<int> channel_sweep() {
  return sweep<int>({1, 3, 4, 7, 8, 9, 15, 16, 17, 31, 32, 33, 64}, {1, 3, 4, 7, 8, 9, 17});
}

// Row lengths for row kernels: every vector body and tail, and a long row.
inline std::vector<int> length_sweep() { return {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 32, 33, 64, 100}; }

// Pools of 1, 2 and 3 threads, made once per test binary.
inline std::vector<ThreadPool*> thread_pools() {
  static std::unique_ptr<ThreadPool> pools[] = {std::make_unique<ThreadPool>(1),
                                                std::make_unique<ThreadPool>(2),
                                                std::make_unique<ThreadPool>(3)};
  return {pools[0].get(), pools[1].get(), pools[2].get()};
}

// Every activation of the fused epilogues, with a LeakyReLU slope and an ELU alpha
// that are not the identity on negative inputs.
inline const std::vector<ActivationSpec>& all_activations() {
  static const std::vector<ActivationSpec> list = {
      {Activation::None},      {Activation::ReLU},           {Activation::ReLU6},
      {Activation::HardSwish}, {Activation::HardSigmoid},    {Activation::Sigmoid},
      {Activation::LeakyReLU, 0.1f}, {Activation::ELU, 1.0f}, {Activation::Tanh},
      {Activation::GELU}};
  return list;
}

struct MapSize {
  int h, w;
};

// Spatial sizes, odd and even, of the smaller side of a 2x resampling; the largest splits
// over several threads even with one channel.
inline std::vector<MapSize> half_sizes() {
  return sweep<MapSize>({{1, 1}, {1, 4}, {2, 3}, {3, 2}, {5, 7}, {8, 6}, {9, 16}, {64, 48}},
                        {{1, 1}, {3, 2}, {2, 5}});
}

// An output buffer whose n values start as NaN (so a value never written fails the
// comparison) followed by guard floats that must stay untouched (so a write past the
// end fails too): a full AVX-512 vector and more.
class GuardedOutput {
 public:
  explicit GuardedOutput(size_t n) : n_(n), data_(n + kGuard, kSentinel) {
    std::fill(data_.begin(), data_.begin() + n, std::numeric_limits<float>::quiet_NaN());
  }
  float* data() { return data_.data(); }
  const float* data() const { return data_.data(); }
  size_t size() const { return n_; }
  bool guard_intact() const {
    return std::all_of(data_.begin() + n_, data_.end(), [](float v) { return v == kSentinel; });
  }
  // The n values, without the guard.
  std::vector<float> values() const { return std::vector<float>(data_.begin(), data_.begin() + n_); }

 private:
  static constexpr size_t kGuard = 64;
  static constexpr float kSentinel = 12345.0f;
  size_t n_;
  std::vector<float> data_;
};

// Outputs of sums are judged relative to the magnitude of what the kernels add up
// (before the activation, plus the residual): an activation can shrink an output (the
// sigmoid of a large sum) but not the rounding error of the sum before it.
constexpr float kRelativeTolerance = 1e-5f;

inline float max_abs(const std::vector<float>& v) {
  float m = 0.0f;
  for (float x : v) m = std::max(m, std::fabs(x));
  return m;
}

}  // namespace ampi::test
