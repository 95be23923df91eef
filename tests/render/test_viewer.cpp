#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mpi/mpi_io.h"
#include "render/renderer.h"
#include "render/video_out.h"
#include "render/viewer.h"
#include "synthetic_mpi.h"
#include "temp_dir.h"

using namespace ampi;
namespace fs = std::filesystem;

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string find_chromium() {
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"})
    if (program_on_path(name)) return name;
  return "";
}

// Headless Chromium's screenshot of `page` at the pose in the address. The flags keep
// it offline and independent of any profile; --no-sandbox lets it run as root.
cv::Mat screenshot(const std::string& chromium, const std::string& page, const std::string& fragment,
                   cv::Size window, const test::TempDir& dir) {
  const std::string png = dir.file("screenshot.png");
  std::ostringstream command;
  command << "timeout 120 " << chromium
          << " --headless --no-sandbox --disable-gpu --disable-background-networking"
             " --disable-component-update --disable-sync --no-first-run --hide-scrollbars"
             " --force-device-scale-factor=1 --virtual-time-budget=5000"
          << " --user-data-dir=" << dir.file("profile") << " --screenshot=" << png
          << " --window-size=" << window.width << "," << window.height << " 'file://"
          << fs::absolute(page).string() << "#" << fragment << "' > " << dir.file("chromium.log") << " 2>&1";
  const int status = std::system(command.str().c_str());
  INFO("chromium command: " << command.str() << "\nlog: " << read_text(dir.file("chromium.log")));
  REQUIRE(status == 0);
  return cv::imread(png, cv::IMREAD_COLOR);
}

double mean_difference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar m = cv::mean(d);
  return (m[0] + m[1] + m[2]) / 3.0;
}

}  // namespace

TEST_CASE("the viewer page is standalone: no network, the scene inside") {
  const Mpi mpi = test::synthetic_mpi(40, 30, 3, 101, test::Alpha::Soft);
  const std::string page = viewer_html(mpi);
  CHECK(page.find("http://") == std::string::npos);
  CHECK(page.find("https://") == std::string::npos);
  CHECK(page.find("@SCENE@") == std::string::npos);
  size_t layers = 0;
  for (size_t at = page.find("data:image/png;base64,"); at != std::string::npos;
       at = page.find("data:image/png;base64,", at + 1))
    ++layers;
  CHECK(layers == 3);
  CHECK(page.find("\"width\": 40, \"height\": 30") != std::string::npos);

  ViewerOptions referenced;
  referenced.embed_layers = false;
  const std::string linked = viewer_html(mpi, referenced);
  CHECK(linked.find("data:image") == std::string::npos);
  CHECK(linked.find("\"src\": \"mpi/layer_02.png\"") != std::string::npos);
  referenced.layer_folder = "../x\"y";
  CHECK_THROWS_WITH(viewer_html(mpi, referenced), Catch::Contains("layer folder"));
}

TEST_CASE("viewer.html goes next to the mpi folder") {
  test::TempDir dir;
  const Mpi mpi = test::synthetic_mpi(40, 30, 2, 102, test::Alpha::Binary);
  write_mpi(mpi, dir.file("mpi"));
  ViewerOptions referenced;
  referenced.embed_layers = false;
  CHECK(write_viewer(mpi, dir.file("mpi"), referenced) == dir.file("viewer.html"));
  CHECK(read_text(dir.file("viewer.html")).find("\"mpi/layer_01.png\"") != std::string::npos);
  fs::remove(dir.file("viewer.html"));
  CHECK(write_viewer(mpi, dir.path().string() + "/", referenced) == dir.file("viewer.html"));
  fs::remove(dir.file("mpi/layer_01.png"));
  CHECK_THROWS_WITH(write_viewer(mpi, dir.path().string(), referenced),
                    Catch::Contains("layer_01.png: missing"));
  CHECK_THROWS_WITH(write_viewer(mpi, dir.file("nothing"), {}), Catch::Contains("nothing: not a directory"));
}

TEST_CASE("headless Chromium shows the viewer as the renderer draws it") {
  const std::string chromium = find_chromium();
  if (chromium.empty()) {
    WARN("chromium is not installed (scripts/setup.sh installs it): viewer screenshot test skipped");
    return;
  }
  test::TempDir dir;
  const Mpi mpi = test::synthetic_mpi(480, 320, 5, 103, test::Alpha::Soft);
  const std::string page = write_viewer(mpi, dir.path().string());
  const Renderer renderer(mpi);
  const double nearest = mpi.planes.back().depth;
  // Translations in scene units (the address carries t as Pose does), and a zoom.
  const Pose poses[] = {
      Pose{},
      Pose{cv::Matx33d::eye(), {0.1 * nearest, -0.06 * nearest, 0}, 1},
      Pose{cv::Matx33d::eye(), {0.04 * nearest, 0.02 * nearest, -0.3 * nearest}, 1.1},
  };
  for (const Pose& pose : poses) {
    std::ostringstream fragment;
    fragment << std::setprecision(17) << "pose=" << pose.t[0] << "," << pose.t[1] << "," << pose.t[2]
             << "&zoom=" << pose.zoom;
    INFO("view " << fragment.str() << ", seed 103");
    const cv::Mat shot = screenshot(chromium, page, fragment.str(), {480, 320}, dir);
    REQUIRE(shot.size() == cv::Size(480, 320));
    const double to_pose = mean_difference(shot, renderer.render(pose));
    INFO("mean |screenshot - render| " << to_pose);
    CHECK(to_pose < 1.5);
    if (pose.t != cv::Vec3d(0, 0, 0)) {
      // The pose must matter: the unmoved view is much further from the screenshot.
      CHECK(mean_difference(shot, renderer.render(Pose{})) > 4 * to_pose);
    }
  }
}
