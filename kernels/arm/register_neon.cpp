#include "kernels/arm/neon_kernels.h"
#include "kernels/kernel_table.h"

namespace ampi {

void fill_neon_kernels(KernelTable& t) {
  t.add = neon::add;
  t.activate = neon::activate_inplace;
  t.gemm_mr = neon::kGemmMr;
  t.gemm_nr = neon::kGemmNr;
  t.gemm = neon::gemm_8x8;
  t.depthwise_row = neon::depthwise_row;
  t.gated_output = neon::gated_output;
  t.concat_channels = neon::concat_channels;
  t.channel_sum = neon::channel_sum;
  t.dense = neon::dense;
  t.haar_dwt = neon::haar_dwt;
  t.haar_idwt = neon::haar_idwt;
  t.resize2x_nearest = neon::resize2x_nearest;
  t.resize2x_bilinear = neon::resize2x_bilinear;
}

}  // namespace ampi
