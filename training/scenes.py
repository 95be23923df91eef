#!/usr/bin/env python3
"""Procedural RGB-D scenes with exact disparity, for training the depth networks.

A scene is a pinhole camera above a ground plane, a background (open land under a sky
with far backdrops, a street between facades, or a room) and many textured objects.
Every pixel's ray is intersected analytically with every shape whose screen box holds
the pixel, so occlusions and disparity (1 / camera depth) are exact. Colours come from
crops of the real photos in ../shared/data/photos, lit by a directional light with cast
shadows, hazed with distance, and passed through a random camera (defocus, optical
softness, white balance, gamma, noise, JPEG).

    /usr/bin/python3 training/scenes.py --bench
    /usr/bin/python3 training/scenes.py --contact-sheet training/scenes_contact_sheet.png

Conventions: world x right, y up, z forward (the camera looks along +z before pitch);
the ground is the plane y = 0; lengths are metres. Camera frame: x right, y down, z
forward. A ray direction has camera-z component 1, so the ray parameter t of a hit is
the hit's camera depth and its disparity is exactly 1 / t; the sky has disparity 0.
"""

import argparse
import functools
import io
import math
import os
import sys
import time
from dataclasses import dataclass

import numpy as np
import torch
from PIL import Image

from photo_folder import is_validation_seed
from textures import DISPLAY_GAMMA, Material, mirror, pool_for_seed, texture_pool

NEAR_CLIP = 0.05                  # metres: nothing nearer than this is rendered
SHADOW_BIAS = 1e-3                # metres: shadow rays start this far along the light
MIN_GRAZING_COS = 0.15            # caps the texture footprint growth at grazing angles
DEFAULT_SIZE = (384, 288)
OBJECT_TEXTURE_SKIP_TOP = 0.3     # object crops start below the top 30% of a photo (its sky)
GROUND_TEXTURE_SKIP_TOP = 0.5     # ground crops from the photo's lower half where they fit
WALL_STREAK_ODDS = 0.3            # walls and facades streaked vertically this often
DEFOCUS_ODDS = 0.3                # photos with a visible depth of field
NEAR_FOCUS_ODDS = 0.7             # of those, focused on the nearest surfaces


# ----------------------------------------------------------------------------------
# Vector helpers. A vector is a length-3 sequence of components, each a scalar or an
# array; all components broadcast together, so one camera origin serves many rays.

def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def to_local(v, rotation, origin=None):
    """Components of rotation^T (v - origin): rotation's columns are the local axes."""
    if origin is not None:
        v = (v[0] - origin[0], v[1] - origin[1], v[2] - origin[2])
    return [rotation[0, i] * v[0] + rotation[1, i] * v[1] + rotation[2, i] * v[2] for i in range(3)]


def to_world(v, rotation):
    return [rotation[i, 0] * v[0] + rotation[i, 1] * v[1] + rotation[i, 2] * v[2] for i in range(3)]


def rotation_x(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1, 0, 0], [0, c, s], [0, -s, c]], dtype=np.float64)


def rotation_y(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]], dtype=np.float64)


def rotation_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]], dtype=np.float64)


def box_corners(center, half, rotation):
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    return np.asarray(center, dtype=np.float64) + (signs * half) @ rotation.T


# ----------------------------------------------------------------------------------
# Shapes: intersect(origin, direction, t_min) -> ray parameter of the nearest hit beyond
# t_min (inf on a miss); surface(points, directions) -> world normal facing the viewer
# side and surface coordinates (u, v) in metres for texturing; corners() -> points whose
# convex hull holds the shape (None: unbounded).

class Box:
    def __init__(self, center, half, rotation=np.eye(3)):
        self.center = np.asarray(center, dtype=np.float64)
        self.half = np.asarray(half, dtype=np.float64)
        self.rotation = np.asarray(rotation, dtype=np.float64)

    def corners(self):
        return box_corners(self.center, self.half, self.rotation)

    def intersect(self, origin, direction, t_min):
        lo = to_local(origin, self.rotation, self.center)
        ld = to_local(direction, self.rotation)
        near, far = -np.inf, np.inf
        with np.errstate(divide='ignore', invalid='ignore'):
            for i in range(3):   # slab test; fmin/fmax skip the NaN of 0 * inf
                inverse = 1.0 / ld[i]
                t1 = (-self.half[i] - lo[i]) * inverse
                t2 = (self.half[i] - lo[i]) * inverse
                near = np.fmax(near, np.fmin(t1, t2))
                far = np.fmin(far, np.fmax(t1, t2))
        return np.where((near <= far) & (near > t_min), near, np.inf)

    def surface(self, points, directions):
        lp = to_local(points, self.rotation, self.center)
        face = np.argmax(np.stack([np.abs(lp[i]) / self.half[i] for i in range(3)]), axis=0)
        side = np.sign(np.choose(face, lp))
        local_normal = [np.where(face == i, side, 0.0) for i in range(3)]
        u = np.choose(face, [lp[2], lp[0], lp[0]])
        v = np.choose(face, [lp[1], lp[2], lp[1]])
        u = u + face * 5.0 + (side > 0) * 2.5      # each face shows another part of the texture
        return to_world(local_normal, self.rotation), (u, v)


class Sphere:
    def __init__(self, center, radius):
        self.center = np.asarray(center, dtype=np.float64)
        self.radius = float(radius)

    def corners(self):
        return box_corners(self.center, np.full(3, self.radius), np.eye(3))

    def intersect(self, origin, direction, t_min):
        oc = [origin[i] - self.center[i] for i in range(3)]
        a = dot(direction, direction)
        b = dot(oc, direction)
        c = dot(oc, oc) - self.radius ** 2
        discriminant = b * b - a * c
        with np.errstate(invalid='ignore'):
            t = (-b - np.sqrt(discriminant)) / a
        return np.where((discriminant >= 0) & (t > t_min), t, np.inf)

    def surface(self, points, directions):
        n = [(points[i] - self.center[i]) / self.radius for i in range(3)]
        u = np.arctan2(n[0], n[2]) * self.radius
        v = np.arcsin(np.clip(n[1], -1, 1)) * self.radius
        return n, (u, v)


