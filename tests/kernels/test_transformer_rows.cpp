// The transformer row kernels (layer_norm_row, softmax_block_row, bilinear_row) and the
// GELU activation: the scalar reference against double-precision formulas, then every
// runnable ISA's table against the reference over sweeps of channel counts around each
// vector width and odd lengths.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <vector>

#include "kernels/reference/reference.h"
#include "kernel_sweeps.h"
#include "support/random.h"

using namespace ampi;

namespace {

double gelu_exact(double x) { return 0.5 * x * (1.0 + std::erf(x / std::sqrt(2.0))); }

// Channel counts around every vector width (4, 8, 16 and their doubles) and ViT widths.
std::vector<int> token_widths() {
  std::vector<int> widths;
  for (int c = 1; c <= 17; ++c) widths.push_back(c);
  for (int c : {31, 32, 33, 63, 64, 65}) widths.push_back(c);
  if (!test::small_tests()) widths.push_back(384);
  return widths;
}

// The distance between a and b in units of the float spacing at the larger of them; values
// below the normal range count in units of the smallest normal's spacing.
float ulps_apart(float a, float b) {
  const float big = std::max({std::fabs(a), std::fabs(b), 1e-30f});
  const float ulp = std::ldexp(1.0f, std::ilogb(big) - 23);
  return std::fabs(a - b) / ulp;
}

// x from -12 to 12 in steps of 1/1024 (every binade the fit spans), then a few extremes.
std::vector<float> gelu_inputs() {
  std::vector<float> x;
  for (int i = -12 * 1024; i <= 12 * 1024; ++i) x.push_back(static_cast<float>(i) / 1024.0f);
  for (float v : {1e-30f, -1e-30f, 1e-6f, -1e-6f, 30.0f, -30.0f, 1e4f, -1e4f, 3e38f, -3e38f}) x.push_back(v);
  return x;
}

}  // namespace

TEST_CASE("gelu is named \"gelu\" and parses back") {
  CHECK(std::string(activation_name(Activation::GELU)) == "gelu");
  CHECK(parse_activation("gelu") == Activation::GELU);
}

TEST_CASE("gelu reference matches the erf formula in double within 2e-7 (relative past |x| = 1)") {
  for (float x : gelu_inputs()) {
    INFO("x " << x);
    const double want = gelu_exact(x);
    const float got = activate(x, {Activation::GELU});
    CHECK(std::fabs(got - want) <= 2e-7 * std::max(1.0, std::fabs(double(x))));
  }
}

TEST_CASE("gelu: every ISA's activate matches the reference within a few ulp") {
  const std::vector<float> x = gelu_inputs();
  std::vector<float> want = x;
  reference::activate(want.data(), static_cast<int64_t>(want.size()), {Activation::GELU});
  for (Isa isa : runnable_isas()) {
    std::vector<float> got = x;
    kernels_for(isa).activate(got.data(), static_cast<int64_t>(got.size()), {Activation::GELU});
    float worst = 0.0f, worst_x = 0.0f;
    for (size_t i = 0; i < x.size(); ++i)
      if (ulps_apart(got[i], want[i]) > worst) worst = ulps_apart(got[i], want[i]), worst_x = x[i];
    INFO("isa " << isa_name(isa) << ", worst at x " << worst_x);
    // The ISAs fuse multiply-adds that the baseline reference rounds twice: in exp's
    // polynomial, Q's and h's product, a few ulp each.
    CHECK(worst <= 8.0f);
  }
}

TEST_CASE("layer_norm_row reference matches a double-precision layer norm") {
  for (int c : token_widths()) {
    const uint32_t seed = static_cast<uint32_t>(100 + c);
    INFO("c " << c << ", seed " << seed);
    // Offset from zero so the mean matters.
    const std::vector<float> in = test::random_floats(c, seed, 2.0f, 5.0f);
    const std::vector<float> gamma = test::random_floats(c, seed + 1, 0.5f, 2.0f);
    const std::vector<float> beta = test::random_floats(c, seed + 2);
    const float eps = 1e-6f;
    double mean = 0.0, var = 0.0;
    for (float v : in) mean += v;
    mean /= c;
    for (float v : in) var += (v - mean) * (v - mean);
    var /= c;
    std::vector<float> got(c);
    reference::layer_norm_row(in.data(), c, gamma.data(), beta.data(), eps, got.data());
    for (int i = 0; i < c; ++i) {
      const double want = (in[i] - mean) / std::sqrt(var + eps) * gamma[i] + beta[i];
      CHECK(std::fabs(got[i] - want) <= 2e-5 * (1.0 + std::fabs(want)));
    }
  }
}

