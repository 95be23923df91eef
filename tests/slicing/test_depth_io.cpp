#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "engine/memory_budget.h"
#include "pipeline/depth_io.h"
#include "weights_format/npy.h"

namespace fs = std::filesystem;
using namespace ampi;

namespace {

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("ampi_depth_io_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

cv::Mat small_float_map() { return (cv::Mat_<float>(2, 3) << 0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 16.0f); }

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

void save_npy(const std::string& path, const Shape& shape, const std::vector<float>& values) {
  Tensor t = Tensor::empty(shape);
  std::copy(values.begin(), values.end(), t.f32());
  write_npy(path, t);
}

// The message of the runtime_error read_depth_map throws.
std::string import_error(const std::string& path, bool is_distance = false) {
  try {
    read_depth_map(path, is_distance);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

bool one_line_naming(const std::string& message, const std::string& path) {
  return message.rfind(path + ": ", 0) == 0 && message.find('\n') == std::string::npos;
}

}  // namespace

TEST_CASE("depth maps in 8-bit and 16-bit PNG and float TIFF") {
  TempDir dir;
  const cv::Mat levels = (cv::Mat_<uint16_t>(2, 2) << 0, 300, 65535, 7);
  REQUIRE(cv::imwrite(dir / "d16.png", levels));
  cv::Mat got = read_depth_map(dir / "d16.png", false);
  REQUIRE(got.type() == CV_32FC1);
  CHECK(got.at<float>(0, 1) == 300.0f);
  CHECK(got.at<float>(1, 0) == 65535.0f);

  cv::Mat levels8;
  levels.convertTo(levels8, CV_8U, 1.0 / 257);
  REQUIRE(cv::imwrite(dir / "d8.png", levels8));
  got = read_depth_map(dir / "d8.png", false);
  CHECK(got.at<float>(1, 0) == 255.0f);

  REQUIRE(cv::imwrite(dir / "d.tiff", small_float_map()));
  got = read_depth_map(dir / "d.tiff", false);
  CHECK(cv::norm(got, small_float_map(), cv::NORM_INF) == 0.0);
}

TEST_CASE("a three-channel depth image is read from its first channel") {
  TempDir dir;
  cv::Mat bgr(4, 5, CV_8UC3, cv::Scalar(40, 90, 200));
  REQUIRE(cv::imwrite(dir / "colour.png", bgr));
  const cv::Mat got = read_depth_map(dir / "colour.png", false);
  REQUIRE(got.channels() == 1);
  CHECK(got.at<float>(2, 3) == 40.0f);
}

TEST_CASE(".npy depth maps: H x W, with size-1 axes dropped") {
  TempDir dir;
  const std::vector<float> values = {1, 2, 3, 4, 5, 6};
  save_npy(dir / "hw.npy", {2, 3}, values);
  save_npy(dir / "chw.npy", {1, 2, 3}, values);
  save_npy(dir / "hwc.npy", {2, 3, 1}, values);
  for (const char* name : {"hw.npy", "chw.npy", "hwc.npy"}) {
    INFO(name);
    const cv::Mat got = read_depth_map(dir / name, false);
    REQUIRE(got.rows == 2);
    REQUIRE(got.cols == 3);
    CHECK(got.at<float>(1, 2) == 6.0f);
  }
  save_npy(dir / "flat.npy", {6}, values);
  CHECK(one_line_naming(import_error(dir / "flat.npy"), dir / "flat.npy"));
  CHECK_THAT(import_error(dir / "flat.npy"), Catch::Contains("expected H x W"));
  save_npy(dir / "two.npy", {2, 1, 3}, values);
  CHECK(read_depth_map(dir / "two.npy", false).size() == cv::Size(3, 2));
  save_npy(dir / "stack.npy", {2, 3, 1, 1}, values);
  CHECK(read_depth_map(dir / "stack.npy", false).size() == cv::Size(3, 2));
  save_npy(dir / "batch.npy", {2, 1, 1, 3}, values);
  CHECK(read_depth_map(dir / "batch.npy", false).size() == cv::Size(3, 2));
  save_npy(dir / "bad.npy", {2, 3, 2}, std::vector<float>(12, 1.0f));
  CHECK_THAT(import_error(dir / "bad.npy"), Catch::Contains("is not a depth map"));
}

TEST_CASE("NaN and infinite values give a clear error naming the file") {
  TempDir dir;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  save_npy(dir / "nan.npy", {2, 2}, {1, nan, 3, 4});
  save_npy(dir / "inf.npy", {2, 2}, {1, 2, -inf, 4});
  cv::Mat tiff = small_float_map();
  tiff.at<float>(1, 1) = nan;
  REQUIRE(cv::imwrite(dir / "nan.tiff", tiff));
  for (const char* name : {"nan.npy", "inf.npy", "nan.tiff"}) {
    INFO(name);
    const std::string message = import_error(dir / name);
    CHECK(one_line_naming(message, dir / name));
    CHECK_THAT(message, Catch::Contains("NaN or infinite"));
  }
}

TEST_CASE("missing, empty and unreadable depth files give one-line errors") {
  TempDir dir;
  write_text(dir / "empty.png", "");
  write_text(dir / "text.png", "this is not an image");
  write_text(dir / "text.npy", "this is not an array");
  std::vector<unsigned char> png;
  REQUIRE(cv::imencode(".png", cv::Mat(64, 64, CV_16UC1, cv::Scalar(1234)), png));
  png.resize(png.size() - 12);
  std::ofstream(dir / "cut.png", std::ios::binary).write(reinterpret_cast<const char*>(png.data()), png.size());
  std::string dicom(128, '\0');  // OpenCV's DICOM decoder (GDCM) aborts on some such files
  dicom += "DICM";
  dicom += std::string(64, '\xff');
  write_text(dir / "scan.png", dicom);
  const struct {
    std::string path, problem;
  } cases[] = {{dir / "missing.png", "no such file"},
               {dir.path.string(), "is a directory"},
               {dir / "empty.png", "empty file"},
               {dir / "text.png", "not a readable image"},
               {dir / "text.npy", "not a .npy file"},
               {dir / "cut.png", "truncated PNG"},
               {dir / "scan.png", "DICOM files are not supported"}};
  for (const auto& c : cases) {
    INFO(c.path);
    const std::string message = import_error(c.path);
    CHECK(one_line_naming(message, c.path));
    CHECK_THAT(message, Catch::Contains(c.problem));
  }
}

TEST_CASE("distance maps are inverted; zero distances become the farthest") {
  TempDir dir;
  save_npy(dir / "dist.npy", {1, 4}, {2.0f, 4.0f, 0.0f, 0.5f});
  const cv::Mat got = read_depth_map(dir / "dist.npy", true);
  CHECK(got.at<float>(0, 0) == 0.5f);
  CHECK(got.at<float>(0, 1) == 0.25f);
  CHECK(got.at<float>(0, 2) == 0.25f);
  CHECK(got.at<float>(0, 3) == 2.0f);
  save_npy(dir / "zeros.npy", {2, 2}, {0, 0, 0, -1});
  CHECK_THAT(import_error(dir / "zeros.npy", true), Catch::Contains("no positive value"));
  // Found by fuzz_depth_map (fuzz/corpus/depth_map/crash-denormal-distance): a positive
  // denormal distance used to become an infinite disparity.
  save_npy(dir / "denormal.npy", {1, 3}, {2.0f, 1e-40f, 4.0f});
  CHECK_THAT(import_error(dir / "denormal.npy", true),
             Catch::Contains("distance 9.99995e-41 at (1, 0) is too small to invert"));
}

TEST_CASE("write_depth_png16 normalises to 0..65535 and leaves no temporary file") {
  TempDir dir;
  write_depth_png16(small_float_map(), dir / "out.png");
  const cv::Mat png = cv::imread(dir / "out.png", cv::IMREAD_UNCHANGED);
  REQUIRE(png.type() == CV_16UC1);
  CHECK(png.at<uint16_t>(0, 0) == 0);
  CHECK(png.at<uint16_t>(1, 2) == 65535);
  CHECK(png.at<uint16_t>(0, 2) == cvRound(65535.0 * 1.5 / 15.5));
  CHECK(!fs::exists(dir / "out.png.tmp"));
  // Round trip: the import reads it back as the same ordering.
  const cv::Mat back = read_depth_map(dir / "out.png", false);
  CHECK(back.at<float>(1, 2) > back.at<float>(1, 1));

  write_depth_png16(cv::Mat(3, 3, CV_32FC1, cv::Scalar(2.0f)), dir / "flat.png");
  CHECK(cv::countNonZero(cv::imread(dir / "flat.png", cv::IMREAD_UNCHANGED)) == 0);

  cv::Mat bad = small_float_map();
  bad.at<float>(0, 0) = std::numeric_limits<float>::infinity();
  CHECK_THROWS_WITH(write_depth_png16(bad, dir / "bad.png"), Catch::StartsWith(dir / "bad.png" + ": "));
  CHECK(!fs::exists(dir / "bad.png"));
  CHECK_THROWS_WITH(write_depth_png16(small_float_map(), dir / "no/such/dir.png"), Catch::Contains("no/such/dir.png"));
}

TEST_CASE("a depth map over the memory budget is refused before it is decoded") {
  TempDir dir;
  std::vector<unsigned char> png;
  REQUIRE(cv::imencode(".png", cv::Mat(64, 64, CV_16UC1, cv::Scalar(1234)), png));
  std::ofstream(dir / "map.png", std::ios::binary).write(reinterpret_cast<const char*>(png.data()), png.size());
  set_memory_budget(64 * 64 * 12 - 1);  // per pixel: 4 x 16 bits decoded + the float map
  const std::string message = import_error(dir / "map.png");
  set_memory_budget(0);
  CHECK(one_line_naming(message, dir / "map.png"));
  CHECK_THAT(message, Catch::Contains("for the decoded 64x64 depth map, over the"));
  CHECK(read_depth_map(dir / "map.png", false).cols == 64);
}