class Cylinder:
    """Capped cylinder around the local y axis (rotation's second column)."""

    def __init__(self, center, radius, half_height, rotation=np.eye(3)):
        self.center = np.asarray(center, dtype=np.float64)
        self.radius = float(radius)
        self.half_height = float(half_height)
        self.rotation = np.asarray(rotation, dtype=np.float64)

    def corners(self):
        half = np.array([self.radius, self.half_height, self.radius])
        return box_corners(self.center, half, self.rotation)

    def intersect(self, origin, direction, t_min):
        lo = to_local(origin, self.rotation, self.center)
        ld = to_local(direction, self.rotation)
        r, hh = self.radius, self.half_height
        a = ld[0] * ld[0] + ld[2] * ld[2]
        b = lo[0] * ld[0] + lo[2] * ld[2]
        c = lo[0] * lo[0] + lo[2] * lo[2] - r * r
        discriminant = b * b - a * c
        with np.errstate(divide='ignore', invalid='ignore'):
            t_side = (-b - np.sqrt(discriminant)) / a
            side_hit = (discriminant >= 0) & (np.abs(lo[1] + t_side * ld[1]) <= hh) & (t_side > t_min)
            best = np.where(side_hit, t_side, np.inf)
            for cap in (hh, -hh):
                t_cap = (cap - lo[1]) / ld[1]
                x, z = lo[0] + t_cap * ld[0], lo[2] + t_cap * ld[2]
                cap_hit = (x * x + z * z <= r * r) & (t_cap > t_min)
                best = np.where(cap_hit & (t_cap < best), t_cap, best)
        return best

    def surface(self, points, directions):
        lp = to_local(points, self.rotation, self.center)
        radial = np.sqrt(lp[0] ** 2 + lp[2] ** 2)
        on_cap = np.abs(lp[1]) / self.half_height > radial / self.radius
        safe_radial = np.maximum(radial, 1e-9)
        local_normal = [np.where(on_cap, 0.0, lp[0] / safe_radial),
                        np.where(on_cap, np.sign(lp[1]), 0.0),
                        np.where(on_cap, 0.0, lp[2] / safe_radial)]
        u = np.where(on_cap, lp[0], np.arctan2(lp[0], lp[2]) * self.radius)
        v = np.where(on_cap, lp[2], lp[1])
        return to_world(local_normal, self.rotation), (u, v)


class Quad:
    """A two-sided rectangle, optionally cut out by a mask (row 0 = the +axis_v edge).

    Infinite half sizes make an unbounded plane (ground, walls)."""

    def __init__(self, center, axis_u, axis_v, half_u, half_v, mask=None):
        self.center = np.asarray(center, dtype=np.float64)
        self.axis_u = np.asarray(axis_u, dtype=np.float64)
        self.axis_v = np.asarray(axis_v, dtype=np.float64)
        self.normal = np.cross(self.axis_u, self.axis_v)
        self.half_u, self.half_v = float(half_u), float(half_v)
        if mask is not None and not (np.isfinite(half_u) and np.isfinite(half_v)):
            raise ValueError('a masked quad needs finite half sizes')
        self.mask = mask

    def corners(self):
        if not (np.isfinite(self.half_u) and np.isfinite(self.half_v)):
            return None
        return np.array([self.center + su * self.half_u * self.axis_u + sv * self.half_v * self.axis_v
                         for su in (-1, 1) for sv in (-1, 1)])

    def intersect(self, origin, direction, t_min):
        oc = [origin[i] - self.center[i] for i in range(3)]
        with np.errstate(divide='ignore', invalid='ignore'):
            t = -dot(oc, self.normal) / dot(direction, self.normal)
            if self.half_u == self.half_v == np.inf:
                return np.where(t > t_min, t, np.inf)
            u = dot(oc, self.axis_u) + t * dot(direction, self.axis_u)
            v = dot(oc, self.axis_v) + t * dot(direction, self.axis_v)
            hit = (t > t_min) & (np.abs(u) <= self.half_u) & (np.abs(v) <= self.half_v)
        if self.mask is not None:
            hit &= self._mask_covers(np.where(hit, u, 0.0), np.where(hit, v, 0.0))
        return np.where(hit, t, np.inf)

    def _mask_covers(self, u, v):
        rows, cols = self.mask.shape
        r = ((self.half_v - v) / (2 * self.half_v) * rows).astype(np.int32)
        c = ((u + self.half_u) / (2 * self.half_u) * cols).astype(np.int32)
        return self.mask[np.clip(r, 0, rows - 1), np.clip(c, 0, cols - 1)]

    def surface(self, points, directions):
        facing = -np.sign(dot(directions, self.normal))
        normal = [self.normal[i] * facing for i in range(3)]
        offset = [points[i] - self.center[i] for i in range(3)]
        return normal, (dot(offset, self.axis_u), dot(offset, self.axis_v))


def ground_plane():
    return Quad((0, 0, 0), (1, 0, 0), (0, 0, 1), np.inf, np.inf)


# ----------------------------------------------------------------------------------
# Camera

@dataclass(frozen=True)
class Camera:
    width: int
    height: int
    fov_x_deg: float
    position: np.ndarray
    pitch_deg: float = 0.0      # positive looks up
    roll_deg: float = 0.0
    yaw_deg: float = 0.0        # positive turns towards +x

    @functools.cached_property
    def focal(self):
        return self.width / 2 / math.tan(math.radians(self.fov_x_deg) / 2)

    @functools.cached_property
    def rotation(self):
        """Camera-to-world rotation: its columns are the camera's x, y, z axes in the world."""
        flip_y = np.diag([1.0, -1.0, 1.0])      # camera y points down, world y up
        return (rotation_y(math.radians(self.yaw_deg)) @ rotation_x(math.radians(self.pitch_deg))
                @ flip_y @ rotation_z(math.radians(self.roll_deg)))

    def ray_directions(self):
        """(3, H, W) float32 world directions through pixel centres, camera-z component 1."""
        f = self.focal
        xn = ((np.arange(self.width, dtype=np.float32) + 0.5 - self.width / 2) / f)[None, :]
        yn = ((np.arange(self.height, dtype=np.float32) + 0.5 - self.height / 2) / f)[:, None]
        r = self.rotation.astype(np.float32)
        return np.stack([np.broadcast_to(r[i, 0] * xn + r[i, 1] * yn + r[i, 2],
                                         (self.height, self.width)) for i in range(3)])

    def screen_box(self, points):
        """Pixel slices (rows, cols) covering the projections of points; None if none show.

        None points mean an unbounded shape (the whole image)."""
        full = (slice(0, self.height), slice(0, self.width))
        if points is None:
            return full
        local = (np.asarray(points) - self.position) @ self.rotation
        z = local[:, 2]
        if np.all(z < NEAR_CLIP):
            return None
        if np.any(z < NEAR_CLIP):
            return full          # straddles the camera plane: projections are unbounded
        u = self.focal * local[:, 0] / z + self.width / 2 - 0.5
        v = self.focal * local[:, 1] / z + self.height / 2 - 0.5
        x0, x1 = max(0, math.floor(u.min()) - 1), min(self.width, math.ceil(u.max()) + 2)
        y0, y1 = max(0, math.floor(v.min()) - 1), min(self.height, math.ceil(v.max()) + 2)
        if x0 >= x1 or y0 >= y1:
            return None
        return slice(y0, y1), slice(x0, x1)


