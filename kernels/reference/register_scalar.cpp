#include "kernels/kernel_table.h"
#include "kernels/reference/reference.h"

namespace ampi {

void fill_scalar_kernels(KernelTable& t) {
  t.add = reference::add;
  t.activate = reference::activate;
  t.gemm_mr = reference::kGemmMr;
  t.gemm_nr = reference::kGemmNr;
  t.gemm = reference::gemm;
  t.depthwise_row = reference::depthwise_row;
  t.gated_output = reference::gated_output;
  t.concat_channels = reference::concat_channels;
  t.channel_sum = reference::channel_sum;
  t.channel_scale = reference::channel_scale;
  t.dense = reference::dense;
  t.haar_dwt = reference::haar_dwt;
  t.haar_idwt = reference::haar_idwt;
  t.resize2x_nearest = reference::resize2x_nearest;
  t.resize2x_bilinear = reference::resize2x_bilinear;
}

}  // namespace ampi
