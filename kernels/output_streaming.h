// When a kernel writes its output with streaming (non-temporal) stores: shared by the
// GEMM op (GemmArgs::stream_c) and the depthwise convolution (DepthwiseRowArgs::stream_out).
#pragma once
#include <cstdint>

namespace ampi {

// Whether an output of `floats` at `out`, written in runs (a pixel's channels, a row of
// a matrix) that start `run_stride` floats apart and cover whole 16-float lines (the
// caller checks its run lengths), can and should go out with streaming stores: every run
// starts 64-byte aligned, and the whole output is larger than the last-level cache (it
// is evicted before the next layer reads it back, so reading each line in before
// writing it is wasted traffic).
bool stream_output(const float* out, int64_t floats, int64_t run_stride);

}  // namespace ampi
