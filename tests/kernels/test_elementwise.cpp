// add and activate: every runnable ISA and thread count against the scalar reference.
#include <catch2/catch.hpp>
#include <vector>

#include "kernels/ops.h"
#include "kernels/reference/reference.h"
#include "kernel_sweeps.h"
#include "support/random.h"

using namespace ampi;

TEST_CASE("add and activate with every activation: every ISA matches the reference") {
  std::vector<int64_t> sizes;
  for (int n : test::length_sweep()) sizes.push_back(n);
  if (!test::small_tests()) sizes.push_back(40001);  // splits over threads (grain 16384)
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (ActivationSpec act : test::all_activations())
        for (int64_t n : sizes) {
          const KernelTable& k = kernels_for(isa);
          const uint32_t seed = static_cast<uint32_t>(n * 31 + static_cast<int>(act.kind));
          INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", activation "
                      << activation_name(act.kind) << ", n " << n << ", seed " << seed);
          auto a = test::random_floats(n, seed, -8.0f, 8.0f);
          auto b = test::random_floats(n, seed + 1, -8.0f, 8.0f);
          std::vector<float> expected(n);
          test::GuardedOutput got(n);
          reference::add(a.data(), b.data(), n, act, expected.data());
          add(a.data(), b.data(), n, got.data(), act, *pool, k);
          CHECK(test::max_abs_diff(expected.data(), got.data(), n) <= 2e-6f * 16);
          CHECK(got.guard_intact());
          std::vector<float> x = a;
          activate(x.data(), n, act, *pool, k);
          reference::activate(a.data(), n, act);
          CHECK(test::max_abs_diff(a.data(), x.data(), n) <= 2e-6f * 16);
        }
}
