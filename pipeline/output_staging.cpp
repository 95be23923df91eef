#include "pipeline/output_staging.h"

#include <unistd.h>

#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace ampi {

OutputStaging::OutputStaging(const std::string& destination, bool force)
    : destination_(destination) {
  const fs::path dest(destination);
  std::error_code ec;
  const auto status = fs::status(dest, ec);
  if (fs::exists(status)) {
    if (!fs::is_directory(status))
      throw std::runtime_error(destination + ": exists and is not a folder");
    if (!force)
      throw std::runtime_error(destination +
                               ": already exists; pass --force to replace ampi's outputs in it");
  }
  fs::path parent = fs::absolute(dest).parent_path();
  if (!fs::is_directory(parent, ec))
    throw std::runtime_error(destination + ": parent folder " + parent.string() + " does not exist");
  // Same parent, so the final moves are renames within one file system.
  const std::string name = ".ampi-staging-" + fs::path(dest).filename().string() + "-" +
                           std::to_string(::getpid());
  const fs::path staging = parent / name;
  fs::remove_all(staging, ec);  // a leftover of a killed run with the same pid
  if (!fs::create_directory(staging, ec) || ec)
    throw std::runtime_error(destination + ": cannot create a folder beside it (" + ec.message() + ")");
  staging_ = staging.string();
}

OutputStaging::~OutputStaging() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void OutputStaging::commit() {
  const fs::path dest(destination_);
  fs::create_directories(dest);
  for (const fs::directory_entry& entry : fs::directory_iterator(staging_)) {
    const fs::path target = dest / entry.path().filename();
    if (fs::exists(fs::symlink_status(target))) fs::remove_all(target);
    fs::rename(entry.path(), target);
  }
  fs::remove(staging_);
  committed_ = true;
}

}  // namespace ampi
