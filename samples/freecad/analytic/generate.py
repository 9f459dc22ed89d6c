"""Deterministic generator of the analytic-geometry sample corpus (STEP + IGES + readings).

Regenerate (any working directory):

    freecadcmd samples/freecad/analytic/generate.py

Writes, into the directory of this script, for every case:
  <case>.step, <case>.igs [, <case>_brep.igs]   exported by FreeCAD, time stamps normalised
  <case>.step.json, <case>.igs.json [, <case>_brep.igs.json]
                                                FreeCAD's reading after RE-IMPORT (Part.read)
  <case>.source.json                            the same reading of the in-memory shape
and index.json (cases, export options, entity types written per file).
The JSON schema ("nurbsx-freecad-analytic/1") and FreeCAD's parameterisation of every geometry
type are described in README.md next to this file; every sample is checked here against those
formulas before anything is written.

Export, time-stamp normalisation and the B-spline descriptions are those of
samples/freecad/generate.py and scripts/freecad/evaluate.py (imported, not copied).
NURBSX_ONLY=case1,case2 regenerates a subset (STEP PRODUCT counters then differ; experiments
only, index.json is not rewritten).
"""

import importlib.util
import math
import os
import re
import sys
import traceback

import FreeCAD
import Part

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))


def _load(name, path):
    """Load a sibling script as a module under a name that does not run its main()."""
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


evaluate = _load("nurbsx_freecad_reader", os.path.join(ROOT, "scripts", "freecad", "evaluate.py"))
corpus = _load("nurbsx_freecad_samples", os.path.join(ROOT, "samples", "freecad", "generate.py"))

SCHEMA_ID = "nurbsx-freecad-analytic/1"
V = FreeCAD.Vector

SAMPLING = (
    "edges: 7 parameters t_i = range[0] + (range[1] - range[0]) * i / 6, i = 0..6 (t_6 = "
    "range[1] exactly) over the EDGE's parameter range, evaluated on Edge.Curve (value, "
    "getDN(t, 1), getDN(t, 2)). faces: 5x5 grid u_i = u0 + (u1 - u0) * i / 4, v_j likewise "
    "(ends exact) over Face.ParameterRange, u outer, v inner, evaluated on Face.Surface "
    "(value, getDN(u, v, 1, 0), (0, 1), (2, 0), (1, 1), (0, 2), normal). Parameters are those "
    "of the geometry as FreeCAD holds it (see README.md for each type's parameterisation); "
    "coordinates in mm."
)

UNIT_MM = {"MM": 1.0, "INCH": 25.4, "M": 1000.0}


# ----------------------------------------------------------------------------- description
def _type(g):
    return "Part." + type(g).__name__ if g is not None else "None"


def _frame_of_rotation(g):
    """(x_axis, y_axis, axis) of an elementary surface from its Rotation and Axis."""
    rot = g.Rotation
    return rot.multVec(V(1, 0, 0)), rot.multVec(V(0, 1, 0)), V(g.Axis)


# Trimmed conics (Geom_TrimmedCurve over a conic) and the FreeCAD attribute of their basis.
ARCS = {Part.ArcOfCircle: "Circle", Part.ArcOfEllipse: "Ellipse",
        Part.ArcOfHyperbola: "Hyperbola", Part.ArcOfParabola: "Parabola"}


