// The operators the networks call. Each splits its work over a thread pool and runs the
// micro-kernels of one dispatch table (default: the active ISA; tests pass each table).
//
// Data layout (see engine/tensor.h): activations are NHWC with batch 1, i.e. a plain
// H x W x C float array, channels innermost. Convolution weights are OHWI:
// [out_c][kernel_h][kernel_w][in_c / groups], which is PyTorch's OIHW transposed.
#pragma once
#include <cstdint>

#include "engine/thread_pool.h"
#include "kernels/kernel_table.h"

namespace ampi {

// out[i] = act(a[i] + b[i]); out may alias a or b.
void add(const float* a, const float* b, int64_t n, float* out, ActivationSpec act = {},
         ThreadPool& pool = default_pool(), const KernelTable& k = kernels());

// x[i] = act(x[i]).
void activate(float* x, int64_t n, ActivationSpec act, ThreadPool& pool = default_pool(),
              const KernelTable& k = kernels());

}  // namespace ampi
