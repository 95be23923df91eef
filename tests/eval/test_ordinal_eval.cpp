// eval/ordinal_eval.h: reading an ordinal set (and refusing malformed ones) and WHDR on
// maps whose order is known.
#include <catch2/catch.hpp>
#include <string>

#include <opencv2/imgproc.hpp>

#include "eval/ordinal_eval.h"
#include "render/temp_dir.h"

using namespace ampi;
using ampi::test::TempDir;

namespace {

const char kSet[] = R"({"seed": 1, "photos": [
 {"photo": "sub/a.jpg", "width": 40, "height": 30, "split": "val", "pairs": [
  {"id": 1, "kind": "random", "a": [5.0, 25.0], "b": [30.5, 4], "label": "A"},
  {"id": 2, "kind": "random", "a": [10, 2.5], "b": [12, 28], "label": "B"},
  {"id": 3, "kind": "edge", "a": [20, 10], "b": [21, 11], "label": "="}]},
 {"photo": "b.png", "width": 8, "height": 8, "split": "holdout", "pairs": []}]})";

std::string error_of(const std::string& path) {
  try {
    read_ordinal_set(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// Disparity growing downwards (the vertical gradient) at a size of its own.
cv::Mat rows_ramp(cv::Size size) {
  cv::Mat m(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y) m.row(y).setTo(float(y));
  return m;
}

}  // namespace

TEST_CASE("an ordinal set is read with its photos, points and labels", "[eval][ordinal]") {
  TempDir dir;
  const auto set = read_ordinal_set(dir.write("set.json", kSet));
  REQUIRE(set.size() == 2);
  CHECK(set[0].photo == "sub/a.jpg");
  CHECK(set[0].split == "val");
  CHECK(set[0].size == cv::Size(40, 30));
  REQUIRE(set[0].pairs.size() == 3);
  CHECK(set[0].pairs[0].a == cv::Point2f(5, 25));
  CHECK(set[0].pairs[0].b == cv::Point2f(30.5f, 4));
  CHECK(set[0].pairs[0].a_nearer == 1);
  CHECK(set[0].pairs[1].a_nearer == -1);
  CHECK(set[0].pairs[2].a_nearer == 0);
  CHECK(set[1].split == "holdout");
  CHECK(set[1].pairs.empty());
}

TEST_CASE("WHDR counts wrong orders, ties as half, and leaves out pairs too close to call", "[eval][ordinal]") {
  TempDir dir;
  const OrdinalPhoto photo = read_ordinal_set(dir.write("set.json", kSet))[0];
  // Lower is nearer: pair 1 (A low) right, pair 2 (B low) right; at any map size.
  for (cv::Size size : {cv::Size(40, 30), cv::Size(13, 7), cv::Size(160, 120)}) {
    const OrdinalScore s = score_ordinal(rows_ramp(size), photo);
    CHECK(s.pairs == 2);
    CHECK(s.wrong == 0);
  }
  cv::Mat upside_down;
  cv::flip(rows_ramp({40, 30}), upside_down, 0);
  CHECK(score_ordinal(upside_down, photo).whdr() == 1.0);
  CHECK(score_ordinal(cv::Mat(30, 40, CV_32FC1, cv::Scalar(2)), photo).whdr() == 0.5);
  // Near only around pair 2's A (10, 2.5): pair 1 now wrong (its B, at the top, is not
  // near), pair 2 wrong too (A, labelled farther, is nearest).
  cv::Mat spot(30, 40, CV_32FC1, cv::Scalar(0));
  cv::circle(spot, {10, 2}, 3, cv::Scalar(5), -1);
  const OrdinalScore s = score_ordinal(spot, photo);
  CHECK(s.wrong == 1.5);  // pair 1 a tie (0 and 0), pair 2 wrong
  CHECK_THROWS_AS(score_ordinal(cv::Mat(30, 40, CV_8UC1), photo), std::invalid_argument);
}

TEST_CASE("a malformed ordinal set gets one error naming the file and the problem", "[eval][ordinal]") {
  TempDir dir;
  const auto broken = [&](const std::string& from, const std::string& to) {
    std::string text = kSet;
    text.replace(text.find(from), from.size(), to);
    return dir.write("bad.json", text);
  };
  std::string path = broken(R"("label": "B")", R"("label": "C")");
  CHECK(error_of(path) == path + ": sub/a.jpg: label 'C' is not A, B or =");
  path = broken(R"("b": [30.5, 4])", R"("b": [30.5])");
  CHECK(error_of(path) == path + ": sub/a.jpg: 'b' is not a point [x, y]");
  path = broken(R"("a": [5.0, 25.0])", R"("a": [5.0, 30.0])");
  CHECK(error_of(path) == path + ": sub/a.jpg: a point lies outside the photo");
  path = broken(R"("split": "val")", R"("split": "held-out")");
  CHECK(error_of(path) == path + ": sub/a.jpg: split 'held-out' is not train, val, test or holdout");
  path = broken(R"("width": 40)", R"("width": 0)");
  CHECK(error_of(path) == path + ": sub/a.jpg: width and height must be positive integers");
  path = dir.write("empty.json", R"({"photos": []})");
  CHECK(error_of(path) == path + ": no photos");
  path = dir.write("truncated.json", std::string(kSet).substr(0, 120));
  CHECK(error_of(path).rfind(path + ": ", 0) == 0);
  CHECK(error_of(dir.file("missing.json")) == dir.file("missing.json") + ": cannot open");
}
