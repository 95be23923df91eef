// The dispatch table: one set of micro-kernel function pointers per instruction set,
// filled once at start-up (MNN-style). Op code (kernels/ops.h) calls through a table and
// never names an instruction set; tests and benchmarks walk every runnable table.
//
// Micro-kernels are pure functions: single-threaded, no allocation, no I/O. The op layer
// splits work across the thread pool and hands each call a range.
//
// Each ISA starts as a copy of the scalar reference table and overwrites the entries it
// accelerates, so a variant that does not pay for some op simply keeps the reference.
#pragma once
#include <cstdint>

#include "engine/isa.h"
#include "kernels/activation.h"

namespace ampi {

struct KernelTable {
  Isa isa = Isa::Scalar;

  // ---- element-wise ------------------------------------------------------------------
  // out[i] = act(a[i] + b[i]) for i in [0, n). out may alias a or b.
  void (*add)(const float* a, const float* b, int64_t n, ActivationSpec act, float* out) = nullptr;
  // x[i] = act(x[i]) for i in [0, n).
  void (*activate)(float* x, int64_t n, ActivationSpec act) = nullptr;
};

// The table for a variant; throws std::runtime_error if this build or CPU cannot run it.
const KernelTable& kernels_for(Isa isa);
// The table of active_isa() (AMPI_ISA or the best variant).
const KernelTable& kernels();

// Per-ISA fill functions, one per instruction set (kernels/*/register_*.cpp).
void fill_scalar_kernels(KernelTable& table);
void fill_avx2_kernels(KernelTable& table);
void fill_avx512_kernels(KernelTable& table);
void fill_neon_kernels(KernelTable& table);

}  // namespace ampi
