// The inpainting network against PyTorch (fixtures written by training/export_inpaint.py),
// on every instruction set this host runs, and the tiled filler built on it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "inpaint/net_filler.h"
#include "inpaint/harmonic_fill.h"
#include "inpaint/push_pull.h"
#include "nets/model_loader.h"
#include "support/random.h"

using namespace ampi;

namespace {

const std::string kFixtures = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/inpaint/";

struct Case {
  int h = 0, w = 0;
  Tensor rgb, hole, expected;
};

Case load_case(const std::string& path) {
  const WeightFile f = WeightFile::open(path);
  const TensorInfo* info = f.find("rgb");
  REQUIRE(info != nullptr);
  Case c;
  c.h = int(info->shape.at(0));
  c.w = int(info->shape.at(1));
  c.rgb = f.tensor("rgb", {c.h, c.w, 3});
  c.hole = f.tensor("hole", {c.h, c.w});
  c.expected = f.tensor("expected", {c.h, c.w, 3});
  return c;
}

// Every network parity test's bound: within 1e-4 of the expected output's range, far
// above what the kernels' reordered float sums move and far below a wrong layer.
void check_parity(const std::string& weights, const std::string& case_path) {
  const Case c = load_case(case_path);
  const float* e = c.expected.f32();
  const size_t n = size_t(c.h) * c.w * 3;
  const float range = *std::max_element(e, e + n) - *std::min_element(e, e + n);
  REQUIRE(range > 0.1f);  // a degenerate fixture would compare nothing
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa) << ", weights " << weights << ", case " << case_path);
    const InpaintNet net = load_inpaint_net(weights, kernels_for(isa));
    std::vector<float> out(n);
    net.run(c.rgb.f32(), c.hole.f32(), c.h, c.w, out.data());
    const float diff = test::max_abs_diff(out.data(), e, n);
    INFO("max |diff| " << diff << ", output range " << range);
    CHECK(diff <= 1e-4f * range);
  }
}

// A BGRA layer of random colour, opaque where `known`, with a disc of pixels to fill.
struct Layer {
  cv::Mat image, known, fill;
};

Layer random_layer(int h, int w, uint32_t seed) {
  Layer l;
  l.image = cv::Mat(h, w, CV_8UC4);
  cv::RNG rng(seed);
  rng.fill(l.image, cv::RNG::UNIFORM, 0, 256);
  l.known = cv::Mat(h, w, CV_8UC1, cv::Scalar(0));
  cv::rectangle(l.known, cv::Rect(0, 0, w / 2, h), cv::Scalar(255), cv::FILLED);
  l.fill = cv::Mat(h, w, CV_8UC1, cv::Scalar(0));
  cv::circle(l.fill, {w / 2 + 6, h / 2}, std::min(h, w) / 4, cv::Scalar(255), cv::FILLED);
  l.fill &= ~l.known;
  return l;
}

// 255 where any channel of a and b (CV_8UC4) differs, in colour (bgr) or in alpha.
cv::Mat changed_pixels(const cv::Mat& a, const cv::Mat& b, bool alpha) {
  cv::Mat changed(a.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x) {
      const cv::Vec4b pa = a.at<cv::Vec4b>(y, x), pb = b.at<cv::Vec4b>(y, x);
      const bool differs = alpha ? pa[3] != pb[3] : (pa[0] != pb[0] || pa[1] != pb[1] || pa[2] != pb[2]);
      if (differs) changed.at<uint8_t>(y, x) = 255;
    }
  return changed;
}

std::string expect_load_error(const std::string& file) {
  try {
    load_inpaint_net(kFixtures + file);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  FAIL("loading " << file << " did not throw");
  return {};
}

}  // namespace

TEST_CASE("inpaint net: tiny random network matches PyTorch on every ISA", "[inpaint]") {
  check_parity(kFixtures + "tiny.ampw", kFixtures + "tiny_case.ampw");
}

TEST_CASE("inpaint net: bundled weights match PyTorch on every ISA", "[inpaint]") {
  check_parity(std::string(AMPI_SOURCE_DIR) + "/weights/inpaint.ampw", kFixtures + "bundled_case.ampw");
}