TEST_CASE("layer_norm_row: every ISA matches the reference, in place too") {
  for (Isa isa : runnable_isas())
    for (int c : token_widths()) {
      const uint32_t seed = static_cast<uint32_t>(200 + c);
      INFO("isa " << isa_name(isa) << ", c " << c << ", seed " << seed);
      const std::vector<float> in = test::random_floats(c, seed, -3.0f, 4.0f);
      const std::vector<float> gamma = test::random_floats(c, seed + 1, -2.0f, 2.0f);
      const std::vector<float> beta = test::random_floats(c, seed + 2);
      std::vector<float> want(c);
      reference::layer_norm_row(in.data(), c, gamma.data(), beta.data(), 1e-5f, want.data());
      test::GuardedOutput got(c);
      kernels_for(isa).layer_norm_row(in.data(), c, gamma.data(), beta.data(), 1e-5f, got.data());
      CHECK(test::max_abs_diff(want.data(), got.data(), c) <= 1e-5f);
      CHECK(got.guard_intact());
      std::vector<float> same = in;
      kernels_for(isa).layer_norm_row(same.data(), c, gamma.data(), beta.data(), 1e-5f, same.data());
      CHECK(test::max_abs_diff(want.data(), same.data(), c) <= 1e-5f);
    }
}

namespace {

// Softmax (base 2) of scores * scale over n keys streamed in blocks of `block` keys through one
// table's kernel, accumulating the probabilities as attention accumulates P V: the row
// so far is multiplied by each block's factor, then divided by the sum at the end.
std::vector<float> streamed_softmax(const KernelTable& k, std::vector<float> scores, float scale, int block) {
  const int n = static_cast<int>(scores.size());
  std::vector<float> probs;
  float running_max = -INFINITY, running_sum = 0.0f;
  for (int begin = 0; begin < n; begin += block) {
    const int len = std::min(block, n - begin);
    const float factor = k.softmax_block_row(scores.data() + begin, len, scale, &running_max, &running_sum);
    if (begin == 0) CHECK(factor == 0.0f);
    for (float& p : probs) p *= factor;
    probs.insert(probs.end(), scores.begin() + begin, scores.begin() + begin + len);
  }
  for (float& p : probs) p /= running_sum;
  return probs;
}

std::vector<int> softmax_lengths() {
  return test::sweep<int>({1, 2, 3, 5, 7, 8, 9, 15, 16, 17, 31, 33, 63, 65, 257, 1370}, {1, 3, 5, 9, 17, 33, 65});
}

}  // namespace

TEST_CASE("softmax_block_row streamed over blocks equals a one-shot softmax in base 2") {
  for (Isa isa : runnable_isas())
    for (int n : softmax_lengths())
      for (int block : {1, 7, 16, 64, n}) {
        const uint32_t seed = static_cast<uint32_t>(300 + n);
        INFO("isa " << isa_name(isa) << ", n " << n << ", block " << block << ", seed " << seed);
        const std::vector<float> scores = test::random_floats(n, seed, -40.0f, 40.0f);
        const float scale = 0.125f * 1.442695f;  // attention's 1/sqrt(64), log2(e) folded in
        double max = -INFINITY, sum = 0.0;
        for (float s : scores) max = std::max(max, double(s) * scale);
        for (float s : scores) sum += std::exp2(double(s) * scale - max);
        const std::vector<float> got = streamed_softmax(kernels_for(isa), scores, scale, block);
        for (int j = 0; j < n; ++j) {
          const double want = std::exp2(double(scores[j]) * scale - max) / sum;
          CHECK(std::fabs(got[j] - want) <= 1e-6 * (want + 1e-3));
        }
      }
}

