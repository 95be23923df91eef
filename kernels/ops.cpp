#include "kernels/ops.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace ampi {

// Element-wise work is split in chunks of this many floats: large enough that the
// scheduling cost vanishes, small enough to keep both threads busy on small maps.
static constexpr int64_t kElementGrain = 16384;

void add(const float* a, const float* b, int64_t n, float* out, ActivationSpec act,
         ThreadPool& pool, const KernelTable& k) {
  pool.parallel_for(n, kElementGrain, [&](int64_t begin, int64_t end) {
    k.add(a + begin, b + begin, end - begin, act, out + begin);
  });
}

void activate(float* x, int64_t n, ActivationSpec act, ThreadPool& pool, const KernelTable& k) {
  pool.parallel_for(n, kElementGrain, [&](int64_t begin, int64_t end) {
    k.activate(x + begin, end - begin, act);
  });
}

// Units (rows or pixels) per chunk for ops given the floats each unit reads and writes:
// about kElementGrain floats of traffic per chunk.
static int64_t chunk_grain(int64_t floats_per_unit) {
  return std::max<int64_t>(1, kElementGrain / std::max<int64_t>(1, floats_per_unit));
}

static void require(bool ok, const char* op, const std::string& problem) {
  if (!ok) throw std::runtime_error(std::string(op) + ": " + problem);
}

static std::string size_str(int h, int w, int c) {
  return std::to_string(h) + "x" + std::to_string(w) + "x" + std::to_string(c);
}

static void require_map(const char* op, int h, int w, int c) {
  require(h > 0 && w > 0 && c > 0, op, "empty or negative size " + size_str(h, w, c));
}

void gated_output(const float* in, int64_t pixels, int c, ActivationSpec feature_act, float* out,
                  ThreadPool& pool, const KernelTable& k) {
  require(c > 0, "gated_output", "channel count must be positive, got " + std::to_string(c));
  pool.parallel_for(pixels, chunk_grain(3 * c), [&](int64_t begin, int64_t end) {
    k.gated_output(in + begin * 2 * c, end - begin, c, feature_act, out + begin * c);
  });
}

void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out,
                     ThreadPool& pool, const KernelTable& k) {
  require(ca > 0 && cb > 0, "concat_channels",
          "channel counts must be positive, got " + std::to_string(ca) + " and " + std::to_string(cb));
  pool.parallel_for(pixels, chunk_grain(2 * (ca + cb)), [&](int64_t begin, int64_t end) {
    k.concat_channels(a + begin * ca, ca, b + begin * cb, cb, end - begin, out + begin * (ca + cb));
  });
}

SqueezeExcite::SqueezeExcite(int channels, int reduced, const float* w1, const float* b1,
                             const float* w2, const float* b2, const KernelTable& k)
    : channels_(channels), reduced_(reduced), k_(&k) {
  require(channels > 0 && reduced > 0, "SqueezeExcite",
          "channels and reduced must be positive, got " + std::to_string(channels) + " and " +
              std::to_string(reduced));
  require(w1 && w2, "SqueezeExcite", "missing fc weights");
  const size_t weights = static_cast<size_t>(channels) * reduced;
  w1_.assign(w1, w1 + weights);
  w2_.assign(w2, w2 + weights);
  if (b1) b1_.assign(b1, b1 + reduced);
  if (b2) b2_.assign(b2, b2 + channels);
}

void SqueezeExcite::run(const float* in, int h, int w, float* out, ThreadPool& pool) const {
  const std::vector<float> scale = gate(in, h, w, pool);
  const int c = channels_;
  pool.parallel_for(static_cast<int64_t>(h) * w, chunk_grain(2 * c), [&](int64_t begin, int64_t end) {
    k_->channel_scale(in + begin * c, end - begin, c, scale.data(), out + begin * c);
  });
}

std::vector<float> SqueezeExcite::gate(const float* in, int h, int w, ThreadPool& pool) const {
  require(k_ != nullptr, "SqueezeExcite", "run on a default-constructed instance");
  require_map("SqueezeExcite", h, w, channels_);
  const int c = channels_;
  const int64_t row = static_cast<int64_t>(w) * c;
  // One partial sum per row, added up in row order below: the same bits for any split.
  std::vector<float> row_sums(static_cast<size_t>(h) * c);
  pool.parallel_for(h, chunk_grain(row), [&](int64_t begin, int64_t end) {
    for (int64_t y = begin; y < end; ++y) k_->channel_sum(in + y * row, w, c, &row_sums[y * c]);
  });
  std::vector<float> mean(c, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int j = 0; j < c; ++j) mean[j] += row_sums[static_cast<size_t>(y) * c + j];
  const float inv_pixels = 1.0f / (static_cast<float>(h) * static_cast<float>(w));
  for (float& m : mean) m *= inv_pixels;

  std::vector<float> hidden(reduced_), gate(c);
  k_->dense(w1_.data(), b1_.empty() ? nullptr : b1_.data(), reduced_, c, mean.data(),
            {Activation::ReLU}, hidden.data());
  k_->dense(w2_.data(), b2_.empty() ? nullptr : b2_.data(), c, reduced_, hidden.data(),
            {Activation::HardSigmoid}, gate.data());
  return gate;
}

void haar_dwt(const float* in, int h, int w, int c, float* out, ThreadPool& pool,
              const KernelTable& k) {
  require_map("haar_dwt", h, w, c);
  require(h % 2 == 0 && w % 2 == 0, "haar_dwt", "height and width must be even, got " + size_str(h, w, c));
  pool.parallel_for(h / 2, chunk_grain(4 * static_cast<int64_t>(w) * c), [&](int64_t begin, int64_t end) {
    k.haar_dwt(in, h, w, c, static_cast<int>(begin), static_cast<int>(end), out);
  });
}

void haar_idwt(const float* in, int h, int w, int c, float* out, ThreadPool& pool,
               const KernelTable& k) {
  require_map("haar_idwt", h, w, c);
  pool.parallel_for(h, chunk_grain(8 * static_cast<int64_t>(w) * c), [&](int64_t begin, int64_t end) {
    k.haar_idwt(in, h, w, c, static_cast<int>(begin), static_cast<int>(end), out);
  });
}

void resize2x_nearest(const float* in, int h, int w, int c, float* out, ThreadPool& pool,
                      const KernelTable& k) {
  require_map("resize2x_nearest", h, w, c);
  pool.parallel_for(h, chunk_grain(5 * static_cast<int64_t>(w) * c), [&](int64_t begin, int64_t end) {
    k.resize2x_nearest(in, h, w, c, static_cast<int>(begin), static_cast<int>(end), out);
  });
}

void resize2x_bilinear(const float* in, int h, int w, int c, float* out, ThreadPool& pool,
                       const KernelTable& k) {
  require_map("resize2x_bilinear", h, w, c);
  pool.parallel_for(h, chunk_grain(5 * static_cast<int64_t>(w) * c), [&](int64_t begin, int64_t end) {
    k.resize2x_bilinear(in, h, w, c, static_cast<int>(begin), static_cast<int>(end), out);
  });
}

}  // namespace ampi
