// What the processor we run on can execute, read once from the hardware
// (cpuid/xgetbv on x86, getauxval on Linux/ARM).
#pragma once
#include <string>

namespace ampi {

struct CpuFeatures {
  bool avx2 = false;
  bool fma = false;
  bool f16c = false;
  bool avx512f = false;
  bool avx512bw = false;
  bool avx512vl = false;
  bool avx512dq = false;
  bool neon = false;
  bool fp16 = false;  // ARMv8.2 half-precision arithmetic
};

const CpuFeatures& cpu_features();
std::string describe(const CpuFeatures& f);

}  // namespace ampi
