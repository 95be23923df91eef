// The renderer's compositor kernels (render/composite_kernels.h): every runnable ISA
// against the scalar reference. They need no OpenCV, so they live in the core and the
// aarch64 build runs this file under qemu for NEON. Whole frames, tiling and culling are
// tested in tests/render/test_renderer.cpp.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "engine/half.h"
#include "engine/isa.h"
#include "render/composite_kernels.h"
#include "support/random.h"

using namespace ampi;

namespace {

// Layer widths around every vector width (4 for NEON, 8 for AVX2) and heights from one
// row up: the kernels' footprints reach the padding on every side of such layers.
const int kWidths[] = {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 33};
const int kHeights[] = {1, 2, 3, 8, 17};
// Row lengths around the vector widths and the pixel pairs of the AVX2 variant.
const int kCounts[] = {1, 2, 3, 4, 5, 7, 8, 9, 16, 17, 40};

// A random premultiplied layer in the padded layout the kernels read (PlaneView): a zero
// border of one pixel left and top, two right and bottom.
struct PaddedPlane {
  std::vector<uint16_t> pixels;
  render::PlaneView view;

  PaddedPlane(int width, int height, uint32_t seed)
      : pixels(static_cast<size_t>(4) * (width + 3) * (height + 3), 0) {
    const auto values = test::random_floats(static_cast<size_t>(4) * width * height, seed, 0.0f, 1.0f);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const float* v = &values[4 * (static_cast<size_t>(y) * width + x)];
        uint16_t* p = &pixels[4 * ((static_cast<size_t>(y) + 1) * (width + 3) + x + 1)];
        for (int k = 0; k < 4; ++k) p[k] = float_to_half(k == 3 ? v[3] : v[k] * v[3]);
      }
    view = render::whole_layer_view(pixels.data() + 4 * (width + 3 + 1), width + 3, width, height);
  }
};

// A layer visible only inside a box, twice: stored whole (the layout of PaddedPlane) and
// stored as the box alone with its border of two pixels, as the renderer stores it.
struct BoxedPlane {
  std::vector<uint16_t> whole_pixels, box_pixels;
  render::PlaneView whole, box;

  BoxedPlane(int width, int height, int box_x, int box_y, int box_width, int box_height, uint32_t seed)
      : whole_pixels(static_cast<size_t>(4) * (width + 3) * (height + 3), 0),
        box_pixels(static_cast<size_t>(4) * (box_width + 4) * (box_height + 4), 0) {
    const auto values = test::random_floats(static_cast<size_t>(4) * box_width * box_height, seed, 0.0f, 1.0f);
    for (int y = 0; y < box_height; ++y)
      for (int x = 0; x < box_width; ++x) {
        const float* v = &values[4 * (static_cast<size_t>(y) * box_width + x)];
        uint16_t* w = &whole_pixels[4 * ((static_cast<size_t>(box_y + y) + 1) * (width + 3) + box_x + x + 1)];
        uint16_t* b = &box_pixels[4 * ((static_cast<size_t>(y) + 2) * (box_width + 4) + x + 2)];
        for (int k = 0; k < 4; ++k) w[k] = b[k] = float_to_half(k == 3 ? v[3] : v[k] * v[3]);
      }
    whole = render::whole_layer_view(whole_pixels.data() + 4 * (width + 3 + 1), width + 3, width, height);
    box = {box_pixels.data() + 4 * (2 * (box_width + 4) + 2), box_width + 4, width, height,
           box_x, box_y, box_width, box_height};
  }
};

// Maps that reach past every edge of a width x height layer: shifts by up to its size,
// zooms in and out, shear, perspective (part of the row behind the camera), and two
// degenerate ones (every point behind the camera; a NaN coefficient).
std::vector<render::InverseHomography> sweep_maps(int width, int height, std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  std::vector<render::InverseHomography> maps = {
      {{0, 0, 0, 0, 0, 0, 0, 0, 0}},
      {{std::numeric_limits<float>::quiet_NaN(), 0, 0, 0, 1, 0, 0, 0, 1}},
      {{1, 0, -0.5f * w, 0, 1, 0.5f * h, 0, 0, 1}},
      {{0.5f, 0, 0.25f, 0, 0.5f, 0.25f, 0, 0, 1}},
      {{2.0f, 0, -1.5f, 0, 2.0f, -0.5f, 0, 0, 1}},
  };
  for (int trial = 0; trial < 4; ++trial)
    maps.push_back({{1 + 0.3f * unit(rng), 0.2f * unit(rng), (w + 2) * unit(rng), 0.2f * unit(rng),
                     1 + 0.3f * unit(rng), (h + 2) * unit(rng), (trial % 2 ? 0.1f : 0.002f) * unit(rng),
                     0.002f * unit(rng), 1}});
  return maps;
}