# ----------------------------------------------------------------------------------
# Materials and lighting

@dataclass
class Light:
    direction: np.ndarray     # unit vector towards the light, y > 0
    sun: np.ndarray           # linear RGB irradiance of the directional light
    ambient: np.ndarray       # linear RGB sky light


@dataclass
class Atmosphere:
    zenith: np.ndarray        # linear RGB sky colours
    horizon: np.ndarray
    haze_density: float       # per metre: transmittance = exp(-density * depth)
    cloud_cover: float = 0.0  # 0: clear; towards 1: overcast
    clouds: np.ndarray = None  # square tile of smooth noise in [0, 1]
    cloud_scale: float = 0.5  # cloud-tile repetitions per unit of the cloud plane


@dataclass
class SceneObject:
    shape: object
    material: Material
    casts_shadow: bool = True


@dataclass
class Scene:
    camera: Camera
    objects: list
    light: Light
    atmosphere: Atmosphere


# ----------------------------------------------------------------------------------
# Rendering

@dataclass
class GBuffer:
    depth: np.ndarray         # (H, W) float32 camera depth, inf where the sky shows
    ids: np.ndarray           # (H, W) int16 index of the visible object, -1 for sky
    object_count: int
    directions: np.ndarray    # (3, H, W) ray directions


def raycast(scene):
    """Z-buffer by exact ray intersection, each shape tested only inside its screen box."""
    camera = scene.camera
    directions = camera.ray_directions()
    origin = np.asarray(camera.position, dtype=np.float64)
    depth = np.full((camera.height, camera.width), np.inf, dtype=np.float32)
    if len(scene.objects) > np.iinfo(np.int16).max:
        raise ValueError(f'{len(scene.objects)} objects: at most {np.iinfo(np.int16).max} per scene')
    ids = np.full((camera.height, camera.width), -1, dtype=np.int16)
    for index, obj in enumerate(scene.objects):
        box = camera.screen_box(obj.shape.corners())
        if box is None:
            continue
        t = obj.shape.intersect(origin, directions[(slice(None),) + box], NEAR_CLIP)
        region = depth[box]
        nearer = t < region
        region[nearer] = t[nearer]
        ids[box][nearer] = index
    return GBuffer(depth, ids, len(scene.objects), directions)


def disparity_of(gbuffer):
    """Exact disparity 1 / depth; 0 for the sky."""
    disparity = np.zeros_like(gbuffer.depth)
    hit = gbuffer.ids >= 0
    disparity[hit] = 1.0 / gbuffer.depth[hit]
    return disparity


def pixels_by_object(gbuffer):
    """Flat pixel indices of each object's visible pixels (one radix sort of the ids)."""
    ids = gbuffer.ids.reshape(-1)
    order = np.argsort(ids, kind='stable')
    ends = np.cumsum(np.bincount(ids.astype(np.int32) + 1, minlength=gbuffer.object_count + 1))
    return [order[start:end] for start, end in zip(ends[:-1], ends[1:])]


def surface_buffers(scene, gbuffer):
    """Per pixel (flat): linear albedo (3, H*W), the cosine to the light (0 when facing
    away or sky) and the normal's up component (for sky light)."""
    count = gbuffer.depth.size
    albedo = np.zeros((3, count), dtype=np.float32)
    lambert = np.zeros(count, dtype=np.float32)
    up = np.zeros(count, dtype=np.float32)
    depth = gbuffer.depth.reshape(-1)
    directions = gbuffer.directions.reshape(3, -1)
    origin, focal = scene.camera.position, scene.camera.focal
    light = scene.light.direction.astype(np.float32)
    for obj, pixels in zip(scene.objects, pixels_by_object(gbuffer)):
        if pixels.size == 0:
            continue
        t = depth[pixels]
        d = np.take(directions, pixels, axis=1)
        normal, uv = obj.shape.surface([origin[i] + t * d[i] for i in range(3)], d)
        cosine = np.abs(dot(normal, d)) / np.sqrt(dot(d, d))
        metres_per_pixel = t / focal / np.maximum(cosine, MIN_GRAZING_COS)
        albedo[:, pixels] = obj.material.albedo(uv, metres_per_pixel)
        lambert[pixels] = np.maximum(dot(normal, light), 0)
        up[pixels] = normal[1]
    return albedo, lambert, up


def shadow_box(camera, shape, light_direction):
    """Screen box of every point that shape can shade: its hull with its ground shadow."""
    corners = shape.corners()
    if corners is None:
        return camera.screen_box(None)
    on_ground = corners - (corners[:, 1:2] / light_direction[1]) * light_direction
    return camera.screen_box(np.vstack([corners, on_ground]))


def sun_visibility(scene, gbuffer, lit):
    """(H*W,) 1 where the directional light reaches a lit pixel, 0 in a cast shadow."""
    visibility = lit.astype(np.float32)
    direction = np.asarray(scene.light.direction, dtype=np.float64)
    origin = scene.camera.position
    depth = gbuffer.depth.reshape(-1)
    directions = gbuffer.directions.reshape(3, -1)
    width = gbuffer.ids.shape[1]
    square = visibility.reshape(gbuffer.ids.shape)
    for index, obj in enumerate(scene.objects):
        if not obj.casts_shadow:
            continue
        box = shadow_box(scene.camera, obj.shape, direction)
        if box is None:
            continue
        rows, cols = np.nonzero((gbuffer.ids[box] != index) & (square[box] > 0))
        if rows.size == 0:
            continue
        pixels = (rows + box[0].start) * width + cols + box[1].start
        t_view = depth[pixels]
        points = [origin[i] + t_view * directions[i, pixels] for i in range(3)]
        t = obj.shape.intersect(points, direction, SHADOW_BIAS)
        visibility[pixels[np.isfinite(t)]] = 0.0
    return visibility


