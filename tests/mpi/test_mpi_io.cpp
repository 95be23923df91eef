#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "engine/memory_budget.h"
#include "mpi/mpi_io.h"

namespace fs = std::filesystem;
using namespace ampi;

namespace {

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("ampi_mpi_io_" + std::to_string(::getpid()));
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

// Three planes of a 7x5 image, layers of seeded random BGRA.
Mpi sample_mpi(uint64_t seed) {
  Mpi m;
  m.camera = camera_from_fov(7, 5, 55);
  m.camera.cy = 2.25;  // not the centre: the reader must not recompute it
  m.range = {0.5, 80};
  const double lo[] = {0, 90, 170}, hi[] = {90, 170, 255};
  cv::RNG rng(seed);
  for (int j = 0; j < 3; ++j) {
    Plane p;
    p.disparity_lo = lo[j];
    p.disparity_hi = hi[j];
    p.disparity = 0.5 * (lo[j] + hi[j]) + 0.123456789;
    p.depth = depth_from_disparity(p.disparity, m.range);
    p.pixel_count = 10 + j;
    m.planes.push_back(p);
    cv::Mat layer(5, 7, CV_8UC4);
    rng.fill(layer, cv::RNG::UNIFORM, cv::Scalar::all(0), cv::Scalar::all(256));
    m.layers.push_back(layer);
  }
  return m;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// Replaces the first occurrence of `from` in the file; the test fails if there is none.
void edit(const std::string& path, const std::string& from, const std::string& to) {
  std::string text = read_text(path);
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  text.replace(at, from.size(), to);
  write_text(path, text);
}

// Replaces the whole first line that contains `key` by `line`.
void replace_line(const std::string& path, const std::string& key, const std::string& line) {
  std::string text = read_text(path);
  const size_t at = text.find(key);
  REQUIRE(at != std::string::npos);
  const size_t begin = text.rfind('\n', at) + 1, end = text.find('\n', at);
  text.replace(begin, end - begin, line);
  write_text(path, text);
}

std::string read_error(const std::string& dir) {
  try {
    read_mpi(dir);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("an MPI survives write and read exactly") {
  TempDir dir;
  const Mpi m = sample_mpi(11);
  write_mpi(m, dir / "mpi");
  CHECK(fs::exists(dir / "mpi/layer_00.png"));
  CHECK(fs::exists(dir / "mpi/layer_02.png"));
  const Mpi back = read_mpi(dir / "mpi");
  CHECK(back.camera.width == 7);
  CHECK(back.camera.height == 5);
  CHECK(back.camera.fx == m.camera.fx);
  CHECK(back.camera.fy == m.camera.fy);
  CHECK(back.camera.cx == m.camera.cx);
  CHECK(back.camera.cy == 2.25);
  CHECK(back.range.near == 0.5);
  CHECK(back.range.far == 80);
  REQUIRE(back.planes.size() == 3);
  REQUIRE(back.layers.size() == 3);
  for (size_t j = 0; j < 3; ++j) {
    INFO("plane " << j);
    CHECK(back.planes[j].depth == m.planes[j].depth);
    CHECK(back.planes[j].disparity == m.planes[j].disparity);
    CHECK(back.planes[j].disparity_lo == m.planes[j].disparity_lo);
    CHECK(back.planes[j].disparity_hi == m.planes[j].disparity_hi);
    CHECK(back.planes[j].pixel_count == m.planes[j].pixel_count);
    REQUIRE(back.layers[j].type() == CV_8UC4);
    CHECK(cv::norm(back.layers[j], m.layers[j], cv::NORM_INF) == 0);
  }
}

TEST_CASE("writing keeps other files, replaces its own, leaves no temporary files") {
  TempDir dir;
  const std::string out = dir / "mpi";
  fs::create_directories(out);
  write_text(out + "/notes.txt", "mine");
  write_text(out + "/layer_07.png", "stale");
  write_mpi(sample_mpi(1), out);
  write_mpi(sample_mpi(2), out);
  CHECK(read_text(out + "/notes.txt") == "mine");
  CHECK(read_text(out + "/layer_07.png") == "stale");
  CHECK(cv::norm(read_mpi(out).layers[1], sample_mpi(2).layers[1], cv::NORM_INF) == 0);
  for (const auto& entry : fs::directory_iterator(out)) CHECK(entry.path().extension() != ".tmp");
}

TEST_CASE("write_mpi refuses an inconsistent MPI before writing anything") {
  TempDir dir;
  const std::function<void(Mpi&)> breakages[] = {
      [](Mpi& m) { m.layers.pop_back(); },
      [](Mpi& m) { m.layers[1] = cv::Mat(5, 7, CV_8UC3); },
      [](Mpi& m) { m.layers[2] = cv::Mat(6, 7, CV_8UC4); },
      [](Mpi& m) { m.planes[1].depth = m.planes[0].depth; },
      [](Mpi& m) { m.planes[2].depth = 0; },
      [](Mpi& m) { m.camera.fx = 0; },
      [](Mpi& m) { m.range.near = m.range.far; },
      [](Mpi& m) {
        m.planes.clear();
        m.layers.clear();
      },
  };
  int index = 0;
  for (const auto& breakage : breakages) {
    INFO("breakage " << index++);
    Mpi m = sample_mpi(3);
    breakage(m);
    CHECK_THROWS_AS(write_mpi(m, dir / "never"), std::runtime_error);
    CHECK(!fs::exists(dir / "never"));
  }
}

TEST_CASE("malformed MPI folders give a one-line error naming the file and the problem") {
  TempDir dir;
  struct Case {
    const char* name;
    std::function<void(const std::string& mpi_dir)> damage;
    const char* file;  // the file the message must start with ("" = the folder)
    const char* problem;
  };
  const auto png = [](const std::string& path, const cv::Mat& image) { REQUIRE(cv::imwrite(path, image)); };
  const Case cases[] = {
      {"missing folder", [](const std::string& d) { fs::remove_all(d); }, "", "no such MPI folder"},
      {"folder is a file", [](const std::string& d) {
         fs::remove_all(d);
         write_text(d, "x");
       }, "", "not a folder"},
      {"missing json", [](const std::string& d) { fs::remove(d + "/mpi.json"); }, "mpi.json", "missing"},
      {"malformed json", [](const std::string& d) { write_text(d + "/mpi.json", "{ \"format\": [1, "); }, "mpi.json",
       "malformed JSON"},
      {"empty json", [](const std::string& d) { write_text(d + "/mpi.json", ""); }, "mpi.json", "malformed JSON"},
      {"not an object", [](const std::string& d) { write_text(d + "/mpi.json", "[1, 2]"); }, "mpi.json",
       "malformed JSON"},
      {"other format", [](const std::string& d) { edit(d + "/mpi.json", "ampi-mpi", "other"); }, "mpi.json",
       "not an ampi MPI"},
      {"wrong version", [](const std::string& d) { edit(d + "/mpi.json", "\"version\": 1", "\"version\": 7"); },
       "mpi.json", "version 7 is not supported"},
      {"missing field", [](const std::string& d) { edit(d + "/mpi.json", "\"near\"", "\"nearby\""); }, "mpi.json",
       "missing field 'near'"},
      {"missing plane field", [](const std::string& d) { edit(d + "/mpi.json", "\"pixels\"", "\"pixel\""); },
       "mpi.json", "missing field 'planes[0].pixels'"},
      {"ill-typed field", [](const std::string& d) { edit(d + "/mpi.json", "\"width\": 7", "\"width\": \"7\""); },
       "mpi.json", "'width' is not an integer"},
      {"bad interval", [](const std::string& d) { edit(d + "/mpi.json", "\"interval\": [", "\"interval\": [ 5.0,"); },
       "mpi.json", "planes[0].interval"},
      {"plane count mismatch",
       [](const std::string& d) { edit(d + "/mpi.json", "\"plane_count\": 3", "\"plane_count\": 4"); }, "mpi.json",
       "lists 3 planes but plane_count is 4"},
      {"layer outside the folder",
       [](const std::string& d) { edit(d + "/mpi.json", "\"layer_01.png\"", "\"../layer_01.png\""); }, "mpi.json",
       "must be a file name"},
      {"missing layer", [](const std::string& d) { fs::remove(d + "/layer_01.png"); }, "layer_01.png",
       "missing layer file"},
      {"unreadable layer", [](const std::string& d) { write_text(d + "/layer_02.png", "garbage"); }, "layer_02.png",
       "not a readable image"},
      {"layer size mismatch", [&](const std::string& d) { png(d + "/layer_00.png", cv::Mat(5, 8, CV_8UC4)); },
       "layer_00.png", "is 8x5 but mpi.json says 7x5"},
      {"layer header claims a huge image",  // refused from the header, before decoding
       [](const std::string& d) {
         std::string png = read_text(d + "/layer_02.png");
         png.replace(16, 8, std::string("\0\0\xEA\x60\0\0\xC3\x50", 8));  // 60000 x 50000
         write_text(d + "/layer_02.png", png);
       },
       "layer_02.png", "is 60000x50000 but mpi.json says 7x5"},
      {"layer not RGBA", [&](const std::string& d) { png(d + "/layer_01.png", cv::Mat(5, 7, CV_8UC3)); },
       "layer_01.png", "not an 8-bit RGBA image (3 channels"},
      {"16-bit layer", [&](const std::string& d) { png(d + "/layer_01.png", cv::Mat(5, 7, CV_16UC4)); },
       "layer_01.png", "(4 channels, 16-bit)"},
      {"depth order", [](const std::string& d) { replace_line(d + "/mpi.json", "\"depth\"", "\"depth\": 0.001,"); },
       "mpi.json", "planes must go back to front"},
      {"non-positive depth", [](const std::string& d) { edit(d + "/mpi.json", "\"depth\": ", "\"depth\": -"); },
       "mpi.json", "non-positive depth"},
      {"bad intrinsics", [](const std::string& d) { edit(d + "/mpi.json", "\"fx\": ", "\"fx\": -"); }, "mpi.json",
       "focal lengths"},
      {"bad range", [](const std::string& d) { replace_line(d + "/mpi.json", "\"far\"", "\"far\": 0.25,"); }, "mpi.json",
       "0 < near < far"},
  };
  for (const Case& c : cases) {
    INFO("case: " << c.name);
    const std::string mpi_dir = dir / "mpi";
    fs::remove_all(mpi_dir);
    write_mpi(sample_mpi(5), mpi_dir);
    REQUIRE_NOTHROW(read_mpi(mpi_dir));
    c.damage(mpi_dir);
    const std::string message = read_error(mpi_dir);
    const std::string file = *c.file ? mpi_dir + "/" + c.file : mpi_dir;
    INFO("message: " << message);
    CHECK(message.rfind(file + ": ", 0) == 0);
    CHECK(message.find('\n') == std::string::npos);
    CHECK_THAT(message, Catch::Contains(c.problem));
  }
}

TEST_CASE("read_mpi refuses layers over the memory budget before decoding any") {
  TempDir dir;
  const std::string mpi_dir = dir / "mpi";
  write_mpi(sample_mpi(5), mpi_dir);
  edit(mpi_dir + "/mpi.json", "\"width\": 7", "\"width\": 70000");
  set_memory_budget(uint64_t(1) << 20);
  const std::string message = read_error(mpi_dir);
  set_memory_budget(0);
  CHECK(message == mpi_dir + "/mpi.json: needs 4.0 MiB for 3 RGBA layers at 70000x5, over the 1.0 MiB memory "
                             "budget (AMPI_MEMORY_BUDGET)");
}
