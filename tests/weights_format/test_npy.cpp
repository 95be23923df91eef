#include <catch2/catch.hpp>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/half.h"
#include "weights_format/npy.h"

using namespace ampi;

namespace {

// Files written by numpy itself (tests/weights_format/npy/make_npy.py).
std::string npy_path(const std::string& name) {
  return std::string(AMPI_SOURCE_DIR) + "/tests/weights_format/npy/" + name;
}

std::vector<uint8_t> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in.good());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<float> values(const Tensor& t) { return {t.f32(), t.f32() + t.numel()}; }

// The message parse_npy throws for `bytes`, or "" if it accepts them.
std::string error_of(const std::vector<uint8_t>& bytes) {
  try {
    parse_npy(bytes.data(), bytes.size(), "mem.npy");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

void check_error(const std::string& message, const std::string& expected_part) {
  INFO("message: " << message);
  CHECK(message.rfind("mem.npy: ", 0) == 0);
  CHECK(message.find(expected_part) != std::string::npos);
  CHECK(message.find('\n') == std::string::npos);
}

// Replaces the first occurrence of `from` by `to` (same length, so offsets stay valid).
std::vector<uint8_t> replaced(std::vector<uint8_t> bytes, const std::string& from, const std::string& to) {
  REQUIRE(from.size() == to.size());
  const std::string text(bytes.begin(), bytes.end());
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  std::copy(to.begin(), to.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at));
  return bytes;
}

}  // namespace

TEST_CASE("npy: every supported dtype reads as f32 with numpy's shape") {
  Tensor f4 = read_npy(npy_path("f4.npy"));
  CHECK(f4.shape() == Shape{2, 3, 4});
  CHECK(f4.dtype() == DType::F32);
  for (int i = 0; i < 24; ++i) CHECK(f4.f32()[i] == (i - 12) / 4.0f);

  CHECK(values(read_npy(npy_path("f8.npy"))) ==
        std::vector<float>{0.1f, -2.5f, static_cast<float>(1e-3), static_cast<float>(12345.678), 0.0f});
  Tensor f2 = read_npy(npy_path("f2.npy"));
  CHECK(f2.shape() == Shape{3, 2});
  for (int i = 0; i < 6; ++i) CHECK(f2.f32()[i] == i / 8.0f - 0.25f);
  Tensor u1 = read_npy(npy_path("u1.npy"));
  CHECK(u1.shape() == Shape{4, 4});
  for (int i = 0; i < 16; ++i) CHECK(u1.f32()[i] == static_cast<float>(i * 17));
  CHECK(values(read_npy(npy_path("u2.npy"))) == std::vector<float>{0, 1000, 65535});
  CHECK(values(read_npy(npy_path("i4.npy"))) == std::vector<float>{-2147483648.0f, -1, 0, 2147483647.0f});
  CHECK(values(read_npy(npy_path("i8.npy"))) == std::vector<float>{-1099511627776.0f, 7, 9007199254740992.0f});
  CHECK(values(read_npy(npy_path("b1.npy"))) == std::vector<float>{1, 0, 1, 1, 0});
}

TEST_CASE("npy: rank 0, empty arrays and header versions 2.0 and 3.0") {
  Tensor scalar = read_npy(npy_path("scalar.npy"));
  CHECK(scalar.rank() == 0);
  CHECK(scalar.f32()[0] == 3.25f);
  Tensor empty = read_npy(npy_path("empty.npy"));
  CHECK(empty.shape() == Shape{0, 3});
  CHECK(empty.numel() == 0);
  for (const char* name : {"v2.npy", "v3.npy"}) {
    INFO(name);
    Tensor t = read_npy(npy_path(name));
    CHECK(t.shape() == Shape{2, 3});
    CHECK(values(t) == std::vector<float>{0, 1, 2, 3, 4, 5});
  }
}

