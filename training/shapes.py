"""Geometry for the ray tracer: vector helpers, rotations and the analytic shapes.

World frame: x right, y up, z forward (the camera looks along +z before pitch); the
ground is the plane y = 0; lengths are metres. Every shape answers the same three
questions (see the Shapes section), so raytracer.py treats them all alike.
"""

import math

import numpy as np


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
