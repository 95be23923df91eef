#include "kernels/kernel_table.h"
#include "kernels/x86/avx512_kernels.h"

namespace ampi {

void fill_avx512_kernels(KernelTable& t) {
  t.add = avx512::add;
  t.activate = avx512::activate_inplace;
}

}  // namespace ampi
