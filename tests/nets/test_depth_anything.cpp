// The C++ Depth Anything V2 against its PyTorch twin: the tiny random-weight model and
// the outputs training/make_dav2_fixtures.py computed with the twin rebuilt from the same
// .ampw, for every ISA this machine runs; the reference preprocessing (working shape,
// cubic resize, bilinear resize back), the position embedding's interpolation, thread
// independence and the checks on the working size.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "kernels/transformer_ops.h"
#include "nets/architectures.h"
#include "nets/depth_anything_net.h"
#include "nets/model_loader.h"
#include "support/random.h"
#include "weights_format/npy.h"

using namespace ampi;

namespace {

const std::string kFixtures = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/nets/";
const std::string kTiny = kFixtures + "dav2_tiny.ampw";

Tensor fixture(const std::string& name) { return read_npy(kFixtures + name + ".npy"); }

float value_range(const Tensor& t) {
  const auto [lo, hi] = std::minmax_element(t.f32(), t.f32() + t.numel());
  return *hi - *lo;
}

// |got - expected| <= 1e-4 of the expected output's range, everywhere.
void check_close(const Tensor& got, const Tensor& expected) {
  REQUIRE(got.shape() == expected.shape());
  const float range = value_range(expected);
  REQUIRE(range > 0.0f);
  const float err = test::max_abs_diff(got.f32(), expected.f32(), size_t(expected.numel()));
  INFO("max error " << err << ", output range " << range);
  CHECK(err <= 1e-4f * range);
}

}  // namespace

TEST_CASE("Depth Anything V2 network matches the twin within 1e-4 of the output range, every ISA") {
  ThreadPool pool(2);
  for (Isa isa : runnable_isas()) {
    const std::unique_ptr<DepthModel> net = load_depth_model(kTiny, kernels_for(isa));
    CHECK(net->architecture() == arch::kDepthDinoV2Dpt);
    CHECK(net->variant() == "tiny");
    // 56x56 is the pretrained 4x4 patch grid (embedding used as it is); 70x98 a 5x7 grid
    // (interpolated). At a working size of the shorter side, neither is resized.
    for (const char* size : {"56x56", "70x98"}) {
      INFO("isa " << isa_name(isa) << ", input " << size);
      const Tensor input = fixture(std::string("dav2_tiny_input_") + size);
      const int h = int(input.dim(0)), w = int(input.dim(1));
      net->set_working_size(std::min(h, w));
      check_close(net->run(input.f32(), h, w, pool), fixture(std::string("dav2_tiny_output_") + size));
    }
  }
}

TEST_CASE("Depth Anything V2 preprocessing: a 45x61 photo resized cubically to 56x70 and back, as infer_image") {
  ThreadPool pool(2);
  const std::vector<Isa> isas = runnable_isas();
  for (Isa isa : {isas.front(), isas.back()}) {
    INFO("isa " << isa_name(isa));
    const std::unique_ptr<DepthModel> net = load_depth_model(kTiny, kernels_for(isa));
    CHECK(net->working_size() == 56);  // the file's depth.working_size
    const Tensor photo = fixture("dav2_tiny_photo_45x61");
    check_close(net->run(photo.f32(), 45, 61, pool), fixture("dav2_tiny_infer_45x61"));
  }
}

TEST_CASE("Depth Anything V2 working shape: shorter side to the size, multiples of the patch, halves to even") {
  const auto shape = [](int h, int w, int size) { return dav2_working_shape(h, w, size, 14); };
  // Values from training/depth_anything.py's working_shape.
  CHECK(shape(45, 61, 56).height == 56);
  CHECK(shape(45, 61, 56).width == 70);
  CHECK(shape(45, 61, 518).width == 700);
  CHECK(shape(480, 640, 518).width == 686);
  CHECK(shape(1000, 333, 518).height == 1554);
  CHECK(shape(1000, 333, 518).width == 518);
  CHECK(shape(300, 1000, 518).width == 1722);
  CHECK(shape(70, 98, 518).width == 728);
  CHECK(shape(70, 98, 70).height == 70);
  CHECK(shape(70, 98, 70).width == 98);
  CHECK(shape(1000, 333, 56).height == 168);
}

TEST_CASE("Depth Anything V2 position embedding for a 5x7 grid equals the twin's interpolate_pos_embed") {
  const WeightFile file = WeightFile::open(kTiny);
  const Tensor pos = file.tensor("pretrained.pos_embed", {17, 16});
  const std::vector<float> got = interpolate_pos_embed(pos.f32(), 4, 16, 5, 7, file.get_float("dav2.pos_offset"));
  const Tensor expected = fixture("dav2_tiny_pos_5x7");
  REQUIRE(expected.numel() == int64_t(got.size()));
  const float scale = std::max(1.0f, value_range(expected));
  CHECK(test::max_abs_diff(got.data(), expected.f32(), got.size()) <= 1e-5f * scale);
}

TEST_CASE("Depth Anything V2: results do not depend on the thread count or on earlier runs") {
  const std::unique_ptr<DepthModel> net = load_depth_model(kTiny);
  const std::vector<float> rgb = test::random_floats(40 * 59 * 3, 21, 0.0f, 1.0f);
  ThreadPool one(1), two(2);
  const Tensor a = net->run(rgb.data(), 40, 59, one);
  const Tensor other = net->run(rgb.data(), 30, 20, two);  // another plan in between
  const Tensor b = net->run(rgb.data(), 40, 59, two);
  CHECK(other.shape() == Shape{30, 20});
  REQUIRE(a.shape() == Shape{40, 59});
  CHECK(test::max_abs_diff(a.f32(), b.f32(), size_t(a.numel())) == 0.0f);
  CHECK(net->arena_bytes() > 0);
}

TEST_CASE("Depth Anything V2 metadata: parameters, working size and its limits") {
  const WeightFile file = WeightFile::open(kTiny);
  DepthAnythingNet net = DepthAnythingNet::from_file(file);
  CHECK(net.multiple() == 14);
  CHECK(net.parameter_count() == file.get_int("depth.parameters"));
  CHECK(net.input_size(45, 61).height == 45);  // it resizes the photo itself
  net.set_working_size(70);
  CHECK(net.working_size() == 70);
  CHECK_THROWS_WITH(net.set_working_size(13), "working size 13 is not in 14..16384");
  CHECK_THROWS_AS(net.set_working_size(20000), std::invalid_argument);
  CHECK(net.working_size() == 70);
}

TEST_CASE("Depth Anything V2: every broken promise of the metadata is one line naming the file") {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"version", "depth.format_version 2 is not supported"},
      {"no_embed_dim", "dav2.embed_dim"},
      {"heads", "dav2.heads 3 does not divide dav2.embed_dim"},
      {"layer_count", "dav2.layers: 3 values, not 4"},
      {"layer_order", "dav2.layers must be 4 increasing block indices below dav2.depth"},
      {"features", "dav2.features 7 is odd"},
      {"multiple", "depth.multiple disagrees with dav2.patch_size"},
      {"working_size", "depth.working_size 10 is not in 14..16384"},
  };
  for (const auto& [name, problem] : cases) {
    const std::string path = kFixtures + "bad_dav2_" + name + ".ampw";
    std::string error;
    try {
      load_depth_model(path);
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
    INFO(name << ": " << error);
    CHECK(error.rfind(path + ": ", 0) == 0);
    CHECK(error.find(problem) != std::string::npos);
    CHECK(error.find('\n') == std::string::npos);
  }
}
