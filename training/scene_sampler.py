"""The scene sampler: draws one random scene (camera, background, objects, light, sky)
from a seed, as a raytracer.Scene that nothing has rendered yet.

What a scene is made of, and with what odds, is written up in SCENES.md. Every draw
comes from numpy.random.default_rng(seed), in a fixed order: a change here changes the
scenes of every seed, and with them the training data.
"""

import math

import numpy as np

from outlines import random_mask, skyline_mask, smooth_noise
from raytracer import Atmosphere, Camera, Light, Scene, SceneObject
from shapes import Box, Cylinder, Quad, Sphere, ground_plane, rotation_x, rotation_y, rotation_z
from textures import Material, pool_for_seed

OBJECT_TEXTURE_SKIP_TOP = 0.3     # object crops start below the top 30% of a photo (its sky)
GROUND_TEXTURE_SKIP_TOP = 0.5     # ground crops from the photo's lower half where they fit
WALL_STREAK_ODDS = 0.3            # walls and facades streaked vertically this often
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


def sample_scene(seed, width, height, pool=None):
    """The scene of seed: deterministic for a given photo pool (default: the seed's split)."""
    rng = np.random.default_rng(seed)
    pool = pool if pool is not None else pool_for_seed(seed)
    kind = rng.choice(SCENE_KINDS, p=SCENE_KIND_ODDS)
    camera = sample_camera(rng, width, height, kind)
    sampler = SceneSampler(rng, pool, camera)
    background = {'open': sampler.open_land, 'street': sampler.street, 'room': sampler.room}[kind]()
    objects = background + sampler.foreground(int(rng.integers(5, 26)))
    return Scene(camera, objects, sample_light(rng, kind), sample_atmosphere(rng, kind))
