// numpy's .npy files: a strict reader (format versions 1.0, 2.0 and 3.0; C order only)
// that converts the common element types to f32, and a writer of f32 tensors. Used by the
// numpy fixture tests, the depth-map importer (ampi run --depth x.npy) and fuzzing.
//
// Read element types: <f4 <f8 <f2 |u1 <u2 <i4 <i8 |b1 (int64 values beyond 2^24 lose
// precision in f32, as they would in numpy's astype). Fortran order, big-endian data,
// structured dtypes and anything else are rejected with a one-line std::runtime_error
// that starts with the file's path.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "engine/tensor.h"

namespace ampi {

// An f32 tensor (Layout::Plain) with the array's shape in numpy order.
Tensor read_npy(const std::string& path);
// The same for a file image in memory; `origin` names it in error messages.
Tensor parse_npy(const uint8_t* data, size_t size, const std::string& origin);

// Writes an f32 tensor as a version 1.0 .npy file ('<f4', C order), data 64-byte aligned
// like numpy's own writer; replaces `path` only once the whole file is written. Throws
// std::invalid_argument for a tensor that is not f32.
void write_npy(const std::string& path, const Tensor& tensor);

}  // namespace ampi
