#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "engine/memory_budget.h"
#include "pipeline/photo_io.h"

namespace fs = std::filesystem;
using namespace ampi;

namespace {

fs::path temp_dir() {
  fs::path dir = fs::temp_directory_path() / ("ampi_photo_io_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

void write_bytes(const fs::path& p, const std::vector<unsigned char>& bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<unsigned char> encode(const cv::Mat& m, const std::string& ext) {
  std::vector<unsigned char> bytes;
  REQUIRE(cv::imencode(ext, m, bytes));
  return bytes;
}

// A gradient that is not symmetric, so a rotation is visible.
cv::Mat test_image(int w, int h) {
  cv::Mat m(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.at<cv::Vec3b>(y, x) = {uchar(x * 255 / w), uchar(y * 255 / h), 0};
  return m;
}

// Inserts an APP1 EXIF segment with one tag, Orientation = `orientation`, after SOI.
std::vector<unsigned char> with_exif_orientation(std::vector<unsigned char> jpeg, int orientation) {
  const unsigned char tiff[] = {'I', 'I', 42, 0, 8, 0, 0, 0,            // header, IFD at 8
                                1, 0,                                   // one entry
                                0x12, 0x01, 3, 0, 1, 0, 0, 0,           // Orientation, SHORT, 1
                                (unsigned char)orientation, 0, 0, 0,    // value
                                0, 0, 0, 0};                            // no next IFD
  std::vector<unsigned char> app1 = {0xFF, 0xE1, 0, 0, 'E', 'x', 'i', 'f', 0, 0};
  app1.insert(app1.end(), std::begin(tiff), std::end(tiff));
  const size_t len = app1.size() - 2;
  app1[2] = static_cast<unsigned char>(len >> 8);
  app1[3] = static_cast<unsigned char>(len & 0xff);
  jpeg.insert(jpeg.begin() + 2, app1.begin(), app1.end());
  return jpeg;
}

std::string error_of(const std::string& path) {
  try {
    read_photo(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("read_photo decodes JPEG and PNG, gray, 16-bit and alpha inputs as 8-bit BGR") {
  const fs::path dir = temp_dir();
  const cv::Mat img = test_image(40, 30);
  write_bytes(dir / "a.jpg", encode(img, ".jpg"));
  write_bytes(dir / "a.png", encode(img, ".png"));
  cv::Mat gray, rgba, deep;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  cv::cvtColor(img, rgba, cv::COLOR_BGR2BGRA);
  img.convertTo(deep, CV_16U, 257.0);
  write_bytes(dir / "gray.png", encode(gray, ".png"));
  write_bytes(dir / "rgba.png", encode(rgba, ".png"));
  write_bytes(dir / "deep.png", encode(deep, ".png"));
  for (const char* name : {"a.jpg", "a.png", "gray.png", "rgba.png", "deep.png"}) {
    INFO(name);
    const cv::Mat m = read_photo((dir / name).string());
    CHECK(m.type() == CV_8UC3);
    CHECK(m.size() == img.size());
  }
  const cv::Mat deep_read = read_photo((dir / "deep.png").string());
  CHECK(cv::norm(deep_read, img, cv::NORM_INF) <= 1);
  fs::remove_all(dir);
}

TEST_CASE("read_photo honours EXIF orientation") {
  const fs::path dir = temp_dir();
  const cv::Mat img = test_image(48, 24);
  write_bytes(dir / "rot.jpg", with_exif_orientation(encode(img, ".jpg"), 6));  // rotate 90 CW
  const cv::Mat m = read_photo((dir / "rot.jpg").string());
  CHECK(m.cols == 24);
  CHECK(m.rows == 48);
  fs::remove_all(dir);
}

TEST_CASE("read_photo rejects bad input with one line naming the file") {
  const fs::path dir = temp_dir();
  const std::vector<unsigned char> jpg = encode(test_image(64, 64), ".jpg");
  const std::vector<unsigned char> png = encode(test_image(64, 64), ".png");
  write_bytes(dir / "empty.jpg", {});
  write_bytes(dir / "text.jpg", {'h', 'e', 'l', 'l', 'o', '\n'});
  write_bytes(dir / "cut.jpg", std::vector<unsigned char>(jpg.begin(), jpg.begin() + jpg.size() / 2));
  write_bytes(dir / "cut.png", std::vector<unsigned char>(png.begin(), png.begin() + png.size() / 2));
  write_bytes(dir / "tiny.png", encode(test_image(8, 40), ".png"));
  std::vector<unsigned char> dicom(128, 0);  // OpenCV's DICOM decoder (GDCM) aborts on some
  for (char c : std::string("DICM") + std::string(64, '\xff')) dicom.push_back(static_cast<unsigned char>(c));
  write_bytes(dir / "scan.jpg", dicom);
  fs::create_directories(dir / "folder.jpg");
  const std::pair<const char*, const char*> cases[] = {
      {"missing.jpg", "no such file"},        {"empty.jpg", "empty file"},
      {"text.jpg", "not a readable image"},   {"cut.jpg", "truncated JPEG"},
      {"cut.png", "truncated PNG"},           {"folder.jpg", "is a directory"},
      {"tiny.png", "at least 16 px"},         {"scan.jpg", "DICOM files are not supported"},
  };
  for (const auto& [name, problem] : cases) {
    const std::string path = (dir / name).string();
    const std::string message = error_of(path);
    INFO(name << " -> " << message);
    CHECK(message.rfind(path + ": ", 0) == 0);
    CHECK(message.find(problem) != std::string::npos);
    CHECK(message.find('\n') == std::string::npos);
  }
  fs::remove_all(dir);
}

TEST_CASE("encoded_image_size reads PNG and JPEG headers without decoding") {
  const cv::Mat img = test_image(40, 30);
  CHECK(encoded_image_size(encode(img, ".png"))->width == 40);
  CHECK(encoded_image_size(encode(img, ".png"))->height == 30);
  std::vector<unsigned char> progressive;
  REQUIRE(cv::imencode(".jpg", img, progressive, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}));
  // EXIF in front of the frame header: the walk must step over the APP1 segment.
  for (const auto& jpeg : {encode(img, ".jpg"), progressive, with_exif_orientation(encode(img, ".jpg"), 6)}) {
    const auto size = encoded_image_size(jpeg);
    REQUIRE(size);
    CHECK(size->width == 40);
    CHECK(size->height == 30);
  }
  CHECK_FALSE(encoded_image_size(encode(img, ".bmp")));
  CHECK_FALSE(encoded_image_size({0xFF, 0xD8, 0xFF, 0xE0, 0x00}));  // cut inside a segment
  CHECK_FALSE(encoded_image_size({'h', 'e', 'l', 'l', 'o'}));
}

TEST_CASE("read_photo refuses a photo over the memory budget before decoding it") {
  const fs::path dir = temp_dir();
  std::vector<unsigned char> png = encode(test_image(64, 64), ".png");
  write_bytes(dir / "small.png", png);
  // The header claims 30000 x 20000: refused from the header alone (the pixel data and
  // the chunk's checksum no longer match, which only a decoder would notice).
  const unsigned char claimed[8] = {0, 0, 0x75, 0x30, 0, 0, 0x4E, 0x20};
  std::copy(std::begin(claimed), std::end(claimed), png.begin() + 16);
  write_bytes(dir / "huge.png", png);
  set_memory_budget(uint64_t(1) << 30);
  const std::string huge = error_of((dir / "huge.png").string());
  CHECK(huge == (dir / "huge.png").string() +
                    ": needs 1.7 GiB for the decoded 30000x20000 photo, over the 1.0 GiB memory budget "
                    "(AMPI_MEMORY_BUDGET)");
  CHECK(read_photo((dir / "small.png").string()).cols == 64);
  set_memory_budget(64 * 64 * 3 - 1);
  CHECK(error_of((dir / "small.png").string()).find("over the") != std::string::npos);
  set_memory_budget(0);
  fs::remove_all(dir);
}