def describe_curve_geometry(c):
    """The defining data of one curve (README: edges[].curve)."""
    vec = evaluate._vec
    d = {"type": _type(c)}
    if isinstance(c, Part.Line):
        d.update(location=vec(c.Location), direction=vec(c.Direction))
    elif isinstance(c, Part.Circle):
        d.update(center=vec(c.Center), axis=vec(c.Axis), x_axis=vec(c.XAxis),
                 y_axis=vec(c.YAxis), radius=float(c.Radius))
    elif isinstance(c, (Part.Ellipse, Part.Hyperbola)):
        d.update(center=vec(c.Center), axis=vec(c.Axis), x_axis=vec(c.XAxis),
                 y_axis=vec(c.YAxis), major_radius=float(c.MajorRadius),
                 minor_radius=float(c.MinorRadius))
    elif isinstance(c, Part.Parabola):
        d.update(vertex=vec(c.Location), axis=vec(c.Axis), x_axis=vec(c.XAxis),
                 y_axis=vec(c.YAxis), focal=float(c.Focal))
    elif isinstance(c, Part.LineSegment):
        # OCCT's trimmed line; its basis line is not exposed by FreeCAD, but a trimmed curve
        # evaluates through its basis at any parameter, so location = value(0).
        d.update(first_parameter=float(c.FirstParameter), last_parameter=float(c.LastParameter),
                 start_point=vec(c.StartPoint), end_point=vec(c.EndPoint),
                 basis_curve={"type": "Part.Line", "location": vec(c.value(0.0)),
                              "direction": vec(c.getDN(float(c.FirstParameter), 1))})
    elif isinstance(c, tuple(ARCS)):
        basis = getattr(c, ARCS[type(c)])
        d.update(first_parameter=float(c.FirstParameter), last_parameter=float(c.LastParameter),
                 basis_curve=describe_curve_geometry(basis))
    elif isinstance(c, Part.BSplineCurve):
        b = evaluate.describe_curve(c)
        del b["evaluations"]
        d.update(b)
    else:
        d.update(first_parameter=float(c.FirstParameter), last_parameter=float(c.LastParameter))
    return d


def describe_surface_geometry(s):
    """The defining data of one surface (README: faces[].surface); frame handedness decided
    by the surface's own value (_frame_matches)."""
    vec = evaluate._vec
    d = {"type": _type(s)}
    elementary = (Part.Plane, Part.Cylinder, Part.Cone, Part.Sphere, Part.Toroid)
    if isinstance(s, elementary):
        x, y, z = _frame_of_rotation(s)
        loc = s.Position if isinstance(s, Part.Plane) else s.Center
        d.update(location=vec(loc))
        if isinstance(s, Part.Cone):
            d["apex"] = vec(s.Apex)
        d.update(axis=vec(z), x_axis=vec(x), y_axis=vec(y), direct=True)
        if isinstance(s, (Part.Cylinder, Part.Cone, Part.Sphere)):
            d["radius"] = float(s.Radius)
        if isinstance(s, Part.Cone):
            d["semi_angle"] = float(s.SemiAngle)
        if isinstance(s, Part.Toroid):
            d.update(major_radius=float(s.MajorRadius), minor_radius=float(s.MinorRadius))
        # OCCT allows a left-handed frame (Y = -Z x X); FreeCAD's Rotation cannot express
        # one, so the sign of Y is taken from the surface itself at u = pi/2.
        if not _frame_matches(s, d):
            d["y_axis"] = [-c for c in d["y_axis"]]
            d["direct"] = False
            if not _frame_matches(s, d):
                raise RuntimeError(f"{d['type']}: frame of Rotation does not fit the surface")
    elif isinstance(s, Part.SurfaceOfRevolution):
        d.update(location=vec(s.Location), direction=vec(s.Direction),
                 basis_curve=describe_curve_geometry(s.BasisCurve))
    elif isinstance(s, Part.SurfaceOfExtrusion):
        d.update(direction=vec(s.Direction), basis_curve=describe_curve_geometry(s.BasisCurve))
    elif isinstance(s, Part.BSplineSurface):
        b = evaluate.describe_surface(s)
        del b["evaluations"]
        d.update(b)
    else:
        d.update(bounds=[float(b) for b in s.bounds()])
    return d


def _frame_matches(s, d):
    u, v = 0.5 * math.pi, 0.0
    if isinstance(s, Part.Sphere):
        v = 0.25
    want = surface_formula(d, u, v)
    got = s.value(u, v)
    return (got - V(*want)).Length <= 1e-9 * (1.0 + V(*want).Length)