def sky_radiance(atmosphere, directions):
    """Linear sky colour (3, N) along (3, N) directions: a zenith-horizon gradient with
    noise clouds."""
    elevation = np.clip(directions[1] / np.sqrt(dot(directions, directions)), 0, 1)
    blend = np.sqrt(elevation)
    colour = atmosphere.horizon[:, None] * (1 - blend) + atmosphere.zenith[:, None] * blend
    if atmosphere.clouds is None or atmosphere.cloud_cover <= 0:
        return colour
    height = np.maximum(directions[1], 1e-3)     # clouds lie on a plane one unit up
    size = atmosphere.clouds.shape[0]
    x = mirror(directions[0] / height * (atmosphere.cloud_scale * size), size - 1)
    y = mirror(directions[2] / height * (atmosphere.cloud_scale * size), size - 1)
    density = atmosphere.clouds[y.astype(np.int32), x.astype(np.int32)]
    cover = np.clip((density - (1 - atmosphere.cloud_cover)) * 4, 0, 1)
    cover *= np.clip(elevation * 8, 0, 1)        # thin out towards the horizon
    cloud_colour = atmosphere.horizon[:, None] * 0.5 + 0.6
    return colour * (1 - cover) + cloud_colour * cover


def shade(scene, gbuffer):
    """(3, H, W) float32 linear radiance: Lambert + ambient + cast shadows, haze, sky."""
    albedo, lambert, up = surface_buffers(scene, gbuffer)
    light = scene.light
    visibility = sun_visibility(scene, gbuffer, lambert > 0)
    sky_light = 0.75 + 0.25 * up            # up-facing surfaces see more of the sky
    irradiance = light.ambient[:, None] * sky_light + light.sun[:, None] * (lambert * visibility)
    radiance = albedo * irradiance
    atmosphere = scene.atmosphere
    hit = gbuffer.ids.reshape(-1) >= 0
    if atmosphere.haze_density > 0:
        depth = np.where(hit, gbuffer.depth.reshape(-1), 0)
        transmittance = np.exp(depth * np.float32(-atmosphere.haze_density))
        radiance = radiance * transmittance + atmosphere.horizon[:, None] * (1 - transmittance)
    sky = np.flatnonzero(~hit)
    radiance[:, sky] = sky_radiance(atmosphere, np.take(gbuffer.directions.reshape(3, -1), sky, axis=1))
    return radiance.reshape((3,) + gbuffer.depth.shape)


def render(scene):
    """Linear radiance (3, H, W) float32 and exact disparity (H, W) float32."""
    gbuffer = raycast(scene)
    return shade(scene, gbuffer), disparity_of(gbuffer)


# ----------------------------------------------------------------------------------
# The camera's image: exposure, defocus, softness, colour, noise, JPEG

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


# ----------------------------------------------------------------------------------
# Random shapes' outlines and noise

def interpolation_matrix(n_out, n_in):
    """(n_out, n_in) weights of linear interpolation from n_in samples to n_out."""
    position = np.linspace(0, n_in - 1, n_out)
    lower = np.minimum(np.floor(position).astype(int), n_in - 2)
    frac = position - lower
    weights = np.zeros((n_out, n_in), dtype=np.float32)
    weights[np.arange(n_out), lower] = 1 - frac
    weights[np.arange(n_out), lower + 1] = frac
    return weights


def smooth_noise(rng, shape, cells, octaves=3):
    """Fractal value noise in [0, 1]: random grids of cells, cells*2, ... upsampled."""
    total = np.zeros(shape, dtype=np.float32)
    amplitude, norm = 1.0, 0.0
    for octave in range(octaves):
        n = cells * 2 ** octave
        grid = rng.random((n + 1, n + 1)).astype(np.float32)
        total += amplitude * (interpolation_matrix(shape[0], n + 1) @ grid @ interpolation_matrix(shape[1], n + 1).T)
        norm += amplitude
        amplitude *= 0.5
    total /= norm
    return (total - total.min()) / max(float(total.max() - total.min()), 1e-6)


def blob_mask(rng, size=96):
    """A star-shaped outline: radius is a random sum of harmonics of the angle."""
    y, x = np.mgrid[-1:1:size * 1j, -1:1:size * 1j]
    angle = np.arctan2(y, x)
    radius = np.ones_like(angle)
    for k in range(1, 7):
        radius += rng.normal(0, 0.25 / k) * np.cos(k * angle + rng.uniform(0, 2 * math.pi))
    return np.hypot(x, y) < 0.9 * radius / max(float(radius.max()), 1e-6)


def foliage_mask(rng, size=96):
    """Thresholded noise inside an ellipse: ragged edges and holes, like a bush."""
    y, x = np.mgrid[-1:1:size * 1j, -1:1:size * 1j]
    noise = smooth_noise(rng, (size, size), rng.integers(3, 7), octaves=4)
    return noise - 0.9 * (x * x + y * y) > rng.uniform(-0.25, 0.1)


def figure_mask(rng, rows=128, cols=64):
    """A standing person's outline: head, torso, two legs, two arms, slightly wobbly."""
    y, x = np.mgrid[0:1:rows * 1j, -0.5:0.5:cols * 1j]
    x = x + 0.03 * np.sin(y * rng.uniform(5, 15) + rng.uniform(0, 6))
    head_r = rng.uniform(0.055, 0.075)
    shoulder = rng.uniform(0.14, 0.2)
    hip_y = rng.uniform(0.5, 0.58)
    head = (x / 0.8) ** 2 + (y - head_r - 0.01) ** 2 < head_r ** 2
    torso = (np.abs(x) < shoulder * (1 - 0.3 * (y - 0.15))) & (y > 2 * head_r) & (y < hip_y)
    stride = rng.uniform(0.02, 0.12)
    legs = (y >= hip_y - 0.02) & (np.abs(np.abs(x) - 0.05 - stride * (y - hip_y)) < 0.055)
    arm_spread = rng.uniform(0.0, 0.25)
    arms = ((y > 2 * head_r + 0.02) & (y < hip_y + 0.05)
            & (np.abs(np.abs(x) - shoulder - arm_spread * (y - 0.2)) < 0.035))
    return head | torso | legs | arms


def animal_mask(rng, rows=64, cols=112):
    """A four-legged animal's side view: body, neck and head, legs, tail."""
    y, x = np.mgrid[0:1:rows * 1j, 0:1:cols * 1j]
    facing = 1 if rng.random() < 0.5 else -1
    x = 0.5 + facing * (x - 0.5)
    belly = rng.uniform(0.5, 0.62)
    body = ((x - 0.5) / 0.3) ** 2 + ((y - (belly - 0.16)) / 0.17) ** 2 < 1
    neck_top = rng.uniform(0.05, 0.25)
    neck = (x > 0.7) & (x < 0.82) & (y > neck_top + 0.05) & (y < belly - 0.15) & (np.abs(x - 0.76 + 0.2 * (y - belly)) < 0.07)
    head = ((x - 0.85) / 0.1) ** 2 + ((y - neck_top - 0.06) / 0.07) ** 2 < 1
    legs = np.zeros_like(body)
    for centre in (0.27, 0.36, 0.64, 0.73):
        legs |= (np.abs(x - centre - rng.uniform(-0.03, 0.03)) < 0.035) & (y > belly - 0.2)
    tail = (x < 0.22) & (x > 0.12) & (np.abs(y - (belly - 0.3) - 0.8 * (0.22 - x)) < 0.03)
    return body | neck | head | legs | tail


