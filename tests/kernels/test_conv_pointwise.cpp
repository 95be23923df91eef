// Pointwise (1x1) convolution: the packed GEMM path, every runnable ISA against the
// direct reference.
#include "test_conv_util.h"

using namespace ampi;
using namespace ampi::test;

namespace {

// Below, at and above each vector width (NEON 4, AVX2 8, AVX-512 16) and panel width
// (8, 16, 32), and multiples of them.
std::vector<int> channel_counts() {
  return sweep<int>({1, 3, 4, 7, 8, 9, 15, 16, 17, 24, 31, 32, 33, 48, 64, 96}, {1, 4, 7, 9, 17, 33});
}

ConvCase pointwise(int in_c, int out_c, int h, int w, uint32_t seed) {
  ConvCase c;
  c.p.in_c = in_c;
  c.p.out_c = out_c;
  c.in_h = h;
  c.in_w = w;
  c.seed = seed;
  return c;
}

}  // namespace

TEST_CASE("pointwise conv matches the reference over input and output channel counts") {
  ThreadPool pool(2);
  uint32_t seed = 1000;
  for (int in_c : channel_counts())
    for (int out_c : channel_counts()) check_all_isas(pointwise(in_c, out_c, 5, 7, seed++), pool);
}

TEST_CASE("pointwise conv matches the reference for pixel counts around every row tile") {
  // 1 to 91 pixels: partial and whole tiles of 4, 6, 8 and 12 rows.
  ThreadPool pool(2);
  uint32_t seed = 2000;
  for (int h : sweep<int>({1, 2, 3, 5, 7}, {1, 3}))
    for (int w : sweep<int>({1, 2, 3, 5, 7, 13}, {1, 5, 13})) check_all_isas(pointwise(17, 33, h, w, seed++), pool);
}

TEST_CASE("pointwise conv with long reductions stays within tolerance") {
  ThreadPool pool(2);
  check_all_isas(pointwise(sweep<int>({576}, {160}).front(), 40, 3, 5, 3000), pool);
}
