#include "mpi/mpi_io.h"

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "engine/memory_budget.h"

namespace fs = std::filesystem;

namespace ampi {
namespace {

const char* const kFormatName = "ampi-mpi";

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

std::string layer_name(size_t j) {
  char name[32];
  std::snprintf(name, sizeof name, "layer_%02zu.png", j);
  return name;
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// What write and read both require of the description (everything but the pixels).
void check_description(const Mpi& mpi, const std::string& where) {
  const Camera& c = mpi.camera;
  if (c.width <= 0 || c.height <= 0) fail(where, "image size " + size_text(c.width, c.height) + " is not positive");
  if (!(c.fx > 0 && c.fy > 0)) fail(where, "focal lengths fx, fy must be positive");
  if (!(mpi.range.near > 0 && mpi.range.far > mpi.range.near)) fail(where, "needs 0 < near < far");
  if (mpi.planes.empty()) fail(where, "has no planes");
  for (size_t j = 0; j < mpi.planes.size(); ++j) {
    const Plane& p = mpi.planes[j];
    if (!(p.depth > 0)) fail(where, "plane " + std::to_string(j) + " has non-positive depth " + std::to_string(p.depth));
    if (j > 0 && !(p.depth < mpi.planes[j - 1].depth))
      fail(where, "plane " + std::to_string(j) + " (depth " + std::to_string(p.depth) + ") is not nearer than plane " +
                      std::to_string(j - 1) + " (depth " + std::to_string(mpi.planes[j - 1].depth) +
                      "): planes must go back to front");
    if (!(p.disparity_lo <= p.disparity_hi))
      fail(where, "plane " + std::to_string(j) + " has an interval with lo > hi");
    if (p.pixel_count < 0 || p.pixel_count > INT_MAX)
      fail(where, "plane " + std::to_string(j) + " has a pixel count out of range");
  }
}

void check_layer(const cv::Mat& layer, const Camera& c, const std::string& path) {
  if (layer.type() != CV_8UC4)
    fail(path, "is not an 8-bit RGBA image (" + std::to_string(layer.channels()) + " channels, " +
                   std::to_string(8 * layer.elemSize1()) + "-bit)");
  if (layer.cols != c.width || layer.rows != c.height)
    fail(path, "is " + size_text(layer.cols, layer.rows) + " but mpi.json says " + size_text(c.width, c.height));
}

std::string description_json(const Mpi& mpi, const std::vector<std::string>& layer_names) {
  cv::FileStorage out("mpi.json", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_JSON);
  out << "format" << kFormatName << "version" << kMpiFormatVersion;
  out << "width" << mpi.camera.width << "height" << mpi.camera.height;
  out << "camera" << "{" << "fx" << mpi.camera.fx << "fy" << mpi.camera.fy << "cx" << mpi.camera.cx << "cy"
      << mpi.camera.cy << "}";
  out << "near" << mpi.range.near << "far" << mpi.range.far;
  out << "plane_count" << static_cast<int>(mpi.planes.size());
  out << "planes" << "[";
  for (size_t j = 0; j < mpi.planes.size(); ++j) {
    const Plane& p = mpi.planes[j];
    out << "{" << "depth" << p.depth << "disparity" << p.disparity;
    out << "interval" << "[" << p.disparity_lo << p.disparity_hi << "]";
    out << "pixels" << static_cast<int>(p.pixel_count) << "layer" << layer_names[j] << "}";
  }
  out << "]";
  return out.releaseAndGetString();
}

// ---- reading ---------------------------------------------------------------------------

// OpenCV's JSON parser reports a syntax error as "PATH(LINE): REASON" in the exception's
// function field; other failures (empty file, no top-level object) carry nothing useful.
std::string json_error(const cv::Exception& e) {
  const size_t close = e.func.rfind("): ");
  const size_t open = close == std::string::npos ? close : e.func.rfind('(', close);
  if (e.code != cv::Error::StsParseError || open == std::string::npos) return "malformed JSON";
  return "malformed JSON at line " + e.func.substr(open + 1, close - open - 1) + " (" + e.func.substr(close + 3) + ")";
}

cv::FileStorage open_json(const std::string& path) {
  try {
    cv::FileStorage in(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON);
    if (!in.isOpened()) fail(path, "cannot be opened");
    return in;
  } catch (const cv::Exception& e) {
    fail(path, json_error(e));
  }
}

// Field readers: `where` names the field in messages, e.g. "planes[2].depth".
cv::FileNode field(const cv::FileNode& parent, const char* key, const std::string& path, const std::string& where) {
  const cv::FileNode node = parent[key];
  if (node.empty() || node.isNone()) fail(path, "missing field '" + where + "'");
  return node;
}

double number(const cv::FileNode& parent, const char* key, const std::string& path, const std::string& where) {
  const cv::FileNode node = field(parent, key, path, where);
  if (!node.isInt() && !node.isReal()) fail(path, "field '" + where + "' is not a number");
  return node.real();
}

int integer(const cv::FileNode& parent, const char* key, const std::string& path, const std::string& where) {
  const cv::FileNode node = field(parent, key, path, where);
  if (!node.isInt()) fail(path, "field '" + where + "' is not an integer");
  return static_cast<int>(node);
}

std::string text(const cv::FileNode& parent, const char* key, const std::string& path, const std::string& where) {
  const cv::FileNode node = field(parent, key, path, where);
  if (!node.isString()) fail(path, "field '" + where + "' is not a string");
  return node.string();
}

Camera read_camera(const cv::FileNode& root, const std::string& path) {
  Camera c;
  c.width = integer(root, "width", path, "width");
  c.height = integer(root, "height", path, "height");
  const cv::FileNode cam = field(root, "camera", path, "camera");
  if (!cam.isMap()) fail(path, "field 'camera' is not an object");
  c.fx = number(cam, "fx", path, "camera.fx");
  c.fy = number(cam, "fy", path, "camera.fy");
  c.cx = number(cam, "cx", path, "camera.cx");
  c.cy = number(cam, "cy", path, "camera.cy");
  return c;
}

// A layer file name must stay inside the MPI folder.
void check_layer_name(const std::string& name, const std::string& path, const std::string& where) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
      name.find('\\') != std::string::npos)
    fail(path, "field '" + where + "' must be a file name inside the MPI folder, not '" + name + "'");
}

Plane read_plane(const cv::FileNode& node, const std::string& path, const std::string& where,
                 std::string* layer) {
  if (!node.isMap()) fail(path, "'" + where + "' is not an object");
  Plane p;
  p.depth = number(node, "depth", path, where + ".depth");
  p.disparity = number(node, "disparity", path, where + ".disparity");
  const cv::FileNode interval = field(node, "interval", path, where + ".interval");
  if (!interval.isSeq() || interval.size() != 2 || !(interval[0].isReal() || interval[0].isInt()) ||
      !(interval[1].isReal() || interval[1].isInt()))
    fail(path, "field '" + where + ".interval' is not a pair of numbers [lo, hi]");
  p.disparity_lo = interval[0].real();
  p.disparity_hi = interval[1].real();
  p.pixel_count = integer(node, "pixels", path, where + ".pixels");
  *layer = text(node, "layer", path, where + ".layer");
  check_layer_name(*layer, path, where + ".layer");
  return p;
}

// Layers are PNGs: their IHDR chunk gives the size before the decoder allocates it, so a
// layer that claims to be huge is refused here rather than decoded (other formats are
// bounded by OpenCV's own limit, OPENCV_IO_MAX_IMAGE_PIXELS).
void check_png_layer_size(const std::string& path, const Camera& c) {
  unsigned char header[24];
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(header), sizeof header)) return;  // imread says what is wrong
  if (std::memcmp(header, "\x89PNG\r\n\x1a\n", 8) != 0 || std::memcmp(header + 12, "IHDR", 4) != 0) return;
  const auto big_endian32 = [&](int at) {
    return uint32_t(header[at]) << 24 | uint32_t(header[at + 1]) << 16 | uint32_t(header[at + 2]) << 8 | header[at + 3];
  };
  const uint32_t width = big_endian32(16), height = big_endian32(20);
  if (width != uint32_t(c.width) || height != uint32_t(c.height))
    fail(path, "is " + std::to_string(width) + "x" + std::to_string(height) + " but mpi.json says " +
                   size_text(c.width, c.height));
}

