#include "weights_format/npy.h"

#include <cstring>
#include <stdexcept>
#include <vector>

#include "engine/half.h"
#include "weights_format/binary_io.h"

// Element bytes are copied as they lie in the file ('<' = little-endian); every target of
// this project is little-endian.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the .npy reader needs a little-endian host");

namespace ampi {
namespace {

constexpr char kMagic[6] = {'\x93', 'N', 'U', 'M', 'P', 'Y'};
constexpr size_t kAlignment = 64;  // numpy pads its header so the data starts aligned

[[noreturn]] void fail(const std::string& origin, const std::string& problem) {
  throw std::runtime_error(origin + ": " + problem);
}

// Converts n elements to f32; returns the index of the first invalid element (only bool
// data can have one: a byte other than 0 or 1), or n.
using ConvertFn = size_t (*)(const uint8_t* src, float* dst, size_t n);

template <class T>
size_t convert_number(const uint8_t* src, float* dst, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, src + i * sizeof(T), sizeof(T));
    dst[i] = static_cast<float>(v);
  }
  return n;
}

size_t convert_half(const uint8_t* src, float* dst, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    uint16_t bits;
    std::memcpy(&bits, src + 2 * i, 2);
    dst[i] = half_to_float(bits);
  }
  return n;
}

size_t convert_bool(const uint8_t* src, float* dst, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    if (src[i] > 1) return i;
    dst[i] = src[i];
  }
  return n;
}

struct ElementType {
  const char* descr;
  size_t size;
  ConvertFn convert;
};

const ElementType kElementTypes[] = {
    {"<f4", 4, convert_number<float>},   {"<f8", 8, convert_number<double>},
    {"<f2", 2, convert_half},            {"|u1", 1, convert_number<uint8_t>},
    {"<u2", 2, convert_number<uint16_t>}, {"<i4", 4, convert_number<int32_t>},
    {"<i8", 8, convert_number<int64_t>},  {"|b1", 1, convert_bool},
};

const ElementType& element_type(const std::string& descr, const std::string& origin) {
  for (const ElementType& t : kElementTypes)
    if (descr == t.descr) return t;
  fail(origin, "unsupported dtype '" + descr + "' (supported: <f4 <f8 <f2 |u1 <u2 <i4 <i8 |b1)");
}

struct NpyHeader {
  std::string descr;
  bool fortran_order = false;
  Shape shape;
};

// The header is a Python dict literal such as
//   {'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }
// padded with spaces and ended by a newline. This parser accepts exactly the three keys
// numpy writes, once each, in any order, and nothing else.
class HeaderParser {
 public:
  HeaderParser(std::string text, const std::string& origin) : text_(std::move(text)), origin_(origin) {}

  NpyHeader parse() {
    if (text_.empty() || text_.back() != '\n') bad("it does not end with a newline");
    NpyHeader header;
    bool seen_descr = false, seen_order = false, seen_shape = false;
    skip_spaces();
    expect('{');
    for (skip_spaces(); peek() != '}'; skip_spaces()) {
      const std::string key = quoted();
      skip_spaces();
      expect(':');
      skip_spaces();
      if (key == "descr") {
        mark_seen(seen_descr, key);
        header.descr = quoted();
      } else if (key == "fortran_order") {
        mark_seen(seen_order, key);
        header.fortran_order = boolean();
      } else if (key == "shape") {
        mark_seen(seen_shape, key);
        header.shape = shape_tuple();
      } else {
        bad("unknown key '" + key + "'");
      }
      skip_spaces();
      if (peek() != '}') expect(',');
    }
    ++pos_;
    skip_spaces();
    if (pos_ != text_.size()) bad("unexpected text after the closing brace");
    if (!seen_descr || !seen_order || !seen_shape) bad("it lacks one of 'descr', 'fortran_order', 'shape'");
    return header;
  }

 private:
  [[noreturn]] void bad(const std::string& problem) const {
    fail(origin_, "bad .npy header: " + problem + " (at character " + std::to_string(pos_) + ")");
  }
  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  void skip_spaces() {
    while (peek() == ' ' || peek() == '\n') ++pos_;
  }
  void expect(char c) {
    if (peek() != c) bad(std::string("expected '") + c + "'");
    ++pos_;
  }
  void mark_seen(bool& seen, const std::string& key) {
    if (seen) bad("duplicate key '" + key + "'");
    seen = true;
  }
  std::string quoted() {
    const char quote = peek();
    if (quote != '\'' && quote != '"') bad("expected a quoted string");
    const size_t end = text_.find(quote, pos_ + 1);
    if (end == std::string::npos) bad("unterminated string");
    std::string s = text_.substr(pos_ + 1, end - pos_ - 1);
    pos_ = end + 1;
    return s;
  }
  bool boolean() {
    for (const char* word : {"True", "False"})
      if (text_.compare(pos_, std::strlen(word), word) == 0) {
        pos_ += std::strlen(word);
        return word[0] == 'T';
      }
    bad("expected True or False");
  }
  int64_t dimension() {
    constexpr int64_t kLargest = int64_t(1) << 62;
    if (peek() < '0' || peek() > '9') bad("expected a non-negative integer");
    int64_t v = 0;
    for (; peek() >= '0' && peek() <= '9'; ++pos_) {
      const int digit = peek() - '0';
      // Checked before multiplying: v * 10 itself must not overflow.
      if (v > (kLargest - digit) / 10) bad("dimension too large");
      v = v * 10 + digit;
    }
    return v;
  }
  // "()", "(3,)", "(2, 3)" or "(2, 3,)"; a lone "(3)" is not a tuple in Python.
  Shape shape_tuple() {
    Shape shape;
    bool trailing_comma = false;
    expect('(');
    for (skip_spaces(); peek() != ')'; skip_spaces()) {
      shape.push_back(dimension());
      skip_spaces();
      trailing_comma = peek() == ',';
      if (peek() != ')') expect(',');
    }
    if (shape.size() == 1 && !trailing_comma) bad("a one-dimensional shape needs a trailing comma");
    ++pos_;
    return shape;
  }

