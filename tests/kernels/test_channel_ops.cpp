// Gated output, concat and squeeze-excite: hand-computed cases pin down the reference,
// then every runnable ISA and thread count is compared with it over channel sweeps.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kernels/ops.h"
#include "kernels/reference/reference.h"
#include "kernel_sweeps.h"
#include "support/random.h"

using namespace ampi;

namespace {

std::vector<int64_t> pixel_sweep() {
  if (test::small_tests()) return {1, 5};
  return {1, 2, 7, 33, 2000};
}

}  // namespace

TEST_CASE("gated_output reference: act(feature) * sigmoid(gate) by hand") {
  // Two pixels, c = 2: [f0 f1 | g0 g1].
  const float in[] = {2.0f, -1.0f, 0.0f, 0.0f, 3.0f, 1.0f, 100.0f, -100.0f};
  float out[4];
  reference::gated_output(in, 2, 2, {Activation::ReLU}, out);
  CHECK(out[0] == Approx(1.0f));   // relu(2) * sigmoid(0)
  CHECK(out[1] == 0.0f);           // relu(-1) = 0
  CHECK(out[2] == Approx(3.0f));   // sigmoid(100) = 1
  CHECK(out[3] == Approx(0.0f).margin(1e-30));  // sigmoid(-100) ~ 0
}

TEST_CASE("gated_output: every ISA, activation and thread count matches the reference") {
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (ActivationSpec act : test::all_activations())
        for (int c : test::channel_sweep())
          for (int64_t pixels : pixel_sweep()) {
            const uint32_t seed = static_cast<uint32_t>(100 * c + pixels + 7 * static_cast<int>(act.kind));
            INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", activation "
                        << activation_name(act.kind) << ", c " << c << ", pixels " << pixels
                        << ", seed " << seed);
            const std::vector<float> in = test::random_floats(pixels * 2 * c, seed, -6.0f, 6.0f);
            const size_t n = static_cast<size_t>(pixels * c);
            std::vector<float> expected(n);
            reference::gated_output(in.data(), pixels, c, act, expected.data());
            test::GuardedOutput got(n);
            gated_output(in.data(), pixels, c, act, got.data(), *pool, kernels_for(isa));
            // The vector exp is a polynomial (relative error ~2e-7); outputs reach 6.
            CHECK(test::max_abs_diff(expected.data(), got.data(), n) <= 1e-5f);
            CHECK(got.guard_intact());
          }
}

TEST_CASE("concat_channels reference interleaves per pixel") {
  const float a[] = {1, 2, 3, 4};  // 2 pixels x 2 channels
  const float b[] = {-1, -2};      // 2 pixels x 1 channel
  float out[6];
  reference::concat_channels(a, 2, b, 1, 2, out);
  const float expected[] = {1, 2, -1, 3, 4, -2};
  for (int i = 0; i < 6; ++i) CHECK(out[i] == expected[i]);
}

TEST_CASE("concat_channels: every ISA and thread count copies exactly") {
  const std::vector<int> channels = test::channel_sweep();
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (int ca : channels)
        for (int cb : {channels.front(), 3, channels.back()})
          for (int64_t pixels : pixel_sweep()) {
            const uint32_t seed = static_cast<uint32_t>(1000 * ca + 10 * cb + pixels);
            INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", ca " << ca << ", cb "
                        << cb << ", pixels " << pixels << ", seed " << seed);
            const auto a = test::random_floats(pixels * ca, seed);
            const auto b = test::random_floats(pixels * cb, seed + 1);
            const size_t n = static_cast<size_t>(pixels * (ca + cb));
            std::vector<float> expected(n);
            reference::concat_channels(a.data(), ca, b.data(), cb, pixels, expected.data());
            test::GuardedOutput got(n);
            concat_channels(a.data(), ca, b.data(), cb, pixels, got.data(), *pool, kernels_for(isa));
            CHECK(test::max_abs_diff(expected.data(), got.data(), n) == 0.0f);
            CHECK(got.guard_intact());
          }
}

