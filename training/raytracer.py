"""The ray tracer: a pinhole camera, the description of a scene, and its exact
rendering into linear radiance and disparity.

Every pixel's ray is intersected analytically with every shape whose screen box holds
the pixel, so occlusions and disparity (1 / camera depth) are exact. Surfaces are lit by
one directional light with cast shadows and a sky term, hazed with distance; rays that
hit nothing see the sky.

Camera frame: x right, y down, z forward. A ray direction has camera-z component 1, so
the ray parameter t of a hit is the hit's camera depth and its disparity is exactly
1 / t; the sky has disparity 0.
"""

import functools
import math
from dataclasses import dataclass

import numpy as np

from shapes import dot, rotation_x, rotation_y, rotation_z
from textures import Material, mirror

NEAR_CLIP = 0.05                  # metres: nothing nearer than this is rendered
SHADOW_BIAS = 1e-3                # metres: shadow rays start this far along the light
MIN_GRAZING_COS = 0.15            # caps the texture footprint growth at grazing angles


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
# Light, atmosphere and the scene

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
