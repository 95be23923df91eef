#include "distill/label_folder.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "pipeline/depth_io.h"

namespace ampi {
namespace {

namespace fs = std::filesystem;

constexpr char kManifest[] = "labels.tsv";
constexpr char kFormatLine[] = "ampi-distill\t1";

std::string join(const std::vector<int>& values) {
  std::string s;
  for (size_t i = 0; i < values.size(); ++i) s += (i ? "," : "") + std::to_string(values[i]);
  return s;
}

// The four header lines after the format line.
std::vector<std::string> header_lines(const LabelRecipe& r) {
  return {"teacher\t" + r.teacher_file + "\t" + r.architecture + "\t" + r.variant,
          "resolutions\t" + join(r.resolutions) + (r.shape == EnsembleShape::kAspectKept ? "\taspect kept" : ""),
          "images\t" + r.images};
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

// The photos an existing manifest lists, after checking its header is `recipe`'s.
std::vector<std::string> read_manifest(const std::string& path, const LabelRecipe& recipe) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot be read");
  std::string line;
  if (!std::getline(in, line) || line != kFormatLine) fail(path, "not a labels.tsv of ampi distill");
  for (const std::string& expected : header_lines(recipe)) {
    if (!std::getline(in, line)) fail(path, "truncated header");
    if (line != expected)
      fail(path, "made with '" + line + "', this run asks for '" + expected + "': use another folder");
  }
  std::vector<std::string> photos;
  while (std::getline(in, line)) {
    const size_t tab = line.find('\t');
    if (tab == std::string::npos) fail(path, "malformed line '" + line + "'");
    photos.push_back(line.substr(tab + 1));
  }
  return photos;
}

void write_manifest_header(const std::string& path, const LabelRecipe& recipe) {
  std::ofstream out(path);
  out << kFormatLine << "\n";
  for (const std::string& line : header_lines(recipe)) out << line << "\n";
  if (!out.flush()) fail(path, "cannot be written");
}

}  // namespace

std::string label_name(const std::string& relative_photo) {
  std::string name = fs::path(relative_photo).replace_extension().generic_string();
  std::replace(name.begin(), name.end(), '/', '_');
  return name + ".png";
}

LabelFolder::LabelFolder(const std::string& folder, const LabelRecipe& recipe)
    : folder_(folder), manifest_((fs::path(folder) / kManifest).string()) {
  std::error_code ec;
  if (fs::exists(manifest_, ec)) {
    done_ = read_manifest(manifest_, recipe);
  } else {
    if (fs::exists(folder, ec) && !fs::is_empty(folder, ec))
      fail(folder, std::string("not empty and not made by ampi distill (no ") + kManifest + ")");
    fs::create_directories(folder, ec);
    if (ec) fail(folder, "cannot be created: " + ec.message());
    write_manifest_header(manifest_, recipe);
  }
  std::sort(done_.begin(), done_.end());
}

bool LabelFolder::has(const std::string& relative_photo) const {
  return std::binary_search(done_.begin(), done_.end(), relative_photo);
}

void LabelFolder::add(const std::string& relative_photo, const cv::Mat& disparity) {
  const std::string name = label_name(relative_photo);
  write_depth_png16(disparity, (fs::path(folder_) / name).string());
  std::ofstream out(manifest_, std::ios::app);
  out << name << "\t" << relative_photo << "\n";
  if (!out.flush()) fail(manifest_, "cannot be written");
  done_.insert(std::upper_bound(done_.begin(), done_.end(), relative_photo), relative_photo);
}

}  // namespace ampi
