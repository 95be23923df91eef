#include "kernels/arm/neon_kernels.h"
#include "kernels/kernel_table.h"

namespace ampi {

void fill_neon_kernels(KernelTable& t) {
  t.add = neon::add;
  t.activate = neon::activate_inplace;
}

}  // namespace ampi
