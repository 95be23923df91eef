// Haar DWT / inverse DWT and 2x resizes: hand-computed cases pin down the reference, then
// every runnable ISA and thread count is compared with the reference over shape sweeps.
#include <catch2/catch.hpp>
#include <stdexcept>
#include <vector>

#include "kernels/ops.h"
#include "kernels/reference/reference.h"
#include "support/random.h"
#include "kernel_sweeps.h"

using namespace ampi;

namespace {

using ResampleOp = void (*)(const float*, int, int, int, float*, ThreadPool&, const KernelTable&);
using ReferenceKernel = void (*)(const float*, int, int, int, int, int, float*);

struct ResampleCase {
  const char* name;
  ResampleOp op;
  ReferenceKernel reference;
  bool full_resolution_input;  // the DWT reads the 2h x 2w side
  int input_channel_factor;    // the IDWT reads 4c channels
  float tolerance;
};

// Runs one case for every ISA, thread count, channel count and size.
void check_against_reference(const ResampleCase& rc) {
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (int c : test::channel_sweep())
        for (test::MapSize half : test::half_sizes()) {
          const int in_h = rc.full_resolution_input ? 2 * half.h : half.h;
          const int in_w = rc.full_resolution_input ? 2 * half.w : half.w;
          const size_t in_n = static_cast<size_t>(in_h) * in_w * c * rc.input_channel_factor;
          // Every one of these ops has 4 * half.h * half.w * c outputs.
          const size_t out_n = static_cast<size_t>(4 * half.h) * half.w * c;
          const uint32_t seed = static_cast<uint32_t>(1000 * c + 10 * half.h + half.w);
          INFO(rc.name << ": isa " << isa_name(isa) << ", threads " << pool->size() << ", c " << c
                       << ", input " << in_h << "x" << in_w << ", seed " << seed);
          const std::vector<float> in = test::random_floats(in_n, seed);
          std::vector<float> expected(out_n);
          rc.reference(in.data(), in_h, in_w, c, 0, half.h, expected.data());
          test::GuardedOutput got(out_n);
          rc.op(in.data(), in_h, in_w, c, got.data(), *pool, kernels_for(isa));
          CHECK(test::max_abs_diff(expected.data(), got.data(), out_n) <= rc.tolerance);
          CHECK(got.guard_intact());
        }
}

}  // namespace

TEST_CASE("haar_dwt reference: one 2x2 block by hand") {
  const float in[] = {1, 2, 3, 4};  // x00 x01 / x10 x11, one channel
  float out[4];
  reference::haar_dwt(in, 2, 2, 1, 0, 1, out);
  CHECK(out[0] == 5.0f);   // LL = (1 + 2 + 3 + 4) / 2
  CHECK(out[1] == -1.0f);  // LH = (1 - 2 + 3 - 4) / 2
  CHECK(out[2] == -2.0f);  // HL = (1 + 2 - 3 - 4) / 2
  CHECK(out[3] == 0.0f);   // HH = (1 - 2 - 3 + 4) / 2
  float back[4];
  reference::haar_idwt(out, 1, 1, 1, 0, 1, back);
  for (int i = 0; i < 4; ++i) CHECK(back[i] == in[i]);
}

TEST_CASE("haar_dwt keeps channels apart and orders the bands LL LH HL HH") {
  // Two channels; channel 1 is channel 0 times 10.
  const float in[] = {1, 10, 2, 20, 3, 30, 4, 40};
  float out[8];
  reference::haar_dwt(in, 2, 2, 2, 0, 1, out);
  const float expected[] = {5, 50, -1, -10, -2, -20, 0, 0};
  for (int i = 0; i < 8; ++i) CHECK(out[i] == expected[i]);
}

TEST_CASE("resize2x_bilinear reference matches a hand-computed 2x2 case") {
  // in = [[0, 4], [8, 12]]: horizontally 0, 4 -> 0, 1, 3, 4 (weights 3/4 : 1/4, clamped
  // at the borders), vertically the rows 0 and 8 blend the same way.
  const float in[] = {0, 4, 8, 12};
  float out[16];
  reference::resize2x_bilinear(in, 2, 2, 1, 0, 2, out);
  const float expected[] = {0, 1, 3, 4, 2, 3, 5, 6, 6, 7, 9, 10, 8, 9, 11, 12};
  for (int i = 0; i < 16; ++i) {
    INFO("index " << i);
    CHECK(out[i] == Approx(expected[i]).margin(1e-6));
  }
}

TEST_CASE("resize2x_nearest reference repeats each pixel 2x2") {
  const float in[] = {1, -1, 2, -2};  // 1x2 pixels, 2 channels
  float out[16];
  reference::resize2x_nearest(in, 1, 2, 2, 0, 1, out);
  const float row[] = {1, -1, 1, -1, 2, -2, 2, -2};
  for (int i = 0; i < 16; ++i) CHECK(out[i] == row[i % 8]);
}

TEST_CASE("2x resampling: every ISA and thread count matches the reference") {
  const ResampleCase cases[] = {
      {"haar_dwt", haar_dwt, reference::haar_dwt, true, 1, 1e-6f},
      {"haar_idwt", haar_idwt, reference::haar_idwt, false, 4, 1e-6f},
      {"resize2x_nearest", resize2x_nearest, reference::resize2x_nearest, false, 1, 0.0f},
      {"resize2x_bilinear", resize2x_bilinear, reference::resize2x_bilinear, false, 1, 1e-6f},
  };
  for (const ResampleCase& rc : cases) check_against_reference(rc);
}

TEST_CASE("haar_idwt inverts haar_dwt for every ISA") {
  for (Isa isa : runnable_isas())
    for (int c : test::channel_sweep())
      for (test::MapSize half : test::half_sizes()) {
        const int h = 2 * half.h, w = 2 * half.w;
        const size_t n = static_cast<size_t>(h) * w * c;
        const uint32_t seed = static_cast<uint32_t>(77 * c + h + 3 * w);
        INFO("isa " << isa_name(isa) << ", c " << c << ", " << h << "x" << w << ", seed " << seed);
        const std::vector<float> in = test::random_floats(n, seed);
        std::vector<float> bands(n), back(n);
        ThreadPool& pool = *test::thread_pools()[1];
        haar_dwt(in.data(), h, w, c, bands.data(), pool, kernels_for(isa));
        haar_idwt(bands.data(), half.h, half.w, c, back.data(), pool, kernels_for(isa));
        CHECK(test::max_abs_diff(in.data(), back.data(), n) <= 1e-6f);
      }
}

TEST_CASE("2x resampling rejects sizes it cannot handle") {
  float buffer[64] = {};
  CHECK_THROWS_AS(haar_dwt(buffer, 3, 2, 1, buffer), std::runtime_error);
  CHECK_THROWS_AS(haar_dwt(buffer, 2, 5, 1, buffer), std::runtime_error);
  CHECK_THROWS_AS(haar_idwt(buffer, 0, 2, 1, buffer), std::runtime_error);
  CHECK_THROWS_AS(resize2x_bilinear(buffer, 2, 2, 0, buffer), std::runtime_error);
  CHECK_THROWS_AS(resize2x_nearest(buffer, -1, 2, 1, buffer), std::runtime_error);
}
