// eval/slicing_eval.h: Table 3's protocol on scenes whose answer is known. A disparity
// map of a few flat steps is cut exactly by any slicing with a plane per step, so such an
// MPI renders the reference's views exactly; fewer planes than steps cannot.
#include <catch2/catch.hpp>
#include <random>

#include "eval/slicing_eval.h"
#include "render/synthetic_mpi.h"

using namespace ampi;

namespace {

// `steps` vertical bands of equally spaced disparity, farthest on the left.
cv::Mat staircase(int width, int height, int steps) {
  cv::Mat d(height, width, CV_32FC1);
  for (int x = 0; x < width; ++x) d.col(x).setTo(1.0 + (x * steps / width));
  return d;
}

cv::Mat photo(int width, int height) {
  std::mt19937 rng(5);
  return ampi::test::smooth_texture(width, height, rng);
}

SlicingEvalOptions small_options(std::vector<int> counts) {
  SlicingEvalOptions o;
  o.counts = std::move(counts);
  o.reference_planes = 32;
  o.poses = 3;
  o.amplitude = 0.1;
  return o;
}

}  // namespace

TEST_CASE("with a plane per step, adaptive and uniform render the reference's views exactly", "[eval][slicing]") {
  SlicingEvaluator eval(small_options({8, 2}), push_pull_filler());
  const std::vector<SlicingScore> rows = eval.add(photo(96, 64), staircase(96, 64, 8));
  REQUIRE(rows.size() == 4);
  // Counts in increasing order, uniform before adaptive.
  CHECK(rows[0].count == 2);
  CHECK(rows[0].method == "uniform");
  CHECK(rows[1].method == "adaptive");
  CHECK(rows[3].count == 8);
  for (int i : {2, 3}) {
    INFO(rows[i].method << " at count 8");
    CHECK(rows[i].planes == 8);
    CHECK(rows[i].psnr == 100.0);
    CHECK(rows[i].ssim == Approx(1.0));
  }
  for (int i : {0, 1}) {
    INFO(rows[i].method << " at count 2");
    CHECK(rows[i].planes <= 2);
    CHECK(rows[i].psnr < 60.0);
    CHECK(rows[i].ssim < 1.0);
  }
  CHECK(rows[0].planes == rows[1].planes);  // uniform gets the count adaptive made
}

TEST_CASE("the adaptive rows follow the chosen slicer, the uniform ones its count", "[eval][slicing]") {
  // Eight equally populated steps in four planes: the optimal cuts pair neighbouring steps,
  // as equal intervals do, so both MPIs are the same; the paper's cuts group them otherwise.
  SlicingEvalOptions options = small_options({4});
  const cv::Mat bgr = photo(96, 64), disparity = staircase(96, 64, 8);
  options.slicer = Slicer::Optimal;
  const std::vector<SlicingScore> optimal = SlicingEvaluator(options, push_pull_filler()).add(bgr, disparity);
  options.slicer = Slicer::Paper;
  const std::vector<SlicingScore> paper = SlicingEvaluator(options, push_pull_filler()).add(bgr, disparity);
  REQUIRE(optimal.size() == 2);
  REQUIRE(paper.size() == 2);
  CHECK(optimal[1].planes == 4);
  CHECK(paper[1].planes == 4);
  CHECK(optimal[1].psnr == optimal[0].psnr);  // optimal cuts = equal intervals here
  CHECK(optimal[1].ssim == optimal[0].ssim);
  CHECK(paper[0].psnr == optimal[0].psnr);  // uniform: the same count, the same MPI
  CHECK(paper[1].psnr != optimal[1].psnr);
}

TEST_CASE("the means are over photos", "[eval][slicing]") {
  SlicingEvaluator eval(small_options({4}), push_pull_filler());
  const std::vector<SlicingScore> a = eval.add(photo(64, 48), staircase(64, 48, 2));
  const std::vector<SlicingScore> b = eval.add(photo(64, 48), staircase(64, 48, 6));
  const std::vector<SlicingScore> mean = eval.mean();
  REQUIRE(mean.size() == 2);
  for (int i : {0, 1}) {
    CHECK(mean[i].photos == 2);
    CHECK(mean[i].psnr == Approx((a[i].psnr + b[i].psnr) / 2));
    CHECK(mean[i].ssim == Approx((a[i].ssim + b[i].ssim) / 2));
    CHECK(mean[i].planes == Approx((a[i].planes + b[i].planes) / 2));
  }
}

TEST_CASE("view comparison: identical views score SSIM 1 and 100 dB, others less", "[eval][slicing]") {
  const cv::Mat a = photo(40, 30);
  cv::Mat b = a.clone();
  b(cv::Rect(0, 0, 20, 30)) += cv::Scalar(30, 30, 30);
  const ViewScore same = compare_views({a, a}, {a.clone(), a.clone()});
  CHECK(same.psnr == 100.0);
  CHECK(same.ssim == Approx(1.0));
  const ViewScore other = compare_views({a, b}, {a, a});
  CHECK(other.psnr < 100.0);
  CHECK(other.ssim < 1.0);
  CHECK_THROWS_AS(compare_views({a}, {a, a}), std::invalid_argument);
}

TEST_CASE("target poses circle the source camera at the amplitude", "[eval][slicing]") {
  SlicingEvalOptions o = small_options({4});
  o.poses = 4;
  o.amplitude = 0.1;
  std::vector<Plane> planes(2);
  planes[0].depth = 10;
  planes[1].depth = 2;
  const std::vector<Pose> poses = target_poses(planes, o);
  REQUIRE(poses.size() == 4);
  for (const Pose& p : poses) CHECK(cv::norm(p.t) == Approx(0.2));  // 0.1 x the nearest depth
}

TEST_CASE("the inpainted margin scales with the photo as in ampi run", "[eval][slicing]") {
  CHECK(margin_for_photo({1024, 768}).dilate_iterations == 40);
  CHECK(margin_for_photo({384, 512}).dilate_iterations == 20);
  CHECK(margin_for_photo({64, 48}).dilate_iterations == 10);
}

TEST_CASE("bad slicing evaluation options are refused", "[eval][slicing]") {
  const auto make = [](SlicingEvalOptions o) { SlicingEvaluator(o, push_pull_filler()); };
  CHECK_THROWS_AS(make(small_options({})), std::invalid_argument);
  CHECK_THROWS_AS(make(small_options({0})), std::invalid_argument);
  CHECK_THROWS_AS(make(small_options({256})), std::invalid_argument);
  SlicingEvalOptions o = small_options({4});
  o.reference_planes = 1;
  CHECK_THROWS_AS(make(o), std::invalid_argument);
  o = small_options({4});
  o.poses = 0;
  CHECK_THROWS_AS(make(o), std::invalid_argument);
  o = small_options({4});
  o.amplitude = 1.0;
  CHECK_THROWS_AS(make(o), std::invalid_argument);
}
