// Depthwise convolution row (DepthwiseRowArgs, kernels/kernel_table.h), written once for
// AVX2, AVX-512 and NEON over the lane-generic channel helpers. Each ISA's
// conv_depthwise_*.cpp includes this inside its own namespace, after its *_channels.h
// (Channels, lane accessors, plus, fmadd), *_math.h (activate) and conv_epilogue.h
// (with_fixed_activation). Not a header: no include guard.
//
// Why it is shaped this way (bench/RESULTS-kernels.md has the numbers):
// - The whole row goes in blocks of kBlock output pixels, one channel vector at a time.
//   A block's accumulators, the current kernel row's weights and one input column fit in
//   the register file, and kBlock independent FMA chains cover the FMA latency. The
//   interior blocks run channel vector by channel vector along the row, so neighbouring
//   blocks find the columns they share (and the weights) in L1; the few border blocks
//   go pixel block by pixel block.
// - The kernel height is a compile-time constant too (square kernels), and the row's
//   arguments are copied to locals: the vector stores may alias anything, so through a
//   reference every store made the compiler reload the output and row pointers.
// - With dilation 1 and the common kernel widths (3, 5) and strides (1, 2) fixed at
//   compile time, each input column of a block is loaded once and feeds every
//   (pixel, tap) pair that reads it: 10 loads for 24 FMAs per kernel row (3x3, stride 1).
// - Where the whole kernel fits in registers beside a block (kDepthwiseWeightRegisters:
//   NEON's 32 registers hold a 3x3 kernel's 9), the interior keeps it there across a
//   channel vector's blocks and steps one pointer per kernel row from block to block;
//   x86 reloads the weights per block (its 16 registers on AVX2; AVX-512 was not tried).
// - Blocks whose taps all fall inside the row load without bounds checks; the few
//   border blocks (and the last, shorter one) load a zero for a column outside the row
//   and store only their valid pixels, so the borders run the same vector code instead
//   of a per-pixel, per-tap scalar path.
// - The activation is a compile-time constant for the kinds the networks use, so the
//   epilogue (bias is the accumulators' start value, activation, residual add, store)
//   runs on the registers, in the same pass, without spilling the tile.
// - The accumulators live in registers only if accumulate() and block() inline into the
//   row loop; they are forced to, since GCC's size limits otherwise keep accumulate()
//   out of line and pass the tile through memory (up to 3.8x slower).
// - Interior blocks prefetch the input row the next output row reads first, so the next
//   call finds it in cache.
// - When the output is larger than the last-level cache (d.stream_out), interior
//   blocks store it with non-temporal stores: a plain store first reads the line it
//   writes, which costs as much memory traffic as reading the input. 3x3 s1 over
//   512x384x64 (50 MB in, 50 MB out): 4.85 -> 4.22 ms on AVX-512.