// Shifts onto, across each edge of and entirely off a layer of `extent` pixels, whole and
// fractional.
std::vector<float> sweep_shifts(int extent, std::mt19937& rng) {
  const float e = static_cast<float>(extent);
  std::vector<float> shifts = {-e - 2, -e + 0.25f, -1.5f, -1, -0.25f, 0, 0.5f, 1, e - 0.5f, e + 1.5f};
  std::uniform_real_distribution<float> any(-e - 3, e + 3);
  for (int k = 0; k < 3; ++k) shifts.push_back(any(rng));
  return shifts;
}

}  // namespace

TEST_CASE("every compositor kernel matches the scalar reference") {
  // One padded random plane, read by every variant along rows of every length around the
  // vector widths, through random homographies (some with points behind the camera).
  const int width = 45, height = 23;
  const uint32_t seed = 11;
  INFO("seed " << seed);
  std::vector<uint16_t> padded(static_cast<size_t>(4) * (width + 3) * (height + 3), 0);
  const auto values = test::random_floats(static_cast<size_t>(4) * width * height, seed, 0.0f, 1.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int k = 0; k < 4; ++k) {
        const float alpha = values[4 * (y * width + x) + 3];
        const float v = values[4 * (y * width + x) + k];
        padded[4 * ((y + 1) * (width + 3) + x + 1) + k] = float_to_half(k == 3 ? alpha : v * alpha);
      }
  const render::PlaneView plane = render::whole_layer_view(padded.data() + 4 * (width + 3 + 1), width + 3, width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(-1.0f, 1.0f);
  const render::CompositeKernels reference = render::composite_kernels(Isa::Scalar);
  for (Isa isa : runnable_isas()) {
    const render::CompositeKernels k = render::composite_kernels(isa);
    for (int trial = 0; trial < 40; ++trial) {
      // Near-identity maps with scale, shear, shift and perspective; every fifth has a
      // strong perspective term that puts part of the row behind the camera.
      render::InverseHomography h{{1 + 0.3f * jitter(rng), 0.2f * jitter(rng), 20 * jitter(rng),
                                   0.2f * jitter(rng), 1 + 0.3f * jitter(rng), 10 * jitter(rng),
                                   (trial % 5 == 0 ? 0.05f : 0.002f) * jitter(rng), 0.002f * jitter(rng), 1}};
      for (int count : {1, 2, 3, 4, 7, 8, 9, 15, 16, 17, 33, 60}) {
        const int x_begin = trial - 20, y = trial % (height + 6) - 3;
        INFO("isa " << isa_name(isa) << ", trial " << trial << ", count " << count);
        const auto start = test::random_floats(4 * count, seed + trial, 0.0f, 1.0f);
        std::vector<float> expected = start, got = start;
        reference.warp_over_row(plane, h, y, x_begin, count, expected.data());
        k.warp_over_row(plane, h, y, x_begin, count, got.data());
        CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-4f);
        std::vector<uint8_t> bgr_expected(3 * count), bgr_got(3 * count, 0xAB);
        reference.accum_to_bgr(expected.data(), count, bgr_expected.data());
        k.accum_to_bgr(expected.data(), count, bgr_got.data());
        CHECK(bgr_expected == bgr_got);
      }
    }
  }
}

TEST_CASE("every translation kernel matches the scalar reference") {
  // Shifts that put the row inside, across each edge and entirely outside the layer.
  const int width = 37, height = 19;
  const uint32_t seed = 13;
  INFO("seed " << seed);
  std::vector<uint16_t> padded(static_cast<size_t>(4) * (width + 3) * (height + 3), 0);
  const auto values = test::random_floats(padded.size(), seed, 0.0f, 1.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int k = 0; k < 4; ++k) {
        const size_t at = 4 * ((y + 1) * (width + 3) + x + 1) + k;
        padded[at] = float_to_half(k == 3 ? values[at - k + 3] : values[at] * values[at - k + 3]);
      }
  const render::PlaneView plane = render::whole_layer_view(padded.data() + 4 * (width + 3 + 1), width + 3, width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> shift(-45.0f, 45.0f);
  const render::CompositeKernels reference = render::composite_kernels(Isa::Scalar);
  for (Isa isa : runnable_isas()) {
    const render::CompositeKernels k = render::composite_kernels(isa);
    for (int trial = 0; trial < 60; ++trial) {
      const float du = trial < 4 ? std::vector<float>{0.0f, -1.0f, 1e9f, -1e9f}[trial] : shift(rng);
      const float dv = trial % 7 == 0 ? std::floor(shift(rng)) : shift(rng) / 2;
      for (int count : {1, 2, 3, 5, 8, 9, 16, 31, 64}) {
        const int x_begin = trial % 11 - 5, y = trial % (height + 4) - 2;
        INFO("isa " << isa_name(isa) << ", du " << du << ", dv " << dv << ", y " << y << ", x " << x_begin
                    << ", count " << count);
        const auto start = test::random_floats(4 * count, seed + trial, 0.0f, 1.0f);
        std::vector<float> expected = start, got = start;
        reference.shift_over_row(plane, du, dv, y, x_begin, count, expected.data());
        k.shift_over_row(plane, du, dv, y, x_begin, count, got.data());
        // The reference rounds x + du for every pixel, the kernels split du once.
        CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-4f);
      }
    }
  }
}