# ----------------------------------------------------------------------------- formulas
# FreeCAD/OCCT's parameterisation of each type as documented in README.md. Used to check
# every sample before it is written, so that the documented formulas are FreeCAD's behaviour.
def _add(*terms):
    return [sum(t[k] for t in terms) for k in range(3)]


def _mul(a, v):
    return [a * x for x in v]


def _sub(a, b):
    return [x - y for x, y in zip(a, b)]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def curve_formula(d, t):
    """Point of the documented parameterisation; None for types without a closed form."""
    ty = d["type"]
    if ty == "Part.LineSegment" or ty.startswith("Part.ArcOf"):
        return curve_formula(d["basis_curve"], t)
    if ty == "Part.Line":
        return _add(d["location"], _mul(t, d["direction"]))
    if ty == "Part.Circle":
        r = d["radius"]
        return _add(d["center"], _mul(r * math.cos(t), d["x_axis"]),
                    _mul(r * math.sin(t), d["y_axis"]))
    if ty == "Part.Ellipse":
        return _add(d["center"], _mul(d["major_radius"] * math.cos(t), d["x_axis"]),
                    _mul(d["minor_radius"] * math.sin(t), d["y_axis"]))
    if ty == "Part.Hyperbola":
        return _add(d["center"], _mul(d["major_radius"] * math.cosh(t), d["x_axis"]),
                    _mul(d["minor_radius"] * math.sinh(t), d["y_axis"]))
    if ty == "Part.Parabola":
        return _add(d["vertex"], _mul(t * t / (4.0 * d["focal"]), d["x_axis"]),
                    _mul(t, d["y_axis"]))
    return None


def surface_formula(d, u, v, geom=None):
    """Point of the documented parameterisation; None for types without a closed form here.
    geom: the FreeCAD surface, whose basis curve evaluates revolution / extrusion profiles."""
    ty = d["type"]
    if ty == "Part.Plane":
        return _add(d["location"], _mul(u, d["x_axis"]), _mul(v, d["y_axis"]))
    if ty in ("Part.Cylinder", "Part.Cone", "Part.Sphere", "Part.Toroid"):
        X, Y, Z = d["x_axis"], d["y_axis"], d["axis"]
        ring = _add(_mul(math.cos(u), X), _mul(math.sin(u), Y))
        if ty == "Part.Cylinder":
            return _add(d["location"], _mul(d["radius"], ring), _mul(v, Z))
        if ty == "Part.Cone":
            a = d["semi_angle"]
            return _add(d["location"], _mul(d["radius"] + v * math.sin(a), ring),
                        _mul(v * math.cos(a), Z))
        if ty == "Part.Sphere":
            r = d["radius"]
            return _add(d["location"], _mul(r * math.cos(v), ring), _mul(r * math.sin(v), Z))
        big, small = d["major_radius"], d["minor_radius"]
        return _add(d["location"], _mul(big + small * math.cos(v), ring),
                    _mul(small * math.sin(v), Z))
    if ty == "Part.SurfaceOfRevolution" and geom is not None:
        c = evaluate._vec(geom.BasisCurve.value(v))
        L, A = d["location"], d["direction"]
        w = _sub(c, L)
        along = _mul(_dot(w, A), A)
        radial = _sub(w, along)
        return _add(L, along, _mul(math.cos(u), radial), _mul(math.sin(u), _cross(A, w)))
    if ty == "Part.SurfaceOfExtrusion" and geom is not None:
        return _add(evaluate._vec(geom.BasisCurve.value(u)), _mul(v, d["direction"]))
    return None


def _check(kind, d, params, point, size, geom):
    want = (curve_formula(d, *params) if kind == "curve"
            else surface_formula(d, *params, geom=geom))
    if want is None:
        return
    err = math.sqrt(sum((a - b) ** 2 for a, b in zip(want, point)))
    if not err <= 1e-9 * size:
        raise RuntimeError(f"{d['type']} at {params}: FreeCAD {point}, formula {want}, "
                           f"|diff| {err:.3g} > 1e-9 x {size:.3g}")


