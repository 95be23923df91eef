// One 64-byte-aligned block that holds every intermediate tensor of a network, with
// buffers whose lifetimes do not overlap sharing the same bytes.
//
// A network declares each activation buffer with the first and last step (layer index)
// that touches it, then calls plan(): buffers are placed largest first at the lowest
// offset that does not collide with an already placed buffer alive at the same time
// (the greedy-by-size strategy of TFLite's arena planner). The result is usually close to
// the peak of simultaneously live bytes rather than the sum of all buffers.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "engine/tensor.h"

namespace ampi {

class Arena {
 public:
  // Declares a buffer of `bytes` used from step `first` to step `last` inclusive; returns
  // its id. Only before plan().
  int request(size_t bytes, int first, int last);
  // Assigns offsets and allocates the block. Returns the block size in bytes. A block
  // over the memory budget (engine/memory_budget.h) throws MemoryBudgetError naming
  // `owner` (e.g. "depth network (lite) at 1024x768") before anything is allocated.
  size_t plan(const std::string& owner = "network");

  size_t total_bytes() const { return total_; }
  // Sum of all requests: what the network would need without reuse.
  size_t unshared_bytes() const;
  size_t offset(int id) const { return requests_.at(id).offset; }
  void* data(int id);
  Tensor tensor(int id, const Shape& shape, Layout layout = Layout::NHWC);

 private:
  struct Request {
    size_t bytes;
    int first, last;
    size_t offset = 0;
  };
  std::vector<Request> requests_;
  size_t total_ = 0;
  bool planned_ = false;
  AlignedBuffer block_;
};

}  // namespace ampi
