#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include "engine/arena.h"
#include "engine/cpu_features.h"
#include "engine/half.h"
#include "engine/isa.h"
#include "engine/tensor.h"
#include "engine/thread_pool.h"

using namespace ampi;

TEST_CASE("tensors are 64-byte aligned and typed") {
  Tensor t = Tensor::zeros({1, 5, 7, 3}, DType::F32, Layout::NHWC);
  CHECK(reinterpret_cast<uintptr_t>(t.data()) % 64 == 0);
  CHECK(t.numel() == 105);
  CHECK(t.bytes() == 420);
  CHECK(t.dim(-1) == 3);
  CHECK(t.f32()[104] == 0.0f);
  CHECK_THROWS_AS(t.f16(), std::logic_error);
  CHECK_THROWS_AS(t.dim(4), std::out_of_range);
  CHECK_THROWS(t.reshaped({2, 2}));
  Tensor r = t.reshaped({105});
  CHECK(r.data() == t.data());
}

TEST_CASE("f16 storage round-trips through f32") {
  Tensor t = Tensor::empty({6});
  const float values[] = {0.0f, 1.0f, -2.5f, 65504.0f, 6.1035156e-05f, 5.9604645e-08f};
  for (int i = 0; i < 6; ++i) t.f32()[i] = values[i];
  Tensor back = t.to_f16().to_f32();
  for (int i = 0; i < 6; ++i) CHECK(back.f32()[i] == values[i]);
  CHECK(half_to_float(float_to_half(1.0f / 3.0f)) == Approx(1.0f / 3.0f).epsilon(1e-3));
  CHECK(std::isinf(half_to_float(float_to_half(1e6f))));
  CHECK(std::isnan(half_to_float(float_to_half(std::nanf("")))));
  // Round to nearest even at the halfway point between 1 and the next half (1 + 2^-10).
  CHECK(half_to_float(float_to_half(1.0f + 1.0f / 2048.0f)) == 1.0f);
  CHECK(half_to_float(float_to_half(1.0f + 3.0f / 2048.0f)) == 1.0f + 2.0f / 1024.0f);
}

TEST_CASE("arena shares bytes between buffers whose lifetimes do not overlap") {
  Arena arena;
  const int a = arena.request(1000, 0, 1);
  const int b = arena.request(2000, 1, 2);
  const int c = arena.request(1000, 2, 3);  // can reuse a's bytes
  const int d = arena.request(64, 0, 3);
  arena.plan();
  CHECK(arena.total_bytes() < arena.unshared_bytes());
  CHECK(arena.total_bytes() == 2048 + 1024 + 64);
  auto overlaps = [&](int x, int y, size_t sx, size_t sy) {
    return arena.offset(x) < arena.offset(y) + sy && arena.offset(y) < arena.offset(x) + sx;
  };
  CHECK_FALSE(overlaps(a, b, 1024, 2048));
  CHECK_FALSE(overlaps(b, c, 2048, 1024));
  CHECK_FALSE(overlaps(d, a, 64, 1024));
  CHECK_FALSE(overlaps(d, b, 64, 2048));
  CHECK_FALSE(overlaps(d, c, 64, 1024));
  for (int id : {a, b, c, d}) CHECK(reinterpret_cast<uintptr_t>(arena.data(id)) % 64 == 0);
  CHECK_NOTHROW(arena.tensor(a, {1, 16, 16, 1}));  // 1000 bytes round up to 1024
  CHECK_THROWS(arena.tensor(a, {1, 16, 16, 2}));
}

TEST_CASE("parallel_for covers every index exactly once, at every thread count") {
  for (int threads : {1, 2, 3, 8}) {
    ThreadPool pool(threads);
    CHECK(pool.size() == threads);
    for (int64_t count : {0, 1, 7, 1000, 100003}) {
      std::vector<std::atomic<int>> hits(count);
      pool.parallel_for(count, 13, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) hits[i]++;
      });
      for (int64_t i = 0; i < count; ++i) REQUIRE(hits[i] == 1);
    }
  }
}

TEST_CASE("parallel_for rethrows a body's exception and stays usable") {
  ThreadPool pool(2);
  CHECK_THROWS_AS(pool.parallel_for(1000, 1,
                                    [](int64_t b, int64_t) {
                                      if (b > 500) throw std::runtime_error("boom");
                                    }),
                  std::runtime_error);
  std::atomic<int64_t> sum{0};
  pool.parallel_for(100, 1, [&](int64_t b, int64_t e) { sum += e - b; });
  CHECK(sum == 100);
}

TEST_CASE("a loop inside a loop runs inline on the calling thread; thread indices are in range") {
  ThreadPool pool(2);
  std::atomic<int64_t> inner_total{0};
  std::atomic<int> bad_index{0}, moved_thread{0};
  pool.parallel_for(8, 1, [&](int64_t b, int64_t e) {
    const int index = ThreadPool::thread_index();
    if (index < 0 || index >= pool.size()) ++bad_index;
    const auto outer_thread = std::this_thread::get_id();
    for (int64_t i = b; i < e; ++i)
      pool.parallel_for(100, 1, [&](int64_t ib, int64_t ie) {
        if (std::this_thread::get_id() != outer_thread) ++moved_thread;
        inner_total += ie - ib;
      });
  });
  CHECK(inner_total == 800);
  CHECK(bad_index == 0);
  CHECK(moved_thread == 0);
  CHECK(ThreadPool::thread_index() == 0);  // the caller, outside a loop
}

TEST_CASE("instruction sets: scalar always runs, names parse, detection is consistent") {
  const auto isas = runnable_isas();
  REQUIRE(!isas.empty());
  CHECK(isas.front() == Isa::Scalar);
  CHECK(best_isa() == isas.back());
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Neon}) CHECK(parse_isa(isa_name(isa)) == isa);
  CHECK_THROWS_AS(parse_isa("sse9"), std::invalid_argument);
  const CpuFeatures& f = cpu_features();
  if (isa_runnable(Isa::Avx512)) CHECK(f.avx512f);
  if (isa_runnable(Isa::Avx2)) CHECK((f.avx2 && f.fma));
  INFO("cpu features: " << describe(f));
  CHECK(!describe(f).empty());
}