TEST_CASE("inpaint net: the graph is read from the file", "[inpaint]") {
  const InpaintNet net = load_inpaint_net(kFixtures + "tiny.ampw");
  REQUIRE(net.layers().size() == 12);
  CHECK(net.multiple() == 4);
  CHECK(net.layers().front().stride == 2);
  CHECK(net.layers()[6].dilation == 8);
  CHECK(net.layers()[8].upsample);
  CHECK(net.layers()[8].skip == 1);
  CHECK(net.layers().back().scale_log2 == 0);
  CHECK_FALSE(net.layers().back().gated);
  CHECK(net.macs_per_pixel() > 0);
  CHECK(net.prefill() == Prefill::Harmonic);  // version 2, as training/inpaint_model.py PREFILL
}

TEST_CASE("inpaint net: version 2 changes only the hole of its input", "[inpaint]") {
  const Case c = load_case(kFixtures + "tiny_case.ampw");
  const InpaintNet net = load_inpaint_net(kFixtures + "tiny.ampw");
  const size_t pixels = size_t(c.h) * c.w;
  std::vector<float> out(pixels * 3);
  net.run(c.rgb.f32(), c.hole.f32(), c.h, c.w, out.data());
  int known = 0, kept = 0, hole_changed = 0;
  for (size_t p = 0; p < pixels; ++p)
    for (int ch = 0; ch < 3; ++ch) {
      const bool same = out[p * 3 + ch] == c.rgb.f32()[p * 3 + ch];
      if (c.hole.f32()[p] == 0.0f) {
        ++known;
        kept += same;
      } else {
        hole_changed += !same;
      }
    }
  CHECK(kept == known);
  CHECK(hole_changed > 0);
}

TEST_CASE("inpaint net: results do not depend on the thread count", "[inpaint]") {
  const Case c = load_case(kFixtures + "tiny_case.ampw");
  const InpaintNet net = load_inpaint_net(kFixtures + "tiny.ampw");
  const size_t n = size_t(c.h) * c.w * 3;
  std::vector<float> one(n), two(n);
  ThreadPool single(1), pair(2);
  net.run(c.rgb.f32(), c.hole.f32(), c.h, c.w, one.data(), single);
  net.run(c.rgb.f32(), c.hole.f32(), c.h, c.w, two.data(), pair);
  CHECK(test::max_abs_diff(one.data(), two.data(), n) == 0.0f);
}

TEST_CASE("inpaint net: bad inputs and bad files are one-line errors", "[inpaint]") {
  const InpaintNet net = load_inpaint_net(kFixtures + "tiny.ampw");
  std::vector<float> rgb(30 * 30 * 3), hole(30 * 30), out(30 * 30 * 3);
  CHECK_THROWS_AS(net.run(rgb.data(), hole.data(), 30, 30, out.data()), std::invalid_argument);

  const std::string channels = expect_load_error("bad_channels.ampw");
  CHECK(channels.rfind(kFixtures + "bad_channels.ampw: layer enc2: in_channels", 0) == 0);
  const std::string forward = expect_load_error("bad_source.ampw");
  CHECK(forward.rfind(kFixtures + "bad_source.ampw: layer enc2: source is not an earlier layer", 0) == 0);
  const std::string dilation = expect_load_error("bad_dilation.ampw");  // found by fuzz_networks
  CHECK(dilation == kFixtures + "bad_dilation.ampw: inpaint.dilation holds 1073741824, outside -2..16384");
  const std::string missing = expect_load_error("no_tensors.ampw");
  CHECK(missing.rfind(kFixtures + "no_tensors.ampw: ", 0) == 0);
  CHECK(missing.find("enc1.weight") != std::string::npos);
  CHECK(missing.find('\n') == std::string::npos);
  const std::string prefill = expect_load_error("bad_prefill.ampw");
  CHECK(prefill == kFixtures + "bad_prefill.ampw: inpaint.prefill 'telea' is not 'push-pull' or 'harmonic'");
  const std::string data = expect_load_error("tiny_case.ampw");  // a test case, no network
  CHECK(data == kFixtures + "tiny_case.ampw: no 'arch' metadata: not a network weight file");
  const std::string depth = expect_load_error("../../../weights/depth_lite.ampw");
  CHECK(depth.find("depth_lite.ampw: architecture 'ampi.depth.dwt-mobilenetv3' is a depth network, "
                   "not an inpainting network") != std::string::npos);
}

