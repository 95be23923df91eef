// Loops over the channels of one NHWC pixel in 4-float vectors, the last one partial.
// Include only from *_neon.cpp files. Same pattern as kernels/x86/avx2_channels.h; NEON
// has no masked loads, so the partial vector goes through a 4-float buffer.
#pragma once
#include <arm_neon.h>

#include <cstring>

namespace ampi::neon {

struct FullVector {
  float32x4_t load(const float* p) const { return vld1q_f32(p); }
  void store(float* p, float32x4_t v) const { vst1q_f32(p, v); }
};

// Reads and writes only the first n lanes; the other lanes load as 0.
struct PartialVector {
  int n;
  float32x4_t load(const float* p) const {
    float lanes[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    std::memcpy(lanes, p, sizeof(float) * n);
    return vld1q_f32(lanes);
  }
  void store(float* p, float32x4_t v) const {
    float lanes[4];
    vst1q_f32(lanes, v);
    std::memcpy(p, lanes, sizeof(float) * n);
  }
};

class Channels {
 public:
  explicit Channels(int c) : c_(c), whole_(c - c % 4), tail_{c % 4} {}
  // Calls body(j, accessor) for j = 0, 4, 8, ... < c.
  template <class Body>
  void each(Body&& body) const {
    for (int j = 0; j < whole_; j += 4) body(j, FullVector{});
    if (whole_ < c_) body(whole_, tail_);
  }

 private:
  int c_, whole_;
  PartialVector tail_;
};

}  // namespace ampi::neon