def describe_edge(i, e, size):
    vec, safe = evaluate._vec, evaluate._safe
    deg = bool(e.Degenerated)
    out = {"index": i, "orientation": e.Orientation, "degenerated": deg,
           "closed": bool(e.isClosed()), "vertices": [vec(p.Point) for p in e.Vertexes],
           "range": [float(e.FirstParameter), float(e.LastParameter)]}
    if deg:
        out.update(length=0.0, curve=None, samples=[])
        return out
    c = e.Curve
    out["length"] = float(e.Length)
    out["curve"] = describe_curve_geometry(c)
    samples = []
    for t in evaluate._params(out["range"][0], out["range"][1], 7):
        p = vec(c.value(t))
        _check("curve", out["curve"], (t,), p, size, c)
        samples.append({"t": t, "point": p, "d1": safe(c.getDN, t, 1), "d2": safe(c.getDN, t, 2)})
    out["samples"] = samples
    return out


def describe_face(i, f, shape_edges, size):
    vec, safe = evaluate._vec, evaluate._safe
    s = f.Surface
    u0, u1, v0, v1 = (float(x) for x in f.ParameterRange)
    edge_indices = []
    for fe in f.Edges:
        edge_indices.append(next(k for k, e in enumerate(shape_edges) if e.isSame(fe)))
    out = {"index": i, "orientation": f.Orientation, "range": [u0, u1, v0, v1],
           "area": float(f.Area), "wires": len(f.Wires), "edge_indices": edge_indices,
           "surface": describe_surface_geometry(s)}
    samples = []
    for u in evaluate._params(u0, u1, 5):
        for v in evaluate._params(v0, v1, 5):
            p = vec(s.value(u, v))
            _check("surface", out["surface"], (u, v), p, size, s)
            samples.append({"u": u, "v": v, "point": p,
                            "su": safe(s.getDN, u, v, 1, 0), "sv": safe(s.getDN, u, v, 0, 1),
                            "suu": safe(s.getDN, u, v, 2, 0), "suv": safe(s.getDN, u, v, 1, 1),
                            "svv": safe(s.getDN, u, v, 0, 2), "normal": safe(s.normal, u, v)})
    out["samples"] = samples
    return out


def describe_shape(shape):
    """shape_type, counts, edges and faces (README: top level, from shape_type on)."""
    size = 1.0 + shape.BoundBox.DiagonalLength
    edges = [describe_edge(i, e, size) for i, e in enumerate(shape.Edges)]
    faces = [describe_face(i, f, shape.Edges, size) for i, f in enumerate(shape.Faces)]
    curve_types, surface_types = {}, {}
    for e in edges:
        k = e["curve"]["type"] if e["curve"] else "None"
        curve_types[k] = curve_types.get(k, 0) + 1
    for f in faces:
        k = f["surface"]["type"]
        surface_types[k] = surface_types.get(k, 0) + 1
    return {
        "shape_type": shape.ShapeType,
        "counts": {"solids": len(shape.Solids), "shells": len(shape.Shells),
                   "faces": len(shape.Faces), "wires": len(shape.Wires),
                   "edges": len(shape.Edges), "curve_types": dict(sorted(curve_types.items())),
                   "surface_types": dict(sorted(surface_types.items()))},
        "edges": edges,
        "faces": faces,
    }


# ----------------------------------------------------------------------------- file facts
def step_entities(text):
    """Entity keyword -> count over the DATA section (complex instances as '(A B C)')."""
    data = text.split("DATA;", 1)[1]
    counts = {}
    for m in re.finditer(r"#\d+\s*=\s*(\(|[A-Z_0-9]+)", data):
        if m.group(1) != "(":
            name = m.group(1)
        else:
            # names at depth 1 of a complex instance (ISO 10303-21 external mapping); the
            # complex instances of these files are contexts and units, their strings (unit
            # names) hold no parentheses
            depth, j, names = 1, m.end(), []
            while depth > 0:
                ch = data[j]
                if ch == "(":
                    depth += 1
                elif ch == ")":
                    depth -= 1
                elif depth == 1 and (ch.isalpha() or ch == "_"):
                    k = j
                    while data[k].isalnum() or data[k] == "_":
                        k += 1
                    names.append(data[j:k])
                    j = k - 1
                j += 1
            name = "(" + " ".join(sorted(names)) + ")"
        counts[name] = counts.get(name, 0) + 1
    return dict(sorted(counts.items()))