cv::Mat read_layer(const fs::path& file, const Camera& c) {
  const std::string path = file.string();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) fail(path, "missing layer file");
  check_png_layer_size(path, c);
  const cv::Mat layer = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (layer.empty()) fail(path, "not a readable image");
  check_layer(layer, c, path);
  return layer;
}

}  // namespace

void write_file_atomic(const std::string& path, const std::vector<unsigned char>& bytes) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) fail(path, std::string("cannot be written: ") + std::strerror(errno));
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      fail(path, "writing failed (disk full?)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    fail(path, "cannot be renamed into place: " + why);
  }
}

void write_mpi(const Mpi& mpi, const std::string& dir) {
  check_description(mpi, dir);
  if (mpi.layers.size() != mpi.planes.size())
    fail(dir, std::to_string(mpi.layers.size()) + " layers for " + std::to_string(mpi.planes.size()) + " planes");
  for (size_t j = 0; j < mpi.layers.size(); ++j)  // every layer checked before any file is written
    check_layer(mpi.layers[j], mpi.camera, (fs::path(dir) / layer_name(j)).string());
  write_mpi_streamed(mpi, [&](size_t j) { return mpi.layers[j]; }, dir);
}

void write_mpi_streamed(const Mpi& description, const std::function<cv::Mat(size_t)>& layer,
                        const std::string& dir) {
  check_description(description, dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) fail(dir, "cannot create the folder" + (ec ? " (" + ec.message() + ")" : std::string()));
  std::vector<std::string> names;
  for (size_t j = 0; j < description.planes.size(); ++j) {
    names.push_back(layer_name(j));
    const std::string path = (fs::path(dir) / names.back()).string();
    std::vector<unsigned char> png;
    {
      const cv::Mat image = layer(j);
      check_layer(image, description.camera, path);
      if (!cv::imencode(".png", image, png)) fail(path, "PNG encoding failed");
    }
    write_file_atomic(path, png);
  }
  // The description goes last: a reader never finds one whose layers are not there yet.
  const std::string json = description_json(description, names);
  write_file_atomic((fs::path(dir) / "mpi.json").string(), std::vector<unsigned char>(json.begin(), json.end()));
}