TEST_CASE("halves at the ends of their range composite as the reference's") {
  // Negative zero, subnormals, the smallest normal and one: the NEON variant widens
  // halves by shifting their bits (composite_neon.cpp), where a sign bit or a subnormal
  // would go wrong first.
  const uint16_t ends[] = {0x8000, 0x0001, 0x0155, 0x03ff, 0x0400, 0x1400, 0x3c00};
  PaddedPlane plane(9, 5, 5);
  for (size_t i = 0; i < plane.pixels.size(); ++i)
    if (plane.pixels[i] != 0) plane.pixels[i] = ends[i % 7];  // the border stays zero
  std::mt19937 rng(5);
  const render::CompositeKernels reference = render::composite_kernels(Isa::Scalar);
  for (Isa isa : runnable_isas()) {
    const render::CompositeKernels k = render::composite_kernels(isa);
    for (const render::InverseHomography& h : sweep_maps(9, 5, rng))
      for (int y = -1; y <= 5; ++y) {
        INFO("isa " << isa_name(isa) << ", y " << y);
        std::vector<float> expected(4 * 13, 0.25f), got = expected;
        reference.warp_over_row(plane.view, h, y, -2, 13, expected.data());
        k.warp_over_row(plane.view, h, y, -2, 13, got.data());
        CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-4f);
        expected.assign(4 * 13, 0.25f), got = expected;
        reference.shift_over_row(plane.view, 0.375f, 0.5f, y, -2, 13, expected.data());
        k.shift_over_row(plane.view, 0.375f, 0.5f, y, -2, 13, got.data());
        CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-4f);
      }
  }
}

TEST_CASE("accumulators outside [0, 1] saturate to black and white") {
  const std::vector<float> accum = {-0.5f, 1.5f, 0.5f, 1.0f, 2.0f, -3.0f, 1.0f, 0.0f};
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa));
    std::vector<uint8_t> bgr(6);
    render::composite_kernels(isa).accum_to_bgr(accum.data(), 2, bgr.data());
    CHECK(bgr == std::vector<uint8_t>{0, 255, 128, 255, 0, 255});
  }
}

TEST_CASE("every warp kernel matches the scalar reference on every layer shape") {
  const render::CompositeKernels reference = render::composite_kernels(Isa::Scalar);
  for (Isa isa : runnable_isas()) {
    const render::CompositeKernels k = render::composite_kernels(isa);
    for (int width : kWidths)
      for (int height : kHeights) {
        const uint32_t seed = static_cast<uint32_t>(100 * width + height);
        const PaddedPlane plane(width, height, seed);
        std::mt19937 rng(seed);
        int map_index = 0;
        for (const render::InverseHomography& h : sweep_maps(width, height, rng)) {
          // Rows above, on and below the layer; rows starting left of it and inside it.
          for (int y : {-2, 0, height / 2, height, height + 1})
            for (int count : kCounts) {
              const int x_begin = (map_index + count) % 5 - 2;
              INFO("isa " << isa_name(isa) << ", layer " << width << "x" << height << ", seed " << seed
                          << ", map " << map_index << ", y " << y << ", x " << x_begin << ", count " << count);
              const auto start = test::random_floats(4 * count, seed + count, 0.0f, 1.0f);
              std::vector<float> expected = start, got = start;
              reference.warp_over_row(plane.view, h, y, x_begin, count, expected.data());
              k.warp_over_row(plane.view, h, y, x_begin, count, got.data());
              // FMA contraction: the variants round differently, never further apart.
              REQUIRE(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-4f);
            }
          ++map_index;
        }
      }
  }
}

TEST_CASE("every translation kernel matches the scalar reference on every layer shape") {
  const render::CompositeKernels reference = render::composite_kernels(Isa::Scalar);
  for (Isa isa : runnable_isas()) {
    const render::CompositeKernels k = render::composite_kernels(isa);
    for (int width : kWidths)
      for (int height : kHeights) {
        const uint32_t seed = static_cast<uint32_t>(1000 * width + height);
        const PaddedPlane plane(width, height, seed);
        std::mt19937 rng(seed);
        const std::vector<float> du_sweep = sweep_shifts(width, rng), dv_sweep = sweep_shifts(height, rng);
        for (float du : du_sweep)
          for (float dv : dv_sweep)
            for (int count : kCounts) {
              const int x_begin = count % 3 - 1, y = (count + height) % (height + 2) - 1;
              INFO("isa " << isa_name(isa) << ", layer " << width << "x" << height << ", seed " << seed << ", du "
                          << du << ", dv " << dv << ", y " << y << ", x " << x_begin << ", count " << count);
              const auto start = test::random_floats(4 * count, seed + count, 0.0f, 1.0f);
              std::vector<float> expected = start, got = start;
              reference.shift_over_row(plane.view, du, dv, y, x_begin, count, expected.data());
              k.shift_over_row(plane.view, du, dv, y, x_begin, count, got.data());
              REQUIRE(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-4f);
            }
      }
  }
}

