// The 2x resampling kernels (Haar DWT and inverse, nearest and bilinear upscaling),
// written once over the lane-generic channel helpers (Vec, Channels, ...). Each ISA's
// resample_*.cpp includes this inside its own namespace, after its *_channels.h, so the
// same bodies compile to AVX2 or NEON code. Not a header: no include guard on purpose.

void haar_dwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  const int64_t pixel_pair = 2 * c;
  for (int y = row_begin; y < row_end; ++y) {
    const float* top = in + static_cast<int64_t>(2 * y) * w * c;
    const float* bottom = top + static_cast<int64_t>(w) * c;
    float* dst = out + static_cast<int64_t>(y) * (w / 2) * 4 * c;
    for (int x = 0; x < w / 2; ++x, top += pixel_pair, bottom += pixel_pair, dst += 4 * c)
      channels.each([&](int j, auto lane) {
        const auto half = lane.splat(0.5f);
        const auto x00 = lane.load(top + j), x01 = lane.load(top + c + j);
        const auto x10 = lane.load(bottom + j), x11 = lane.load(bottom + c + j);
        const auto top_sum = plus(x00, x01), top_diff = minus(x00, x01);
        const auto bottom_sum = plus(x10, x11), bottom_diff = minus(x10, x11);
        lane.store(dst + j, times(plus(top_sum, bottom_sum), half));
        lane.store(dst + c + j, times(plus(top_diff, bottom_diff), half));
        lane.store(dst + 2 * c + j, times(minus(top_sum, bottom_sum), half));
        lane.store(dst + 3 * c + j, times(minus(top_diff, bottom_diff), half));
      });
  }
}

void haar_idwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  for (int y = row_begin; y < row_end; ++y) {
    const float* src = in + static_cast<int64_t>(y) * w * 4 * c;
    float* top = out + static_cast<int64_t>(2 * y) * 2 * w * c;
    float* bottom = top + static_cast<int64_t>(2 * w) * c;
    for (int x = 0; x < w; ++x, src += 4 * c, top += 2 * c, bottom += 2 * c)
      channels.each([&](int j, auto lane) {
        const auto half = lane.splat(0.5f);
        const auto ll = lane.load(src + j), lh = lane.load(src + c + j);
        const auto hl = lane.load(src + 2 * c + j), hh = lane.load(src + 3 * c + j);
        // x00 = (s + t) / 2, x01 = (s - t) / 2 with s = LL + HL, t = LH + HH; the bottom
        // row likewise with the differences.
        const auto s = plus(ll, hl), t = plus(lh, hh);
        const auto sd = minus(ll, hl), td = minus(lh, hh);
        lane.store(top + j, times(plus(s, t), half));
        lane.store(top + c + j, times(minus(s, t), half));
        lane.store(bottom + j, times(plus(sd, td), half));
        lane.store(bottom + c + j, times(minus(sd, td), half));
      });
  }
}

void resize2x_nearest(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const int64_t out_row = 2 * static_cast<int64_t>(w) * c;
  for (int y = row_begin; y < row_end; ++y) {
    const float* src = in + static_cast<int64_t>(y) * w * c;
    float* top = out + 2 * y * out_row;
    float* dst = top;
    for (int x = 0; x < w; ++x, src += c, dst += 2 * c) {
      copy_floats(src, c, dst);
      copy_floats(src, c, dst + c);
    }
    copy_floats(top, out_row, top + out_row);  // the second output row repeats the first
  }
}

// With half-pixel centres a 2x upscale has fixed weights: output 2i blends input i and
// i-1 by 3/4 : 1/4, output 2i+1 blends i and i+1, neighbours clamped at the border. One
// output row is the vertical blend `near * 3/4 + far * 1/4` of two input rows, then the
// same blend horizontally.
static void bilinear_row(const float* near, const float* far, int w, const Channels& channels,
                         int c, float* dst) {
  for (int x = 0; x < w; ++x, dst += 2 * c) {
    const int64_t left = std::max(x - 1, 0) * static_cast<int64_t>(c);
    const int64_t centre = static_cast<int64_t>(x) * c;
    const int64_t right = std::min(x + 1, w - 1) * static_cast<int64_t>(c);
    channels.each([&](int j, auto lane) {
      const auto three_quarters = lane.splat(0.75f), quarter = lane.splat(0.25f);
      auto column = [&](int64_t at) {
        return fmadd(lane.load(near + at + j), three_quarters, times(lane.load(far + at + j), quarter));
      };
      const auto mid = times(column(centre), three_quarters);
      lane.store(dst + j, fmadd(column(left), quarter, mid));
      lane.store(dst + c + j, fmadd(column(right), quarter, mid));
    });
  }
}

void resize2x_bilinear(const float* in, int h, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  const int64_t in_row = static_cast<int64_t>(w) * c;
  for (int y = row_begin; y < row_end; ++y) {
    const float* row = in + y * in_row;
    float* top = out + static_cast<int64_t>(2 * y) * 2 * in_row;
    bilinear_row(row, in + std::max(y - 1, 0) * in_row, w, channels, c, top);
    bilinear_row(row, in + std::min(y + 1, h - 1) * in_row, w, channels, c, top + 2 * in_row);
  }
}