  std::string text_;
  const std::string& origin_;
  size_t pos_ = 0;
};

uint64_t load_le(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

// Magic, version and header length; returns the header text and sets `data_start`.
std::string read_header_text(const uint8_t* data, size_t size, const std::string& origin, size_t& data_start) {
  if (size == 0) fail(origin, "empty file");
  if (size < 10) fail(origin, "truncated: the .npy preamble needs 10 bytes, file has " + std::to_string(size));
  if (std::memcmp(data, kMagic, sizeof kMagic) != 0) fail(origin, "not a .npy file (bad magic)");
  const int major = data[6], minor = data[7];
  if (major < 1 || major > 3 || minor != 0)
    fail(origin, "unsupported .npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                     " (supported: 1.0, 2.0, 3.0)");
  const size_t length_bytes = major == 1 ? 2 : 4;
  if (size < 8 + length_bytes) fail(origin, "truncated: the .npy header length is cut off");
  const uint64_t header_bytes = load_le(data + 8, static_cast<int>(length_bytes));
  data_start = 8 + length_bytes + header_bytes;
  if (header_bytes > size - 8 - length_bytes)
    fail(origin, "truncated: the .npy header needs " + std::to_string(data_start) + " bytes, file has " +
                     std::to_string(size));
  // Versions 1 and 2 store latin-1, version 3 UTF-8; the keys and values accepted here are
  // ASCII in both.
  return std::string(reinterpret_cast<const char*>(data) + 8 + length_bytes, header_bytes);
}

int64_t element_count(const Shape& shape, const std::string& origin) {
  int64_t n = 1;
  for (int64_t d : shape)
    if (__builtin_mul_overflow(n, d, &n)) fail(origin, "shape " + shape_str(shape) + " overflows");
  return n;
}

}  // namespace

Tensor parse_npy(const uint8_t* data, size_t size, const std::string& origin) {
  size_t data_start = 0;
  const NpyHeader header = HeaderParser(read_header_text(data, size, origin, data_start), origin).parse();
  const ElementType& type = element_type(header.descr, origin);
  if (header.fortran_order)
    fail(origin, "Fortran-order arrays are not supported (save np.ascontiguousarray(a) instead)");
  const int64_t n = element_count(header.shape, origin);
  uint64_t needed;
  if (__builtin_mul_overflow(static_cast<uint64_t>(n), type.size, &needed))
    fail(origin, "shape " + shape_str(header.shape) + " overflows");
  const uint64_t available = size - data_start;
  if (needed > available)
    fail(origin, "truncated: shape " + shape_str(header.shape) + " of " + type.descr + " needs " +
                     std::to_string(needed) + " data bytes, file has " + std::to_string(available));
  if (needed < available)
    fail(origin, std::to_string(available - needed) + " unexpected bytes after the array data");

  Tensor out = Tensor::empty(header.shape, DType::F32);
  const size_t converted = type.convert(data + data_start, out.f32(), static_cast<size_t>(n));
  if (converted != static_cast<size_t>(n))
    fail(origin, "bool element " + std::to_string(converted) + " is neither 0 nor 1");
  return out;
}

Tensor read_npy(const std::string& path) {
  InputFile file(path);
  std::vector<uint8_t> bytes(file.size());
  file.read(bytes.data(), bytes.size());
  return parse_npy(bytes.data(), bytes.size(), path);
}

void write_npy(const std::string& path, const Tensor& tensor) {
  if (tensor.dtype() != DType::F32)
    throw std::invalid_argument(path + ": write_npy writes f32 tensors only, got " + dtype_name(tensor.dtype()));
  std::string dims;
  for (int64_t d : tensor.shape()) dims += std::to_string(d) + ", ";
  if (tensor.rank() > 1) dims.resize(dims.size() - 2);  // numpy writes (3,) but (2, 3)
  else if (tensor.rank() == 1) dims.pop_back();
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
  const size_t fixed = 10 + header.size() + 1;  // magic, version, length, header, newline
  const size_t padded = (fixed + kAlignment - 1) / kAlignment * kAlignment;
  header.append(padded - fixed, ' ');
  header += '\n';
  if (header.size() > 0xFFFF)  // version 1.0's 16-bit length field; only thousands of dimensions reach it
    throw std::invalid_argument(path + ": a rank-" + std::to_string(tensor.rank()) +
                                " shape does not fit a .npy 1.0 header");

  std::vector<uint8_t> bytes(kMagic, kMagic + sizeof kMagic);
  bytes.push_back(1);
  bytes.push_back(0);
  bytes.push_back(static_cast<uint8_t>(header.size() & 0xFF));
  bytes.push_back(static_cast<uint8_t>(header.size() >> 8));
  bytes.insert(bytes.end(), header.begin(), header.end());
  const auto* values = static_cast<const uint8_t*>(tensor.data());
  bytes.insert(bytes.end(), values, values + tensor.bytes());
  write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace ampi