TEST_CASE("every accum_to_bgr variant equals the scalar reference bit for bit on every row length") {
  const render::CompositeKernels reference = render::composite_kernels(Isa::Scalar);
  for (Isa isa : runnable_isas()) {
    const render::AccumToBgrFn accum_to_bgr = render::composite_kernels(isa).accum_to_bgr;
    for (int count = 0; count <= 41; ++count) {
      const uint32_t seed = static_cast<uint32_t>(count);
      // Beyond [0, 1] on both sides (saturation), and halfway values between two levels.
      std::vector<float> accum = test::random_floats(4 * static_cast<size_t>(count) + 1, seed, -0.2f, 1.2f);
      for (int i = 0; i < count; i += 3) accum[4 * i] = (static_cast<float>(i % 255) + 0.5f) / 255.0f;
      // One byte past the row: a variant must not write it.
      std::vector<uint8_t> expected(3 * count + 1, 0xCD), got(3 * count + 1, 0xCD);
      reference.accum_to_bgr(accum.data(), count, expected.data());
      accum_to_bgr(accum.data(), count, got.data());
      INFO("isa " << isa_name(isa) << ", count " << count << ", seed " << seed);
      REQUIRE(got == expected);
    }
  }
}

TEST_CASE("a layer stored as the box around its visible pixels composites as the whole layer, bit for bit") {
  // Boxes touching each edge of the layer, inside it, the whole layer, one pixel, none.
  struct Box {
    int x, y, width, height;
  };
  const int width = 17, height = 9;
  for (Isa isa : runnable_isas()) {
    const render::CompositeKernels k = render::composite_kernels(isa);
    for (const Box& b : {Box{0, 0, 17, 9}, Box{0, 0, 5, 3}, Box{12, 6, 5, 3}, Box{3, 2, 9, 4}, Box{8, 4, 1, 1},
                         Box{1, 0, 16, 9}, Box{0, 1, 17, 8}, Box{5, 5, 0, 0}}) {
      const uint32_t seed = static_cast<uint32_t>(31 * b.x + 7 * b.y + b.width + 100 * b.height);
      const BoxedPlane plane(width, height, b.x, b.y, b.width, b.height, seed);
      std::mt19937 rng(seed);
      int map_index = 0;
      for (const render::InverseHomography& h : sweep_maps(width, height, rng)) {
        for (int y : {-2, 0, b.y, b.y + b.height, height / 2, height, height + 1})
          for (int count : kCounts) {
            const int x_begin = (map_index + count) % 5 - 2;
            INFO("isa " << isa_name(isa) << ", box " << b.width << "x" << b.height << " at " << b.x << "," << b.y
                        << ", seed " << seed << ", map " << map_index << ", y " << y << ", count " << count);
            const auto start = test::random_floats(4 * count, seed + count, 0.0f, 1.0f);
            std::vector<float> expected = start, got = start;
            k.warp_over_row(plane.whole, h, y, x_begin, count, expected.data());
            k.warp_over_row(plane.box, h, y, x_begin, count, got.data());
            REQUIRE(test::max_abs_diff(expected.data(), got.data(), expected.size()) == 0.0f);
          }
        ++map_index;
      }
      const std::vector<float> du_sweep = sweep_shifts(width, rng), dv_sweep = sweep_shifts(height, rng);
      for (float du : du_sweep)
        for (float dv : dv_sweep)
          for (int count : kCounts) {
            const int x_begin = count % 3 - 1, y = (count + height) % (height + 2) - 1;
            INFO("isa " << isa_name(isa) << ", box " << b.width << "x" << b.height << " at " << b.x << "," << b.y
                        << ", seed " << seed << ", du " << du << ", dv " << dv << ", y " << y << ", count " << count);
            const auto start = test::random_floats(4 * count, seed + count, 0.0f, 1.0f);
            std::vector<float> expected = start, got = start;
            k.shift_over_row(plane.whole, du, dv, y, x_begin, count, expected.data());
            k.shift_over_row(plane.box, du, dv, y, x_begin, count, got.data());
            REQUIRE(test::max_abs_diff(expected.data(), got.data(), expected.size()) == 0.0f);
          }
    }
  }
}