Mpi read_mpi(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) fail(dir, "no such MPI folder");
  if (!fs::is_directory(dir, ec)) fail(dir, "is not a folder (an MPI is a folder with mpi.json)");
  const std::string path = (fs::path(dir) / "mpi.json").string();
  if (!fs::exists(path, ec)) fail(path, "missing (not an MPI folder?)");
  cv::FileStorage in = open_json(path);
  const cv::FileNode root = in.root();
  if (text(root, "format", path, "format") != kFormatName) fail(path, "is not an ampi MPI description");
  const int version = integer(root, "version", path, "version");
  if (version != kMpiFormatVersion)
    fail(path, "format version " + std::to_string(version) + " is not supported (this ampi reads version " +
                   std::to_string(kMpiFormatVersion) + ")");
  Mpi mpi;
  mpi.camera = read_camera(root, path);
  mpi.range.near = number(root, "near", path, "near");
  mpi.range.far = number(root, "far", path, "far");
  const int plane_count = integer(root, "plane_count", path, "plane_count");
  const cv::FileNode planes = field(root, "planes", path, "planes");
  if (!planes.isSeq()) fail(path, "field 'planes' is not a list");
  if (static_cast<int>(planes.size()) != plane_count)
    fail(path, "lists " + std::to_string(planes.size()) + " planes but plane_count is " + std::to_string(plane_count));
  std::vector<std::string> names(planes.size());
  for (size_t j = 0; j < planes.size(); ++j)
    mpi.planes.push_back(read_plane(planes[static_cast<int>(j)], path, "planes[" + std::to_string(j) + "]", &names[j]));
  check_description(mpi, path);
  check_allocation(bytes_for({names.size(), uint64_t(mpi.camera.width), uint64_t(mpi.camera.height), 4}), path,
                   std::to_string(names.size()) + " RGBA layers at " + size_text(mpi.camera.width, mpi.camera.height));
  for (const std::string& name : names) mpi.layers.push_back(read_layer(fs::path(dir) / name, mpi.camera));
  return mpi;
}

}  // namespace ampi
