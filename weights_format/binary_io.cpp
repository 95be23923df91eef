#include "weights_format/binary_io.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <unistd.h>

namespace ampi {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

}  // namespace

InputFile::InputFile(const std::string& path) : path_(path), file_(nullptr, std::fclose) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) fail(path, "cannot open: no such file");
  if (!std::filesystem::is_regular_file(status)) fail(path, "cannot open: not a regular file");
  size_ = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot open: " + ec.message());
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) fail(path, std::string("cannot open: ") + std::strerror(errno));
}

void InputFile::read(void* dst, size_t bytes) {
  if (std::fread(dst, 1, bytes, file_.get()) != bytes)
    fail(path_, std::ferror(file_.get()) ? "read error" : "read error: the file shrank while it was read");
}

void write_file_atomically(const std::string& path, const void* data, size_t bytes) {
  const std::string tmp = path + "." + std::to_string(::getpid()) + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) fail(path, std::string("cannot write: ") + std::strerror(errno));
  const bool written = std::fwrite(data, 1, bytes, f) == bytes;
  const int saved_errno = errno;
  if (std::fclose(f) != 0 || !written) {
    std::remove(tmp.c_str());
    fail(path, std::string("cannot write: ") + std::strerror(written ? errno : saved_errno));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(tmp.c_str());
    fail(path, std::string("cannot write: ") + std::strerror(rename_errno));
  }
}

}  // namespace ampi
