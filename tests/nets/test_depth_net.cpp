// The C++ depth network against PyTorch (fixtures from training/make_depth_fixtures.py,
// computed with the bundled weights), for every ISA this machine runs, and its input
// handling: padding, working size, malformed weight files.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "nets/architectures.h"
#include "nets/depth_net.h"
#include "nets/model_loader.h"
#include "support/random.h"
#include "weights_format/npy.h"

using namespace ampi;

namespace {

std::string source_path(const std::string& relative) { return std::string(AMPI_SOURCE_DIR) + "/" + relative; }

std::string weights(const std::string& variant) { return source_path("weights/depth_" + variant + ".ampw"); }

Tensor fixture(const std::string& name) { return read_npy(source_path("tests/fixtures/nets/" + name + ".npy")); }

float value_range(const Tensor& t) {
  const float* p = t.f32();
  const auto [lo, hi] = std::minmax_element(p, p + t.numel());
  return *hi - *lo;
}

}  // namespace

TEST_CASE("depth net matches PyTorch within 1e-4 of the output range, every ISA and size") {
  ThreadPool pool(2);
  for (const char* variant : {"lite", "heavy"}) {
    for (Isa isa : runnable_isas()) {
      const std::unique_ptr<DepthModel> model = load_depth_model(weights(variant), kernels_for(isa));
      DepthModel& net = *model;
      CHECK(net.variant() == variant);
      CHECK(net.architecture() == arch::kDepthDwtMobileNetV3);
      for (const char* size : {"64x96", "50x70"}) {
        INFO("variant " << variant << ", isa " << isa_name(isa) << ", input " << size);
        const Tensor input = fixture(std::string("depth_input_") + size);
        const Tensor expected = fixture(std::string("depth_") + variant + "_" + size);
        const int h = int(input.dim(0)), w = int(input.dim(1));
        const Tensor got = net.run(input.f32(), h, w, pool);
        REQUIRE(got.shape() == Shape{h, w});
        REQUIRE(expected.shape() == Shape{h, w});
        const float range = value_range(expected);
        REQUIRE(range > 0.0f);
        const float err = test::max_abs_diff(got.f32(), expected.f32(), size_t(h) * w);
        INFO("max error " << err << ", output range " << range);
        CHECK(err <= 1e-4f * range);
      }
    }
  }
}

TEST_CASE("depth net: results do not depend on the thread count or on earlier runs") {
  const std::unique_ptr<DepthModel> model = load_depth_model(weights("lite"));
  DepthModel& net = *model;
  const uint32_t seed = 11;
  INFO("seed " << seed);
  const std::vector<float> rgb = test::random_floats(40 * 72 * 3, seed, 0.0f, 1.0f);
  ThreadPool one(1), two(2);
  const Tensor a = net.run(rgb.data(), 40, 72, one);
  const Tensor other = net.run(rgb.data(), 33, 65, two);  // another plan in between
  const Tensor b = net.run(rgb.data(), 40, 72, two);
  CHECK(other.shape() == Shape{33, 65});
  CHECK(test::max_abs_diff(a.f32(), b.f32(), size_t(a.numel())) == 0.0f);
  CHECK(net.arena_bytes() > 0);
}

TEST_CASE("depth net metadata: parameter counts and multiple") {
  const DepthNet lite = DepthNet::from_file(WeightFile::open(weights("lite")));
  const DepthNet heavy = DepthNet::from_file(WeightFile::open(weights("heavy")));
  CHECK(lite.multiple() == 32);
  CHECK(heavy.multiple() == 32);
  // A file may ask for a working resolution (weights trained on small images do).
  CHECK(lite.working_size() >= lite.multiple());
  CHECK(heavy.working_size() >= heavy.multiple());
  // The inference graph: the folded count of training/depth_model.py minus the three
  // coarse heads, which are trained but not run (nets/ARCHITECTURE.md).
  CHECK(lite.parameter_count() == 2'656'800 - 1156 - 2308 - 4036);
  CHECK(heavy.parameter_count() == 6'295'920 - 1732 - 3460 - 5764);
}

TEST_CASE("depth working size: long side capped, aspect kept, never upscaled") {
  CHECK(depth_working_size(3000, 4000).height == 768);
  CHECK(depth_working_size(3000, 4000).width == 1024);
  CHECK(depth_working_size(4000, 3000, 512).height == 512);
  CHECK(depth_working_size(4000, 3000, 512).width == 384);
  CHECK(depth_working_size(600, 800).height == 600);  // smaller than 1024: unchanged
  CHECK(depth_working_size(600, 800).width == 800);
  CHECK(depth_working_size(1, 5000).height == 1);
  CHECK_THROWS_AS(depth_working_size(0, 10), std::invalid_argument);
}

TEST_CASE("depth net rejects files that are not depth networks, naming the file") {
  const std::string other = source_path("tests/fixtures/weights/small.ampw");
  try {
    load_depth_model(other);
    FAIL("loading " << other << " should have thrown");
  } catch (const std::runtime_error& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find(other) == 0);
  }
  CHECK_THROWS_AS(load_depth_model(source_path("tests/fixtures/nets/missing.ampw")), std::runtime_error);
}
