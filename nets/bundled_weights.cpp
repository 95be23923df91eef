#include "nets/bundled_weights.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "nets/model_loader.h"
#include "weights_format/weight_file.h"

namespace ampi {

namespace fs = std::filesystem;

namespace {

// The running program's folder (Linux: /proc/self/exe); empty when unknown.
fs::path executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

std::vector<fs::path> weight_folders() {
  if (const char* env = std::getenv("AMPI_WEIGHTS_DIR"); env && *env) return {env};
  if (const fs::path dir = executable_dir(); !dir.empty())
    return {dir / "weights", dir.parent_path() / "weights", dir.parent_path() / "share" / "ampi" / "weights"};
  return {};
}

struct BundledFile {
  std::string path;
  ModelKind kind;
  std::string name;
};

// The network files of the first folder that has any, by file name. Files that are not
// networks of a known architecture are left out: they are not this build's to run.
std::vector<BundledFile> bundled_files(std::string& searched) {
  for (const fs::path& folder : weight_folders()) {
    searched += (searched.empty() ? "" : ", ") + folder.string();
    std::error_code ec;
    std::vector<fs::path> paths;
    for (const fs::directory_entry& e : fs::directory_iterator(folder, ec))
      if (e.path().extension() == ".ampw" && e.is_regular_file(ec)) paths.push_back(e.path());
    std::sort(paths.begin(), paths.end());
    std::vector<BundledFile> files;
    for (const fs::path& p : paths) {
      try {
        const WeightFile header = WeightFile::open_header(p.string());
        files.push_back({p.string(), model_kind(header), model_name(header)});
      } catch (const std::runtime_error&) {
      }
    }
    if (!files.empty()) return files;
  }
  return {};
}

std::string names_of(const std::vector<BundledFile>& files, ModelKind kind) {
  std::string names;
  for (const BundledFile& f : files)
    if (f.kind == kind) names += (names.empty() ? "" : ", ") + f.name;
  return names.empty() ? "none" : names;
}

[[noreturn]] void not_found(const std::string& what, const std::string& searched, const std::string& have) {
  throw std::runtime_error(what + ": no bundled weight file (searched: " +
                           (searched.empty() ? std::string("nowhere") : searched) + "; found: " + have +
                           "); set AMPI_WEIGHTS_DIR or pass --weights FILE");
}

}  // namespace

std::vector<std::string> bundled_depth_models() {
  std::string searched;
  std::vector<std::string> names;
  for (const BundledFile& f : bundled_files(searched))
    if (f.kind == ModelKind::Depth) names.push_back(f.name);
  std::sort(names.begin(), names.end());
  return names;
}

void check_depth_model_name(const std::string& model) {
  const std::vector<std::string> names = bundled_depth_models();
  if (std::find(names.begin(), names.end(), model) != names.end()) return;
  std::string have;
  for (const std::string& n : names) have += (have.empty() ? "" : ", ") + n;
  throw std::runtime_error("--model: '" + model + "' is not a bundled depth model (bundled: " +
                           (have.empty() ? "none" : have) + ")");
}

std::string depth_weights_path(const std::string& weights, const std::string& model) {
  if (!weights.empty()) return weights;
  std::string searched;
  const std::vector<BundledFile> files = bundled_files(searched);
  for (const BundledFile& f : files)
    if (f.kind == ModelKind::Depth && f.name == model) return f.path;
  not_found("depth model '" + model + "'", searched, "depth models " + names_of(files, ModelKind::Depth));
}

std::string inpaint_weights_path(const std::string& weights) {
  if (!weights.empty()) return weights;
  std::string searched;
  const std::vector<BundledFile> files = bundled_files(searched);
  for (const BundledFile& f : files)
    if (f.kind == ModelKind::Inpaint) return f.path;
  not_found("inpainting network", searched, "no inpainting network");
}

}  // namespace ampi
