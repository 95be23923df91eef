// The C++ push-pull (inpaint/push_pull.cpp) against training/inpaint_push_pull.py, the
// numpy port the inpainting network trains with: the network's input at inference must be
// the input it learned from. Fixtures written by training/export_inpaint.py.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <string>

#include "inpaint/push_pull.h"
#include "weights_format/weight_file.h"

using namespace ampi;

namespace {

const std::string kFixtures = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/inpaint/";

// A float tensor of 0..255 values as an 8-bit Mat with `channels` channels.
cv::Mat as_bytes(const Tensor& t, int h, int w, int channels) {
  cv::Mat m(h, w, CV_8UC(channels));
  const float* v = t.f32();
  for (int i = 0; i < h * w * channels; ++i) m.data[i] = cv::saturate_cast<uint8_t>(v[i]);
  return m;
}

}  // namespace

TEST_CASE("push-pull: C++ and the training's numpy port give the same fill", "[inpaint][push-pull]") {
  for (const char* name : {"push_pull_odd", "push_pull_even", "push_pull_thin"}) {
    INFO("fixture " << name);
    const WeightFile f = WeightFile::open(kFixtures + name + ".ampw");
    const TensorInfo* info = f.find("image");
    REQUIRE(info != nullptr);
    const int h = int(info->shape.at(0)), w = int(info->shape.at(1));
    const cv::Mat image = as_bytes(f.tensor("image", {h, w, 3}), h, w, 3);
    const cv::Mat known = as_bytes(f.tensor("known", {h, w}), h, w, 1) * 255;
    const cv::Mat fill = as_bytes(f.tensor("fill", {h, w}), h, w, 1) * 255;
    const cv::Mat expected = as_bytes(f.tensor("expected", {h, w, 3}), h, w, 3);
    REQUIRE(cv::countNonZero(fill) > 0);

    const cv::Mat filled = push_pull_fill(image, known, fill);
    cv::Mat diff;
    cv::absdiff(filled, expected, diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    // float sums in another order may round a .5 the other way: one level, rarely
    const int off = cv::countNonZero(diff.reshape(1));
    INFO("max |diff| " << worst << ", " << off << " of " << diff.total() * 3 << " values differ");
    CHECK(worst <= 1);
    CHECK(off <= int(diff.total() * 3 / 1000));
    // and the fill really is a fill: the hole's values differ from the image's
    cv::Mat changed;
    cv::absdiff(expected, image, changed);
    CHECK(cv::countNonZero(changed.reshape(1)) > 0);
  }
}
