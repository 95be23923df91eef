#include "kernels/kernel_table.h"
#include "kernels/x86/avx2_kernels.h"

namespace ampi {

void fill_avx2_kernels(KernelTable& t) {
  t.add = avx2::add;
  t.activate = avx2::activate_inplace;
  t.gemm_mr = avx2::kGemmMr;
  t.gemm_nr = avx2::kGemmNr;
  t.gemm = avx2::gemm_6x16;
  t.depthwise_row = avx2::depthwise_row;
  t.gated_output = avx2::gated_output;
  t.concat_channels = avx2::concat_channels;
  t.channel_sum = avx2::channel_sum;
  t.dense = avx2::dense;
  t.haar_dwt = avx2::haar_dwt;
  t.haar_idwt = avx2::haar_idwt;
  t.resize2x_nearest = avx2::resize2x_nearest;
  t.resize2x_bilinear = avx2::resize2x_bilinear;
}

}  // namespace ampi
