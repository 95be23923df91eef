#include "nets/weights_path.h"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace ampi {

namespace fs = std::filesystem;

namespace {

// The running program's folder (Linux: /proc/self/exe); empty when unknown.
fs::path executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

}  // namespace

std::string find_weights(const std::string& file_name) {
  std::vector<fs::path> folders;
  if (const char* env = std::getenv("AMPI_WEIGHTS_DIR"); env && *env) {
    folders.push_back(env);
  } else if (const fs::path dir = executable_dir(); !dir.empty()) {
    folders.push_back(dir / "weights");
    folders.push_back(dir.parent_path() / "weights");
  }
  std::string searched;
  for (const fs::path& folder : folders) {
    const fs::path candidate = folder / file_name;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
    searched += (searched.empty() ? "" : ", ") + folder.string();
  }
  throw std::runtime_error(file_name + ": bundled weight file not found (searched: " +
                           (searched.empty() ? std::string("nowhere") : searched) +
                           "); set AMPI_WEIGHTS_DIR or pass --weights FILE");
}

}  // namespace ampi
