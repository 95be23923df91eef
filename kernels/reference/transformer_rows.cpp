// Scalar reference transformer row kernels (contracts in kernels/kernel_list.def).
#include <cmath>

#include "kernels/reference/reference.h"

namespace ampi::reference {

void layer_norm_row(const float* in, int c, const float* gamma, const float* beta, float eps, float* out) {
  // Two passes (mean, then the squared deviations) rather than E[x^2] - E[x]^2, which
  // cancels badly when the mean is large against the spread.
  float sum = 0.0f;
  for (int i = 0; i < c; ++i) sum += in[i];
  const float mean = sum / static_cast<float>(c);
  float squares = 0.0f;
  for (int i = 0; i < c; ++i) squares += (in[i] - mean) * (in[i] - mean);
  const float inv_std = 1.0f / std::sqrt(squares / static_cast<float>(c) + eps);
  for (int i = 0; i < c; ++i) out[i] = (in[i] - mean) * inv_std * gamma[i] + beta[i];
}

float softmax_block_row(float* scores, int n, float scale, float* running_max, float* running_sum) {
  float block_max = -INFINITY;
  for (int j = 0; j < n; ++j) block_max = std::max(block_max, scores[j] * scale);
  const float old_max = *running_max;
  const float new_max = std::max(old_max, block_max);
  // Every score of an empty or all -inf block keeps new_max at -inf: subtracting it would
  // make NaN, so such a block contributes nothing.
  const float shift = new_max == -INFINITY ? 0.0f : new_max;
  float sum = 0.0f;
  for (int j = 0; j < n; ++j) {
    scores[j] = exp2_polynomial_nonpositive(scores[j] * scale - shift);
    sum += scores[j];
  }
  const float factor = old_max == -INFINITY ? 0.0f : exp2_polynomial_nonpositive(old_max - new_max);
  *running_sum = *running_sum * factor + sum;
  *running_max = new_max;
  return factor;
}

void bilinear_row(const float* top, const float* bottom, float wy, const int32_t* x0, const int32_t* x1,
                  const float* wx, int out_w, int c, float* out) {
  for (int x = 0; x < out_w; ++x) {
    const float* t0 = top + static_cast<int64_t>(x0[x]) * c;
    const float* t1 = top + static_cast<int64_t>(x1[x]) * c;
    const float* b0 = bottom + static_cast<int64_t>(x0[x]) * c;
    const float* b1 = bottom + static_cast<int64_t>(x1[x]) * c;
    float* o = out + static_cast<int64_t>(x) * c;
    for (int ch = 0; ch < c; ++ch) {
      const float t = t0[ch] + wx[x] * (t1[ch] - t0[ch]);
      const float b = b0[ch] + wx[x] * (b1[ch] - b0[ch]);
      o[ch] = t + wy * (b - t);
    }
  }
}

}  // namespace ampi::reference
