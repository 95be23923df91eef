"""The camera's image: what turns rendered linear radiance into a photo-like uint8 image.

A random set-up per image (exposure, white balance, defocus, lens softness, display
gamma, contrast, sensor noise, JPEG), so that the depth networks meet the artefacts of
real photos. Every draw comes from the rng passed in; scenes.render_scene gives the
camera a stream of its own, so that the camera's draws stay put when the scene sampler
changes.
"""

import io

import numpy as np
import torch
from PIL import Image

from textures import DISPLAY_GAMMA

DEFOCUS_ODDS = 0.3                # photos with a visible depth of field
NEAR_FOCUS_ODDS = 0.7             # of those, focused on the nearest surfaces


def defocus(image, disparity, rng):
    """Thin-lens-like blur of image (3, H, W) growing with |disparity - focus disparity|.

    Blurred copies come from 2x, 4x and 8x box-downsampled images upsampled bilinearly
    (blur radii of about 1, 3 and 7 pixels); each pixel blends the two nearest copies."""
    scale = max(float(np.percentile(disparity[::4, ::4], 99)), 1e-6)
    if rng.random() < NEAR_FOCUS_ODDS:   # focused on a near subject: blur grows with distance
        focus = float(np.percentile(disparity[::4, ::4], rng.uniform(85, 99))) / scale
    else:
        focus = disparity[rng.integers(disparity.shape[0]), rng.integers(disparity.shape[1])] / scale
    strength = rng.uniform(4, 14)           # blur radius in pixels per unit normalised disparity
    radius = np.minimum(np.abs(disparity * np.float32(1 / scale) - focus) * np.float32(strength), 7)
    level = np.log2(1 + radius)             # 0 (sharp) .. 3
    sharp = torch.from_numpy(image)[None]
    out = image * np.maximum(0, 1 - level)
    for k in (1, 2, 3):
        weight = np.maximum(0, 1 - np.abs(level - k))
        if not weight.any():
            continue
        small = torch.nn.functional.avg_pool2d(sharp, 2 ** k, ceil_mode=True)
        blurred = torch.nn.functional.interpolate(small, size=disparity.shape, mode='bilinear',
                                                  align_corners=False)
        out += weight * blurred[0].numpy()
    return out


def optical_softness(image, weight):
    """Separable [w, 1 - 2w, w] blur of image (3, H, W), edges replicated: lens softness,
    and anti-aliasing of the one-ray-per-pixel raster."""
    out = image * (1 - 2 * weight)
    out[:, 1:] += image[:, :-1] * weight
    out[:, :-1] += image[:, 1:] * weight
    out[:, 0] += image[:, 0] * weight
    out[:, -1] += image[:, -1] * weight
    image = out
    out = image * (1 - 2 * weight)
    out[:, :, 1:] += image[:, :, :-1] * weight
    out[:, :, :-1] += image[:, :, 1:] * weight
    out[:, :, 0] += image[:, :, 0] * weight
    out[:, :, -1] += image[:, :, -1] * weight
    return out


def encode(image, exponent):
    """image ** exponent for image in [0, 1], through a 16-bit table (a power per pixel
    costs several times more)."""
    table = (np.linspace(0, 1, 65536, dtype=np.float32) ** np.float32(exponent)).astype(np.float32)
    return table[(np.clip(image, 0, 1) * 65535 + 0.5).astype(np.uint16)]


def jpeg_roundtrip(image, quality):
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format='JPEG', quality=int(quality))
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        return np.array(decoded.convert('RGB'), dtype=np.uint8)     # a writable copy


def photograph(radiance, disparity, rng):
    """uint8 sRGB photo (H, W, 3) of the linear radiance (3, H, W), through a randomly
    set-up camera: exposure, white balance, defocus, softness, gamma, contrast, noise, JPEG."""
    sample = radiance[:, ::4, ::4]
    luminance = 0.2126 * sample[0] + 0.7152 * sample[1] + 0.0722 * sample[2]
    exposure = rng.uniform(0.75, 1.05) / max(float(np.percentile(luminance, 98)), 1e-4)
    gains = (np.exp(rng.normal(0, 0.06, 3)) * exposure).astype(np.float32)   # white balance
    image = np.minimum(radiance * gains[:, None, None], 1)
    if rng.random() < DEFOCUS_ODDS:
        image = defocus(image, disparity, rng)
    image = optical_softness(image, np.float32(rng.uniform(0.08, 0.22)))
    image = encode(image, rng.uniform(0.8, 1.25) / DISPLAY_GAMMA)    # display gamma, randomised
    contrast = np.float32(rng.uniform(0.85, 1.15))
    image = (image - 0.5) * contrast + np.float32(0.5 + rng.normal(0, 0.03) + 0.5 / 255)
    if rng.random() < 0.6:      # sensor noise (uniform: cheaper than normal, same variance)
        sigma = np.float32(rng.uniform(0.002, 0.02))
        image += (rng.random(image.shape, dtype=np.float32) - 0.5) * (sigma * np.float32(12 ** 0.5))
    photo = np.ascontiguousarray((np.clip(image, 0, 1) * 255).astype(np.uint8).transpose(1, 2, 0))
    if rng.random() < 0.6:
        photo = jpeg_roundtrip(photo, rng.integers(40, 96))
    return photo
