// Scalar Winograd F(4x4, 3x3) transforms: the matrix products of kernels/winograd.h as
// written there, channel by channel, in float.
#include "kernels/reference/reference.h"
#include "kernels/winograd.h"

namespace ampi::reference {

using winograd::kTile;
using winograd::kWindow;

void winograd_input(const float* in, int64_t row_stride, int c, float* v, int64_t v_stride) {
  for (int ch = 0; ch < c; ++ch) {
    float rows[kWindow][kWindow];  // B^T d
    for (int i = 0; i < kWindow; ++i)
      for (int b = 0; b < kWindow; ++b) {
        float sum = 0.0f;
        for (int a = 0; a < kWindow; ++a)
          sum += static_cast<float>(winograd::kInputT[i][a]) * in[a * row_stride + static_cast<int64_t>(b) * c + ch];
        rows[i][b] = sum;
      }
    for (int i = 0; i < kWindow; ++i)  // (B^T d) B
      for (int j = 0; j < kWindow; ++j) {
        float sum = 0.0f;
        for (int b = 0; b < kWindow; ++b) sum += rows[i][b] * static_cast<float>(winograd::kInputT[j][b]);
        v[(i * kWindow + j) * v_stride + ch] = sum;
      }
  }
}

void winograd_output(const WinogradOutputArgs& o) {
  for (int ch = 0; ch < o.channels; ++ch) {
    float rows[kTile][kWindow];  // A^T M
    for (int y = 0; y < kTile; ++y)
      for (int j = 0; j < kWindow; ++j) {
        float sum = 0.0f;
        for (int i = 0; i < kWindow; ++i)
          sum += static_cast<float>(winograd::kOutputT[y][i]) * o.m[(i * kWindow + j) * o.m_stride + ch];
        rows[y][j] = sum;
      }
    for (int y = 0; y < o.rows; ++y)  // (A^T M) A, then the epilogue
      for (int x = 0; x < o.cols; ++x) {
        float sum = 0.0f;
        for (int j = 0; j < kWindow; ++j) sum += rows[y][j] * static_cast<float>(winograd::kOutputT[x][j]);
        const int64_t at = y * o.row_stride + static_cast<int64_t>(x) * o.channels + ch;
        o.out[at] = ampi::activate(sum + o.bias[ch], o.act) + (o.residual ? o.residual[at] : 0.0f);
      }
  }
}

}  // namespace ampi::reference
