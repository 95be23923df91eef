// The one loader of every network (nets/model_loader.h): the architecture key, each
// metadata check of the depth network's builder, and the bundled weights found by their
// metadata (nets/bundled_weights.h). Fixtures: tests/fixtures/nets/make_loader_fixtures.py.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/isa.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "support/random.h"
#include "weights_format/weight_file.h"

using namespace ampi;

namespace {

const std::string kNets = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/nets/";
const std::string kInpaint = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/inpaint/";
const std::string kBundled = std::string(AMPI_SOURCE_DIR) + "/weights";

std::string load_error(const std::string& path) {
  try {
    load_depth_model(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  FAIL("loading " << path << " did not throw");
  return {};
}

// Points the bundled-weights lookup at `dir` for one test, and back after it.
class WeightsDir {
 public:
  explicit WeightsDir(const std::string& dir) {
    if (const char* old = std::getenv("AMPI_WEIGHTS_DIR")) old_ = old, had_ = true;
    setenv("AMPI_WEIGHTS_DIR", dir.c_str(), 1);
  }
  ~WeightsDir() { had_ ? (void)setenv("AMPI_WEIGHTS_DIR", old_.c_str(), 1) : (void)unsetenv("AMPI_WEIGHTS_DIR"); }

 private:
  std::string old_;
  bool had_ = false;
};

}  // namespace

TEST_CASE("model loader: a depth file builds the depth network its arch names, on every ISA") {
  ThreadPool pool(2);
  const std::vector<float> rgb = test::random_floats(40 * 50 * 3, 3, 0.0f, 1.0f);
  std::vector<float> first;  // the first ISA's output
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa));
    const std::unique_ptr<DepthModel> net = load_depth_model(kNets + "tiny_depth.ampw", kernels_for(isa));
    CHECK(net->architecture() == "ampi.depth.dwt-mobilenetv3");
    CHECK(net->variant() == "tiny");
    CHECK(net->working_size() == 64);
    const Tensor out = net->run(rgb.data(), 40, 50, pool);
    REQUIRE(out.shape() == Shape{40, 50});
    if (first.empty()) first.assign(out.f32(), out.f32() + out.numel());
    // ISAs differ in rounding only (the bundled nets' parity test holds them to PyTorch)
    const auto [lo, hi] = std::minmax_element(first.begin(), first.end());
    REQUIRE(*hi - *lo > 0.0f);
    CHECK(test::max_abs_diff(out.f32(), first.data(), first.size()) <= 1e-4f * (*hi - *lo));
  }
}

TEST_CASE("model loader: the kind and name of a file come from its metadata") {
  CHECK(model_kind(WeightFile::open(kNets + "tiny_depth.ampw")) == ModelKind::Depth);
  CHECK(model_name(WeightFile::open(kNets + "tiny_depth.ampw")) == "tiny");
  CHECK(model_kind(WeightFile::open(kInpaint + "tiny.ampw")) == ModelKind::Inpaint);
  // A header alone is enough to tell, and holds no weights.
  const WeightFile header = WeightFile::open_header(kNets + "tiny_depth.ampw");
  CHECK(model_name(header) == "tiny");
  CHECK(header.tensors().size() == WeightFile::open(kNets + "tiny_depth.ampw").tensors().size());
  CHECK_THROWS_WITH(header.tensor("head1.bias", {4}), Catch::Contains("only the header was read"));
}

TEST_CASE("model loader: every broken promise of a depth file is one line naming the file") {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"no_arch", "no 'arch' metadata: not a network weight file"},
      {"unknown_arch", "unknown architecture 'ampi.depth.vit-huge' (this build runs ampi.depth.dwt-mobilenetv3, "
                       "ampi.depth.dav2-vit-dpt, ampi.inpaint.gated-conv)"},
      {"version", "depth.format_version 2 is not supported"},
      {"levels", "depth.levels 9 is not in 2..8"},
      {"multiple", "depth.multiple disagrees with 2^depth.levels"},
      {"std", "depth.input_std must be positive"},
      {"block_kind", "depth.encoder.1 block 0: unknown block kind 7"},
      {"kernel", "depth.encoder.1 block 0: kernel 4 is not odd in 1..15"},
      {"activation", "depth.encoder.1 block 0: unknown activation code 9"},
      {"stage_length", "depth.encoder.1: 5 values, not a non-empty multiple of 6"},
      {"working_side", "depth.working_long_side 8 is not in 32..16384"},
  };
  for (const auto& [name, problem] : cases) {
    const std::string path = kNets + "bad_depth_" + name + ".ampw";
    const std::string error = load_error(path);
    INFO(error);
    CHECK(error.rfind(path + ": ", 0) == 0);
    CHECK(error.find(problem) != std::string::npos);
    CHECK(error.find('\n') == std::string::npos);
  }
  CHECK(load_error(kInpaint + "tiny.ampw") ==
        kInpaint + "tiny.ampw: architecture 'ampi.inpaint.gated-conv' is an inpainting network, not a depth network");
}

TEST_CASE("bundled weights: depth models are found by the name their file gives") {
  const WeightsDir dir(kBundled);
  CHECK(bundled_depth_models() == std::vector<std::string>{"heavy", "lite"});
  CHECK(depth_weights_path("", "lite") == kBundled + "/depth_lite.ampw");
  CHECK(depth_weights_path("", "heavy") == kBundled + "/depth_heavy.ampw");
  CHECK(depth_weights_path("mine.ampw", "lite") == "mine.ampw");  // --weights wins
  CHECK(inpaint_weights_path() == kBundled + "/inpaint.ampw");
  CHECK_NOTHROW(check_depth_model_name("heavy"));
  CHECK_THROWS_WITH(check_depth_model_name("medium"),
                    "--model: 'medium' is not a bundled depth model (bundled: heavy, lite)");
  CHECK_THROWS_WITH(depth_weights_path("", "medium"), Catch::Contains("depth models heavy, lite"));
}

TEST_CASE("bundled weights: a folder without networks names what was searched") {
  const WeightsDir dir(kInpaint + "no-such-folder");
  CHECK(bundled_depth_models().empty());
  CHECK_THROWS_WITH(inpaint_weights_path(), Catch::Contains("no-such-folder"));
  CHECK_THROWS_WITH(check_depth_model_name("lite"), "--model: 'lite' is not a bundled depth model (bundled: none)");
}
