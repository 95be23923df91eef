// One output row of a bilinear resize of an NHWC map with c channels, written once over
// the lane-generic channel helpers (Channels, plus the lane's load, store and splat, and
// fmadd and minus): each ISA's transformer_rows_*.cpp includes it inside its own
// namespace, after its *_channels.h. Output pixel x blends input columns x0[x] and x1[x]
// of the rows top and bottom by wx[x], then the two rows by wy (kernels/kernel_table.h).
// Not a header: no include guard on purpose.

void bilinear_row_channels(const float* top, const float* bottom, float wy, const int32_t* x0,
                           const int32_t* x1, const float* wx, int out_w, int c, float* out) {
  const Channels channels(c);
  for (int x = 0; x < out_w; ++x) {
    const float *t0 = top + int64_t{x0[x]} * c, *t1 = top + int64_t{x1[x]} * c;
    const float *b0 = bottom + int64_t{x0[x]} * c, *b1 = bottom + int64_t{x1[x]} * c;
    float* o = out + int64_t{x} * c;
    channels.each([&](int j, auto lane) {
      const auto vx = lane.splat(wx[x]), vy = lane.splat(wy);
      const auto t0v = lane.load(t0 + j), b0v = lane.load(b0 + j);
      const auto t = fmadd(vx, minus(lane.load(t1 + j), t0v), t0v);
      const auto b = fmadd(vx, minus(lane.load(b1 + j), b0v), b0v);
      lane.store(o + j, fmadd(vy, minus(b, t), t));
    });
  }
}
