// distill/: the ensemble against training/distill.py (fixtures from
// tests/fixtures/distill/make_distill_fixtures.py), its parts on maps with known answers,
// and the label folder's manifest, resumption and refusals.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "distill/ensemble.h"
#include "distill/label_folder.h"
#include "render/temp_dir.h"
#include "weights_format/npy.h"

using namespace ampi;
using ampi::test::TempDir;
namespace fs = std::filesystem;

namespace {

const std::string kFixtures = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/distill/";

cv::Mat read_npy_mat(const std::string& path) {
  const Tensor t = read_npy(path);
  const int channels = t.rank() == 3 ? static_cast<int>(t.dim(2)) : 1;
  return cv::Mat(static_cast<int>(t.dim(0)), static_cast<int>(t.dim(1)), CV_32FC(channels),
                 const_cast<float*>(t.f32()))
      .clone();
}

// The fixture's teacher (make_distill_fixtures.py's `teacher`), on an RGB image.
cv::Mat analytic_teacher(const cv::Mat& rgb) {
  cv::Mat d(rgb.size(), CV_32FC1);
  for (int y = 0; y < rgb.rows; ++y)
    for (int x = 0; x < rgb.cols; ++x) {
      const cv::Vec3f p = rgb.at<cv::Vec3f>(y, x);
      const float column = (x + 0.5f) / rgb.cols;
      d.at<float>(y, x) = 0.3f * p[0] + 0.5f * p[1] * p[1] + 0.2f * std::sin(6 * p[2]) + 0.4f * column;
    }
  return d;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

LabelRecipe recipe(const std::string& teacher_file = "teacher.ampw") {
  return {teacher_file, "ampi.depth.dwt-mobilenetv3", "lite", {16, 24}, EnsembleShape::kSquare, "/photos"};
}

}  // namespace

TEST_CASE("the ensemble equals training/distill.py on the fixture") {
  const cv::Mat rgb = read_npy_mat(kFixtures + "rgb.npy");
  const cv::Mat expected = read_npy_mat(kFixtures + "label.npy");
  const cv::Mat label = pseudo_ground_truth(rgb, analytic_teacher, {16, 24, 40});
  REQUIRE(label.size() == expected.size());
  CHECK(cv::norm(label, expected, cv::NORM_INF) < 1e-4);
}

TEST_CASE("the ensemble with the aspect kept equals training/distill.py on the fixture") {
  const cv::Mat rgb = read_npy_mat(kFixtures + "rgb.npy");
  const cv::Mat expected = read_npy_mat(kFixtures + "label_aspect.npy");
  const cv::Mat label = pseudo_ground_truth(rgb, analytic_teacher, {16, 24, 40}, EnsembleShape::kAspectKept);
  REQUIRE(label.size() == expected.size());
  CHECK(cv::norm(label, expected, cv::NORM_INF) < 1e-4);
  CHECK(cv::norm(label, read_npy_mat(kFixtures + "label.npy"), cv::NORM_INF) > 1e-3);  // not the squares'
}

TEST_CASE("ensemble sizes: squares, or long sides with the aspect kept") {
  const std::vector<cv::Size> squares = ensemble_sizes({300, 200}, {16, 64}, EnsembleShape::kSquare);
  CHECK(squares == std::vector<cv::Size>{{16, 16}, {64, 64}});
  const std::vector<cv::Size> kept = ensemble_sizes({300, 200}, {30, 256}, EnsembleShape::kAspectKept);
  CHECK(kept == std::vector<cv::Size>{{30, 20}, {256, 171}});
  CHECK(ensemble_sizes({200, 300}, {30}, EnsembleShape::kAspectKept) == std::vector<cv::Size>{{20, 30}});
}

TEST_CASE("a mirrored prediction is flipped back before the median") {
  // A teacher that reads its input's red channel, on an image whose red grows to the
  // right: with the mirrored prediction flipped back, all predictions agree and the
  // ensemble is the plain prediction normalised; without, half of them would run the
  // other way and the median would flatten.
  cv::Mat rgb(8, 8, CV_32FC3);
  for (int x = 0; x < 8; ++x) rgb.col(x).setTo(cv::Scalar(x / 8.0, 0.5, 0.5));
  const Teacher red_teacher = [](const cv::Mat& image) {
    cv::Mat channels[3];
    cv::split(image, channels);
    return channels[0];
  };
  const cv::Mat median = ensemble_median(rgb, red_teacher, {8});
  CHECK(cv::norm(median, normalise_median_mad(red_teacher(rgb)), cv::NORM_INF) < 1e-6);
  CHECK(median.at<float>(0, 0) < median.at<float>(0, 7));
}

TEST_CASE("median/MAD normalisation") {
  cv::Mat d = (cv::Mat_<float>(1, 4) << 1, 2, 3, 10);  // median 2.5, MAD (1.5+0.5+0.5+7.5)/4 = 2.5
  const cv::Mat n = normalise_median_mad(d);
  CHECK(n.at<float>(0, 0) == Approx(-0.6));
  CHECK(n.at<float>(0, 3) == Approx(3.0));
  CHECK(cv::countNonZero(normalise_median_mad(cv::Mat(3, 3, CV_32FC1, cv::Scalar(7)))) == 0);
}

TEST_CASE("a label folder records, resumes and refuses what is not its own") {
  TempDir dir;
  const std::string folder = (dir.path() / "labels").string();
  const cv::Mat disparity = (cv::Mat_<float>(2, 3) << 0, 1, 2, 3, 4, 5);
  {
    LabelFolder labels(folder, recipe());
    CHECK_FALSE(labels.has("a/b.jpg"));
    labels.add("a/b.jpg", disparity);
    CHECK(labels.has("a/b.jpg"));
  }
  const cv::Mat png = cv::imread(folder + "/a_b.png", cv::IMREAD_UNCHANGED);
  REQUIRE(png.type() == CV_16UC1);
  CHECK(png.at<uint16_t>(1, 2) == 65535);
  CHECK(png.at<uint16_t>(0, 0) == 0);

  LabelFolder resumed(folder, recipe());
  CHECK(resumed.has("a/b.jpg"));
  CHECK(resumed.size() == 1);
  CHECK(error_of([&] { LabelFolder other(folder, recipe("other.ampw")); }).find("use another folder") !=
        std::string::npos);

  const std::string foreign = (dir.path() / "foreign").string();
  fs::create_directories(foreign);
  std::ofstream(foreign + "/mine.txt") << "the user's";
  CHECK(error_of([&] { LabelFolder labels(foreign, recipe()); }) ==
        foreign + ": not empty and not made by ampi distill (no labels.tsv)");
  CHECK(fs::exists(foreign + "/mine.txt"));
}

TEST_CASE("label names flatten the photo's path") {
  CHECK(label_name("a/b/c.jpg") == "a_b_c.png");
  CHECK(label_name("x.PNG") == "x.png");
}
