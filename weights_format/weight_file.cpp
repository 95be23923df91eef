#include "weights_format/weight_file.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <tuple>

#include "engine/half.h"
#include "weights_format/binary_io.h"
#include "weights_format/crc32.h"

// Tensor data is handed out with memcpy, which is only right where the host's byte order
// is the file's. Every target of this project (x86-64, aarch64) is little-endian.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the .ampw reader needs a little-endian host");

namespace ampi {
namespace {

using namespace ampw;

uint64_t load_le(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

std::string hex32(uint32_t v) {
  char s[11];
  std::snprintf(s, sizeof s, "0x%08x", v);
  return s;
}

// Bytes shown inside a one-line message: printable ASCII as is, the rest as \xHH.
std::string printable(const uint8_t* p, size_t n) {
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    if (p[i] >= 0x20 && p[i] < 0x7F && p[i] != '"' && p[i] != '\\') {
      s += static_cast<char>(p[i]);
    } else {
      char esc[5];
      std::snprintf(esc, sizeof esc, "\\x%02x", p[i]);
      s += esc;
    }
  }
  return s;
}

// Python's strict UTF-8 decoder accepts exactly these sequences: no overlong forms, no
// surrogates, nothing above U+10FFFF.
bool is_valid_utf8(const uint8_t* s, size_t n) {
  static const uint32_t kSmallest[5] = {0, 0, 0x80, 0x800, 0x10000};
  size_t i = 0;
  while (i < n) {
    const uint8_t lead = s[i];
    size_t len;
    uint32_t cp;
    if (lead < 0x80) {
      ++i;
      continue;
    } else if ((lead & 0xE0) == 0xC0) {
      len = 2, cp = lead & 0x1Fu;
    } else if ((lead & 0xF0) == 0xE0) {
      len = 3, cp = lead & 0x0Fu;
    } else if ((lead & 0xF8) == 0xF0) {
      len = 4, cp = lead & 0x07u;
    } else {
      return false;
    }
    if (len > n - i) return false;
    for (size_t k = 1; k < len; ++k) {
      if ((s[i + k] & 0xC0) != 0x80) return false;
      cp = cp << 6 | (s[i + k] & 0x3Fu);
    }
    if (cp < kSmallest[len] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += len;
  }
  return true;
}

[[noreturn]] void fail_at(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

// The checks that tell whether this is an .ampw file of a version we read at all. They
// need only the first kPreambleBytes, so open() runs them before loading a large file.
void check_identity(const uint8_t* p, uint64_t file_size, const std::string& path) {
  if (file_size == 0) fail_at(path, "empty file");
  if (file_size < kPreambleBytes)
    fail_at(path, "truncated: preamble needs " + std::to_string(kPreambleBytes) + " bytes, file has " +
                      std::to_string(file_size));
  if (std::memcmp(p, kMagic, 4) != 0)
    fail_at(path, "bad magic: expected \"AMPW\", found \"" + printable(p, 4) + "\"");
  const uint64_t major = load_le(p + 4, 2), minor = load_le(p + 6, 2);
  if (major != kVersionMajor)
    fail_at(path, "unsupported format version " + std::to_string(major) + "." + std::to_string(minor) +
                      " (this reader reads " + std::to_string(kVersionMajor) + ".x)");
}

// Reads little-endian fields of the header, never past its end.
class HeaderCursor {
 public:
  HeaderCursor(const uint8_t* file, size_t pos, size_t end, const std::string& path)
      : file_(file), pos_(pos), end_(end), path_(path) {}

  size_t pos() const { return pos_; }
  const uint8_t* take(uint64_t n, const std::string& what) {
    if (n > end_ - pos_)
      fail_at(path_, "header overrun: " + what + " needs " + std::to_string(n) + " bytes at offset " +
                         std::to_string(pos_) + ", header ends at " + std::to_string(end_));
    const uint8_t* p = file_ + pos_;
    pos_ += n;
    return p;
  }
  uint64_t uint(int bytes, const std::string& what) { return load_le(take(bytes, what), bytes); }

  // Key or tensor name: 1..kMaxNameBytes bytes of printable ASCII without spaces, so
  // that every name fits in a one-line message and a shell command.
  std::string name(const std::string& what) {
    const uint64_t len = uint(2, what + " name length");
    if (len == 0 || len > kMaxNameBytes)
      fail_at(path_, what + ": name length " + std::to_string(len) + " is outside 1.." +
                         std::to_string(kMaxNameBytes));
    const uint8_t* p = take(len, what + " name");
    for (uint64_t i = 0; i < len; ++i)
      if (p[i] <= 0x20 || p[i] >= 0x7F)
        fail_at(path_, what + ": name \"" + printable(p, len) +
                           "\" has a byte outside printable ASCII without space");
    return std::string(reinterpret_cast<const char*>(p), len);
  }

 private:
  const uint8_t* file_;
  size_t pos_, end_;
  const std::string& path_;
};

MetaValue read_meta_value(HeaderCursor& cur, uint8_t type_code, const std::string& what,
                          const std::string& path) {
  switch (static_cast<MetaType>(type_code)) {
    case MetaType::String: {
      const uint64_t len = cur.uint(4, what + " string length");
      if (len > kMaxStringBytes)
        fail_at(path, what + ": string of " + std::to_string(len) + " bytes exceeds the limit of " +
                          std::to_string(kMaxStringBytes));
      const uint8_t* p = cur.take(len, what + " string");
      if (!is_valid_utf8(p, len)) fail_at(path, what + ": string is not valid UTF-8");
      return std::string(reinterpret_cast<const char*>(p), len);
    }
    case MetaType::Int:
      return static_cast<int64_t>(cur.uint(8, what + " value"));
    case MetaType::Float: {
      const uint64_t bits = cur.uint(8, what + " value");
      double v;
      std::memcpy(&v, &bits, 8);
      return v;
    }
    case MetaType::Bool: {
      const uint64_t b = cur.uint(1, what + " value");
      if (b > 1) fail_at(path, what + ": bool byte is " + std::to_string(b) + ", not 0 or 1");
      return b == 1;
    }
    case MetaType::IntArray:
    case MetaType::FloatArray: {
      const uint64_t count = cur.uint(4, what + " array length");
      if (count > kMaxArrayLength)
        fail_at(path, what + ": array of " + std::to_string(count) + " values exceeds the limit of " +
                          std::to_string(kMaxArrayLength));
      const uint8_t* p = cur.take(count * 8, what + " array");
      if (static_cast<MetaType>(type_code) == MetaType::IntArray) {
        std::vector<int64_t> ints(count);
        for (uint64_t i = 0; i < count; ++i) ints[i] = static_cast<int64_t>(load_le(p + 8 * i, 8));
        return ints;
      }
      std::vector<double> floats(count);
      for (uint64_t i = 0; i < count; ++i) {
        const uint64_t bits = load_le(p + 8 * i, 8);
        std::memcpy(&floats[i], &bits, 8);
      }
      return floats;
    }
  }
  fail_at(path, what + ": unknown type code " + std::to_string(type_code));
}

void append_number(std::string& s, double v) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, v);  // shortest exact form
  s.append(buf, result.ptr);
}
void append_number(std::string& s, int64_t v) { s += std::to_string(v); }

// Long arrays are cut short so that a row stays readable.
template <class T>
std::string array_text(const std::vector<T>& values) {
  constexpr size_t kShown = 16;
  std::string s = "[";
  for (size_t i = 0; i < values.size() && i < kShown; ++i) {
    if (i) s += ", ";
    append_number(s, values[i]);
  }
  if (values.size() > kShown) s += ", ... (" + std::to_string(values.size()) + " values)";
  return s + "]";
}

std::string quoted(const std::string& text) {
  std::string s = "\"";
  for (const char c : text) {
    const auto u = static_cast<uint8_t>(c);
    if (c == '"' || c == '\\') {
      s += '\\';
      s += c;
    } else if (u < 0x20 || u == 0x7F) {
      s += printable(&u, 1);
    } else {
      s += c;  // UTF-8 passes through
    }
  }
  return s + "\"";
}

std::string value_text(const MetaValue& value) {
  switch (static_cast<MetaType>(value.index())) {
    case MetaType::String: return quoted(std::get<std::string>(value));
    case MetaType::Int: return std::to_string(std::get<int64_t>(value));
    case MetaType::Float: {
      std::string s;
      append_number(s, std::get<double>(value));
      return s;
    }
    case MetaType::Bool: return std::get<bool>(value) ? "true" : "false";
    case MetaType::IntArray: return array_text(std::get<std::vector<int64_t>>(value));
    case MetaType::FloatArray: return array_text(std::get<std::vector<double>>(value));
  }
  return "";
}

// Checks the preamble before loading the rest, so that a large file of another kind is
// rejected without being read.
std::vector<uint8_t> read_ampw_file(const std::string& path) {
  InputFile file(path);
  std::vector<uint8_t> bytes(std::min<uint64_t>(file.size(), kPreambleBytes));
  file.read(bytes.data(), bytes.size());
  check_identity(bytes.data(), file.size(), path);
  bytes.resize(file.size());
  file.read(bytes.data() + kPreambleBytes, bytes.size() - kPreambleBytes);
  return bytes;
}

}  // namespace

const char* meta_type_name(MetaType type) {
  switch (type) {
    case MetaType::String: return "string";
    case MetaType::Int: return "int64";
    case MetaType::Float: return "float64";
    case MetaType::Bool: return "bool";
    case MetaType::IntArray: return "int64[]";
    case MetaType::FloatArray: return "float64[]";
  }
  return "unknown";
}

WeightFile WeightFile::open(const std::string& path) { return from_bytes(read_ampw_file(path), path); }

WeightFile WeightFile::from_bytes(std::vector<uint8_t> bytes, const std::string& origin) {
  WeightFile wf;
  wf.path_ = origin;
  wf.file_size_ = bytes.size();
  wf.bytes_ = std::make_shared<const std::vector<uint8_t>>(std::move(bytes));
  wf.parse();
  return wf;
}

WeightFile WeightFile::open_header(const std::string& path) {
  InputFile file(path);
  std::vector<uint8_t> bytes(std::min<uint64_t>(file.size(), kPreambleBytes));
  file.read(bytes.data(), bytes.size());
  check_identity(bytes.data(), file.size(), path);
  // parse() refuses a header that does not fit the file before it reads past the preamble
  const uint64_t header_bytes = load_le(bytes.data() + 16, 8);
  const uint64_t wanted = header_bytes <= file.size() - kChecksumBytes ? header_bytes + kChecksumBytes : kPreambleBytes;
  bytes.resize(std::max<uint64_t>(wanted, kPreambleBytes));
  file.read(bytes.data() + kPreambleBytes, bytes.size() - kPreambleBytes);
  WeightFile wf;
  wf.path_ = path;
  wf.file_size_ = file.size();
  wf.header_only_ = true;
  wf.bytes_ = std::make_shared<const std::vector<uint8_t>>(std::move(bytes));
  wf.parse();
  return wf;
}

void WeightFile::fail(const std::string& problem) const { fail_at(path_, problem); }

// Order of the checks: identity, header size, header checksum (so that a damaged header
// is reported as damaged, not by whichever field the damage hit), then the header's
// contents, then the data section against the file, then the tensors' checksums.
void WeightFile::parse() {
  const uint8_t* p = bytes_->data();
  const uint64_t size = file_size_;
  check_identity(p, size, path_);
  version_major_ = static_cast<int>(load_le(p + 4, 2));
  version_minor_ = static_cast<int>(load_le(p + 6, 2));
  const uint64_t metadata_count = load_le(p + 8, 4);
  const uint64_t tensor_count = load_le(p + 12, 4);
  const uint64_t header_bytes = load_le(p + 16, 8);
  const uint64_t data_offset = load_le(p + 24, 8);
  const uint64_t data_bytes = load_le(p + 32, 8);

  if (header_bytes < kPreambleBytes)
    fail("header size " + std::to_string(header_bytes) + " is smaller than the " +
         std::to_string(kPreambleBytes) + "-byte preamble");
  if (header_bytes > size - kChecksumBytes)
    fail("truncated: header needs " + std::to_string(header_bytes + kChecksumBytes) + " bytes, file has " +
         std::to_string(size));
  const uint32_t stored = static_cast<uint32_t>(load_le(p + header_bytes, 4));
  const uint32_t computed = crc32(p, header_bytes);
  if (stored != computed)
    fail("header checksum mismatch: stored " + hex32(stored) + ", computed " + hex32(computed));

  if (metadata_count > kMaxMetadataEntries)
    fail("too many metadata entries: " + std::to_string(metadata_count) + " (limit " +
         std::to_string(kMaxMetadataEntries) + ")");
  if (tensor_count > kMaxTensors)
    fail("too many tensors: " + std::to_string(tensor_count) + " (limit " + std::to_string(kMaxTensors) + ")");
  if (data_offset % kAlignment != 0)
    fail("data section offset " + std::to_string(data_offset) + " is not a multiple of " +
         std::to_string(kAlignment));
  if (data_offset < header_bytes + kChecksumBytes)
    fail("data section offset " + std::to_string(data_offset) + " lies inside the header (" +
         std::to_string(header_bytes + kChecksumBytes) + " bytes)");

  size_t pos = parse_metadata(kPreambleBytes, static_cast<uint32_t>(metadata_count), header_bytes);
  pos = parse_tensor_table(pos, static_cast<uint32_t>(tensor_count), header_bytes, data_offset, data_bytes);
  // A later minor version may append fields that this reader skips; the same version may not.
  if (pos != header_bytes && version_minor_ <= kVersionMinor)
    fail("header has " + std::to_string(header_bytes - pos) + " unread bytes after the tensor table");

  if (data_offset > size || data_bytes > size - data_offset)
    fail("truncated: data section of " + std::to_string(data_bytes) + " bytes at offset " +
         std::to_string(data_offset) + ", file has " + std::to_string(size) + " bytes");
  if (data_bytes < size - data_offset)
    fail(std::to_string(size - data_offset - data_bytes) + " unexpected bytes after the data section");
  check_overlaps();
  if (!header_only_) check_tensor_checksums();
}

size_t WeightFile::parse_metadata(size_t pos, uint32_t count, size_t header_end) {
  HeaderCursor cur(bytes_->data(), pos, header_end, path_);
  metadata_.reserve(count);
  for (uint32_t i = 0; i < count; ++i) {
    const std::string key = cur.name("metadata entry " + std::to_string(i));
    const std::string what = "metadata '" + key + "'";
    const auto type_code = static_cast<uint8_t>(cur.uint(1, what + " type"));
    MetaValue value = read_meta_value(cur, type_code, what, path_);
    if (!metadata_index_.emplace(key, metadata_.size()).second) fail("duplicate metadata key '" + key + "'");
    metadata_.push_back({key, std::move(value)});
  }
  return cur.pos();
}

size_t WeightFile::parse_tensor_table(size_t pos, uint32_t count, size_t header_end, uint64_t data_offset,
                                      uint64_t data_bytes) {
  HeaderCursor cur(bytes_->data(), pos, header_end, path_);
  tensors_.reserve(count);
  for (uint32_t i = 0; i < count; ++i) {
    TensorInfo info;
    info.name = cur.name("tensor entry " + std::to_string(i));
    const std::string what = "tensor '" + info.name + "'";
    const uint64_t dtype_code = cur.uint(1, what + " dtype");
    if (dtype_code > 1) fail(what + ": unknown dtype code " + std::to_string(dtype_code));
    info.dtype = dtype_code == 0 ? DType::F32 : DType::F16;
    const uint64_t rank = cur.uint(1, what + " rank");
    if (rank > static_cast<uint64_t>(kMaxRank))
      fail(what + ": rank " + std::to_string(rank) + " exceeds the limit of " + std::to_string(kMaxRank));
    // The element count is bounded dimension by dimension, so it can never overflow.
    const uint64_t max_elements = kMaxTensorBytes / dtype_size(info.dtype);
    uint64_t elements = 1;
    for (uint64_t d = 0; d < rank; ++d) {
      const uint64_t dim = cur.uint(8, what + " dimension");
      if (dim == 0) fail(what + ": dimension " + std::to_string(d) + " is 0");
      if (dim > max_elements / elements)
        fail(what + ": dimension " + std::to_string(d) + " of " + std::to_string(dim) +
             " makes the tensor larger than the limit of " + std::to_string(kMaxTensorBytes) + " bytes");
      elements *= dim;
      info.shape.push_back(static_cast<int64_t>(dim));
    }
    const uint64_t relative_offset = cur.uint(8, what + " offset");
    info.bytes = cur.uint(8, what + " byte size");
    const auto checksum = static_cast<uint32_t>(cur.uint(4, what + " checksum"));
    const uint64_t expected_bytes = elements * dtype_size(info.dtype);
    if (info.bytes != expected_bytes)
      fail(what + ": byte size " + std::to_string(info.bytes) + " does not match shape " +
           shape_str(info.shape) + " of " + dtype_name(info.dtype) + " (" + std::to_string(expected_bytes) +
           " bytes)");
    if (relative_offset % kAlignment != 0)
      fail(what + ": offset " + std::to_string(relative_offset) + " is not a multiple of " +
           std::to_string(kAlignment));
    if (relative_offset > data_bytes || info.bytes > data_bytes - relative_offset)
      fail(what + ": offset " + std::to_string(relative_offset) + " + " + std::to_string(info.bytes) +
           " bytes is out of range of the " + std::to_string(data_bytes) + "-byte data section");
    info.offset = data_offset + relative_offset;
    if (!tensor_index_.emplace(info.name, tensors_.size()).second)
      fail("duplicate tensor name '" + info.name + "'");
    tensors_.push_back(std::move(info));
    tensor_checksums_.push_back(checksum);
  }
  return cur.pos();
}

void WeightFile::check_overlaps() const {
  std::vector<const TensorInfo*> by_offset;
  for (const TensorInfo& t : tensors_) by_offset.push_back(&t);
  std::sort(by_offset.begin(), by_offset.end(),
            [](const TensorInfo* a, const TensorInfo* b) {
              // Ties broken like the Python reader, so both name the same pair.
              return std::tie(a->offset, a->bytes, a->name) < std::tie(b->offset, b->bytes, b->name);
            });
  for (size_t i = 1; i < by_offset.size(); ++i) {
    const TensorInfo& a = *by_offset[i - 1];
    const TensorInfo& b = *by_offset[i];
    if (a.offset + a.bytes > b.offset)
      fail("tensors '" + a.name + "' and '" + b.name + "' overlap: bytes [" + std::to_string(a.offset) + ", " +
           std::to_string(a.offset + a.bytes) + ") and [" + std::to_string(b.offset) + ", " +
           std::to_string(b.offset + b.bytes) + ")");
  }
}

void WeightFile::check_tensor_checksums() const {
  for (size_t i = 0; i < tensors_.size(); ++i) {
    const TensorInfo& t = tensors_[i];
    const uint32_t computed = crc32(bytes_->data() + t.offset, t.bytes);
    if (computed != tensor_checksums_[i])
      fail("tensor '" + t.name + "': data checksum mismatch: stored " + hex32(tensor_checksums_[i]) +
           ", computed " + hex32(computed));
  }
}

bool WeightFile::has(const std::string& key) const { return metadata_index_.count(key) != 0; }

const MetaValue& WeightFile::value_of(const std::string& key) const {
  const auto it = metadata_index_.find(key);
  if (it == metadata_index_.end()) fail("no metadata key '" + key + "'");
  return metadata_[it->second].value;
}

namespace {
template <class T>
const T& typed(const MetaValue& value, MetaType wanted, const std::string& key, const std::string& path) {
  if (value.index() != static_cast<size_t>(wanted))
    fail_at(path, "metadata '" + key + "' is " + meta_type_name(static_cast<MetaType>(value.index())) +
                      ", not " + meta_type_name(wanted));
  return std::get<T>(value);
}
}  // namespace

std::string WeightFile::get_string(const std::string& key) const {
  return typed<std::string>(value_of(key), MetaType::String, key, path_);
}
int64_t WeightFile::get_int(const std::string& key) const {
  return typed<int64_t>(value_of(key), MetaType::Int, key, path_);
}
bool WeightFile::get_bool(const std::string& key) const {
  return typed<bool>(value_of(key), MetaType::Bool, key, path_);
}
std::vector<int64_t> WeightFile::get_ints(const std::string& key) const {
  return typed<std::vector<int64_t>>(value_of(key), MetaType::IntArray, key, path_);
}

double WeightFile::get_float(const std::string& key) const {
  const MetaValue& value = value_of(key);
  if (const auto* i = std::get_if<int64_t>(&value)) return static_cast<double>(*i);
  return typed<double>(value, MetaType::Float, key, path_);
}

std::vector<double> WeightFile::get_floats(const std::string& key) const {
  const MetaValue& value = value_of(key);
  if (const auto* ints = std::get_if<std::vector<int64_t>>(&value)) return {ints->begin(), ints->end()};
  return typed<std::vector<double>>(value, MetaType::FloatArray, key, path_);
}

const TensorInfo* WeightFile::find(const std::string& name) const {
  const auto it = tensor_index_.find(name);
  return it == tensor_index_.end() ? nullptr : &tensors_[it->second];
}

Tensor WeightFile::tensor(const std::string& name, const Shape& expected) const {
  const TensorInfo* info = find(name);
  if (!info) fail("no tensor named '" + name + "'");
  if (header_only_) fail("tensor '" + name + "': only the header was read");
  if (info->shape != expected)
    fail("tensor '" + name + "' has shape " + shape_str(info->shape) + ", expected " + shape_str(expected));
  const uint8_t* src = bytes_->data() + info->offset;
  Tensor out = Tensor::empty(info->shape, DType::F32);
  if (info->dtype == DType::F32) {
    std::memcpy(out.data(), src, info->bytes);
  } else {
    float* dst = out.f32();
    for (int64_t i = 0; i < out.numel(); ++i) dst[i] = half_to_float(static_cast<uint16_t>(load_le(src + 2 * i, 2)));
  }
  return out;
}

std::vector<std::array<std::string, 3>> WeightFile::metadata_rows() const {
  std::vector<std::array<std::string, 3>> rows;
  for (const MetaEntry& e : metadata_)
    rows.push_back({e.key, meta_type_name(static_cast<MetaType>(e.value.index())), value_text(e.value)});
  return rows;
}

}  // namespace ampi
