// The architectures this build runs. Every weight file names its own in the required
// metadata key `arch` (weights_format/SPEC.md); the loaders (nets/model_loader.h) pick
// the network that builds it, and refuse any other name in one line.
#pragma once

namespace ampi::arch {

// The paper's depth networks (lite, heavy): MobileNetV3 blocks between Haar wavelet
// transforms (nets/ARCHITECTURE.md, nets/depth_net.h).
inline constexpr const char* kDepthDwtMobileNetV3 = "ampi.depth.dwt-mobilenetv3";
// Depth Anything V2 (vits, vitb, vitl): a DINOv2 vision transformer and a DPT head
// (nets/depth_anything_net.h), from training/import_depth_anything.py.
inline constexpr const char* kDepthDinoV2Dpt = "ampi.depth.dav2-vit-dpt";
// The inpainting generator: gated convolutions in a U-Net (nets/inpaint_net.h).
inline constexpr const char* kInpaintGatedConv = "ampi.inpaint.gated-conv";

}  // namespace ampi::arch