def iges_records(text, letter):
    return [ln for ln in text.split("\n") if len(ln) >= 73 and ln[72] == letter]


def iges_entities(text):
    """Entity type number (string) -> count, from the first record of each DE pair."""
    counts = {}
    for ln in iges_records(text, "D"):
        if int(ln[73:80]) % 2 == 1:
            k = str(int(ln[0:8]))
            counts[k] = counts.get(k, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: int(kv[0])))


def iges_global(text):
    """Global-section parameters as strings (IGES 5.3 section 2.2.4: Hollerith nH...)."""
    g = "".join(ln[:72] for ln in iges_records(text, "G"))
    pd, rd = ",", ";"
    if g.startswith("1H"):
        pd = g[2]
    params, i = [], 0
    while i < len(g):
        m = re.match(r"\s*(\d+)H", g[i:])
        if m:
            n = int(m.group(1))
            start = i + m.end()
            params.append(g[start:start + n])
            i = start + n
        else:
            j = i
            while j < len(g) and g[j] not in (pd, rd):
                j += 1
            params.append(g[i:j].strip())
            i = j
        if i < len(g) and g[i] == rd:
            break
        i += 1
    return params


def declared_unit(path):
    with open(path, "r", encoding="latin-1") as f:
        text = f.read()
    if path.endswith(".step"):
        flat = re.sub(r"\s+", " ", text)
        m = re.search(r"\( *CONVERSION_BASED_UNIT *\( *'([^']*)'[^;]*LENGTH_UNIT[^;]*;", flat)
        if m:
            name = m.group(1).upper()
            return {"name": name, "mm_per_unit": UNIT_MM.get(name), "evidence": m.group(0)}
        m = re.search(r"\( *LENGTH_UNIT *\( *\) *NAMED_UNIT *\( *\* *\) *SI_UNIT *\( *"
                      r"(\.MILLI\.|\$) *, *\.METRE\. *\) *\) *;", flat)
        name = {".MILLI.": "MM", "$": "M"}[m.group(1)]
        return {"name": name, "mm_per_unit": UNIT_MM[name], "evidence": m.group(0)}
    g = iges_global(text)
    flag, uname = int(g[13]), g[14]
    # IGES 5.3 section 2.2.4.3.14, units flag: 1 = inch, 2 = mm, 6 = m
    name = {1: "INCH", 2: "MM", 6: "M"}[flag]
    return {"name": name, "mm_per_unit": UNIT_MM[name],
            "evidence": f"Global 14 (units flag) = {flag}, Global 15 (units name) = {uname}"}


def file_entities(path):
    with open(path, "r", encoding="latin-1") as f:
        text = f.read()
    return step_entities(text) if path.endswith(".step") else iges_entities(text)


# ----------------------------------------------------------------------------- cases
def placed(geom, base, axis_angle):
    """geom moved by the placement (translation base, rotation (axis, degrees))."""
    rot = FreeCAD.Rotation(V(*axis_angle[0]), axis_angle[1])
    geom.transform(FreeCAD.Placement(V(*base), rot).toMatrix())
    return geom


def profile_bspline():
    """A cubic profile in the XZ plane (x > 0), for the surface of revolution."""
    return corpus.curve([(6.0, 0.0, 0.0), (9.0, 0.0, 3.0), (5.0, 0.0, 6.5), (7.5, 0.0, 10.0)],
                        [4, 4], [0.0, 1.0], 3)


