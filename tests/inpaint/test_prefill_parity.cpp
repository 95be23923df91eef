// The C++ prefills (inpaint/push_pull.cpp, inpaint/harmonic_fill.cpp) against
// training/inpaint_push_pull.py, the numpy ports the inpainting network trains with: the
// network's input at inference must be the input it learned from. Fixtures written by
// training/export_inpaint.py.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "inpaint/harmonic_fill.h"
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

// The fill of image where fill != 0 from the known pixels; the fixture's metadata holds
// the fill's parameters, if any.
using Filler = std::function<cv::Mat(const cv::Mat&, const cv::Mat&, const cv::Mat&, const WeightFile&)>;

void check_against_numpy(const std::vector<std::string>& names, const Filler& fill_with) {
  for (const std::string& name : names) {
    INFO("fixture " << name);
    const WeightFile f = WeightFile::open(kFixtures + name);
    const TensorInfo* info = f.find("image");
    REQUIRE(info != nullptr);
    const int h = int(info->shape.at(0)), w = int(info->shape.at(1));
    const cv::Mat image = as_bytes(f.tensor("image", {h, w, 3}), h, w, 3);
    const cv::Mat known = as_bytes(f.tensor("known", {h, w}), h, w, 1) * 255;
    const cv::Mat fill = as_bytes(f.tensor("fill", {h, w}), h, w, 1) * 255;
    const cv::Mat expected = as_bytes(f.tensor("expected", {h, w, 3}), h, w, 3);
    REQUIRE(cv::countNonZero(fill) > 0);

    const cv::Mat filled = fill_with(image, known, fill, f);
    cv::Mat diff;
    cv::absdiff(filled, expected, diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    // float sums in another order (or a fused multiply-add) may round a .5 the other
    // way: one level, rarely
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

}  // namespace

TEST_CASE("push-pull: C++ and the training's numpy port give the same fill", "[inpaint][push-pull]") {
  check_against_numpy({"push_pull_odd.ampw", "push_pull_even.ampw", "push_pull_thin.ampw"},
                      [](const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill, const WeightFile&) {
                        return push_pull_fill(image, known, fill);
                      });
}

TEST_CASE("harmonic fill: C++ and the training's numpy port give the same fill", "[inpaint][harmonic]") {
  for (int threads : {1, 2}) {
    INFO(threads << " threads");
    ThreadPool pool(threads);
    check_against_numpy({"harmonic_odd.ampw", "harmonic_even.ampw", "harmonic_thin.ampw",
                         "harmonic_cascade_odd.ampw", "harmonic_cascade_even.ampw"},
                        [&](const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill, const WeightFile& f) {
                          HarmonicFill params;
                          if (f.has("coarsest_side")) params.coarsest_side = int(f.get_int("coarsest_side"));
                          if (f.has("band")) params.band = int(f.get_int("band"));
                          if (f.has("start_side")) params.start_side = int(f.get_int("start_side"));
                          if (f.has("coarsest_sweeps")) params.coarsest_sweeps = int(f.get_int("coarsest_sweeps"));
                          if (f.has("sweeps")) params.sweeps = int(f.get_int("sweeps"));
                          return harmonic_fill(image, known, fill, params, pool);
                        });
  }
}
