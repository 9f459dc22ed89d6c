"""FreeCAD's own reading of a STEP or IGES file, as JSON (the nurbsx reference reader).

Run headless with FreeCAD's command-line interpreter; freecadcmd swallows argv, so the
paths come from environment variables:

    NURBSX_IN=path/to/file.step NURBSX_OUT=path/to/reading.json freecadcmd scripts/freecad/evaluate.py

The file is re-imported with ``Part.read`` (OCCT STEPControl_Reader / IGESControl_Reader,
FreeCAD's default import path for a plain shape).  Every edge whose 3D curve is a
``Part.BSplineCurve`` and every face whose surface is a ``Part.BSplineSurface`` is
described: its full definition (degree, knots, multiplicities, poles, weights, flags,
parameter range) plus evaluations at fixed parameters, all numbers written with Python's
``repr`` (shortest string that round-trips the IEEE double exactly).

The same module is imported by samples/freecad/generate.py so that there is one reader.
"""

import json
import math
import os
import sys

import FreeCAD  # noqa: F401  (provided by freecadcmd)
import Part

SCHEMA_ID = "nurbsx-freecad-reading/1"

ORDER_RULE = (
    "curves: edges of the re-imported shape in Part.Shape.Edges order (OCCT "
    "TopExp::MapShapes order: depth-first traversal of the shape, each distinct edge once at its "
    "first occurrence), keeping only edges whose Edge.Curve is a BSplineCurve; "
    "edge_index is the 0-based position in Shape.Edges. "
    "surfaces: faces in Part.Shape.Faces order (same rule), keeping only faces whose "
    "Face.Surface is a BSplineSurface; face_index is the 0-based position in Shape.Faces."
)

PARAMETER_SPACE = (
    "All parameters and evaluations are in the parameter space of the geometry as FreeCAD/OCCT "
    "holds it AFTER re-import (Edge.Curve / Face.Surface, i.e. the underlying untrimmed "
    "Geom_BSplineCurve / Geom_BSplineSurface), not of the curve that was originally built or "
    "written. OCCT may have clamped (IGES Segment), re-periodised (STEP closed curves), "
    "unperiodised (export), shifted or re-scaled parameters (units). Curves are evaluated at 9 "
    "parameters t_i = first + (last - first) * i / 8, i = 0..8 (t_8 = last exactly) over "
    "[first_parameter, last_parameter] of the geometry (NOT the edge range). Surfaces are "
    "evaluated on a 5x5 grid u_i = u0 + (u1 - u0) * i / 4, v_j likewise (ends exact) over "
    "Surface.bounds() = (u0, u1, v0, v1); grid order: u outer, v inner. Derivatives are "
    "with respect to these parameters (Curve.getDN(t, n), Surface.getDN(u, v, nu, nv)). "
    "Coordinates are in millimetres (OCCT converts the file's length unit to mm on read)."
)


def _vec(v):
    """A FreeCAD vector as a list of three floats."""
    return [float(v.x), float(v.y), float(v.z)]


def _params(a, b, n):
    """n parameters evenly spaced over [a, b], ends exact."""
    out = []
    for i in range(n):
        if i == 0:
            out.append(float(a))
        elif i == n - 1:
            out.append(float(b))
        else:
            out.append(float(a) + (float(b) - float(a)) * i / (n - 1))
    return out


def _safe(fn, *args):
    """Call fn; on failure (e.g. undefined normal at a pole) return None."""
    try:
        r = fn(*args)
    except Exception:  # OCCT raises Base.FreeCADError / Part.OCCError
        return None
    v = _vec(r)
    if any(math.isnan(x) or math.isinf(x) for x in v):
        return None
    return v


def describe_curve(c):
    """Definition and evaluations of one Part.BSplineCurve."""
    first = float(c.FirstParameter)
    last = float(c.LastParameter)
    evals = []
    for t in _params(first, last, 9):
        evals.append(
            {
                "t": t,
                "point": _vec(c.value(t)),
                "d1": _safe(c.getDN, t, 1),
                "d2": _safe(c.getDN, t, 2),
            }
        )
    return {
        "degree": int(c.Degree),
        "periodic": bool(c.isPeriodic()),
        "rational": bool(c.isRational()),
        "closed": bool(c.isClosed()),
        "knots": [float(k) for k in c.getKnots()],
        "multiplicities": [int(m) for m in c.getMultiplicities()],
        "knot_sequence": [float(k) for k in c.KnotSequence],
        "poles": [_vec(p) for p in c.getPoles()],
        "weights": [float(w) for w in c.getWeights()],
        "first_parameter": first,
        "last_parameter": last,
        "evaluations": evals,
    }


def describe_surface(s):
    """Definition and evaluations of one Part.BSplineSurface."""
    u0, u1, v0, v1 = (float(x) for x in s.bounds())
    evals = []
    for u in _params(u0, u1, 5):
        for v in _params(v0, v1, 5):
            evals.append(
                {
                    "u": u,
                    "v": v,
                    "point": _vec(s.value(u, v)),
                    "su": _safe(s.getDN, u, v, 1, 0),
                    "sv": _safe(s.getDN, u, v, 0, 1),
                    "suu": _safe(s.getDN, u, v, 2, 0),
                    "suv": _safe(s.getDN, u, v, 1, 1),
                    "svv": _safe(s.getDN, u, v, 0, 2),
                    "normal": _safe(s.normal, u, v),
                }
            )
    poles = s.getPoles()
    weights = s.getWeights()
    return {
        "u_degree": int(s.UDegree),
        "v_degree": int(s.VDegree),
        "u_periodic": bool(s.isUPeriodic()),
        "v_periodic": bool(s.isVPeriodic()),
        "u_rational": bool(s.isURational()),
        "v_rational": bool(s.isVRational()),
        "u_closed": bool(s.isUClosed()),
        "v_closed": bool(s.isVClosed()),
        "u_knots": [float(k) for k in s.getUKnots()],
        "u_multiplicities": [int(m) for m in s.getUMultiplicities()],
        "v_knots": [float(k) for k in s.getVKnots()],
        "v_multiplicities": [int(m) for m in s.getVMultiplicities()],
        "u_knot_sequence": [float(k) for k in s.UKnotSequence],
        "v_knot_sequence": [float(k) for k in s.VKnotSequence],
        "nb_u_poles": int(s.NbUPoles),
        "nb_v_poles": int(s.NbVPoles),
        "poles": [[_vec(p) for p in row] for row in poles],
        "weights": [[float(w) for w in row] for row in weights],
        "bounds": [u0, u1, v0, v1],
        "evaluations": evals,
    }