def composite_wire():
    line = Part.LineSegment(V(0, 0, 0), V(10, 0, 0)).toShape()
    arc = Part.Arc(V(10, 0, 0), V(13, 3, 1), V(10, 6, 2)).toShape()
    spl = corpus.curve([(10.0, 6.0, 2.0), (6.0, 9.0, 3.0), (3.0, 5.0, 4.0), (0.0, 7.0, 4.5)],
                       [4, 4], [0.0, 1.0], 3).toShape()
    return Part.Wire([line, arc, spl])


def plane_with_hole():
    face = Part.makePlane(30.0, 20.0, V(-5, -4, 2), V(0, 0, 1))
    hole = Part.makeCylinder(4.0, 10.0, V(8, 6, -3), V(0, 0, 1))
    return face.cut(hole).Faces[0]


def filleted_box_with_hole():
    box = Part.makeBox(30.0, 20.0, 10.0)
    box = box.makeFillet(2.0, box.Edges)
    hole = Part.makeCylinder(4.0, 20.0, V(15, 10, -5), V(0, 0, 1))
    return box.cut(hole)


def ruled():
    line = Part.LineSegment(V(0, 0, 0), V(12, 0, 0)).toShape()
    arc = Part.ArcOfCircle(Part.Circle(V(6, 8, 3), V(0, 1, 0), 6.0), 0.0, math.pi).toShape()
    return Part.makeRuledSurface(line, arc)


def placed_compound():
    cyl = Part.makeCylinder(3.0, 8.0)
    a, b = cyl.copy(False), cyl.copy(False)
    a.Placement = FreeCAD.Placement(V(10, 0, 0), FreeCAD.Rotation(V(1, 1, 0), 30.0))
    b.Placement = FreeCAD.Placement(V(-5, 4, 2), FreeCAD.Rotation(V(1, 0, 0), 90.0))
    return Part.Compound([a, b])


def periodic_trimmed_edge():
    builders = {c[0]: c[2] for c in corpus.case_curves()}
    return builders["curve_deg3_periodic_trimmed_edge"]()


