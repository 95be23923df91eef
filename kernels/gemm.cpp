#include "kernels/gemm.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "engine/cpu_caches.h"
#include "engine/tensor.h"
#include "kernels/output_streaming.h"

namespace ampi {
namespace {

// Gemm tiles per parallel_for grain, enough to amortise the scheduling.
constexpr int64_t kGrainTiles = 4;
// A block of packed panels takes at most 1/kBlockL2Share of the L2 cache, a group of
// tiles' rows of A at most 1/kRowsL2Share: both stay in L2 while the group's tiles run
// against the block, with room left for the C tiles and what the prefetcher brings in.
constexpr size_t kBlockL2Share = 2, kRowsL2Share = 4;
// When the system does not say (no sysfs cache description, e.g. under qemu).
constexpr size_t kDefaultL2Bytes = size_t{1} << 20;
// Floats of a 64-byte line: streamed outputs are written in whole lines.
constexpr int kLineFloats = 16;
// Packing is split over threads in chunks of about this many floats.
constexpr int64_t kPackGrainFloats = 16384;

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error("gemm: " + what); }

void validate(const GemmProblem& p) {
  if (p.m < 0 || p.n <= 0 || p.k <= 0)
    fail("sizes m " + std::to_string(p.m) + ", n " + std::to_string(p.n) + ", k " + std::to_string(p.k) +
         " must be positive (m may be 0)");
  if (p.m > 0 && (!p.a || !p.c)) fail(std::string(p.a ? "C" : "A") + " is missing");
  if (p.a_stride < p.k)
    fail("a_stride " + std::to_string(p.a_stride) + " is shorter than a row of A (k " + std::to_string(p.k) + ")");
  if (p.c_stride < p.n)
    fail("c_stride " + std::to_string(p.c_stride) + " is shorter than a row of C (n " + std::to_string(p.n) + ")");
}

void validate(StridedMatrix b, int n, int k) {
  if (!b.data) fail("B is missing");
  const int row = b.transposed ? k : n;
  if (b.stride < row)
    fail("B's stride " + std::to_string(b.stride) + " is shorter than its rows (" + std::to_string(row) + " floats)");
}

// Panel j0 / nr, columns [j0, j0 + columns), of a row-major B: one contiguous run of each row.
void pack_rows(StridedMatrix b, int k, int nr, int j0, int columns, float* panel_rows) {
  for (int kk = 0; kk < k; ++kk)
    std::memcpy(panel_rows + static_cast<int64_t>(kk) * nr, b.data + kk * b.stride + j0, columns * sizeof(float));
}

// The same of a transposed B: column j of the panel is one contiguous row of the memory.
void pack_transposed(StridedMatrix b, int k, int nr, int j0, int columns, float* panel_rows) {
  for (int j = 0; j < columns; ++j) {
    const float* column = b.data + static_cast<int64_t>(j0 + j) * b.stride;
    for (int kk = 0; kk < k; ++kk) panel_rows[static_cast<int64_t>(kk) * nr + j] = column[kk];
  }
}

// The calling thread's buffer for a strided B's panels. It grows to the largest B a
// product on this thread has packed and is reused, never shrunk (an attention head's K^T
// or V: a few hundred KiB).
float* packing_scratch(int64_t floats) {
  thread_local AlignedBuffer buffer;
  thread_local int64_t capacity = 0;
  if (capacity < floats) {
    buffer = aligned_alloc64(static_cast<size_t>(floats) * sizeof(float));
    capacity = floats;
  }
  return static_cast<float*>(buffer.get());
}

// The arguments every tile of a product shares.
GemmArgs shared_args(const GemmProblem& p) {
  GemmArgs g;
  g.k = p.k;
  g.a_stride = p.a_stride;
  g.c_stride = p.c_stride;
  g.act = p.act;
  // Blocks are whole lines wide (gemm_block_columns), so whole-line rows stay whole.
  g.stream_c = p.n % kLineFloats == 0 && stream_output(p.c, static_cast<int64_t>(p.m) * p.n, p.c_stride);
  return g;
}

// Rows [row, row + mr) of the product against the block of panels g.packed (g.n columns
// from column j0), into C.
void run_tile(const GemmProblem& p, int mr, int64_t row, int j0, GemmArgs& g, const KernelTable& table) {
  g.m = static_cast<int>(std::min<int64_t>(mr, p.m - row));
  g.a = p.a + row * p.a_stride;
  g.c = p.c + row * p.c_stride + j0;
  g.residual = p.residual ? p.residual + row * p.c_stride + j0 : nullptr;
  // The next tile's rows follow this one's in memory when A is contiguous: worth a
  // prefetch. A strided A (a head's columns) would bring in the other heads' too.
  const int64_t next_rows = std::min<int64_t>(mr, std::max<int64_t>(0, p.m - row - mr));
  const bool contiguous = p.a_stride == p.k && next_rows > 0;
  g.prefetch_a = contiguous ? g.a + static_cast<int64_t>(mr) * p.a_stride : nullptr;
  g.prefetch_floats = contiguous ? next_rows * p.k : 0;
  table.gemm(g);
}

int64_t l2_bytes() { return static_cast<int64_t>(cache_bytes(2, kDefaultL2Bytes)); }

}  // namespace

int64_t gemm_packed_size(int n, int k, int nr) {
  const int64_t panels = (n + nr - 1) / nr;
  return panels * (1 + static_cast<int64_t>(k)) * nr;
}

