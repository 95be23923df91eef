// The executor every network runs on: a network unrolled for one input size into a list
// of steps, each reading and writing activation values that live in one arena
// (engine/arena.h).
//
// A builder declares, step by step, the value the next step writes (produce) and the
// values it reads (consume), then pushes the step. A value's lifetime runs from the step
// that writes it to the last step that reads it; allocate() lets values whose lifetimes
// do not overlap share bytes, and never places a step's output over one of its inputs.
//
//   Plan p;
//   const int y = p.produce(h, w, c);          // written by the next step
//   p.consume(x);                              // read by the next step
//   p.push([=](Plan& pl, ThreadPool& pool) { conv.run(pl.data(x), h, w, pl.data(y), nullptr, pool); });
//   p.allocate("depth network (lite) at 1024x768");
//   p.execute(pool);
//
// Steps capture what they need from outside the arena (the caller's input, an output
// buffer) themselves; the plan only owns the intermediate values.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "engine/arena.h"
#include "engine/thread_pool.h"

namespace ampi {

class Plan {
 public:
  // An activation map of h x w pixels and c channels (floats), NHWC.
  struct Value {
    int h, w, c;
    int first, last;  // the steps that write it and that read it last
    int arena_id = -1;
  };
  using Step = std::function<void(Plan&, ThreadPool&)>;

  // Declares the value the next pushed step writes; returns its id.
  int produce(int h, int w, int c);
  // Marks value `v` as read by the next pushed step.
  void consume(int v);
  void push(Step step) { steps_.push_back(std::move(step)); }
  const Value& value(int v) const { return values_.at(v); }

  // Places every value and allocates the arena; `owner` names the network in a
  // memory-budget error (engine/memory_budget.h).
  void allocate(const std::string& owner);
  float* data(int v) { return static_cast<float*>(arena_.data(values_[v].arena_id)); }
  void execute(ThreadPool& pool);
  size_t arena_bytes() const { return arena_.total_bytes(); }

 private:
  std::vector<Value> values_;
  std::vector<Step> steps_;
  Arena arena_;
};

}  // namespace ampi