TEST_CASE("softmax_block_row: every ISA matches the reference block by block") {
  for (Isa isa : runnable_isas())
    for (int n : softmax_lengths()) {
      const uint32_t seed = static_cast<uint32_t>(400 + n);
      INFO("isa " << isa_name(isa) << ", n " << n << ", seed " << seed);
      const std::vector<float> scores = test::random_floats(n, seed, -20.0f, 20.0f);
      // A running state from an earlier block, below and above this block's maximum.
      for (float earlier_max : {-INFINITY, -30.0f, 1.0f, 30.0f}) {
        std::vector<float> want = scores;
        float want_max = earlier_max, want_sum = earlier_max == -INFINITY ? 0.0f : 3.0f;
        const float want_factor = reference::softmax_block_row(want.data(), n, 0.7f, &want_max, &want_sum);
        std::vector<float> got = scores;
        float got_max = earlier_max, got_sum = earlier_max == -INFINITY ? 0.0f : 3.0f;
        const float got_factor = kernels_for(isa).softmax_block_row(got.data(), n, 0.7f, &got_max, &got_sum);
        INFO("earlier max " << earlier_max);
        CHECK(got_max == want_max);
        CHECK(ulps_apart(got_factor, want_factor) <= 4.0f);
        // Summed in another order: the bound of n float additions of positive terms.
        CHECK(std::fabs(got_sum - want_sum) <= std::ldexp(float(8 + n), -24) * want_sum);
        // 2^(s_j - m) within a few ulp, plus what rounding s_j = scores[j] * scale and
        // s_j - m may move the exponent by: an ISA may fuse the two (one rounding where
        // the reference has two).
        for (int j = 0; j < n; ++j) {
          const float exponent_error = std::ldexp(2.0f * std::fabs(scores[j] * 0.7f) + std::fabs(want_max), -23);
          CHECK(std::fabs(got[j] - want[j]) <= want[j] * (std::ldexp(4.0f, -23) + exponent_error));
        }
      }
    }
}

namespace {

// align_corners=True source columns of an out_w-wide row resized from in_w columns.
struct SourceColumns {
  std::vector<int32_t> x0, x1;
  std::vector<float> wx;
};

SourceColumns align_corners_columns(int in_w, int out_w) {
  SourceColumns s;
  for (int x = 0; x < out_w; ++x) {
    const double src = out_w > 1 ? double(x) * (in_w - 1) / (out_w - 1) : 0.0;
    const int lo = std::min(static_cast<int>(src), in_w - 1);
    s.x0.push_back(lo);
    s.x1.push_back(std::min(lo + 1, in_w - 1));
    s.wx.push_back(static_cast<float>(src - lo));
  }
  return s;
}

}  // namespace

TEST_CASE("bilinear_row reference matches the interpolation formula in double") {
  const int in_w = 5, out_w = 13, c = 3;
  const std::vector<float> top = test::random_floats(in_w * c, 500), bottom = test::random_floats(in_w * c, 501);
  const SourceColumns s = align_corners_columns(in_w, out_w);
  const float wy = 0.3f;
  std::vector<float> got(out_w * c);
  reference::bilinear_row(top.data(), bottom.data(), wy, s.x0.data(), s.x1.data(), s.wx.data(), out_w, c, got.data());
  for (int x = 0; x < out_w; ++x)
    for (int ch = 0; ch < c; ++ch) {
      const double a = s.wx[x];
      const double t = (1 - a) * top[s.x0[x] * c + ch] + a * top[s.x1[x] * c + ch];
      const double b = (1 - a) * bottom[s.x0[x] * c + ch] + a * bottom[s.x1[x] * c + ch];
      CHECK(std::fabs(got[x * c + ch] - ((1 - wy) * t + wy * b)) <= 1e-6);
    }
  // The corners land on the input's corners exactly.
  CHECK(got[0] == top[0] + wy * (bottom[0] - top[0]));
}

TEST_CASE("bilinear_row: every ISA matches the reference") {
  for (Isa isa : runnable_isas())
    for (int c : token_widths())
      for (int out_w : {1, 3, 7, 16, 17, 37}) {
        const int in_w = std::max(1, out_w / 2 + 1);
        const uint32_t seed = static_cast<uint32_t>(600 + 64 * c + out_w);
        INFO("isa " << isa_name(isa) << ", c " << c << ", out_w " << out_w << ", seed " << seed);
        const std::vector<float> top = test::random_floats(size_t(in_w) * c, seed);
        const std::vector<float> bottom = test::random_floats(size_t(in_w) * c, seed + 1);
        const SourceColumns s = align_corners_columns(in_w, out_w);
        const size_t n = size_t(out_w) * c;
        std::vector<float> want(n);
        reference::bilinear_row(top.data(), bottom.data(), 0.6f, s.x0.data(), s.x1.data(), s.wx.data(), out_w, c,
                                want.data());
        test::GuardedOutput got(n);
        kernels_for(isa).bilinear_row(top.data(), bottom.data(), 0.6f, s.x0.data(), s.x1.data(), s.wx.data(), out_w,
                                      c, got.data());
        CHECK(test::max_abs_diff(want.data(), got.data(), n) <= 1e-6f);
        CHECK(got.guard_intact());
      }
}