def cases():
    tilt = ((1.0, 2.0, 0.5), 35.0)
    return [
        # name, description, builder, options (brep: also an IGES B-rep mode file)
        ("line_segment", "LineSegment (1,2,3) -> (11,-4,8)",
         lambda: Part.LineSegment(V(1, 2, 3), V(11, -4, 8)).toShape(), {}),
        ("circle_full", "full circle r=7.5 at (1,2,3), axis z",
         lambda: Part.Circle(V(1, 2, 3), V(0, 0, 1), 7.5).toShape(), {}),
        ("circle_arc_tilted", "ArcOfCircle r=4 at (2,-1,0.5), axis (1,1,1), t 0.3..4.0",
         lambda: Part.ArcOfCircle(Part.Circle(V(2, -1, 0.5), V(1, 1, 1), 4.0), 0.3,
                                  4.0).toShape(), {}),
        ("ellipse_full", "full ellipse 12 x 5, placed at (3,1,-2) rotated 35 deg about "
         "(1,2,0.5)", lambda: placed(Part.Ellipse(V(0, 0, 0), 12.0, 5.0), (3, 1, -2),
                                     tilt).toShape(), {}),
        ("ellipse_arc", "ArcOfEllipse 12 x 5, t 0.4..2.8, same placement",
         lambda: Part.ArcOfEllipse(placed(Part.Ellipse(V(0, 0, 0), 12.0, 5.0), (3, 1, -2),
                                          tilt), 0.4, 2.8).toShape(), {}),
        ("parabola_arc", "ArcOfParabola focal 2, t -3..4, placed at (1,2,3) rotated 35 deg "
         "about (1,2,0.5)", lambda: Part.ArcOfParabola(_parabola(), -3.0, 4.0).toShape(), {}),
        ("hyperbola_arc", "ArcOfHyperbola a=3 b=2, t -1.2..1.5, placed at (-2,0,1) rotated 35 "
         "deg about (1,2,0.5)", lambda: Part.ArcOfHyperbola(_hyperbola(), -1.2, 1.5).toShape(),
         {}),
        ("polyline", "makePolygon of 5 points (open)",
         lambda: Part.makePolygon([V(0, 0, 0), V(10, 0, 0), V(10, 5, 2), V(3, 8, 4),
                                   V(-2, 4, 1)]), {}),
        ("composite_wire", "one wire: line (0,0,0)-(10,0,0), 3-point arc to (10,6,2), cubic "
         "Bezier-like B-spline to (0,7,4.5)", composite_wire, {}),
        ("periodic_trimmed_edge", "degree 3 periodic B-spline (as samples/freecad/"
         "curve_deg3_periodic) as an edge over [1.0, 4.0] only", periodic_trimmed_edge, {}),
        ("plane_rectangle", "makePlane 20 x 12 at (1,2,3), normal (0,1,1)",
         lambda: Part.makePlane(20.0, 12.0, V(1, 2, 3), V(0, 1, 1)), {}),
        ("plane_with_hole", "planar face 30 x 20 with a circular hole r=4 (cut by a cylinder)",
         plane_with_hole, {"brep": 1}),
        ("cylinder_full", "solid cylinder r=5 h=12 at (1,2,3), axis (1,0,1)",
         lambda: Part.makeCylinder(5.0, 12.0, V(1, 2, 3), V(1, 0, 1)), {"brep": 1}),
        ("cylinder_partial", "solid cylinder sector r=5 h=12, 120 degrees, axis z",
         lambda: Part.makeCylinder(5.0, 12.0, V(0, 0, 0), V(0, 0, 1), 120.0), {}),
        ("cone", "solid cone r=6 to apex, h=10, axis (0,1,1)",
         lambda: Part.makeCone(6.0, 0.0, 10.0, V(0, 0, 0), V(0, 1, 1)), {"brep": 1}),
        ("cone_frustum", "solid frustum r 6 -> 3, h=8 at (2,0,1), axis z",
         lambda: Part.makeCone(6.0, 3.0, 8.0, V(2, 0, 1), V(0, 0, 1)), {"brep": 1}),
        ("sphere", "solid sphere r=10 at (1,2,3)",
         lambda: Part.makeSphere(10.0, V(1, 2, 3)), {"brep": 1}),
        ("torus", "solid torus 20 / 4, axis (0,1,1)",
         lambda: Part.makeTorus(20.0, 4.0, V(0, 0, 0), V(0, 1, 1)), {"brep": 1}),
        ("revolution_bspline", "SurfaceOfRevolution of a cubic B-spline profile (XZ plane) "
         "about z, face over angle 0..4.5 rad",
         lambda: _revolution().toShape(0.0, 4.5, 0.0, 1.0), {"brep": 1}),
        ("extrusion_ellipse", "SurfaceOfExtrusion of an ellipse 6 x 3 (placed as ellipse_full) "
         "along (0,0.2,1), face over the full ellipse and v 0..15",
         lambda: Part.SurfaceOfExtrusion(
             placed(Part.Ellipse(V(0, 0, 0), 6.0, 3.0), (3, 1, -2), tilt),
             V(0, 0.2, 1)).toShape(0.0, 2 * math.pi, 0.0, 15.0), {"brep": 1}),
        ("ruled_surface", "makeRuledSurface between a line segment and a half circle", ruled,
         {}),
        ("filleted_box_with_hole", "box 30 x 20 x 10, all 12 edges filleted r=2, through hole "
         "r=4 along z", filleted_box_with_hole, {"brep": 1}),
        ("units_inch", "the 120-degree cylinder sector of cylinder_partial exported with "
         "Part.exportUnits('INCH')",
         lambda: Part.makeCylinder(5.0, 12.0, V(0, 0, 0), V(0, 0, 1), 120.0), {"units": "INCH"}),
        ("units_metre", "the same sector exported with Part.exportUnits('M')",
         lambda: Part.makeCylinder(5.0, 12.0, V(0, 0, 0), V(0, 0, 1), 120.0), {"units": "M"}),
        # Appended last: the STEP PRODUCT counter of the cases above stays as it was.
        ("placed_compound", "one solid cylinder r=3 h=8 placed twice in a compound: "
         "Placement((10,0,0), 30 deg about (1,1,0)) and Placement((-5,4,2), 90 deg about x) "
         "(two copies sharing the geometry, each with its own location)", placed_compound, {"brep": 1}),
    ]


