// Photos above max_working_side: the MPI is made at the reduced size, the written layers
// are at the photo's size, own pixels in the photo's colours, margins from the reduced fill.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "mpi/mpi_io.h"
#include "pipeline/full_resolution.h"
#include "pipeline/make_mpi.h"
#include "slicing/adaptive.h"

using namespace ampi;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("ampi_full_resolution_" + std::to_string(getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

// A photo of coloured noise over three depth bands (far left, middle, near right), and
// its disparity as a 16-bit PNG.
cv::Mat banded_photo(int w, int h) {
  cv::Mat bgr(h, w, CV_8UC3);
  cv::randu(bgr, cv::Scalar::all(0), cv::Scalar::all(256));
  return bgr;
}
cv::Mat banded_disparity(int w, int h) {
  cv::Mat d(h, w, CV_16UC1);
  for (int x = 0; x < w; ++x) d.col(x).setTo(x < w / 3 ? 1000 : x < 2 * w / 3 ? 30000 : 60000);
  return d;
}

}  // namespace

TEST_CASE("a full-resolution layer: own pixels from the photo, the rest the reduced layer enlarged") {
  const cv::Mat bgr = banded_photo(8, 4);
  cv::Mat levels(4, 8, CV_8UC1, cv::Scalar(0));
  levels.colRange(4, 8).setTo(200);
  Plane plane;
  plane.disparity_lo = 150;
  plane.disparity_hi = 255;
  cv::Mat reduced(2, 4, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  reduced.at<cv::Vec4b>(0, 1) = {10, 20, 30, 255};  // a filled margin pixel
  const cv::Mat layer = full_resolution_layer(bgr, levels, plane, reduced);
  REQUIRE(layer.size() == bgr.size());
  REQUIRE(layer.type() == CV_8UC4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      INFO("pixel " << x << "," << y);
      const cv::Vec4b p = layer.at<cv::Vec4b>(y, x);
      if (x >= 4) {
        const cv::Vec3b c = bgr.at<cv::Vec3b>(y, x);
        CHECK(p == cv::Vec4b(c[0], c[1], c[2], 255));
      } else if ((x == 2 || x == 3) && y < 2) {
        CHECK(p == cv::Vec4b(10, 20, 30, 255));  // the reduced pixel (1, 0), enlarged 2x
      } else {
        CHECK(p[3] == 0);
      }
    }
}

TEST_CASE("a photo above max_working_side: MPI at the reduced size, written layers at full size") {
  TempDir temp;
  const int w = 96, h = 48;
  const cv::Mat bgr = banded_photo(w, h);
  const std::string depth_file = (temp.path / "depth.png").string();
  REQUIRE(cv::imwrite(depth_file, banded_disparity(w, h)));
  MpiOptions options;
  options.depth_file = depth_file;
  options.max_working_side = 32;
  options.inpainter = Inpainter::PushPull;  // what is tested is the sizes, not the fill: no weight file
  MpiMaker maker(options);
  Progress progress(true);
  const MpiResult result = maker.make(bgr, "photo", progress);
  REQUIRE(is_reduced(result));
  CHECK(result.mpi.camera.width == 32);
  CHECK(result.mpi.camera.height == 16);
  CHECK(result.full_camera.width == w);
  CHECK(result.full_camera.height == h);
  CHECK(disparity_at_photo_size(result).size() == bgr.size());
  REQUIRE(result.mpi.planes.size() >= 2);

  const std::string dir = (temp.path / "mpi").string();
  write_mpi_at_photo_size(result, dir);
  const Mpi written = read_mpi(dir);
  REQUIRE(written.layers.size() == result.mpi.planes.size());
  CHECK(written.camera.width == w);
  CHECK(written.camera.fx == Approx(result.full_camera.fx));
  // Away from the bands' edges, each photo pixel is opaque, in its own colour, in the
  // plane that holds its band.
  const cv::Mat levels = normalize_disparity(disparity_at_photo_size(result));
  for (int y = 0; y < h; y += 5)
    for (int x : {5, w / 2, w - 5}) {
      INFO("pixel " << x << "," << y);
      const int j = plane_of_level(result.mpi.planes, levels.at<uchar>(y, x));
      REQUIRE(j >= 0);
      const cv::Vec3b c = bgr.at<cv::Vec3b>(y, x);
      CHECK(written.layers[j].at<cv::Vec4b>(y, x) == cv::Vec4b(c[0], c[1], c[2], 255));
    }

  // Without the cap, nothing is reduced.
  options.max_working_side = 0;
  MpiMaker full(options);
  const MpiResult unreduced = full.make(bgr, "photo", progress);
  CHECK_FALSE(is_reduced(unreduced));
  CHECK(unreduced.mpi.camera.width == w);
}
