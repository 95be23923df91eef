// What the kernel tests sweep over: channel counts around every vector width (4 for NEON,
// 8 for AVX2, 16 for AVX-512), thread counts, activations. AMPI_TEST_SMALL=1 picks a
// subset that runs in seconds under qemu (about 150x slower on float code).
#pragma once
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "engine/thread_pool.h"
#include "kernels/activation.h"

namespace ampi::test {

inline bool small_tests() {
  const char* v = std::getenv("AMPI_TEST_SMALL");
  return v && *v && std::strcmp(v, "0") != 0;
}

inline std::vector<int> channel_sweep() {
  if (small_tests()) return {1, 3, 4, 7, 8, 9, 17};
  return {1, 3, 4, 7, 8, 9, 15, 16, 17, 31, 32, 33, 64};
}

// Pools of 1, 2 and 3 threads, made once per test binary.
inline std::vector<ThreadPool*> thread_pools() {
  static std::unique_ptr<ThreadPool> pools[] = {std::make_unique<ThreadPool>(1),
                                                std::make_unique<ThreadPool>(2),
                                                std::make_unique<ThreadPool>(3)};
  return {pools[0].get(), pools[1].get(), pools[2].get()};
}

inline const std::vector<ActivationSpec>& all_activations() {
  static const std::vector<ActivationSpec> list = {
      {Activation::None},      {Activation::ReLU},           {Activation::ReLU6},
      {Activation::HardSwish}, {Activation::HardSigmoid},    {Activation::Sigmoid},
      {Activation::LeakyReLU, 0.2f}, {Activation::ELU, 1.0f}, {Activation::Tanh}};
  return list;
}

struct MapSize {
  int h, w;
};

// Spatial sizes, odd and even, of the smaller side of a 2x resampling; the largest splits
// over several threads even with one channel.
inline std::vector<MapSize> half_sizes() {
  if (small_tests()) return {{1, 1}, {3, 2}, {2, 5}};
  return {{1, 1}, {1, 4}, {2, 3}, {3, 2}, {5, 7}, {8, 6}, {9, 16}, {64, 48}};
}

// An output buffer whose n values start as NaN (so a value never written fails the
// comparison) followed by guard floats that must stay untouched (so a write past the
// end fails too).
class GuardedOutput {
 public:
  explicit GuardedOutput(size_t n) : n_(n), data_(n + kGuard, kSentinel) {
    for (size_t i = 0; i < n; ++i) data_[i] = std::numeric_limits<float>::quiet_NaN();
  }
  float* data() { return data_.data(); }
  const float* data() const { return data_.data(); }
  size_t size() const { return n_; }
  bool guard_intact() const {
    for (size_t i = n_; i < data_.size(); ++i)
      if (data_[i] != kSentinel) return false;
    return true;
  }

 private:
  static constexpr size_t kGuard = 32;
  static constexpr float kSentinel = 1234.5f;
  size_t n_;
  std::vector<float> data_;
};

}  // namespace ampi::test