def _parabola():
    p = Part.Parabola()
    p.Focal = 2.0
    return placed(p, (1, 2, 3), ((1.0, 2.0, 0.5), 35.0))


def _hyperbola():
    h = Part.Hyperbola()
    h.MajorRadius = 3.0
    h.MinorRadius = 2.0
    return placed(h, (-2, 0, 1), ((1.0, 2.0, 0.5), 35.0))


def _revolution():
    return Part.SurfaceOfRevolution(profile_bspline(), V(0, 0, 0), V(0, 0, 1))


# ----------------------------------------------------------------------------- main
def reading(case, desc, fmt, path, export_opts, shape):
    fc, occt = evaluate.versions()
    out = {"schema": SCHEMA_ID, "case": case, "description": desc,
           "file": os.path.basename(path) if path else None, "format": fmt,
           "export": export_opts,
           "reader": "Part.read" if path else "in-memory shape before export",
           "freecad_version": fc, "occt_version": occt,
           "declared_unit": declared_unit(path) if path else None,
           "file_entities": file_entities(path) if path else None,
           "coordinates": "mm", "sampling": SAMPLING}
    out.update(describe_shape(shape))
    return out


def write_json(path, obj):
    with open(path, "w", encoding="utf-8") as f:
        f.write(evaluate.dumps(obj))


def main():
    only = os.environ.get("NURBSX_ONLY")
    all_cases = cases()
    assert len({c[0] for c in all_cases}) == len(all_cases)
    index = []
    for name, desc, build, opts in all_cases:
        if only and name not in only.split(","):
            continue
        shape = build()
        unit = opts.get("units", "MM")
        files = [(name + ".step", "step", {}), (name + ".igs", "iges", {})]
        if opts.get("brep"):
            files.append((name + "_brep.igs", "iges", {"brep": 1}))
        step_export = {"step_schema": "AP214IS", "unit": unit, "iges_brep_mode": 0}
        write_json(os.path.join(HERE, name + ".source.json"),
                   reading(name, desc, "in-memory", None, step_export, shape))
        entry = {"case": name, "description": desc, "files": []}
        for fname, fmt, extra in files:
            path = os.path.join(HERE, fname)
            eopts = dict(extra)
            if "units" in opts:
                eopts["units"] = opts["units"]
            corpus.set_statics(eopts)
            corpus.export(shape, path, {})
            corpus.set_statics({})
            export_opts = {"step_schema": "AP214IS", "unit": unit,
                           "iges_brep_mode": eopts.get("brep", 0)}
            r = reading(name, desc, fmt, path, export_opts, Part.read(path))
            if r["declared_unit"]["name"] != unit:
                raise RuntimeError(f"{fname}: declares {r['declared_unit']}, exported as {unit}")
            write_json(path + ".json", r)
            entry["files"].append({"file": fname, "export": export_opts,
                                   "declared_unit": r["declared_unit"]["name"],
                                   "counts": r["counts"], "file_entities": r["file_entities"]})
        index.append(entry)
    if not only:
        fc, occt = evaluate.versions()
        write_json(os.path.join(HERE, "index.json"),
                   {"schema": SCHEMA_ID, "freecad_version": fc, "occt_version": occt,
                    "cases": index})


def run_as_script(entry):
    """Run entry() and end the process with status 0, or 1 when it raised (freecadcmd itself
    exits 0 when a script raises, hence the explicit status). Shared with parts/generate.py."""
    try:
        entry()
    except Exception:  # report any failure as exit status 1
        traceback.print_exc()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(1)
    sys.stdout.flush()
    os._exit(0)


# freecadcmd runs a script under the name of its file stem ("generate") or "__main__".
if __name__ in ("__main__", "generate"):
    run_as_script(main)
