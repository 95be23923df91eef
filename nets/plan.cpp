#include "nets/plan.h"

#include <algorithm>

namespace ampi {

int Plan::produce(int h, int w, int c) {
  const int now = static_cast<int>(steps_.size());
  values_.push_back({h, w, c, now, now});
  return static_cast<int>(values_.size()) - 1;
}

void Plan::consume(int v) {
  Value& value = values_.at(v);
  value.last = std::max(value.last, static_cast<int>(steps_.size()));
}

void Plan::allocate(const std::string& owner) {
  for (Value& v : values_)
    v.arena_id = arena_.request(size_t(v.h) * v.w * v.c * sizeof(float), v.first, v.last);
  arena_.plan(owner);
}

void Plan::execute(ThreadPool& pool) {
  for (Step& s : steps_) s(*this, pool);
}

}  // namespace ampi
