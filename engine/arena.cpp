#include "engine/arena.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

#include "engine/memory_budget.h"

namespace ampi {

static size_t round64(size_t bytes) { return (bytes + 63) / 64 * 64; }

int Arena::request(size_t bytes, int first, int last) {
  if (planned_) throw std::logic_error("arena: request after plan()");
  if (last < first) throw std::invalid_argument("arena: buffer ends before it starts");
  requests_.push_back({round64(bytes), first, last});
  return static_cast<int>(requests_.size()) - 1;
}

size_t Arena::unshared_bytes() const {
  size_t sum = 0;
  for (const Request& r : requests_) sum += r.bytes;
  return sum;
}

size_t Arena::plan(const std::string& owner) {
  if (planned_) return total_;
  std::vector<int> order(requests_.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return requests_[a].bytes > requests_[b].bytes; });
  std::vector<int> placed;
  total_ = 0;
  for (int id : order) {
    Request& r = requests_[id];
    // Placed buffers alive at the same time, by offset: take the first gap that fits.
    std::vector<const Request*> live;
    for (int other : placed) {
      const Request& o = requests_[other];
      if (o.first <= r.last && r.first <= o.last) live.push_back(&o);
    }
    std::sort(live.begin(), live.end(),
              [](const Request* a, const Request* b) { return a->offset < b->offset; });
    size_t offset = 0;
    for (const Request* o : live) {
      if (offset + r.bytes <= o->offset) break;
      offset = std::max(offset, o->offset + o->bytes);
    }
    r.offset = offset;
    total_ = std::max(total_, offset + r.bytes);
    placed.push_back(id);
  }
  check_allocation(total_, owner, "its activations (" + std::to_string(requests_.size()) + " buffers)");
  block_ = aligned_alloc64(total_);
  planned_ = true;
  return total_;
}

void* Arena::data(int id) {
  if (!planned_) throw std::logic_error("arena: data() before plan()");
  return static_cast<char*>(block_.get()) + requests_.at(id).offset;
}

Tensor Arena::tensor(int id, const Shape& shape, Layout layout) {
  const size_t need = static_cast<size_t>(shape_numel(shape)) * sizeof(float);
  if (need > requests_.at(id).bytes)
    throw std::invalid_argument("arena: shape " + shape_str(shape) + " exceeds buffer " +
                                std::to_string(id));
  return Tensor::view(data(id), shape, DType::F32, layout);
}

}  // namespace ampi
