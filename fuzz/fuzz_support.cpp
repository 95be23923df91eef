#include "fuzz/fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "engine/memory_budget.h"

namespace ampi::fuzz {
namespace {

void remove_scratch_dir() {
  std::error_code ignored;
  std::filesystem::remove_all(scratch_dir(), ignored);
}

std::string make_scratch_dir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "ampi_fuzz_XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    std::perror("ampi fuzz: mkdtemp");
    std::abort();
  }
  return pattern;
}

}  // namespace

void init_target() {
  set_memory_budget(kFuzzMemoryBudget);
  scratch_dir();
  std::atexit(remove_scratch_dir);
}

const std::string& scratch_dir() {
  static const std::string dir = make_scratch_dir();
  return dir;
}

std::string path_of(const std::string& name) { return (std::filesystem::path(scratch_dir()) / name).string(); }

std::string write_scratch_file(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = path_of(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  require(static_cast<bool>(out), "cannot write a scratch file");
  return path;
}

void require(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "ampi fuzz: broken promise: %s\n", what);
  std::abort();
}

}  // namespace ampi::fuzz
