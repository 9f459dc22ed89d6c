#!/usr/bin/env python3
"""Writes geomdl_halving.json: interval halving done by geomdl's single knot insertion
(operations.insert_knot, one midpoint of every knot span of the domain at a time), the
reference tests/nurbs_knot_intervals.rs compares nurbsx's `refine --halve` with.

Regenerate (from the repository root):

    pip install geomdl==5.4.0
    python3 tests/data/knot_intervals/make_geomdl_halving.py

Knot vectors lie in [0, 1] (geomdl normalises others).
"""
import json
import os

import geomdl
from geomdl import BSpline, NURBS, operations


def halve(curve):
    p = curve.degree
    kv = list(curve.knotvector)
    domain = kv[p:len(kv) - p]
    mids = [a + (b - a) * 0.5 for a, b in zip(domain, domain[1:]) if a < b]
    for u in mids:
        operations.insert_knot(curve, [u], [1])
    return mids


def as_json(curve, rational):
    out = {
        "degree": curve.degree,
        "knots": list(curve.knotvector),
        "control_points": [list(p) for p in curve.ctrlpts],
    }
    if rational:
        out["weights"] = list(curve.weights)
    return out


def case(name, curve, rational):
    before = as_json(curve, rational)
    mids = halve(curve)
    return {"name": name, "curve": before, "midpoints": mids, "halved": as_json(curve, rational)}


def main():
    cubic = BSpline.Curve()
    cubic.degree = 3
    cubic.ctrlpts = [[0, 0, 0], [1, 2, 0], [3, 3, 0.5], [5, 1, 1], [7, 2.5, 0], [8, 0, -1]]
    cubic.knotvector = [0, 0, 0, 0, 0.25, 0.5, 1, 1, 1, 1]

    quad = NURBS.Curve()
    quad.degree = 2
    w = 0.7071067811865476
    quad.ctrlptsw = [[1, 0, 0, 1], [w, w, 0, w], [0, 1, 0, 1], [-1, 1, 0, 1], [-2, 0.5, 0, 1]]
    quad.knotvector = [0, 0, 0, 0.3, 0.7, 1, 1, 1]

    out = {
        "geomdl": geomdl.__version__,
        "cases": [case("cubic", cubic, False), case("rational quadratic", quad, True)],
    }
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "geomdl_halving.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