TEST_CASE("squeeze-excite parts: every ISA matches the reference") {
  for (Isa isa : runnable_isas()) {
    const KernelTable& k = kernels_for(isa);
    for (int c : test::channel_sweep())
      for (int64_t pixels : pixel_sweep()) {
        const uint32_t seed = static_cast<uint32_t>(31 * c + pixels);
        INFO("isa " << isa_name(isa) << ", c " << c << ", pixels " << pixels << ", seed " << seed);
        const auto in = test::random_floats(pixels * c, seed);
        const auto scale = test::random_floats(c, seed + 1);
        const size_t n = static_cast<size_t>(pixels * c);

        std::vector<float> expected_sum(c);
        test::GuardedOutput sum(c);
        reference::channel_sum(in.data(), pixels, c, expected_sum.data());
        k.channel_sum(in.data(), pixels, c, sum.data());
        // Both add in pixel order, so the results agree bit for bit.
        CHECK(test::max_abs_diff(expected_sum.data(), sum.data(), c) == 0.0f);
        CHECK(sum.guard_intact());

        std::vector<float> expected_scaled(n);
        test::GuardedOutput scaled(n);
        reference::channel_scale(in.data(), pixels, c, scale.data(), expected_scaled.data());
        k.channel_scale(in.data(), pixels, c, scale.data(), scaled.data());
        CHECK(test::max_abs_diff(expected_scaled.data(), scaled.data(), n) == 0.0f);
        CHECK(scaled.guard_intact());
      }
  }
}

TEST_CASE("dense: every ISA and activation matches the reference") {
  for (Isa isa : runnable_isas())
    for (ActivationSpec act : test::all_activations())
      for (int cols : test::channel_sweep())
        for (int rows : {1, 4, 17}) {
          const uint32_t seed = static_cast<uint32_t>(100 * cols + rows + 13 * static_cast<int>(act.kind));
          INFO("isa " << isa_name(isa) << ", activation " << activation_name(act.kind) << ", rows "
                      << rows << ", cols " << cols << ", seed " << seed);
          const auto w = test::random_floats(static_cast<size_t>(rows) * cols, seed);
          const auto bias = test::random_floats(rows, seed + 1);
          const auto x = test::random_floats(cols, seed + 2);
          for (const float* b : {bias.data(), static_cast<const float*>(nullptr)}) {
            std::vector<float> expected(rows);
            test::GuardedOutput got(rows);
            reference::dense(w.data(), b, rows, cols, x.data(), act, expected.data());
            kernels_for(isa).dense(w.data(), b, rows, cols, x.data(), act, got.data());
            CHECK(test::max_abs_diff(expected.data(), got.data(), rows) <= 1e-5f);
            CHECK(got.guard_intact());
          }
        }
}

namespace {

// Squeeze-excite from its definition, in double: the independent check of the op.
std::vector<float> squeeze_excite_by_definition(const std::vector<float>& in, int64_t pixels,
                                                int c, int reduced, const std::vector<float>& w1,
                                                const std::vector<float>& b1,
                                                const std::vector<float>& w2,
                                                const std::vector<float>& b2) {
  std::vector<double> mean(c, 0.0), hidden(reduced);
  for (int64_t p = 0; p < pixels; ++p)
    for (int j = 0; j < c; ++j) mean[j] += in[p * c + j];
  for (double& m : mean) m /= static_cast<double>(pixels);
  for (int r = 0; r < reduced; ++r) {
    double acc = b1[r];
    for (int j = 0; j < c; ++j) acc += w1[static_cast<size_t>(r) * c + j] * mean[j];
    hidden[r] = std::max(acc, 0.0);
  }
  std::vector<float> out(in.size());
  for (int j = 0; j < c; ++j) {
    double acc = b2[j];
    for (int r = 0; r < reduced; ++r) acc += w2[static_cast<size_t>(j) * reduced + r] * hidden[r];
    const double gate = std::min(std::max(acc + 3.0, 0.0), 6.0) / 6.0;
    for (int64_t p = 0; p < pixels; ++p) out[p * c + j] = static_cast<float>(in[p * c + j] * gate);
  }
  return out;
}

}  // namespace