void pack_gemm_panels(StridedMatrix b, const float* bias, int n, int k, int nr, int panel_begin,
                      int panel_end, float* packed) {
  const int64_t panel_floats = (1 + static_cast<int64_t>(k)) * nr;
  for (int panel = panel_begin; panel < panel_end; ++panel) {
    float* dst = packed + panel * panel_floats;
    const int j0 = panel * nr, columns = std::min(nr, n - j0);
    if (columns < nr) std::fill(dst, dst + panel_floats, 0.0f);  // columns past n stay zero
    for (int j = 0; j < columns; ++j) dst[j] = bias ? bias[j0 + j] : 0.0f;
    if (b.transposed)
      pack_transposed(b, k, nr, j0, columns, dst + nr);
    else
      pack_rows(b, k, nr, j0, columns, dst + nr);
  }
}

void pack_gemm_weights(const float* w, const float* bias, int n, int k, int nr, float* packed) {
  pack_gemm_panels({w, k, true}, bias, n, k, nr, 0, (n + nr - 1) / nr, packed);
}

int gemm_block_columns(int k, int nr) {
  // Whole panels, and (nr and 16 being powers of two) whole streamed lines.
  const int64_t unit = std::max(nr, kLineFloats);
  const int64_t unit_bytes = (1 + static_cast<int64_t>(k)) * unit * static_cast<int64_t>(sizeof(float));
  const int64_t budget = l2_bytes() / static_cast<int64_t>(kBlockL2Share);
  const int64_t units = std::max<int64_t>(1, budget / unit_bytes);
  return static_cast<int>(std::min<int64_t>(units * unit, std::numeric_limits<int>::max() / 2 / unit * unit));
}

int64_t gemm_group_rows(int k, int mr) {
  const int64_t tile_bytes = static_cast<int64_t>(mr) * k * static_cast<int64_t>(sizeof(float));
  return mr * std::max<int64_t>(1, l2_bytes() / static_cast<int64_t>(kRowsL2Share) / tile_bytes);
}

GemmWeights::GemmWeights(const float* w, const float* bias, int n, int k, const KernelTable& table)
    : n_(n), k_(k), table_(&table) {
  if (n <= 0 || k <= 0) fail("weights of " + std::to_string(n) + "x" + std::to_string(k) + " are empty");
  if (!w) fail("weights are missing");
  const int64_t floats = gemm_packed_size(n, k, table.gemm_nr);
  AlignedBuffer buffer = aligned_alloc64(static_cast<size_t>(floats) * sizeof(float));
  float* packed = static_cast<float*>(buffer.release());
  packed_ = std::shared_ptr<const float>(packed, AlignedDeleter{});
  pack_gemm_weights(w, bias, n, k, table.gemm_nr, packed);
}

void gemm(const GemmProblem& p, const GemmWeights& w, ThreadPool& pool) {
  if (!w.packed()) fail("run with empty weights");
  if (p.n != w.n() || p.k != w.k())
    fail("a " + std::to_string(p.k) + "x" + std::to_string(p.n) + " product with " + std::to_string(w.k()) +
         "x" + std::to_string(w.n()) + " weights");
  validate(p);
  gemm_packed(p, w.packed(), pool, w.table());
}

void gemm(const GemmProblem& p, StridedMatrix b, const float* bias, ThreadPool& pool, const KernelTable& table) {
  validate(p);
  validate(b, p.n, p.k);
  if (p.m == 0) return;
  const int nr = table.gemm_nr, panels = (p.n + nr - 1) / nr;
  float* packed = packing_scratch(gemm_packed_size(p.n, p.k, nr));
  const int64_t grain = std::max<int64_t>(1, kPackGrainFloats / ((1 + static_cast<int64_t>(p.k)) * nr));
  pool.parallel_for(panels, grain, [&](int64_t first, int64_t last) {
    pack_gemm_panels(b, bias, p.n, p.k, nr, static_cast<int>(first), static_cast<int>(last), packed);
  });
  gemm_packed(p, packed, pool, table);
}

void gemm_packed(const GemmProblem& p, const float* packed, ThreadPool& pool, const KernelTable& table) {
  if (p.m <= 0) return;
  const int mr = table.gemm_mr, nr = table.gemm_nr;
  const int block = gemm_block_columns(p.k, nr);
  const int64_t group = gemm_group_rows(p.k, mr) / mr;  // tiles
  const int64_t panel_floats = (1 + static_cast<int64_t>(p.k)) * nr;
  const GemmArgs shared = shared_args(p);
  const int64_t tiles = (p.m + mr - 1) / mr;
  pool.parallel_for(tiles, kGrainTiles, [&](int64_t first, int64_t last) {
    GemmArgs g = shared;
    // A group of tiles' rows stays in L2 while every block of B passes over them, so each
    // block is read from L2 by all of the group's tiles. With B in one block (every
    // convolution of the depth networks) this is a plain walk over the tiles.
    for (int64_t t0 = first; t0 < last; t0 += group) {
      const int64_t t1 = std::min(last, t0 + group);
      for (int j0 = 0; j0 < p.n; j0 += block) {
        g.n = std::min(block, p.n - j0);
        g.packed = packed + (j0 / nr) * panel_floats;
        for (int64_t t = t0; t < t1; ++t) run_tile(p, mr, t * mr, j0, g, table);
      }
    }
  });
}

}  // namespace ampi
