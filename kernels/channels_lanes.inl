// Kernels along the channel axis (gated output, concat, channel sums), written once over
// the lane-generic channel helpers. Each ISA's channels_*.cpp includes this inside its
// own namespace, after its *_channels.h and *_math.h. Not a header: no include guard.

void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out) {
  const Channels channels(c);
  for (int64_t p = 0; p < pixels; ++p) {
    const float* feature = in + p * 2 * c;
    const float* gate = feature + c;
    float* dst = out + p * c;
    channels.each([&](int j, auto lane) {
      lane.store(dst + j, times(activate(lane.load(feature + j), act), sigmoid(lane.load(gate + j))));
    });
  }
}

void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out) {
  for (int64_t p = 0; p < pixels; ++p) {
    float* dst = out + p * (ca + cb);
    copy_floats(a + p * ca, ca, dst);
    copy_floats(b + p * cb, cb, dst + ca);
  }
}

// Channel blocks outermost: each block's running sum stays in a register, and adding in
// pixel order gives the reference's result bit for bit.
void channel_sum(const float* in, int64_t pixels, int c, float* sum) {
  Channels(c).each([&](int j, auto lane) {
    auto acc = lane.splat(0.0f);
    for (int64_t p = 0; p < pixels; ++p) acc = plus(acc, lane.load(in + p * c + j));
    lane.store(sum + j, acc);
  });
}