TEST_CASE("inpaint filler: changes only the pixels to fill", "[inpaint]") {
  const InpaintNet net = load_inpaint_net(kFixtures + "tiny.ampw");
  for (uint32_t seed : {1u, 2u}) {
    INFO("seed " << seed);
    const Layer l = random_layer(70, 90, seed);
    const cv::Mat out = inpaint_layer(net, l.image, l.known, l.fill, {16, 8});
    const cv::Mat changed = changed_pixels(out, l.image, false);
    CHECK(cv::countNonZero(changed & ~l.fill) == 0);
    CHECK(cv::countNonZero(changed) > cv::countNonZero(l.fill) / 2);  // the net did write
    CHECK(cv::countNonZero(changed_pixels(out, l.image, true)) == 0);  // alpha: the caller's
  }
}

TEST_CASE("inpaint filler: one window over the whole layer equals a direct run", "[inpaint]") {
  // the same tiny net, saved with each prefill: the filler must feed it the one named
  for (const auto& [file, prefill] : {std::pair<const char*, Prefill>{"tiny.ampw", Prefill::Harmonic},
                                      std::pair<const char*, Prefill>{"tiny_push_pull.ampw", Prefill::PushPull}}) {
    INFO(file);
    const InpaintNet net = load_inpaint_net(kFixtures + file);
    REQUIRE(net.prefill() == prefill);
    const int h = 48, w = 64;  // multiples of 4: the window needs no padding
    const Layer l = random_layer(h, w, 3);
    const cv::Mat out = inpaint_layer(net, l.image, l.known, l.fill, {256, 256});

    // a version-2 network reads its prefill in every unknown pixel
    const cv::Mat unknown = l.known == 0;
    const cv::Mat input = prefill == Prefill::Harmonic ? harmonic_fill(l.image, l.known, unknown)
                                                       : push_pull_fill(l.image, l.known, unknown);
    std::vector<float> rgb(size_t(h) * w * 3), hole(size_t(h) * w), pred(size_t(h) * w * 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * w + x;
        const cv::Vec4b px = input.at<cv::Vec4b>(y, x);
        for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = px[2 - c] / 127.5f - 1.0f;
        hole[p] = l.known.at<uint8_t>(y, x) ? 0.0f : 1.0f;
      }
    net.run(rgb.data(), hole.data(), h, w, pred.data());
    int mismatches = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!l.fill.at<uint8_t>(y, x)) continue;
        const cv::Vec4b px = out.at<cv::Vec4b>(y, x);
        for (int c = 0; c < 3; ++c) {
          const long want = std::lround((pred[(size_t(y) * w + x) * 3 + c] + 1.0f) * 127.5f);
          mismatches += std::abs(long(px[2 - c]) - std::clamp(want, 0L, 255L)) > 0;
        }
      }
    CHECK(mismatches == 0);
  }
}

TEST_CASE("inpaint filler: tiles cover a fill region larger than one core", "[inpaint]") {
  const InpaintNet net = load_inpaint_net(kFixtures + "tiny.ampw");
  const Layer l = random_layer(101, 133, 4);  // odd sizes: windows are padded
  const cv::Mat tiled = inpaint_layer(net, l.image, l.known, l.fill, {12, 4});
  const cv::Mat changed = changed_pixels(tiled, l.image, false);
  // every core holding fill pixels ran: nearly every fill pixel got a new colour
  CHECK(cv::countNonZero(changed & l.fill) > 0.9 * cv::countNonZero(l.fill));
  CHECK(cv::countNonZero(changed & ~l.fill) == 0);
  CHECK_THROWS_AS(inpaint_layer(net, l.image, l.known, l.fill, {2, 4}), std::invalid_argument);
}
