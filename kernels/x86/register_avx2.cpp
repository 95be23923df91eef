#include "kernels/kernel_table.h"
#include "kernels/x86/avx2_kernels.h"

namespace ampi {

void fill_avx2_kernels(KernelTable& t) {
  t.add = avx2::add;
  t.activate = avx2::activate_inplace;
}

}  // namespace ampi
