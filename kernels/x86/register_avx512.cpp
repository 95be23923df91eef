#include "kernels/kernel_table.h"
#include "kernels/x86/avx512_kernels.h"

namespace ampi {

void fill_avx512_kernels(KernelTable& t) {
  t.add = avx512::add;
  t.activate = avx512::activate_inplace;
  t.gemm_mr = avx512::kGemmMr;
  t.gemm_nr = avx512::kGemmNr;
  t.gemm = avx512::gemm_12x32;
  t.depthwise_row = avx512::depthwise_row;
  t.gated_output = avx512::gated_output;
  t.concat_channels = avx512::concat_channels;
  t.channel_sum = avx512::channel_sum;
  t.dense = avx512::dense;
  t.haar_dwt = avx512::haar_dwt;
  t.haar_idwt = avx512::haar_idwt;
  t.resize2x_nearest = avx512::resize2x_nearest;
  t.resize2x_bilinear = avx512::resize2x_bilinear;
}

}  // namespace ampi
