#include <catch2/catch.hpp>
#include <vector>

#include "kernels/ops.h"
#include "kernels/reference/reference.h"
#include "support/random.h"

using namespace ampi;

static const ActivationSpec kAllActivations[] = {
    {Activation::None},      {Activation::ReLU},    {Activation::ReLU6},
    {Activation::HardSwish}, {Activation::HardSigmoid}, {Activation::Sigmoid},
    {Activation::LeakyReLU, 0.2f}, {Activation::ELU, 1.0f}, {Activation::Tanh}};

TEST_CASE("add and activate with every activation: every ISA matches the reference") {
  ThreadPool pool(2);
  for (Isa isa : runnable_isas()) {
    const KernelTable& k = kernels_for(isa);
    for (ActivationSpec act : kAllActivations) {
      for (int64_t n : {1, 3, 4, 7, 8, 9, 15, 16, 17, 31, 33, 64, 100, 40001}) {
        const uint32_t seed = static_cast<uint32_t>(n * 31 + static_cast<int>(act.kind));
        INFO("isa " << isa_name(isa) << ", activation " << activation_name(act.kind) << ", n " << n
                    << ", seed " << seed);
        auto a = test::random_floats(n, seed, -8.0f, 8.0f);
        auto b = test::random_floats(n, seed + 1, -8.0f, 8.0f);
        std::vector<float> expected(n), got(n);
        reference::add(a.data(), b.data(), n, act, expected.data());
        add(a.data(), b.data(), n, got.data(), act, pool, k);
        CHECK(test::max_abs_diff(expected.data(), got.data(), n) <= 2e-6f * 16);
        std::vector<float> x = a;
        activate(x.data(), n, act, pool, k);
        reference::activate(a.data(), n, act);
        CHECK(test::max_abs_diff(a.data(), x.data(), n) <= 2e-6f * 16);
      }
    }
  }
}
