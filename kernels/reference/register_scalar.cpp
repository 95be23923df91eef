#include "kernels/kernel_table.h"
#include "kernels/reference/reference.h"

namespace ampi {

void fill_scalar_kernels(KernelTable& t) {
  t.add = reference::add;
  t.activate = reference::activate;
}

}  // namespace ampi
