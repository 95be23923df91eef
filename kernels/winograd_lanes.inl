// Winograd F(4x4, 3x3) window and output transforms (kernels/winograd.h), written once
// for AVX2, AVX-512 and NEON over the lane-generic channel helpers. Each ISA's
// winograd_*.cpp includes this inside its own namespace, after its *_channels.h
// (Channels, lane accessors, plus, minus, fmadd), *_math.h (activate) and
// kernels/conv_epilogue.h (the activation fixed at compile time). Not a header: no
// include guard.
//
// Channels are independent, so each channel vector goes through the 6x6 window as the
// reference does, one axis then the other, with the matrices' structure written out:
// each 1-D window transform takes 6 adds and 10 multiply-adds where the dense B^T would
// take 36, the output one 6 adds and 6 multiply-adds for 24. The half-transformed 6x6
// block (36 vectors) lives on the stack between the two passes: more than the register
// file, and in L1 either way.

namespace winograd_lanes {

// r = B^T d on six values of one column or row (kernels/winograd.h, kInputT).
template <class Lane, class V>
inline void input_axis(Lane lane, const V d[6], V r[6]) {
  const V e = minus(d[3], d[1]), f = minus(d[4], d[2]);
  r[0] = fmadd(lane.splat(1.5f), e, fmadd(lane.splat(-2.0f), d[2], plus(d[0], d[4])));
  r[1] = fmadd(lane.splat(0.5f), d[2], fmadd(lane.splat(2.5f), d[3], minus(d[4], d[1])));
  r[2] = fmadd(lane.splat(-2.5f), d[2], fmadd(lane.splat(0.5f), d[3], plus(d[4], d[1])));
  r[3] = fmadd(lane.splat(2.0f), e, f);
  r[4] = fmadd(lane.splat(-0.5f), e, f);
  r[5] = fmadd(lane.splat(1.5f), f, fmadd(lane.splat(-2.0f), d[3], plus(d[1], d[5])));
}

// y = A^T m on six values (kOutputT).
template <class Lane, class V>
inline void output_axis(Lane lane, const V m[6], V y[4]) {
  const V sum = plus(m[1], m[2]), difference = minus(m[1], m[2]);
  y[0] = plus(plus(m[0], sum), plus(m[3], m[4]));
  y[1] = fmadd(lane.splat(0.5f), m[3], fmadd(lane.splat(-2.0f), m[4], difference));
  y[2] = fmadd(lane.splat(0.25f), m[3], fmadd(lane.splat(4.0f), m[4], sum));
  y[3] = fmadd(lane.splat(0.125f), m[3], fmadd(lane.splat(-8.0f), m[4], plus(difference, m[5])));
}

}  // namespace winograd_lanes

void winograd_input(const float* in, int64_t row_stride, int c, float* v, int64_t v_stride) {
  Channels(c).each([&](int j, auto lane) {
    using V = decltype(lane.load(in));
    V rows[6][6];  // B^T d: row i, window column b
    for (int b = 0; b < 6; ++b) {
      V column[6], out[6];
      for (int a = 0; a < 6; ++a) column[a] = lane.load(in + a * row_stride + static_cast<int64_t>(b) * c + j);
      winograd_lanes::input_axis(lane, column, out);
      for (int i = 0; i < 6; ++i) rows[i][b] = out[i];
    }
    for (int i = 0; i < 6; ++i) {
      V out[6];
      winograd_lanes::input_axis(lane, rows[i], out);
      for (int k = 0; k < 6; ++k) lane.store(v + (i * 6 + k) * v_stride + j, out[k]);
    }
  });
}

namespace winograd_lanes {

template <int kAct>
void output(const WinogradOutputArgs& a) {
  Channels(a.channels).each([&](int j, auto lane) {
    using V = decltype(lane.load(a.m));
    V rows[4][6];  // A^T M: output row y, position column k
    for (int k = 0; k < 6; ++k) {
      V column[6], out[4];
      for (int i = 0; i < 6; ++i) column[i] = lane.load(a.m + (i * 6 + k) * a.m_stride + j);
      winograd_lanes::output_axis(lane, column, out);
      for (int y = 0; y < 4; ++y) rows[y][k] = out[y];
    }
    const V bias = lane.load(a.bias + j);
    for (int y = 0; y < a.rows; ++y) {
      V out[4];
      winograd_lanes::output_axis(lane, rows[y], out);
      for (int x = 0; x < a.cols; ++x) {
        const int64_t at = y * a.row_stride + static_cast<int64_t>(x) * a.channels + j;
        V value = activate_of<kAct>(plus(out[x], bias), a.act, [](V v, ActivationSpec s) { return activate(v, s); });
        if (a.residual) value = plus(value, lane.load(a.residual + at));
        lane.store(a.out + at, value);
      }
    }
  });
}

}  // namespace winograd_lanes

void winograd_output(const WinogradOutputArgs& o) {
  const WinogradOutputArgs a = o;  // locals: the vector stores may alias anything
  with_fixed_activation(kGemmActivations, a.act.kind, [&](auto act) { winograd_lanes::output<decltype(act)::value>(a); });
}
