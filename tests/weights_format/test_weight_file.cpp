// The .ampw reader against small.ampw, written by the Python writer
// (tests/fixtures/weights/make_small.py): exact round trip of every value, then one
// damaged copy per check the reader makes, each of which must fail with its own message.
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/half.h"
#include "weights_format/crc32.h"
#include "weights_format/weight_file.h"

using namespace ampi;

namespace {

using Bytes = std::vector<uint8_t>;
const std::string kOrigin = "small.ampw";

std::string fixture_path() { return std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/weights/small.ampw"; }

Bytes fixture_bytes() {
  std::ifstream in(fixture_path(), std::ios::binary);
  REQUIRE(in.good());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

uint64_t get_le(const Bytes& b, size_t pos, int n) {
  uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = v << 8 | b.at(pos + i);
  return v;
}

void put_le(Bytes& b, size_t pos, uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b.at(pos + i) = static_cast<uint8_t>(v >> (8 * i));
}

void put_text(Bytes& b, size_t pos, const std::string& text) {
  for (size_t i = 0; i < text.size(); ++i) b.at(pos + i) = static_cast<uint8_t>(text[i]);
}

// Where the fields of small.ampw lie, found by walking the header with SPEC.md's layout
// rather than with the reader under test.
struct MetaFields {
  size_t key_length, key, type, value;
};
struct TensorFields {
  size_t name, rank, dims, offset, bytes, checksum;
  size_t dtype() const { return rank - 1; }
};
struct FileLayout {
  uint64_t header_bytes, data_offset, data_bytes;
  std::map<std::string, MetaFields> meta;
  std::map<std::string, TensorFields> tensors;
};

FileLayout layout_of(const Bytes& b) {
  FileLayout l{get_le(b, 16, 8), get_le(b, 24, 8), get_le(b, 32, 8), {}, {}};
  size_t pos = 40;
  auto read_name = [&](size_t& name_at) {
    const size_t len = get_le(b, pos, 2);
    name_at = pos + 2;
    pos += 2 + len;
    return std::string(b.begin() + name_at, b.begin() + pos);
  };
  for (uint64_t i = 0, n = get_le(b, 8, 4); i < n; ++i) {
    MetaFields f{pos, 0, 0, 0};
    const std::string key = read_name(f.key);
    f.type = pos;
    f.value = pos + 1;
    const uint8_t type = b.at(pos);
    const uint64_t count = type == 0 || type >= 4 ? get_le(b, pos + 1, 4) : 0;
    const uint64_t value_bytes[] = {4 + count, 8, 8, 1, 4 + 8 * count, 4 + 8 * count};
    pos += 1 + value_bytes[type];
    l.meta[key] = f;
  }
  for (uint64_t i = 0, n = get_le(b, 12, 4); i < n; ++i) {
    TensorFields f{};
    const std::string name = read_name(f.name);
    f.rank = pos + 1;
    f.dims = pos + 2;
    f.offset = f.dims + 8 * b.at(f.rank);
    f.bytes = f.offset + 8;
    f.checksum = f.bytes + 8;
    pos = f.checksum + 4;
    l.tensors[name] = f;
  }
  REQUIRE(pos == l.header_bytes);
  return l;
}

// A damaged header with a valid checksum: what a buggy writer would produce.
void reseal(Bytes& b) {
  const uint64_t header_bytes = get_le(b, 16, 8);
  put_le(b, header_bytes, crc32(b.data(), header_bytes), 4);
}

// The message WeightFile throws for `bytes`, or "" when it accepts them.
std::string error_of(const Bytes& bytes) {
  try {
    WeightFile::from_bytes(bytes, kOrigin);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

struct Corruption {
  const char* what;
  bool reseal;  // false where the damage is to the checksum, or comes before it is checked
  std::function<void(Bytes&, const FileLayout&)> damage;
  const char* expected;
};

// Each entry damages one thing.
const std::vector<Corruption>& corruptions() {
  using L = const FileLayout&;
  static const std::vector<Corruption> cases = {
      {"empty file", false, [](Bytes& b, L) { b.clear(); }, "empty file"},
      {"truncated in the preamble", false, [](Bytes& b, L) { b.resize(20); },
       "truncated: preamble needs 40 bytes, file has 20"},
      {"truncated in the metadata", false, [](Bytes& b, L) { b.resize(300); },
       "truncated: header needs 746 bytes, file has 300"},
      {"truncated in the header checksum", false, [](Bytes& b, L l) { b.resize(l.header_bytes + 2); },
       "truncated: header needs 746 bytes, file has 744"},
      {"truncated in the data", false, [](Bytes& b, L l) { b.resize(l.data_offset + 100); },
       "truncated: data section of 588 bytes at offset 768, file has 868 bytes"},
      {"truncated by one byte", false, [](Bytes& b, L) { b.pop_back(); },
       "truncated: data section of 588 bytes at offset 768, file has 1355 bytes"},
      {"wrong magic", true, [](Bytes& b, L) { b[0] = 'X'; }, "bad magic: expected \"AMPW\", found \"XMPW\""},
      {"binary magic", true, [](Bytes& b, L) { put_le(b, 0, 0x0a000089, 4); }, "found \"\\x89\\x00\\x00\\x0a\""},
      {"wrong major version", true, [](Bytes& b, L) { put_le(b, 4, 2, 2); },
       "unsupported format version 2.0 (this reader reads 1.x)"},
      {"bad header checksum", false, [](Bytes& b, L l) { b[l.meta.at("model.width").value] ^= 1; },
       "header checksum mismatch"},
      {"bad tensor checksum", true, [](Bytes& b, L l) { b[l.data_offset + 320] ^= 0x40; },
       "tensor 'conv1.bias': data checksum mismatch"},
      {"duplicate tensor names", true, [](Bytes& b, L l) { put_text(b, l.tensors.at("block1.gain").name, "block0.gain"); },
       "duplicate tensor name 'block0.gain'"},
      {"duplicate metadata keys", true, [](Bytes& b, L l) { put_text(b, l.meta.at("model.depth").key, "model.width"); },
       "duplicate metadata key 'model.width'"},
      {"huge dimension", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.weight").dims, uint64_t(1) << 40, 8); },
       "tensor 'conv1.weight': dimension 0 of 1099511627776 makes the tensor larger than the limit"},
      {"dimensions whose product overflows", true,
       [](Bytes& b, L l) {
         for (int d = 0; d < 4; ++d) put_le(b, l.tensors.at("conv1.weight").dims + 8 * d, uint64_t(1) << 20, 8);
       },
       "tensor 'conv1.weight': dimension 1 of 1048576 makes the tensor larger"},
      {"zero dimension", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.weight").dims + 8, 0, 8); },
       "tensor 'conv1.weight': dimension 1 is 0"},
      {"rank above the limit", true, [](Bytes& b, L l) { b[l.tensors.at("conv1.bias").rank] = 9; },
       "tensor 'conv1.bias': rank 9 exceeds the limit of 8"},
      {"unknown dtype", true, [](Bytes& b, L l) { b[l.tensors.at("conv1.bias").dtype()] = 7; },
       "tensor 'conv1.bias': unknown dtype code 7"},
      {"byte size against shape", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.bias").bytes, 20, 8); },
       "tensor 'conv1.bias': byte size 20 does not match shape [4] of f32 (16 bytes)"},
      {"misaligned offset", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.bias").offset, 328, 8); },
       "tensor 'conv1.bias': offset 328 is not a multiple of 64"},
      {"offset out of range", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.bias").offset, uint64_t(1) << 40, 8); },
       "tensor 'conv1.bias': offset 1099511627776 + 16 bytes is out of range of the 588-byte data section"},
      {"tensor ending past the data section", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.bias").offset, 576, 8); },
       "tensor 'conv1.bias': offset 576 + 16 bytes is out of range"},
      {"overlapping tensors", true, [](Bytes& b, L l) { put_le(b, l.tensors.at("conv1.bias").offset, 0, 8); },
       "tensors 'conv1.bias' and 'conv1.weight' overlap: bytes [768, 784) and [768, 1056)"},
      {"misaligned data section", true, [](Bytes& b, L) { put_le(b, 24, 769, 8); },
       "data section offset 769 is not a multiple of 64"},
      {"data section inside the header", true, [](Bytes& b, L) { put_le(b, 24, 704, 8); },
       "data section offset 704 lies inside the header (746 bytes)"},
      {"header smaller than the preamble", false, [](Bytes& b, L) { put_le(b, 16, 16, 8); },
       "header size 16 is smaller than the 40-byte preamble"},
      {"too many tensors", true, [](Bytes& b, L) { put_le(b, 12, 70000, 4); }, "too many tensors: 70000 (limit 65536)"},
      {"too many metadata entries", true, [](Bytes& b, L) { put_le(b, 8, 5000, 4); },
       "too many metadata entries: 5000 (limit 4096)"},
      {"tensor count beyond the table", true, [](Bytes& b, L) { put_le(b, 12, 7, 4); },
       "header overrun: tensor entry 6 name length needs 2 bytes at offset 742, header ends at 742"},
      {"array running past the header", true, [](Bytes& b, L l) { put_le(b, l.meta.at("model.scales").value, 1000, 4); },
       "header overrun: metadata 'model.scales' array needs 8000 bytes"},
      {"unread header bytes", true, [](Bytes& b, L l) { put_le(b, 16, l.header_bytes + 4, 8); },
       "header has 4 unread bytes after the tensor table"},
      {"trailing bytes", true, [](Bytes& b, L) { b.insert(b.end(), 8, 0); }, "8 unexpected bytes after the data section"},
      {"unknown metadata type", true, [](Bytes& b, L l) { b[l.meta.at("model.width").type] = 9; },
       "metadata 'model.width': unknown type code 9"},
      {"bool that is neither 0 nor 1", true, [](Bytes& b, L l) { b[l.meta.at("model.residual").value] = 2; },
       "metadata 'model.residual': bool byte is 2, not 0 or 1"},
      {"string that is not UTF-8", true, [](Bytes& b, L l) { b[l.meta.at("general.name").value + 4] = 0xC0; },
       "metadata 'general.name': string is not valid UTF-8"},
      {"string above the limit", true, [](Bytes& b, L l) { put_le(b, l.meta.at("general.name").value, 1u << 21, 4); },
       "metadata 'general.name': string of 2097152 bytes exceeds the limit of 1048576"},
      {"array above the limit", true, [](Bytes& b, L l) { put_le(b, l.meta.at("model.strides").value, 1u << 21, 4); },
       "metadata 'model.strides': array of 2097152 values exceeds the limit of 1048576"},
      {"key with a space", true, [](Bytes& b, L l) { put_text(b, l.meta.at("model.width").key, "model width"); },
       "metadata entry 2: name \"model width\" has a byte outside printable ASCII without space"},
      {"empty key", true, [](Bytes& b, L l) { put_le(b, l.meta.at("general.name").key_length, 0, 2); },
       "metadata entry 0: name length 0 is outside 1..255"},
      {"key above the name limit", true, [](Bytes& b, L l) { put_le(b, l.meta.at("general.name").key_length, 300, 2); },
       "metadata entry 0: name length 300 is outside 1..255"},
  };
  return cases;
}

}  // namespace

TEST_CASE("small.ampw written by Python reads back exactly") {
  const WeightFile wf = WeightFile::open(fixture_path());
  CHECK(wf.path() == fixture_path());
  CHECK(wf.version_major() == 1);
  CHECK(wf.version_minor() == 0);

  const Tensor w = wf.tensor("conv1.weight", {4, 3, 3, 2});
  REQUIRE(w.dtype() == DType::F32);
  for (int i = 0; i < 72; ++i) CHECK(w.f32()[i] == (i - 36) * 0.125f);
  const Tensor bias = wf.tensor("conv1.bias", {4});
  const float bias_expected[] = {0.1f, -0.2f, 1e-30f, 3.4e38f};
  for (int i = 0; i < 4; ++i) CHECK(bias.f32()[i] == bias_expected[i]);
  CHECK(wf.tensor("block0.gain", {}).f32()[0] == 2.5f);
  CHECK(wf.tensor("block1.gain", {1}).f32()[0] == -0.5f);

  // Stored as f16: binary fractions are exact, other values round as float_to_half does.
  const Tensor proj = wf.tensor("decoder/proj.weight", {2, 3, 4});
  for (int i = 0; i < 24; ++i) CHECK(proj.f32()[i] == static_cast<float>(i * 37 % 101) / 64.0f - 0.75f);
  const Tensor rounding = wf.tensor("rounding", {6});
  const float inputs[] = {0.1f, 1.0f / 3.0f, 65504.0f, -1e-7f, 6e-8f, -0.0f};
  for (int i = 0; i < 6; ++i) {
    INFO("rounding[" << i << "] from " << inputs[i]);
    CHECK(rounding.f32()[i] == half_to_float(float_to_half(inputs[i])));
  }
  CHECK(std::signbit(rounding.f32()[5]));
}

TEST_CASE("small.ampw tensor table: order, dtypes, aligned offsets") {
  const WeightFile wf = WeightFile::open(fixture_path());
  const std::vector<std::string> names = {"conv1.weight", "conv1.bias", "block0.gain",
                                          "block1.gain", "decoder/proj.weight", "rounding"};
  REQUIRE(wf.tensors().size() == names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    const TensorInfo& t = wf.tensors()[i];
    INFO(t.name);
    CHECK(t.name == names[i]);
    CHECK(t.offset % 64 == 0);
    CHECK(t.bytes == static_cast<uint64_t>(shape_numel(t.shape)) * dtype_size(t.dtype));
    CHECK(wf.find(t.name) == &t);
  }
  CHECK(wf.tensors()[4].dtype == DType::F16);
  CHECK(wf.tensors()[0].dtype == DType::F32);
  CHECK(wf.find("conv2.weight") == nullptr);
}

TEST_CASE("small.ampw metadata of every type") {
  const WeightFile wf = WeightFile::open(fixture_path());
  CHECK(wf.get_string("general.name") == "ampi-test-small");
  CHECK(wf.get_string("general.description") == "line one\nline \"two\"\t\xc3\x9cnic\xc3\xb8" "de \xe2\x9c\x93");
  CHECK(wf.get_int("model.width") == 8);
  CHECK(wf.get_int("model.min_int") == INT64_MIN);
  CHECK(wf.get_int("model.big_int") == (int64_t(1) << 40) + 1);
  CHECK(wf.get_float("train.lr") == 0.001);
  CHECK(wf.get_float("train.momentum") == 0.1);
  CHECK(wf.get_float("train.epochs_as_int") == 30.0);  // int accepted as float
  CHECK(wf.get_bool("model.residual"));
  CHECK_FALSE(wf.get_bool("model.squeeze"));
  CHECK(wf.get_ints("model.strides") == std::vector<int64_t>{1, -2, 3, int64_t(1) << 50});
  CHECK(wf.get_floats("model.scales") == std::vector<double>{0.5, 0.1, -2.25});
  CHECK(wf.get_floats("model.strides") == std::vector<double>{1, -2, 3, 1125899906842624.0});
  CHECK(wf.get_floats("model.empty").empty());
  CHECK(wf.has("model.depth"));
  CHECK_FALSE(wf.has("model.height"));
}

TEST_CASE("metadata rows print each value on one line") {
  const WeightFile wf = WeightFile::open(fixture_path());
  std::map<std::string, std::array<std::string, 3>> rows;
  for (const auto& row : wf.metadata_rows()) rows[row[0]] = row;
  REQUIRE(rows.size() == 14);
  using Row = std::array<std::string, 3>;
  CHECK(rows["model.width"] == Row{"model.width", "int64", "8"});
  CHECK(rows["train.momentum"] == Row{"train.momentum", "float64", "0.1"});
  CHECK(rows["model.squeeze"] == Row{"model.squeeze", "bool", "false"});
  CHECK(rows["model.strides"] == Row{"model.strides", "int64[]", "[1, -2, 3, 1125899906842624]"});
  CHECK(rows["model.scales"] == Row{"model.scales", "float64[]", "[0.5, 0.1, -2.25]"});
  CHECK(rows["model.empty"][2] == "[]");
  CHECK(rows["general.description"][2] ==
        "\"line one\\x0aline \\\"two\\\"\\x09\xc3\x9cnic\xc3\xb8" "de \xe2\x9c\x93\"");
}

TEST_CASE("missing keys, wrong types and wrong shapes name the file and the key") {
  const WeightFile wf = WeightFile::open(fixture_path());
  const std::string prefix = fixture_path() + ": ";
  CHECK_THROWS_WITH(wf.get_int("model.height"), prefix + "no metadata key 'model.height'");
  CHECK_THROWS_WITH(wf.get_string("model.width"), prefix + "metadata 'model.width' is int64, not string");
  CHECK_THROWS_WITH(wf.get_int("train.lr"), prefix + "metadata 'train.lr' is float64, not int64");
  CHECK_THROWS_WITH(wf.get_bool("model.width"), prefix + "metadata 'model.width' is int64, not bool");
  CHECK_THROWS_WITH(wf.get_ints("model.scales"), prefix + "metadata 'model.scales' is float64[], not int64[]");
  CHECK_THROWS_WITH(wf.get_floats("general.name"), prefix + "metadata 'general.name' is string, not float64[]");
  CHECK_THROWS_WITH(wf.tensor("conv2.weight", {1}), prefix + "no tensor named 'conv2.weight'");
  CHECK_THROWS_WITH(wf.tensor("conv1.weight", {4, 3, 3, 3}),
                    prefix + "tensor 'conv1.weight' has shape [4, 3, 3, 2], expected [4, 3, 3, 3]");
  CHECK_THROWS_WITH(wf.tensor("block0.gain", {1}), prefix + "tensor 'block0.gain' has shape [], expected [1]");
}

TEST_CASE("every kind of damage gives its own one-line error") {
  const Bytes good = fixture_bytes();
  REQUIRE(error_of(good).empty());
  const FileLayout layout = layout_of(good);
  REQUIRE(layout.data_offset - layout.header_bytes >= 8);  // room for "unread header bytes"
  std::set<std::string> messages;
  for (const Corruption& c : corruptions()) {
    Bytes bytes = good;
    c.damage(bytes, layout);
    if (c.reseal) reseal(bytes);
    const std::string message = error_of(bytes);
    INFO("damage: " << c.what << "\nmessage: " << message);
    CHECK(message.rfind(kOrigin + ": ", 0) == 0);
    CHECK(message.find(c.expected) != std::string::npos);
    CHECK(message.find('\n') == std::string::npos);
    CHECK(messages.insert(message).second);
  }
}

TEST_CASE("a newer minor version is read, skipping header fields it added") {
  Bytes bytes = fixture_bytes();
  const FileLayout layout = layout_of(bytes);
  put_le(bytes, 6, 1, 2);
  put_le(bytes, 16, layout.header_bytes + 4, 8);  // four bytes a version 1.1 field might use
  reseal(bytes);
  const WeightFile wf = WeightFile::from_bytes(bytes, kOrigin);
  CHECK(wf.version_minor() == 1);
  CHECK(wf.tensor("block0.gain", {}).f32()[0] == 2.5f);
}

TEST_CASE("every truncation and random damage is rejected or read, never a crash") {
  const Bytes good = fixture_bytes();
  for (size_t size = 1; size < good.size(); ++size) {
    INFO("truncated to " << size << " bytes");
    const std::string message = error_of(Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(size)));
    CHECK(message.find("truncated") != std::string::npos);
  }
  // Random bytes, resealed so that they get past the header checksum into the parser.
  const uint32_t seed = 77;
  INFO("seed " << seed);
  std::mt19937 rng(seed);
  const size_t header_bytes = get_le(good, 16, 8);
  int rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Bytes bytes = good;
    for (int k = 0; k < 1 + trial % 4; ++k) bytes[rng() % header_bytes] = static_cast<uint8_t>(rng());
    // The checksum goes where the undamaged header says, even if the damage moved it.
    put_le(bytes, header_bytes, crc32(bytes.data(), header_bytes), 4);
    rejected += !error_of(bytes).empty();
  }
  CHECK(rejected > 0);
}

TEST_CASE("open() names the path: missing file, empty file, truncated file") {
  const std::string dir = AMPI_BINARY_DIR;
  const std::string missing = dir + "/no_such_weights.ampw";
  CHECK_THROWS_WITH(WeightFile::open(missing), missing + ": cannot open: no such file");
  CHECK_THROWS_WITH(WeightFile::open(dir), dir + ": cannot open: not a regular file");

  const std::string empty = dir + "/test_weights_empty.ampw";
  std::ofstream(empty, std::ios::binary).close();
  CHECK_THROWS_WITH(WeightFile::open(empty), empty + ": empty file");

  const Bytes good = fixture_bytes();
  const std::string cut = dir + "/test_weights_cut.ampw";
  std::ofstream(cut, std::ios::binary).write(reinterpret_cast<const char*>(good.data()), 100);
  CHECK_THROWS_WITH(WeightFile::open(cut), cut + ": truncated: header needs 746 bytes, file has 100");
  std::remove(empty.c_str());
  std::remove(cut.c_str());
}
