// Reader of ampi's weight file, .ampw (byte layout: weights_format/SPEC.md; the Python
// writer is weights_format/ampw.py). Like GGUF, the file describes itself: typed metadata,
// then a table of named tensors whose data lies 64-byte aligned after the header.
//
// WeightFile::open validates the whole file before returning (magic, version, every
// length and count against the file size and the format's limits, alignment, overlaps,
// dtype codes, shapes against byte sizes, duplicate names, the header checksum and every
// tensor's checksum), so code that holds a WeightFile never meets a malformed one. Every
// failure is a std::runtime_error whose one-line message starts with the file's path.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

#include "engine/tensor.h"

namespace ampi {

// Constants and limits of format version 1.x; SPEC.md explains each.
namespace ampw {
constexpr char kMagic[4] = {'A', 'M', 'P', 'W'};
constexpr int kVersionMajor = 1;
constexpr int kVersionMinor = 0;
constexpr size_t kPreambleBytes = 40;
constexpr size_t kChecksumBytes = 4;
constexpr uint64_t kAlignment = 64;
constexpr size_t kMaxNameBytes = 255;
constexpr int kMaxRank = 8;
constexpr uint32_t kMaxMetadataEntries = 4096;
constexpr uint32_t kMaxTensors = 65536;
constexpr uint32_t kMaxStringBytes = 1u << 20;
constexpr uint32_t kMaxArrayLength = 1u << 20;
constexpr uint64_t kMaxTensorBytes = uint64_t(1) << 30;
}  // namespace ampw

// Metadata value types; the enumerator is the type code stored in the file and the
// index of the alternative in MetaValue.
enum class MetaType : uint8_t { String = 0, Int = 1, Float = 2, Bool = 3, IntArray = 4, FloatArray = 5 };
using MetaValue =
    std::variant<std::string, int64_t, double, bool, std::vector<int64_t>, std::vector<double>>;
const char* meta_type_name(MetaType type);  // "string", "int64", ..., "float64[]"

struct TensorInfo {
  std::string name;
  DType dtype;
  Shape shape;      // numpy order
  uint64_t offset;  // of the first byte, from the start of the file (a multiple of 64)
  uint64_t bytes;
};

class WeightFile {
 public:
  // Reads and validates the file; throws std::runtime_error("PATH: problem").
  static WeightFile open(const std::string& path);
  // The same for a file image already in memory (tests, fuzzing); `origin` names it in
  // error messages.
  static WeightFile from_bytes(std::vector<uint8_t> bytes, const std::string& origin);
  // Reads only the preamble and the header (metadata and tensor table), checked as open()
  // checks them and against the file's real size, but not the tensor data: finding a
  // file by its metadata costs its header, not its weights. tensor() on it throws.
  static WeightFile open_header(const std::string& path);

  const std::string& path() const { return path_; }
  int version_major() const { return version_major_; }
  int version_minor() const { return version_minor_; }

  // Metadata by key. A missing key or a value of another type throws, naming the file
  // and the key. get_float and get_floats also accept int64 values.
  bool has(const std::string& key) const;
  std::string get_string(const std::string& key) const;
  int64_t get_int(const std::string& key) const;
  double get_float(const std::string& key) const;
  bool get_bool(const std::string& key) const;
  std::vector<int64_t> get_ints(const std::string& key) const;
  std::vector<double> get_floats(const std::string& key) const;

  // Tensors in file order.
  const std::vector<TensorInfo>& tensors() const { return tensors_; }
  const TensorInfo* find(const std::string& name) const;  // nullptr when absent
  // An f32 copy of tensor `name` (f16 data converted); throws when the tensor is missing
  // or its shape differs from `expected`.
  Tensor tensor(const std::string& name, const Shape& expected) const;

  // Metadata in file order for printing: key, type name, value as one line of text.
  std::vector<std::array<std::string, 3>> metadata_rows() const;

 private:
  struct MetaEntry {
    std::string key;
    MetaValue value;
  };

  WeightFile() = default;
  void parse();
  size_t parse_metadata(size_t pos, uint32_t count, size_t header_end);
  size_t parse_tensor_table(size_t pos, uint32_t count, size_t header_end, uint64_t data_offset,
                            uint64_t data_bytes);
  void check_overlaps() const;
  void check_tensor_checksums() const;
  const MetaValue& value_of(const std::string& key) const;
  [[noreturn]] void fail(const std::string& problem) const;

  std::string path_;
  uint64_t file_size_ = 0;    // bytes_->size(), or more when only the header was read
  bool header_only_ = false;
  int version_major_ = 0;
  int version_minor_ = 0;
  std::vector<MetaEntry> metadata_;
  std::unordered_map<std::string, size_t> metadata_index_;
  std::vector<TensorInfo> tensors_;
  std::vector<uint32_t> tensor_checksums_;
  std::unordered_map<std::string, size_t> tensor_index_;
  // The whole file; shared so that copies of a WeightFile are cheap.
  std::shared_ptr<const std::vector<uint8_t>> bytes_;
};

}  // namespace ampi