def skyline_mask(rng, rows=64, cols=256, blocky=False):
    """Columns filled from the bottom to a ridge (smooth) or roof-line (blocky) profile."""
    if blocky:
        heights = np.empty(cols, dtype=np.float32)
        start = 0
        while start < cols:
            width = rng.integers(cols // 40 + 1, cols // 8 + 2)
            heights[start:start + width] = rng.uniform(0.3, 1.0)
            start += width
    else:
        heights = 0.25 + 0.75 * smooth_noise(rng, (1, cols), rng.integers(2, 6), octaves=4)[0]
    level = 1 - (np.arange(rows, dtype=np.float32)[:, None] + 0.5) / rows
    return level <= heights[None, :]


def random_mask(rng, kind):
    makers = {'blob': blob_mask, 'foliage': foliage_mask, 'figure': figure_mask, 'animal': animal_mask}
    while True:      # a rare draw covers almost nothing: draw again
        mask = makers[kind](rng)
        if mask.mean() > 0.08:
            return mask


# ----------------------------------------------------------------------------------
# Random scenes

SCENE_KINDS = ('open', 'street', 'room')
SCENE_KIND_ODDS = (0.45, 0.25, 0.30)
OBJECT_KINDS = ('box', 'sphere', 'cylinder', 'pole', 'slanted', 'cutout', 'tree', 'table', 'stack')
OBJECT_KIND_ODDS = (0.18, 0.11, 0.10, 0.09, 0.11, 0.17, 0.09, 0.06, 0.09)


def log_uniform(rng, low, high):
    return math.exp(rng.uniform(math.log(low), math.log(high)))


def vertical_quad(center, width, height, yaw, mask=None):
    """An upright rectangle facing the camera when yaw = 0."""
    axis_u = (math.cos(yaw), 0.0, -math.sin(yaw))
    return Quad(center, axis_u, (0.0, 1.0, 0.0), width / 2, height / 2, mask)


class SceneSampler:
    """Draws one scene's parts from a seeded generator and a photo pool."""

    def __init__(self, rng, pool, camera):
        self.rng, self.pool, self.camera = rng, pool, camera
        self.half_tan = math.tan(math.radians(camera.fov_x_deg) / 2)
        self.x_limit = np.inf       # rooms bound objects between their walls
        self.z_far = 50.0

    # -- materials
    def photo_material(self, span_m, skip_top=0.0, stretch=1.0):
        """A crop of a random photo, tiled so that the crop spans about span_m metres.
        skip_top: the crop starts below this share of the photo's height where it can
        (the sky of a photo is no texture for a near object). stretch: the crop drawn that
        many times taller than wide."""
        rng = self.rng
        pyramid = self.pool.pyramids[rng.integers(len(self.pool.pyramids))]
        h, w = pyramid[0].shape[1:]
        cw = max(8.0, rng.uniform(0.2, 0.9) * w)
        ch = max(8.0, min(h, cw * rng.uniform(0.6, 1.4)))
        top = min(skip_top * h, h - ch)
        crop = (rng.uniform(0, w - cw), rng.uniform(top, h - ch), cw, ch)
        tint = (np.exp(rng.normal(0, 0.08, 3)) * rng.uniform(0.8, 1.1)).astype(np.float32)
        texels_per_metre = cw / (span_m * rng.uniform(0.6, 1.6))
        offset = (rng.uniform(0, cw), rng.uniform(0, ch))
        return Material(tint, pyramid, crop, texels_per_metre, offset, stretch)

    def wall_material(self, span_m):
        """A wall's texture: now and then streaked vertically (shelves, curtains, panels),
        so that vertical texture on a flat surface is no sign of depth."""
        stretch = log_uniform(self.rng, 4, 16) if self.rng.random() < WALL_STREAK_ODDS else 1.0
        return self.photo_material(span_m, stretch=stretch)

    def flat_material(self):
        """A plain paint: mostly muted colours, now and then a saturated one."""
        rng = self.rng
        brightness = log_uniform(rng, 0.03, 0.6)
        hue = rng.dirichlet((1.0, 1.0, 1.0)) * 3
        saturation = rng.uniform(0, 0.7)
        return Material((brightness * (1 - saturation + saturation * hue)).astype(np.float32))

    def object_material(self, size_m):
        if self.rng.random() < 0.82:
            return self.photo_material(size_m, skip_top=OBJECT_TEXTURE_SKIP_TOP)
        return self.flat_material()

    # -- placement
    def ground_spot(self, near=0.8):
        """(x, z) on the ground inside the view, depth log-uniform, biased to the centre."""
        rng = self.rng
        z = log_uniform(rng, near, self.z_far)
        x = z * self.half_tan * float(np.clip(rng.normal(0, 0.6), -1.3, 1.3))
        return float(np.clip(x, -self.x_limit, self.x_limit)), z

    def object_size(self, z):
        """Object size in metres: a little larger far away so that it still shows, and
        never so large near the camera that it fills the view."""
        size = log_uniform(self.rng, 0.25, 2.0) * (1 + z / 25)
        return min(size, 0.8 * z * self.half_tan)

    # -- single objects, resting on the ground at (x, base_y, z)
    def box(self, x, z, base_y=0.0, size=None):
        rng = self.rng
        size = size or self.object_size(z)
        half = size * rng.uniform(0.25, 0.6, 3)
        rotation = rotation_y(rng.uniform(0, math.pi))
        if rng.random() < 0.12:     # knocked over: tilted, sunk a little into the ground
            rotation = rotation @ rotation_x(rng.uniform(-0.5, 0.5)) @ rotation_z(rng.uniform(-0.5, 0.5))
        shape = Box((x, base_y + half[1], z), half, rotation)
        return [SceneObject(shape, self.object_material(size))]

    def sphere(self, x, z, base_y=0.0):
        rng = self.rng
        radius = self.object_size(z) * rng.uniform(0.2, 0.5)
        lift = rng.uniform(0.2, 3.0) if rng.random() < 0.15 else 0.0
        shape = Sphere((x, base_y + radius + lift, z), radius)
        return [SceneObject(shape, self.object_material(radius * 3))]

    def cylinder(self, x, z, base_y=0.0):
        rng = self.rng
        size = self.object_size(z)
        radius, half_height = size * rng.uniform(0.1, 0.35), size * rng.uniform(0.2, 0.8)
        if rng.random() < 0.25:     # a log lying on the ground
            rotation = rotation_y(rng.uniform(0, math.pi)) @ rotation_z(math.pi / 2)
            center = (x, base_y + radius, z)
        else:
            rotation = np.eye(3)
            center = (x, base_y + half_height, z)
        shape = Cylinder(center, radius, half_height, rotation)
        return [SceneObject(shape, self.object_material(size))]

    def pole(self, x, z, base_y=0.0):
        rng = self.rng
        height = rng.uniform(1.2, 7.0)
        radius = rng.uniform(0.015, 0.08)
        parts = [SceneObject(Cylinder((x, base_y + height / 2, z), radius, height / 2),
                             self.object_material(0.5))]
        if rng.random() < 0.4:      # a sign on top
            width, tall = rng.uniform(0.3, 1.2), rng.uniform(0.2, 0.8)
            sign = vertical_quad((x, base_y + height + tall / 2 - 0.05, z - radius - 0.01), width, tall,
                                 rng.uniform(-0.6, 0.6))
            parts.append(SceneObject(sign, self.object_material(width)))
        return parts

    def slanted(self, x, z, base_y=0.0):
        """A board: leaning on something, lying as a ramp, or hanging at a random slant."""
        rng = self.rng
        size = self.object_size(z)
        half_u, half_v = size * rng.uniform(0.3, 1.0), size * rng.uniform(0.3, 1.0)
        orientation = rotation_y(rng.uniform(0, 2 * math.pi)) @ rotation_x(rng.uniform(-1.3, 1.3))
        axis_u, axis_v = orientation[:, 0], orientation[:, 1]
        lowest = abs(axis_u[1]) * half_u + abs(axis_v[1]) * half_v
        lift = rng.uniform(0, 2.0) if rng.random() < 0.3 else 0.0
        shape = Quad((x, base_y + lowest + lift - 0.02, z), axis_u, axis_v, half_u, half_v)
        return [SceneObject(shape, self.object_material(size))]

    def cutout(self, x, z, base_y=0.0, kind=None):
        """A flat standing cut-out with an irregular outline (bush, blob, person)."""
        rng = self.rng
        kind = kind or rng.choice(['blob', 'foliage', 'figure'], p=[0.35, 0.4, 0.25])
        if kind == 'figure':
            height = rng.uniform(1.4, 1.9) * (1 + z / 40)
            width = height * 0.5
        elif kind == 'animal':
            height = rng.uniform(0.4, 1.6) * (1 + z / 40)
            width = height * rng.uniform(1.3, 2.0)
        else:
            height = self.object_size(z) * rng.uniform(0.6, 1.5)
            width = height * rng.uniform(0.6, 1.6)
        lift = rng.uniform(0.3, 2.5) if rng.random() < 0.15 else 0.0
        shape = vertical_quad((x, base_y + height / 2 + lift, z), width, height,
                              rng.uniform(-0.7, 0.7), random_mask(rng, kind))
        return [SceneObject(shape, self.object_material(max(width, height)))]

    def tree(self, x, z, base_y=0.0):
        rng = self.rng
        height = rng.uniform(1.5, 6.0)
        trunk_radius = height * rng.uniform(0.02, 0.05)
        parts = [SceneObject(Cylinder((x, base_y + height / 2, z), trunk_radius, height / 2),
                             self.object_material(1.0))]
        crown = min(height * rng.uniform(0.3, 0.6), 0.8 * z * self.half_tan)
        center = (x, base_y + height + crown * 0.5, z)
        if rng.random() < 0.5:
            parts.append(SceneObject(Sphere(center, crown), self.object_material(crown * 2)))
        else:
            shape = vertical_quad(center, crown * 2.4, crown * 2.4, rng.uniform(-0.5, 0.5),
                                  random_mask(rng, 'foliage'))
            parts.append(SceneObject(shape, self.object_material(crown * 2)))
        return parts

    def table(self, x, z, base_y=0.0):
        rng = self.rng
        height = rng.uniform(0.45, 1.1)
        half_w, half_d = rng.uniform(0.3, 1.0), rng.uniform(0.25, 0.6)
        orientation = rotation_y(rng.uniform(0, math.pi))
        top_center = np.array([x, base_y + height, z])
        top = Quad(top_center, orientation[:, 0], orientation[:, 2], half_w, half_d)
        parts = [SceneObject(top, self.object_material(2 * half_w))]
        leg_material = self.object_material(0.5)
        for su in (-0.9, 0.9):
            for sv in (-0.9, 0.9):
                foot = top_center + su * half_w * orientation[:, 0] + sv * half_d * orientation[:, 2]
                leg = Cylinder((foot[0], base_y + height / 2, foot[2]), 0.03, height / 2)
                parts.append(SceneObject(leg, leg_material))
        if rng.random() < 0.6:       # something standing on the table
            maker = rng.choice([self.box, self.sphere, self.cylinder])
            parts += maker(x, z, base_y + height + 0.001)
        return parts

    def stack(self, x, z, base_y=0.0):
        """Two to four boxes, each smaller, resting on the one below."""
        rng = self.rng
        size = self.object_size(z)
        parts = []
        for _ in range(rng.integers(2, 5)):
            box = self.box(x, z, base_y, size)[0]
            shape = box.shape
            shape.rotation = rotation_y(rng.uniform(0, math.pi))     # stacked boxes stay level
            parts.append(box)
            base_y = shape.center[1] + shape.half[1]
            size *= rng.uniform(0.5, 0.9)
            x += rng.normal(0, size * 0.15)
            z += rng.normal(0, size * 0.15)
        return parts

    def foreground(self, count):
        """count objects, partly clustered so that they overlap in the image."""
        rng = self.rng
        objects, spots = [], []
        for _ in range(count):
            if spots and rng.random() < 0.35:
                px, pz = spots[rng.integers(len(spots))]
                x, z = px + rng.normal(0, 0.2 + pz * 0.05), pz + rng.normal(0, 0.3 + pz * 0.08)
                z = max(z, 0.8)
            else:
                x, z = self.ground_spot()
            spots.append((x, z))
            kind = rng.choice(OBJECT_KINDS, p=OBJECT_KIND_ODDS)
            objects += getattr(self, kind)(x, z)
        if rng.random() < 0.55:      # a person-like subject, in front of the background
            objects += self.cutout(rng.normal(0, 1.0), rng.uniform(1.5, 8.0), kind='figure')
        if rng.random() < 0.25:      # an animal-like one
            objects += self.cutout(rng.normal(0, 1.0), rng.uniform(1.5, 10.0), kind='animal')
        if rng.random() < 0.3:       # a large near occluder entering from the frame's edge
            z = rng.uniform(0.6, 1.8)
            x = math.copysign(z * self.half_tan * rng.uniform(0.6, 1.1), rng.normal())
            objects += getattr(self, rng.choice(['box', 'cutout', 'tree', 'slanted']))(x, z)
        return objects

    # -- backgrounds
    def ground(self):
        return SceneObject(ground_plane(), self.photo_material(log_uniform(self.rng, 1.5, 10.0),
                                                               skip_top=GROUND_TEXTURE_SKIP_TOP), False)

    def backdrop(self, distance, blocky):
        """A far cut-out across the view: hills, a tree line or a city roof-line."""
        rng = self.rng
        width = 2 * distance * self.half_tan * rng.uniform(1.6, 2.5)
        height = distance * rng.uniform(0.04, 0.3)
        shape = vertical_quad((rng.uniform(-0.2, 0.2) * width, height / 2 - 1.0, distance), width,
                              height + 2.0, 0.0, skyline_mask(rng, blocky=blocky))
        material = self.photo_material(width * rng.uniform(0.3, 1.0))
        return SceneObject(shape, material, False)

    def facade(self, distance):
        """A building front standing free in the middle distance."""
        rng = self.rng
        width, height = rng.uniform(5, 30), rng.uniform(4, 25)
        x = rng.uniform(-1, 1) * distance * self.half_tan
        mask = skyline_mask(rng, blocky=True) if rng.random() < 0.5 else None
        shape = vertical_quad((x, height / 2, distance), width, height, rng.uniform(-0.8, 0.8), mask)
        return SceneObject(shape, self.wall_material(rng.uniform(3, 12)))

    def open_land(self):
        rng = self.rng
        self.z_far = 50.0
        parts = [self.ground()]
        for _ in range(rng.integers(0, 4)):
            parts.append(self.backdrop(log_uniform(rng, 40, 400), blocky=rng.random() < 0.3))
        if rng.random() < 0.35:
            parts.append(self.facade(log_uniform(rng, 10, 40)))
        return parts

    def street(self):
        rng = self.rng
        self.z_far = 60.0
        parts = [self.ground()]
        length = rng.uniform(60, 250)
        for side in (-1, 1):
            if rng.random() < 0.85:
                x = side * rng.uniform(3, 12)
                height = rng.uniform(5, 30)
                shape = Quad((x, height / 2, length / 2 - 2), (0, 0, 1), (0, 1, 0), length / 2, height / 2,
                             skyline_mask(rng, cols=512, blocky=True))
                parts.append(SceneObject(shape, self.wall_material(rng.uniform(4, 15)), False))
                self.x_limit = min(self.x_limit, abs(x) - 0.5)
        parts.append(self.backdrop(length + rng.uniform(0, 200), blocky=rng.random() < 0.6))
        return parts

    def room(self):
        rng = self.rng
        camera = self.camera
        depth = rng.uniform(3.5, 20)
        half_width = rng.uniform(1.8, 8)
        ceiling = max(camera.position[1] + 0.5, rng.uniform(2.4, 5))
        self.z_far = depth - 0.3
        self.x_limit = half_width - 0.3
        has_ceiling = rng.random() < 0.75
        wall_half_height = np.inf if has_ceiling else ceiling / 2
        wall_y = 0.0 if has_ceiling else ceiling / 2
        walls = [Quad((0, wall_y, depth), (1, 0, 0), (0, 1, 0), np.inf, wall_half_height)]
        for side in (-1, 1):
            walls.append(Quad((side * half_width, wall_y, 0), (0, 0, 1), (0, 1, 0), np.inf, wall_half_height))
        if has_ceiling:
            walls.append(Quad((0, ceiling, 0), (1, 0, 0), (0, 0, 1), np.inf, np.inf))
        parts = [self.ground()]
        for wall in walls[:3]:
            parts.append(SceneObject(wall, self.wall_material(rng.uniform(2, 8)), False))
        for ceiling_quad in walls[3:]:
            parts.append(SceneObject(ceiling_quad, self.photo_material(rng.uniform(2, 8)), False))
        return parts


def sample_camera(rng, width, height, kind):
    eye_height = log_uniform(rng, 0.4, 3.0) if kind != 'room' else rng.uniform(0.5, 2.0)
    return Camera(width, height, fov_x_deg=rng.uniform(45, 85),
                  position=np.array([0.0, eye_height, 0.0]),
                  pitch_deg=float(np.clip(rng.normal(-6, 8), -30, 15)),
                  roll_deg=float(np.clip(rng.normal(0, 2), -6, 6)))


def sample_light(rng, kind):
    elevation = math.radians(rng.uniform(15, 70) if kind != 'room' else rng.uniform(35, 80))
    azimuth = rng.uniform(0, 2 * math.pi)
    direction = np.array([math.cos(elevation) * math.sin(azimuth), math.sin(elevation),
                          math.cos(elevation) * math.cos(azimuth)])
    sun = np.array([1.0, rng.uniform(0.85, 1.0), rng.uniform(0.7, 1.0)]) * rng.uniform(1.5, 3.5)
    ambient = np.array([rng.uniform(0.7, 0.9), rng.uniform(0.8, 0.95), 1.0]) * rng.uniform(0.25, 0.6)
    if rng.random() < 0.25:     # overcast or indoor diffuse light: weak sun, strong ambient
        sun, ambient = sun * 0.15, ambient * 2.0
    return Light(direction, sun.astype(np.float32), ambient.astype(np.float32))


def sample_atmosphere(rng, kind):
    style = rng.choice(['blue', 'grey', 'sunset'], p=[0.6, 0.25, 0.15])
    if style == 'blue':
        zenith = np.array([0.12, 0.25, 0.65]) * rng.uniform(0.7, 1.2)
        horizon = np.array([0.6, 0.7, 0.85]) * rng.uniform(0.8, 1.1)
    elif style == 'grey':
        zenith = np.full(3, rng.uniform(0.4, 0.7))
        horizon = zenith * rng.uniform(1.0, 1.3)
    else:
        zenith = np.array([0.2, 0.22, 0.45]) * rng.uniform(0.6, 1.0)
        horizon = np.array([1.0, 0.55, 0.3]) * rng.uniform(0.7, 1.0)
    haze = 0.0 if kind == 'room' else 1.0 / log_uniform(rng, 60, 2000)
    clouds = smooth_noise(rng, (64, 64), 4, octaves=3)
    return Atmosphere(zenith.astype(np.float32), horizon.astype(np.float32), haze,
                      cloud_cover=rng.uniform(0, 0.8), clouds=clouds, cloud_scale=rng.uniform(0.05, 0.3))


def sample_scene(seed, width=DEFAULT_SIZE[0], height=DEFAULT_SIZE[1], pool=None):
    """The scene of seed: deterministic for a given photo pool (default: the seed's split)."""
    rng = np.random.default_rng(seed)
    pool = pool if pool is not None else pool_for_seed(seed)
    kind = rng.choice(SCENE_KINDS, p=SCENE_KIND_ODDS)
    camera = sample_camera(rng, width, height, kind)
    sampler = SceneSampler(rng, pool, camera)
    background = {'open': sampler.open_land, 'street': sampler.street, 'room': sampler.room}[kind]()
    objects = background + sampler.foreground(int(rng.integers(5, 26)))
    return Scene(camera, objects, sample_light(rng, kind), sample_atmosphere(rng, kind))


def render_scene(seed, width=DEFAULT_SIZE[0], height=DEFAULT_SIZE[1]):
    """(rgb uint8 HxWx3, disparity float32 HxW): one random photo-like scene, exact 1/depth.

    Deterministic by seed; seeds >= 10**9 are validation scenes textured only with the
    validation photos, the others only with the training photos."""
    scene = sample_scene(seed, width, height)
    radiance, disparity = render(scene)
    rng = np.random.default_rng([seed, 1])      # the camera's own stream: edits to shading keep it
    return photograph(radiance, disparity, rng), disparity


class SceneDataset(torch.utils.data.Dataset):
    """Scenes seed_start .. seed_start + count - 1 as (image, disparity) tensors.

    image: float32 (3, H, W) in [0, 1]; disparity: float32 (1, H, W), 1 / depth in 1/metres,
    0 for sky. size = (width, height). The texture pool is loaded here, before a
    DataLoader forks its workers, so that they share it."""

    def __init__(self, seed_start, count, size=DEFAULT_SIZE):
        if is_validation_seed(seed_start) != is_validation_seed(seed_start + max(count, 1) - 1):
            raise ValueError(f'seeds {seed_start}..{seed_start + count - 1} mix training and validation')
        self.seed_start, self.count = seed_start, count
        self.width, self.height = size
        pool_for_seed(seed_start)

    def __len__(self):
        return self.count

    def __getitem__(self, index):
        if not 0 <= index < self.count:
            raise IndexError(f'scene {index} outside 0..{self.count - 1}')
        rgb, disparity = render_scene(self.seed_start + index, self.width, self.height)
        image = torch.from_numpy(rgb).permute(2, 0, 1).float().div_(255)
        return image, torch.from_numpy(disparity)[None]


# ----------------------------------------------------------------------------------
# Command line: benchmark and contact sheet

DISPARITY_COLOURS = np.array([        # far (dark violet) to near (pale yellow)
    [0.02, 0.02, 0.10], [0.30, 0.08, 0.50], [0.75, 0.20, 0.45], [0.98, 0.55, 0.18], [0.99, 0.95, 0.65]])


def colour_disparity(disparity):
    """uint8 RGB picture of disparity, normalised by its 99th percentile."""
    scale = max(float(np.percentile(disparity, 99)), 1e-6)
    x = np.clip(disparity / scale, 0, 1) * (len(DISPARITY_COLOURS) - 1)
    i = np.minimum(x.astype(np.int32), len(DISPARITY_COLOURS) - 2)
    f = (x - i)[..., None]
    rgb = DISPARITY_COLOURS[i] * (1 - f) + DISPARITY_COLOURS[i + 1] * f
    return (rgb * 255 + 0.5).astype(np.uint8)


def contact_sheet(path, seeds, tile=(192, 144), columns=3):
    """A grid of (photo | disparity) pairs, rendered at full size and shown downscaled."""
    tw, th = tile
    rows = math.ceil(len(seeds) / columns)
    sheet = np.full((rows * (th + 4), columns * (2 * tw + 8), 3), 255, dtype=np.uint8)
    for k, seed in enumerate(seeds):
        rgb, disparity = render_scene(seed)
        r, c = divmod(k, columns)
        y, x = r * (th + 4), c * (2 * tw + 8)
        for j, picture in enumerate((rgb, colour_disparity(disparity))):
            small = Image.fromarray(picture).resize(tile, Image.BILINEAR, reducing_gap=2.0)
            sheet[y:y + th, x + j * tw:x + (j + 1) * tw] = np.asarray(small)
    Image.fromarray(sheet).save(path, optimize=True)


def benchmark(count, workers, size):
    """Prints images per second, in this process and through a DataLoader.

    The machine is often shared, so the CPU time per image and the load average are
    printed too: 1000 / (CPU ms per image) is the rate of one core of one's own."""
    texture_pool('train')
    wall, cpu = time.perf_counter(), time.process_time()
    for seed in range(count):
        render_scene(seed, *size)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f'render_scene {size[0]}x{size[1]}: {count / wall:.1f} images/s in one process, '
          f'{1000 * cpu / count:.1f} ms of CPU per image ({count / cpu:.1f} images/s per free core)')
    if workers > 0:
        loader = torch.utils.data.DataLoader(SceneDataset(count, count, size), batch_size=8,
                                             num_workers=workers)
        start = time.perf_counter()
        for _ in loader:
            pass
        rate = count / (time.perf_counter() - start)
        print(f'SceneDataset + DataLoader, {workers} workers: {rate:.1f} images/s')
    print('load average (1, 5, 15 min): {:.1f} {:.1f} {:.1f} on {} cores'.format(*os.getloadavg(), os.cpu_count()))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--bench', type=int, nargs='?', const=200, metavar='COUNT',
                        help='render COUNT scenes (default 200) and print images/s')
    parser.add_argument('--workers', type=int, default=2, help='DataLoader workers for --bench')
    parser.add_argument('--size', type=int, nargs=2, default=DEFAULT_SIZE, metavar=('W', 'H'))
    parser.add_argument('--contact-sheet', metavar='PNG', help='write a grid of sample scenes')
    parser.add_argument('--seeds', type=int, nargs='+', default=list(range(12)),
                        help='seeds shown on the contact sheet')
    args = parser.parse_args(argv)
    if args.bench is None and args.contact_sheet is None:
        parser.error('nothing to do: give --bench and/or --contact-sheet')
    try:
        if args.contact_sheet:
            contact_sheet(args.contact_sheet, args.seeds)
        if args.bench is not None:
            benchmark(args.bench, args.workers, tuple(args.size))
    except (RuntimeError, ValueError, OSError) as error:
        print(f'scenes.py: {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
