// The architectures this build runs. Every weight file names its own in the required
// metadata key `arch` (weights_format/SPEC.md); the loaders (nets/model_loader.h) pick
// the network that builds it, and refuse any other name in one line.
#pragma once

namespace ampi::arch {

// The paper's depth networks (lite, heavy): MobileNetV3 blocks between Haar wavelet
// transforms (nets/ARCHITECTURE.md, nets/depth_net.h).
inline constexpr const char* kDepthDwtMobileNetV3 = "ampi.depth.dwt-mobilenetv3";
// The inpainting generator: gated convolutions in a U-Net (nets/inpaint_net.h).
inline constexpr const char* kInpaintGatedConv = "ampi.inpaint.gated-conv";

}  // namespace ampi::arch