def _type_name(g):
    return type(g).__name__ if g is not None else "None"


def describe_shape(shape):
    """The reading of an in-memory shape (no file fields)."""
    curves = []
    other_curves = {}
    for i, e in enumerate(shape.Edges):
        try:
            g = e.Curve
        except Exception:  # degenerated edges (sphere poles) have no 3D curve
            g = None
        if isinstance(g, Part.BSplineCurve):
            d = {"edge_index": i}
            d["edge_range"] = [float(x) for x in e.ParameterRange]
            d.update(describe_curve(g))
            curves.append(d)
        else:
            key = _type_name(g)
            other_curves[key] = other_curves.get(key, 0) + 1
    surfaces = []
    other_surfaces = {}
    for i, f in enumerate(shape.Faces):
        g = f.Surface
        if isinstance(g, Part.BSplineSurface):
            d = {"face_index": i}
            d["face_range"] = [float(x) for x in f.ParameterRange]
            d["face_wires"] = len(f.Wires)
            d.update(describe_surface(g))
            surfaces.append(d)
        else:
            key = _type_name(g)
            other_surfaces[key] = other_surfaces.get(key, 0) + 1
    return {
        "shape_type": shape.ShapeType if not shape.isNull() else "Null",
        "counts": {
            "solids": len(shape.Solids),
            "shells": len(shape.Shells),
            "faces": len(shape.Faces),
            "wires": len(shape.Wires),
            "edges": len(shape.Edges),
            "bspline_curves": len(curves),
            "bspline_surfaces": len(surfaces),
            "other_curves": dict(sorted(other_curves.items())),
            "other_surfaces": dict(sorted(other_surfaces.items())),
        },
        "curves": curves,
        "surfaces": surfaces,
    }


def versions():
    """FreeCAD and OCCT versions as strings."""
    v = FreeCAD.Version()
    return ".".join(v[0:3]), str(Part.OCC_VERSION)


def read_file(path):
    """Re-import path (STEP or IGES) with Part.read and describe it."""
    shape = Part.read(path)
    fc, occt = versions()
    ext = os.path.splitext(path)[1].lower()
    fmt = "step" if ext in (".step", ".stp") else "iges" if ext in (".igs", ".iges") else ext
    out = {
        "schema": SCHEMA_ID,
        "file": os.path.basename(path),
        "format": fmt,
        "reader": "Part.read",
        "freecad_version": fc,
        "occt_version": occt,
        "order_rule": ORDER_RULE,
        "parameter_space": PARAMETER_SPACE,
    }
    out.update(describe_shape(shape))
    return out


def _fmt(obj, ind):
    """JSON text: objects one key a line, lists of scalars (and of 3-vectors) on one line."""
    pad = " " * ind
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [
            pad + " " + json.dumps(k) + ": " + _fmt(v, ind + 1) for k, v in obj.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list):
        flat = all(not isinstance(x, (dict, list)) for x in obj)
        vecs = all(
            isinstance(x, list) and all(not isinstance(y, (dict, list)) for y in x) for x in obj
        )
        if flat or (vecs and len(obj) <= 3):
            return json.dumps(obj, allow_nan=False, separators=(",", ":"))
        items = [pad + " " + _fmt(x, ind + 1) for x in obj]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(obj, allow_nan=False)


def dumps(obj):
    """Deterministic JSON text; key order is the schema order, floats use repr (exact)."""
    return _fmt(obj, 0) + "\n"


def run_cli(read, schema, script):
    """Read NURBSX_IN with read(path), write dumps(...) to NURBSX_OUT; exit status 0 on
    success, 1 on failure, 2 on usage (shared by the readers in scripts/freecad/).

    freecadcmd itself exits 0 even when a script raises, so failures end the process with
    os._exit after writing {"schema", "file", "error"} to NURBSX_OUT (when given).
    """
    src = os.environ.get("NURBSX_IN")
    dst = os.environ.get("NURBSX_OUT")
    if not src or not dst:
        print(f"usage: NURBSX_IN=file.step|file.igs NURBSX_OUT=out.json freecadcmd {script}")
        sys.stdout.flush()
        os._exit(2)
    try:
        text = dumps(read(src))
        status = 0
    except Exception as ex:  # report every reader failure to the caller as data
        text = dumps({"schema": schema, "file": os.path.basename(src), "error": str(ex)})
        status = 1
    with open(dst, "w", encoding="utf-8") as f:
        f.write(text)
    sys.stdout.flush()
    os._exit(status)


def main():
    run_cli(read_file, SCHEMA_ID, "evaluate.py")


# freecadcmd runs a script under the name of its file stem ("evaluate"), or "__main__" with
# some launchers; generate.py loads this file under another module name, so it does not run.
if __name__ in ("__main__", "evaluate"):
    main()
