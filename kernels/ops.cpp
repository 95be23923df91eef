#include "kernels/ops.h"

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

}  // namespace ampi
