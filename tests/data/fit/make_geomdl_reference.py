#!/usr/bin/env python3
"""Writes geomdl_reference.json: least-squares curve and surface approximations (and a
surface interpolation) computed by geomdl, the reference tests/nurbs_fit.rs compares
nurbsx's fits with.

Regenerate (from the repository root):

    pip install geomdl==5.4.0
    python3 tests/data/fit/make_geomdl_reference.py

The data points come from random.Random with fixed seeds, so the output is the same on every
run. For each case the file holds the data points, geomdl's parameters, knots and poles,
and the residual (largest and root-mean-square distance of the data points from geomdl's
result at geomdl's parameters, evaluated by geomdl).
"""
import json
import math
import os
import random

import geomdl
from geomdl import fitting


def curve_points(seed, count, dim):
    rng = random.Random(seed)
    out = []
    for k in range(count):
        s = 4.0 * math.pi * k / (count - 1)
        p = [3.0 * math.cos(s) + 0.2 * rng.uniform(-1, 1),
             2.0 * math.sin(s) + 0.2 * rng.uniform(-1, 1),
             0.5 * s + 0.1 * rng.uniform(-1, 1)]
        out.append(p[:dim])
    return out


def grid_points(seed, nu, nv):
    rng = random.Random(seed)
    out = []
    for i in range(nu):
        for j in range(nv):
            x = 5.0 * i / (nu - 1) + 0.05 * rng.uniform(-1, 1)
            y = 4.0 * j / (nv - 1) + 0.05 * rng.uniform(-1, 1)
            z = math.sin(x) * math.cos(0.8 * y) + 0.1 * rng.uniform(-1, 1)
            out.append([x, y, z])
    return out


def residual(distances):
    return max(distances), math.sqrt(sum(d * d for d in distances) / len(distances))


def curve_case(seed, count, dim, degree, poles, centripetal):
    q = curve_points(seed, count, dim)
    c = fitting.approximate_curve(q, degree, ctrlpts_size=poles, centripetal=centripetal)
    uk = fitting.compute_params_curve(q, centripetal)
    d = [math.dist(c.evaluate_single(u), p) for u, p in zip(uk, q)]
    rmax, rrms = residual(d)
    return {"points": q, "degree": degree, "poles": poles,
            "params": "centripetal" if centripetal else "chord",
            "parameters": uk, "knots": list(c.knotvector), "control_points": c.ctrlpts,
            "residual_max": rmax, "residual_rms": rrms}


def surface_case(seed, nu, nv, degrees, poles, centripetal):
    q = grid_points(seed, nu, nv)
    if poles is None:
        s = fitting.interpolate_surface(q, nu, nv, degrees[0], degrees[1], centripetal=centripetal)
    else:
        s = fitting.approximate_surface(q, nu, nv, degrees[0], degrees[1], centripetal=centripetal,
                                        ctrlpts_size_u=poles[0], ctrlpts_size_v=poles[1])
    uk, vl = fitting.compute_params_surface(q, nu, nv, centripetal)
    d = [math.dist(s.evaluate_single((uk[i], vl[j])), q[j + nv * i])
         for i in range(nu) for j in range(nv)]
    rmax, rrms = residual(d)
    return {"grid": [q[i * nv:(i + 1) * nv] for i in range(nu)],
            "degree": list(degrees), "poles": poles,
            "params": "centripetal" if centripetal else "chord",
            "parameters_u": uk, "parameters_v": vl,
            "knots_u": list(s.knotvector_u), "knots_v": list(s.knotvector_v),
            "control_points": s.ctrlpts, "poles_uv": [s.ctrlpts_size_u, s.ctrlpts_size_v],
            "residual_max": rmax, "residual_rms": rrms}


def main():
    out = {
        "geomdl": geomdl.__version__,
        "curves": [
            curve_case(1, 40, 3, 3, 10, False),
            curve_case(2, 40, 3, 2, 7, True),
            curve_case(3, 25, 2, 4, 12, False),
            curve_case(4, 30, 3, 3, 4, False),
            curve_case(5, 200, 3, 5, 41, True),
        ],
        "surfaces": [
            surface_case(6, 12, 9, (3, 2), [7, 5], False),
            surface_case(7, 10, 11, (2, 3), [6, 6], True),
            surface_case(8, 8, 6, (3, 3), None, False),
        ],
    }
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "geomdl_reference.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


main()