TEST_CASE("SqueezeExcite: every ISA matches the definition, the same bits for any thread count") {
  const std::vector<test::MapSize> sizes =
      test::small_tests() ? std::vector<test::MapSize>{{3, 5}}
                          : std::vector<test::MapSize>{{1, 1}, {3, 5}, {40, 31}};
  for (Isa isa : runnable_isas())
    for (int c : test::channel_sweep())
      for (test::MapSize size : sizes) {
        const int reduced = std::max(1, c / 4);
        const int64_t pixels = static_cast<int64_t>(size.h) * size.w;
        const uint32_t seed = static_cast<uint32_t>(17 * c + size.h + size.w);
        INFO("isa " << isa_name(isa) << ", c " << c << ", reduced " << reduced << ", " << size.h
                    << "x" << size.w << ", seed " << seed);
        const auto in = test::random_floats(pixels * c, seed);
        const auto w1 = test::random_floats(static_cast<size_t>(reduced) * c, seed + 1);
        const auto b1 = test::random_floats(reduced, seed + 2);
        const auto w2 = test::random_floats(static_cast<size_t>(reduced) * c, seed + 3, -3.0f, 3.0f);
        const auto b2 = test::random_floats(c, seed + 4);
        const std::vector<float> expected =
            squeeze_excite_by_definition(in, pixels, c, reduced, w1, b1, w2, b2);
        const SqueezeExcite se(c, reduced, w1.data(), b1.data(), w2.data(), b2.data(), kernels_for(isa));

        std::vector<float> first;
        for (ThreadPool* pool : test::thread_pools()) {
          INFO("threads " << pool->size());
          test::GuardedOutput got(in.size());
          se.run(in.data(), size.h, size.w, got.data(), *pool);
          CHECK(test::max_abs_diff(expected.data(), got.data(), in.size()) <= 1e-5f);
          CHECK(got.guard_intact());
          if (first.empty()) first.assign(got.data(), got.data() + in.size());
          CHECK(test::max_abs_diff(first.data(), got.data(), in.size()) == 0.0f);
        }
        // The gate is what run() multiplies by (Conv2d::run_scaled_input folds it instead).
        const std::vector<float> gate = se.gate(in.data(), size.h, size.w, *test::thread_pools()[1]);
        REQUIRE(gate.size() == size_t(c));
        bool gate_is_the_scale = true;
        for (int64_t i = 0; i < pixels * c; ++i) gate_is_the_scale &= first[i] == in[i] * gate[i % c];
        CHECK(gate_is_the_scale);
        std::vector<float> in_place = in;  // out may alias in
        se.run(in_place.data(), size.h, size.w, in_place.data(), *test::thread_pools()[1]);
        CHECK(test::max_abs_diff(first.data(), in_place.data(), in.size()) == 0.0f);
      }
}

TEST_CASE("channel ops reject bad sizes") {
  float buffer[16] = {};
  CHECK_THROWS_AS(gated_output(buffer, 1, 0, {}, buffer), std::runtime_error);
  CHECK_THROWS_AS(concat_channels(buffer, 0, buffer, 1, 1, buffer), std::runtime_error);
  CHECK_THROWS_AS(SqueezeExcite(0, 1, buffer, buffer, buffer, buffer), std::runtime_error);
  CHECK_THROWS_AS(SqueezeExcite().run(buffer, 1, 1, buffer), std::runtime_error);
  const SqueezeExcite se(2, 1, buffer, buffer, buffer, buffer);
  CHECK_THROWS_AS(se.run(buffer, 0, 4, buffer), std::runtime_error);
}
