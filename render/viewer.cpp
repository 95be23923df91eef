#include "render/viewer.h"

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "mpi/mpi_io.h"
#include "render/renderer.h"
#include "render/viewer_page.h"

namespace ampi {
namespace fs = std::filesystem;
namespace {

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t group = static_cast<uint32_t>(bytes[i]) << 16;
    if (n > 1) group |= static_cast<uint32_t>(bytes[i + 1]) << 8;
    if (n > 2) group |= bytes[i + 2];
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string layer_file_name(size_t j) {
  char name[32];
  std::snprintf(name, sizeof name, "layer_%02zu.png", j);
  return name;
}

std::string png_data_uri(const cv::Mat& bgra) {
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", bgra, png)) throw std::runtime_error("viewer: cannot encode a layer as PNG");
  return "data:image/png;base64," + base64(png);
}

// The layer sources are data URIs or paths relative to the page (letters, digits, '_',
// '.', '-' and '/' only, checked by the caller), so none needs escaping inside a string.
std::string scene_json(const Mpi& mpi, const std::vector<std::string>& sources, double amplitude) {
  std::ostringstream j;
  j << std::setprecision(17);
  const Camera& c = mpi.camera;
  j << "{\"width\": " << c.width << ", \"height\": " << c.height << ", \"fx\": " << c.fx
    << ", \"fy\": " << c.fy << ", \"cx\": " << c.cx << ", \"cy\": " << c.cy
    << ", \"amplitude\": " << amplitude << ", \"planes\": [";
  for (size_t p = 0; p < mpi.planes.size(); ++p)
    j << (p ? ", " : "") << "{\"depth\": " << mpi.planes[p].depth << ", \"src\": \"" << sources[p] << "\"}";
  j << "]}";
  return j.str();
}

bool plain_relative_path(const std::string& path) {
  if (path.empty() || path[0] == '/') return false;
  for (char ch : path)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '.' && ch != '-' && ch != '/') return false;
  return true;
}

std::string render_page(const Mpi& mpi, const std::vector<std::string>& sources, double amplitude) {
  std::string page = kViewerPageTemplate;
  const std::string placeholder = "@SCENE@";
  page.replace(page.find(placeholder), placeholder.size(), scene_json(mpi, sources, amplitude));
  return page;
}

std::vector<std::string> referenced_sources(const Mpi& mpi, const std::string& folder) {
  if (!plain_relative_path(folder))
    throw std::invalid_argument("viewer: the layer folder '" + folder +
                                "' must be a relative path of letters, digits, '_', '.', '-' and '/'");
  std::vector<std::string> sources;
  for (size_t j = 0; j < mpi.layers.size(); ++j) sources.push_back(folder + "/" + layer_file_name(j));
  return sources;
}

}  // namespace

std::string viewer_html(const Mpi& mpi, const ViewerOptions& options) {
  validate_mpi(mpi);
  if (!(options.amplitude > 0 && options.amplitude < 1))
    throw std::invalid_argument("viewer: the amplitude must be in (0, 1)");
  std::vector<std::string> sources;
  if (options.embed_layers) {
    for (const cv::Mat& layer : mpi.layers) sources.push_back(png_data_uri(layer));
  } else {
    sources = referenced_sources(mpi, options.layer_folder);
  }
  return render_page(mpi, sources, options.amplitude);
}

std::string write_viewer(const Mpi& mpi, const std::string& dir, const ViewerOptions& options) {
  fs::path given = fs::path(dir).lexically_normal();
  if (given.has_parent_path() && given.filename().empty()) given = given.parent_path();  // "a/mpi/"

  const bool is_mpi_folder = fs::exists(given / "mpi.json");
  const fs::path page_dir = is_mpi_folder ? fs::absolute(given).parent_path() : given;
  ViewerOptions o = options;
  if (is_mpi_folder) o.layer_folder = fs::absolute(given).filename().string();
  if (!fs::is_directory(page_dir)) throw std::runtime_error(page_dir.string() + ": not a directory");
  if (!o.embed_layers)
    for (size_t j = 0; j < mpi.layers.size(); ++j) {
      const fs::path layer = page_dir / o.layer_folder / layer_file_name(j);
      if (!fs::is_regular_file(layer))
        throw std::runtime_error(layer.string() + ": missing (the viewer refers to it)");
    }
  const std::string page = viewer_html(mpi, o);
  const std::string path = (page_dir / "viewer.html").string();
  write_file_atomic(path, std::vector<unsigned char>(page.begin(), page.end()));
  return path;
}

}  // namespace ampi