TEST_CASE("npy: unsupported layouts and dtypes are refused") {
  auto message = [](const char* name) {
    try {
      read_npy(npy_path(name));
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string fortran = message("fortran.npy");
  CHECK(fortran.rfind(npy_path("fortran.npy") + ": ", 0) == 0);
  CHECK(fortran.find("Fortran-order arrays are not supported") != std::string::npos);
  CHECK(message("big_endian.npy").find("unsupported dtype '>f4'") != std::string::npos);
  CHECK(message("no_such_file.npy").find("cannot open: no such file") != std::string::npos);
}

TEST_CASE("npy: damaged files give distinct one-line errors") {
  const std::vector<uint8_t> good = file_bytes(npy_path("f4.npy"));
  REQUIRE(error_of(good).empty());
  check_error(error_of({}), "empty file");
  check_error(error_of({good.begin(), good.begin() + 5}), "truncated: the .npy preamble");
  check_error(error_of({good.begin(), good.begin() + 40}), "truncated: the .npy header needs 128 bytes");
  check_error(error_of({good.begin(), good.end() - 1}), "truncated: shape [2, 3, 4] of <f4 needs 96 data bytes");
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  check_error(error_of(longer), "1 unexpected bytes after the array data");

  std::vector<uint8_t> magic = good;
  magic[1] = 'X';
  check_error(error_of(magic), "not a .npy file (bad magic)");
  std::vector<uint8_t> version = good;
  version[6] = 4;
  check_error(error_of(version), "unsupported .npy format version 4.0");

  check_error(error_of(replaced(good, "'descr'", "'desc' ")), "unknown key 'desc'");
  check_error(error_of(replaced(good, "'shape'", "'descr'")), "duplicate key 'descr'");
  check_error(error_of(replaced(good, "False", "Fals ")), "expected True or False");
  check_error(error_of(replaced(good, "(2, 3, 4)", "(2, 3,-4)")), "expected a non-negative integer");
  check_error(error_of(replaced(good, "(2, 3, 4)", "(24)     ")), "needs a trailing comma");
  // Found by fuzz_npy (fuzz/corpus/npy/crash-dimension-overflow): 20 digits overflowed
  // int64 while being parsed (undefined behaviour) before the size check saw them.
  check_error(error_of(replaced(good, "(2, 3, 4), }              ", "(99999999999999999999,), }")),
              "dimension too large");
  check_error(error_of(replaced(good, "'<f4', ", "'<f4'  ")), "expected ','");
  check_error(error_of(replaced(good, "'<f4'", "'<i2'")), "unsupported dtype '<i2'");
  std::vector<uint8_t> no_newline = good;
  no_newline[good.size() - 96 - 1] = ' ';
  check_error(error_of(no_newline), "does not end with a newline");
}

TEST_CASE("npy: bool bytes other than 0 and 1 are refused") {
  std::vector<uint8_t> bytes = file_bytes(npy_path("b1.npy"));
  bytes[bytes.size() - 2] = 2;  // element 3 of 5
  check_error(error_of(bytes), "bool element 3 is neither 0 nor 1");
}

TEST_CASE("npy: write_npy output is byte for byte what np.save writes") {
  // f4.npy holds (arange(24) - 12) / 4 as <f4 in shape (2, 3, 4).
  Tensor t = Tensor::empty({2, 3, 4});
  for (int i = 0; i < 24; ++i) t.f32()[i] = (i - 12) / 4.0f;
  const std::string out = std::string(AMPI_BINARY_DIR) + "/test_write_npy_f4.npy";
  write_npy(out, t);
  CHECK(file_bytes(out) == file_bytes(npy_path("f4.npy")));

  for (const Shape& shape : {Shape{}, Shape{7}, Shape{0, 3}, Shape{1, 2, 1, 2, 1}}) {
    INFO("shape " << shape_str(shape));
    Tensor x = Tensor::zeros(shape);
    for (int64_t i = 0; i < x.numel(); ++i) x.f32()[i] = static_cast<float>(i) * 0.5f - 1.0f;
    write_npy(out, x);
    Tensor back = read_npy(out);
    CHECK(back.shape() == shape);
    CHECK(values(back) == values(x));
  }
  CHECK_THROWS_AS(write_npy(out, t.to_f16()), std::invalid_argument);
}
