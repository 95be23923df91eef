// Shared by the libFuzzer targets in fuzz/: the rules every target follows, and a
// scratch folder for parsers that only read from a path.
//
// The rules: a parser of outside data may only reject its input with
// std::runtime_error (the one-line "PATH: problem" that reaches the user); any other
// exception escaping, a sanitizer report, or a result that breaks the parser's promises
// (checked with require()) is a finding, and libFuzzer saves the input that caused it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace ampi::fuzz {

// The budget every target runs under (engine/memory_budget.h): small, so that an input
// whose declared size would need more memory is rejected by the parser's own check
// long before libFuzzer's RSS limit (2 GiB by default) would call it an out-of-memory.
constexpr uint64_t kFuzzMemoryBudget = uint64_t(64) << 20;

// Called from each target's LLVMFuzzerInitialize.
void init_target();

// A private folder for this process (removed at exit); path_of(name) is a file in it.
const std::string& scratch_dir();
std::string path_of(const std::string& name);
// Replaces the file `name` in the scratch folder with `size` bytes of `data`; returns
// its path.
std::string write_scratch_file(const std::string& name, const uint8_t* data, size_t size);

// Aborts with `what` on stderr when `condition` is false: libFuzzer then reports the
// input as a crash.
void require(bool condition, const char* what);

}  // namespace ampi::fuzz
