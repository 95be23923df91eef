// Matrix multiplication with a fused epilogue: the op behind 1x1 convolutions (Conv2d's
// pointwise path), linear layers and attention's two products.
//
//   C[i][j] = act(bias[j] + sum_kk A[i][kk] * B[kk][j]) (+ R[i][j])   i < m, j < n, kk < k
//
// A is row-major with unit column stride (rows a_stride floats apart), so a head's
// columns of a [tokens][3 dim] buffer are an A without a copy. B comes one of two ways:
// - packed once (GemmWeights, or any buffer laid out by pack_gemm_weights): the weights
//   of a linear layer or a 1x1 convolution, with their bias;
// - a strided view (StridedMatrix), row-major or transposed, packed on each call: K^T and
//   V of one attention head are views of the same [tokens][3 dim] buffer.
//
// Tiling (gemm_packed, the one loop every path runs): the m rows go in tiles of the
// table's gemm_mr rows, split over the pool's threads; each tile calls the table's gemm
// micro-kernel on a block of packed column panels. B is cut into blocks of columns whose
// packed panels fit in half the L2 cache, and a thread's tiles go in groups whose rows of
// A fit in a quarter of it: every block passes over a group while both stay in L2,
// instead of each tile reading the whole of B from memory. B of every convolution of the
// depth networks fits one block (the loop is then a plain walk over the tiles); a ViT-S's
// products (B up to 2.4 MB) measured the same blocked or not, a 1024x4096 B (a ViT-L
// MLP) 1.7x faster blocked (4096 rows, AVX-512, 1 thread: 71 against 41 GFLOP/s, the
// L2 taken as 1 MiB). Every output value comes from one micro-kernel call
// over the whole k in the same order, so results are bitwise identical for any thread
// count and either way of passing B.
#pragma once
#include <cstdint>
#include <memory>

#include "engine/thread_pool.h"
#include "kernels/kernel_table.h"

namespace ampi {

// A k x n operand B in memory: element (kk, j) at data[kk * stride + j], or when
// transposed at data[j * stride + kk] (then the memory holds B^T, n rows of k floats: a
// PyTorch Linear weight, or K when the product is Q K^T).
struct StridedMatrix {
  const float* data = nullptr;
  int64_t stride = 0;
  bool transposed = false;
};

// Everything of one product but B: the sizes, A, C and the epilogue.
struct GemmProblem {
  int m = 0, n = 0, k = 0;
  const float* a = nullptr;  // m rows of k floats, a_stride floats apart
  int64_t a_stride = 0;
  float* c = nullptr;  // m rows of n floats, c_stride floats apart; never overlaps A or B
  int64_t c_stride = 0;
  // nullptr, or m rows of n floats laid out like C (c_stride apart); may be C itself, to
  // add the product to what C holds.
  const float* residual = nullptr;
  ActivationSpec act;  // applied before the residual is added
};

// Packing, for a table whose micro-kernel takes panels nr columns wide: ceil(n / nr)
// panels of (1 + k) * nr floats each, the panel's nr biases, then for each kk the nr
// values B[kk][j0 .. j0 + nr); columns past n are zero.
int64_t gemm_packed_size(int n, int k, int nr);
// Panels [panel_begin, panel_end) of B, into their places in `packed` (the whole
// buffer's start). bias [n] or nullptr (zeros).
void pack_gemm_panels(StridedMatrix b, const float* bias, int n, int k, int nr, int panel_begin,
                      int panel_end, float* packed);
// Every panel of B^T given as w [n][k] row-major (n filters of k weights; one OHWI
// filter per row of a 1x1 convolution).
void pack_gemm_weights(const float* w, const float* bias, int n, int k, int nr, float* packed);

// Columns of B per cache block (a multiple of nr) and rows of A per group of tiles (a
// multiple of mr) for a reduction of k: the tests size their problems with them to cross
// blocks and groups.
int gemm_block_columns(int k, int nr);
int64_t gemm_group_rows(int k, int mr);

// B packed once, with its bias, for one table.
class GemmWeights {
 public:
  GemmWeights() = default;
  // w [n][k] row-major (B^T: a PyTorch Linear weight), bias [n] or nullptr. Throws
  // std::runtime_error on empty sizes or missing weights.
  GemmWeights(const float* w, const float* bias, int n, int k, const KernelTable& table = kernels());

  int n() const { return n_; }
  int k() const { return k_; }
  const float* packed() const { return packed_.get(); }
  const KernelTable& table() const { return *table_; }

 private:
  int n_ = 0, k_ = 0;
  const KernelTable* table_ = nullptr;
  std::shared_ptr<const float> packed_;  // immutable, shared by copies
};

// C = act(A B + bias) (+ R) with B and its bias from w, on w's table. p.n and p.k must
// be w's. Throws std::runtime_error on sizes or strides that do not fit.
void gemm(const GemmProblem& p, const GemmWeights& w, ThreadPool& pool = default_pool());

// The same with B a strided view, packed for the table on each call (threaded over the
// panels); bias [n] or nullptr.
void gemm(const GemmProblem& p, StridedMatrix b, const float* bias, ThreadPool& pool = default_pool(),
          const KernelTable& table = kernels());

// The tiling both run, for B already packed for `table` (pack_gemm_weights' layout).
// Conv2d's pointwise path calls it with its packed filters. Does not validate.
void gemm_packed(const GemmProblem& p, const float* packed, ThreadPool& pool, const KernelTable& table);

}  // namespace ampi
