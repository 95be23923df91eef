// Whole-file binary input and output for the file formats in this folder (.ampw, .npy).
// Every failure throws std::runtime_error with a one-line message that starts with the
// file's path.
#pragma once
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace ampi {

class InputFile {
 public:
  // Throws when `path` is missing, not a regular file, or unreadable.
  explicit InputFile(const std::string& path);
  uint64_t size() const { return size_; }
  // Reads the next `bytes` bytes; throws when the file ends first.
  void read(void* dst, size_t bytes);

 private:
  std::string path_;
  uint64_t size_ = 0;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
};

// Writes `bytes` to a temporary file beside `path` and renames it over `path`, so that a
// failed write never leaves a partial file behind.
void write_file_atomically(const std::string& path, const void* data, size_t bytes);

}  // namespace ampi