namespace depthwise {
constexpr int kBlock = 8;  // output pixels per block

// A square K x K kernel, dilation 1 and stride S across the row, known at compile time.
template <int K, int S>
struct FixedGeometry {};
// Any kernel width, stride and dilation, read from the arguments.
struct AnyGeometry {};

// The epilogue's activation, its kind fixed at compile time unless kKind is
// kActivationAtRunTime (conv_epilogue.h).
template <int kKind>
struct RowActivation {
  ActivationSpec spec;
  template <class V>
  V operator()(V v) const {
    return activate_of<kKind>(v, spec, [](V x, ActivationSpec s) { return activate(x, s); });
  }
};

// Column ix of input row `row`, channels [ch, ch + lane width); zero outside the row
// when kChecked.
template <bool kChecked, class Lane>
[[gnu::always_inline]] inline auto column(const DepthwiseRowArgs& d, const float* row, int ix, int ch,
                                          Lane lane) {
  if constexpr (kChecked)
    if (ix < 0 || ix >= d.in_w) return lane.splat(0.0f);
  return lane.load(row + static_cast<int64_t>(ix) * d.channels + ch);
}

// acc[i] += the taps of output pixel i (input columns from ix0 + i*S), shared columns.
template <bool kChecked, int K, int S, class Lane, class V>
[[gnu::always_inline]] inline void accumulate(const DepthwiseRowArgs& d, FixedGeometry<K, S>, int ix0, int ch,
                                              Lane lane, V (&acc)[kBlock]) {
  constexpr int kColumns = (kBlock - 1) * S + K;
  const int64_t c = d.channels;
#pragma GCC unroll 8
  for (int ky = 0; ky < K; ++ky) {
    const float* row = d.in_rows[ky];
    if (!row) continue;
    V w[K];
    for (int kx = 0; kx < K; ++kx) w[kx] = lane.load(d.weights + (static_cast<int64_t>(ky) * K + kx) * c + ch);
    // kStepColumns (each ISA's *_channels.h): unchecked columns read through a pointer
    // stepping one pixel at a time instead of each indexed from ix0.
    const float* next = row + static_cast<int64_t>(ix0) * c + ch;
#pragma GCC unroll 32
    for (int j = 0; j < kColumns; ++j, next += c) {
      V x = (kStepColumns && !kChecked) ? lane.load(next) : column<kChecked>(d, row, ix0 + j, ch, lane);
      keep_in_register(x);  // one load per column, not one per tap (avx512_channels.h)
#pragma GCC unroll 8
      for (int kx = 0; kx < K; ++kx) {
        const int offset = j - kx;  // = i * S for the pixel i reading column j at tap kx
        if (offset >= 0 && offset % S == 0 && offset / S < kBlock)
          acc[offset / S] = fmadd(w[kx], x, acc[offset / S]);
      }
    }
  }
}

template <bool kChecked, class Lane, class V>
[[gnu::always_inline]] inline void accumulate(const DepthwiseRowArgs& d, AnyGeometry, int ix0, int ch, Lane lane,
                                              V (&acc)[kBlock]) {
  const int64_t c = d.channels;
  for (int ky = 0; ky < d.kernel_h; ++ky) {
    const float* row = d.in_rows[ky];
    if (!row) continue;
    for (int kx = 0; kx < d.kernel_w; ++kx) {
      const V w = lane.load(d.weights + (static_cast<int64_t>(ky) * d.kernel_w + kx) * c + ch);
      const int ix = ix0 + kx * d.dilation_w;
      for (int i = 0; i < kBlock; ++i)
        acc[i] = fmadd(w, column<kChecked>(d, row, ix + i * d.stride_w, ch, lane), acc[i]);
    }
  }
}

// Output pixels [ox, ox + count) of the row, channels [ch, ch + lane width): the
// convolution, then act(acc) (+ residual), stored (streamed when kStream).
// count == kBlock unless kChecked.
template <bool kChecked, bool kStream, class Geometry, class Act, class Lane>
[[gnu::always_inline]] inline void block(const DepthwiseRowArgs& d, Geometry g, Act act, int ox, int count, int ch,
                                         Lane lane) {
  using V = decltype(lane.load(d.bias));
  const V bias = lane.load(d.bias + ch);
  V acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  accumulate<kChecked>(d, g, ox * d.stride_w - d.pad_left, ch, lane, acc);
  const int64_t c = d.channels, first = static_cast<int64_t>(ox) * c + ch;
  for (int i = 0; i < kBlock; ++i) {
    if (kChecked && i >= count) break;
    V v = act(acc[i]);
    if (d.residual) v = plus(v, lane.load(d.residual + first + i * c));
    if constexpr (kStream)
      lane.stream(d.out + first + i * c, v);
    else
      lane.store(d.out + first + i * c, v);
  }
}

// The interior blocks [first, end) of one channel vector with the whole K x K kernel
// held in registers (kDepthwiseWeightRegisters, each ISA's *_channels.h), loaded once
// instead of once per block, and one column pointer per kernel row stepping from block
// to block instead of recomputed from the row, the block and the channel each time.
// The FMAs run in the same order as accumulate()'s, so the sums are the same bits.
template <bool kStream, int K, int S, class Act, class Lane>
[[gnu::always_inline]] inline void interior_with_weights_held(const DepthwiseRowArgs& d, FixedGeometry<K, S>,
                                                              Act act, int first, int end, int ch, Lane lane) {
  using V = decltype(lane.load(d.bias));
  constexpr int kColumns = (kBlock - 1) * S + K;
  const int64_t c = d.channels;
  V w[K][K];
  for (int ky = 0; ky < K; ++ky)
    for (int kx = 0; kx < K; ++kx) w[ky][kx] = lane.load(d.weights + (static_cast<int64_t>(ky) * K + kx) * c + ch);
  const float* bias = d.bias + ch;
  const int64_t first_column = static_cast<int64_t>(first * S - d.pad_left) * c + ch;
  const float* rows[K];  // block p's first column in each kernel row; null: a padding row
  for (int ky = 0; ky < K; ++ky) rows[ky] = d.in_rows[ky] ? d.in_rows[ky] + first_column : nullptr;
  const int64_t block_step = static_cast<int64_t>(kBlock) * S * c;
  // Column j of a block at rows[ky] + column_offset[j]: one load with a register offset,
  // no address arithmetic per column.
  int64_t column_offset[kColumns];
  for (int j = 0; j < kColumns; ++j) column_offset[j] = j * c;
  // The output and residual through locals: the stores may alias d.
  float* out = d.out + static_cast<int64_t>(first) * c + ch;
  const float* residual = d.residual ? d.residual + static_cast<int64_t>(first) * c + ch : nullptr;
  for (int p = first; p < end; p += kBlock) {
    V acc[kBlock];
    // Each accumulator from its own load of the bias (load_again, each ISA's *_channels.h).
    for (int i = 0; i < kBlock; ++i) acc[i] = lane.load_again(bias);
#pragma GCC unroll 8
    for (int ky = 0; ky < K; ++ky) {
      if (!rows[ky]) continue;
      const float* row = rows[ky];
      rows[ky] += block_step;
#pragma GCC unroll 32
      for (int j = 0; j < kColumns; ++j) {
        const V x = lane.load(row + column_offset[j]);
#pragma GCC unroll 8
        for (int kx = 0; kx < K; ++kx) {
          const int offset = j - kx;  // as in accumulate()
          if (offset >= 0 && offset % S == 0 && offset / S < kBlock)
            acc[offset / S] = fmadd(w[ky][kx], x, acc[offset / S]);
        }
      }
    }
    for (int i = 0; i < kBlock; ++i) {
      V v = act(acc[i]);
      // Rounded before the residual is added, as in block() (opaque, each ISA's *_channels.h).
      if (residual) v = plus(opaque(v), lane.load(residual + i * c));
      if constexpr (kStream)
        lane.stream(out + i * c, v);
      else
        lane.store(out + i * c, v);
    }
    out += kBlock * c;
    if (residual) residual += kBlock * c;
  }
}

template <class Geometry>
constexpr bool weights_fit_in_registers(Geometry) { return false; }
template <int K, int S>
constexpr bool weights_fit_in_registers(FixedGeometry<K, S>) { return K * K <= kDepthwiseWeightRegisters; }

// The input row the next output row reads first, at the columns of block ox: one
// prefetch per 64-byte line.
inline void prefetch_next_row(const DepthwiseRowArgs& d, int ox) {
  if (!d.prefetch_row) return;
  const int64_t c = d.channels;
  const int64_t first = static_cast<int64_t>(ox * d.stride_w - d.pad_left) * c;
  const int64_t last = std::min<int64_t>(first + static_cast<int64_t>(kBlock) * d.stride_w * c, int64_t{d.in_w} * c);
  const float* begin = d.prefetch_row + first;
  const float* end = d.prefetch_row + last;
  for (const float* p = begin; p < end; p += 16) __builtin_prefetch(p);
}

// Interior blocks stream their stores when kStream; the few border blocks of a row keep
// plain stores.
template <bool kStream, class Geometry, class Act>
void blocks(const DepthwiseRowArgs& args, Act act) {
  // Local copies whose addresses never leave this function (see the top).
  const float* in_rows[kMaxDepthwiseKernelH];
  std::copy(args.in_rows, args.in_rows + args.kernel_h, in_rows);
  DepthwiseRowArgs d = args;
  d.in_rows = in_rows;
  const Channels channels(d.channels);
  const Geometry g;
  const auto border_block = [&](int ox) {
    const int count = std::min(kBlock, d.out_w - ox);
    channels.each([&](int ch, auto lane) { block<true, false>(d, g, act, ox, count, ch, lane); });
  };
  // Whole blocks with every tap inside the row: [interior_first, interior_end).
  const int interior_first = (d.interior_begin + kBlock - 1) / kBlock * kBlock;
  int interior_end = interior_first;
  while (interior_end + kBlock <= std::min(d.interior_end, d.out_w)) interior_end += kBlock;
  int ox = 0;
  for (; ox < std::min(interior_first, d.out_w); ox += kBlock) border_block(ox);
  // The interior channel vector by channel vector (see the top).
  for (int p = interior_first; p < interior_end; p += kBlock) prefetch_next_row(d, p);
  channels.each([&](int ch, auto lane) {
    if constexpr (!weights_fit_in_registers(Geometry{}))
      for (int p = interior_first; p < interior_end; p += kBlock) block<false, kStream>(d, g, act, p, kBlock, ch, lane);
    else
      interior_with_weights_held<kStream>(d, g, act, interior_first, interior_end, ch, lane);
  });
  for (ox = std::max(ox, interior_end); ox < d.out_w; ox += kBlock) border_block(ox);
}

// The store kind is a template parameter so that the interior loop has no branch on it.
template <class Geometry, class Act>
void row(const DepthwiseRowArgs& d, Act act) {
  if (!d.stream_out) return blocks<false, Geometry>(d, act);
  blocks<true, Geometry>(d, act);
  finish_streaming();
}

template <class Geometry>
void row_for_activation(const DepthwiseRowArgs& d) {
  with_fixed_activation(kDepthwiseActivations, d.act.kind,
                        [&](auto kind) { row<Geometry>(d, RowActivation<decltype(kind)::value>{d.act}); });
}

}  // namespace depthwise

void depthwise_row(const DepthwiseRowArgs& d) {
  using namespace depthwise;
  if (d.dilation_w == 1 && d.kernel_h == d.kernel_w) {
    if (d.kernel_w == 3 && d.stride_w == 1) return row_for_activation<FixedGeometry<3, 1>>(d);
    if (d.kernel_w == 3 && d.stride_w == 2) return row_for_activation<FixedGeometry<3, 2>>(d);
    if (d.kernel_w == 5 && d.stride_w == 1) return row_for_activation<FixedGeometry<5, 1>>(d);
    if (d.kernel_w == 5 && d.stride_w == 2) return row_for_activation<FixedGeometry<5, 2>>(d);
  }
  row_for_activation<AnyGeometry>(d);
}
