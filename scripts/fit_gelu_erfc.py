#!/usr/bin/env python3
"""Reproduces GELU's erfc polynomial (kernels/exp_polynomials.h, namespace erfc_poly).

gelu(x) = x Phi(x) is evaluated through the tail h(u) = Phi(-u) = erfc(u / sqrt 2) / 2,
u = |x|, written as h(u) = exp(-u^2 / 2) Q(u). Q(u) = h(u) exp(u^2 / 2) is smooth, so a
polynomial in t = u - CENTRE fits it on [0, MAX_ARG] with no division at run time.

The fit minimises the largest error of h itself, |exp(-u^2/2) (P(u) - Q(u))|, by Lawson's
iteratively reweighted least squares (which converges to the minimax fit) on Chebyshev
nodes, in 40-digit arithmetic (mpmath, no numpy needed). The coefficients are then
rounded to float32 from the highest degree down, the lower ones refitted after each
rounding so they absorb it. Finally h is evaluated the way the scalar reference does it
(Horner in float32, no fused multiply-add) on a dense grid and its worst error printed.

usage: python3 scripts/fit_gelu_erfc.py   (about ten seconds)
"""
import struct

import mpmath as mp

MAX_ARG = 5.65  # erfc(MAX_ARG / sqrt 2) / 2 < 1e-8: past it Q is held constant
CENTRE = 2.825  # the middle of [0, MAX_ARG]: keeps every term small against Q
DEGREE = 12
NODES = 300
LAWSON_STEPS = 40

mp.mp.dps = 40


def f32(x):
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def q_exact(u):
    return mp.erfc(u / mp.sqrt(2)) * mp.exp(u * u / 2) / 2


def powers(u):
    t = u - CENTRE
    return [t**k for k in range(DEGREE + 1)]


def weighted_fit(nodes, targets, weights, fixed):
    """Least squares for the coefficients not in `fixed` (degree -> value), lowest first."""
    free = [k for k in range(DEGREE + 1) if k not in fixed]
    m = mp.matrix(len(free), len(free))
    b = mp.matrix(len(free), 1)
    for u, target, weight in zip(nodes, targets, weights):
        pw = powers(u)
        residual = target - sum(v * pw[k] for k, v in fixed.items())
        for r, kr in enumerate(free):
            b[r] += weight * pw[kr] * residual
            for c, kc in enumerate(free):
                m[r, c] += weight * pw[kr] * pw[kc]
    solution = mp.lu_solve(m, b)
    coefficients = dict(fixed)
    for i, k in enumerate(free):
        coefficients[k] = solution[i]
    return coefficients


def main():
    nodes = [MAX_ARG / 2 * (1 - mp.cos(mp.pi * (k + 0.5) / NODES)) for k in range(NODES)]
    targets = [q_exact(u) for u in nodes]
    # The error that matters is h's: Q's error scaled by exp(-u^2 / 2).
    scale = [mp.exp(-u * u / 2) for u in nodes]
    lawson = [mp.mpf(1)] * NODES
    for _ in range(LAWSON_STEPS):
        weights = [w * s * s for w, s in zip(lawson, scale)]
        coefficients = weighted_fit(nodes, targets, weights, {})
        errors = [s * abs(sum(coefficients[k] * p for k, p in enumerate(powers(u))) - t)
                  for u, t, s in zip(nodes, targets, scale)]
        total = sum(w * e for w, e in zip(lawson, errors))
        lawson = [w * e / total for w, e in zip(lawson, errors)]
    print("minimax error of h (exact arithmetic): %.3g" % float(max(errors)))

    weights = [w * s * s for w, s in zip(lawson, scale)]
    fixed = {}
    for degree in range(DEGREE, -1, -1):
        fixed[degree] = f32(coefficients[degree])
        if degree > 0:
            coefficients = weighted_fit(nodes, targets, weights, fixed)
    q = [fixed[k] for k in range(DEGREE + 1)]

    def h_in_float(u):
        t = f32(f32(min(u, MAX_ARG)) - CENTRE)
        p = q[DEGREE]
        for k in range(DEGREE - 1, -1, -1):
            p = f32(f32(p * t) + q[k])
        return mp.exp(-u * u / 2) * p

    worst = max(abs(h_in_float(f32(7.0 * i / 3999)) - q_exact(f32(7.0 * i / 3999)) *
                    mp.exp(-f32(7.0 * i / 3999) ** 2 / 2)) for i in range(4000))
    print("worst error of h evaluated in float32 on [0, 7]: %.3g" % float(worst))
    print("constexpr float kQ[] = {" + ", ".join(repr(c) + "f" for c in reversed(q)) + "};")


if __name__ == "__main__":
    main()
