"""Deterministic generator of the FreeCAD/OCCT sample corpus (STEP + IGES + readings).

Regenerate (from the repository root):

    freecadcmd samples/freecad/generate.py

Writes, into the directory of this script, for every case:
  <case>.step / <case>.igs        files exported by FreeCAD (time stamps normalised)
  <case>.step.json / <case>.igs.json
                                  FreeCAD's reading of the file after RE-IMPORT
                                  (scripts/freecad/evaluate.py, same code)
  <case>.source.json              the same reading of the in-memory shape BEFORE export
and comparison.json / COMPARISON.md: what changed between source and re-import.

Determinism: poles/knots/weights come from random.Random(<fixed seed per case>); the only
varying bytes OCCT writes are time stamps, which are rewritten to fixed values
(STEP FILE_NAME time_stamp -> 2000-01-01T00:00:00, IGES Global parameters 18 and 25 ->
15H20000101.000000, same lengths so IGES 80-column records stay intact).
"""

import importlib.util
import json
import math
import os
import random
import re
import sys

import FreeCAD
import Import
import Part

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
# One reader for generator and live checks: load scripts/freecad/evaluate.py under a module
# name other than "evaluate" so that its command-line entry point does not run.
_spec = importlib.util.spec_from_file_location(
    "nurbsx_freecad_reader", os.path.join(ROOT, "scripts", "freecad", "evaluate.py")
)
evaluate = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(evaluate)

V = FreeCAD.Vector

FIXED_STEP_STAMP = "2000-01-01T00:00:00"
FIXED_IGES_STAMP = "20000101.000000"

# Statics touched by cases, with the values restored after every case.
DEFAULT_STATICS = [
    ("write.step.schema", "AP214IS"),
    ("write.step.unit", "MM"),
    ("write.iges.unit", "MM"),
    ("write.iges.brep.mode", 0),
]


# ----------------------------------------------------------------------------- helpers
def rng_for(seed):
    return random.Random(seed)


def curve(poles, mults, knots, degree, weights=None, periodic=False):
    c = Part.BSplineCurve()
    c.buildFromPolesMultsKnots(
        [V(*p) for p in poles], mults, knots, periodic, degree, weights, bool(weights)
    )
    return c


def surface(poles, umults, vmults, uknots, vknots, udeg, vdeg, weights=None, up=False, vp=False):
    s = Part.BSplineSurface()
    pts = [[V(*p) for p in row] for row in poles]
    if weights is None:
        s.buildFromPolesMultsKnots(pts, umults, vmults, uknots, vknots, up, vp, udeg, vdeg)
    else:
        s.buildFromPolesMultsKnots(
            pts, umults, vmults, uknots, vknots, up, vp, udeg, vdeg, weights
        )
    return s


def increasing(r, n, start=0.0):
    """n strictly increasing, irregularly spaced values."""
    out = [start]
    for _ in range(n - 1):
        out.append(round(out[-1] + r.uniform(0.4, 1.6), 6))
    return out


def space_poles(r, n, scale=1.0):
    """n poles of a wavy space curve."""
    return [
        (
            scale * (i * 10.0 + r.uniform(-2, 2)),
            scale * r.uniform(-8, 8),
            scale * r.uniform(-5, 5),
        )
        for i in range(n)
    ]


def clamped_curve(seed, degree, rational, scale=1.0):
    """Clamped, non-uniform; one interior knot doubled when the degree allows."""
    r = rng_for(seed)
    ninterior = 3
    knots = increasing(r, ninterior + 2, start=-1.25)
    mults = [degree + 1] + [1] * ninterior + [degree + 1]
    if degree >= 2:
        mults[2] = 2
    npoles = sum(mults) - degree - 1
    poles = space_poles(r, npoles, scale)
    weights = [round(r.uniform(0.5, 2.0), 6) for _ in range(npoles)] if rational else None
    return curve(poles, mults, knots, degree, weights)


def grid_poles(r, nu, nv, amp=3.0):
    return [
        [(i * 10.0, j * 8.0, r.uniform(-amp, amp) + 0.3 * i - 0.2 * j) for j in range(nv)]
        for i in range(nu)
    ]


def ring(n, radius, z, r, wobble=0.5, phase=0.0):
    return [
        (
            (radius + r.uniform(-wobble, wobble)) * math.cos(phase + 2 * math.pi * k / n),
            (radius + r.uniform(-wobble, wobble)) * math.sin(phase + 2 * math.pi * k / n),
            z + r.uniform(-wobble, wobble),
        )
        for k in range(n)
    ]


def edge(c):
    return c.toShape()


def compound(*shapes):
    return Part.Compound(list(shapes))


# ----------------------------------------------------------------------------- cases
def case_curves():
    cases = []
    for d in list(range(1, 10)) + [25]:
        cases.append(
            (f"curve_deg{d}_clamped", f"degree {d}, polynomial, clamped, non-uniform knots "
             "starting at -1.25, one interior knot of multiplicity 2 (degree >= 2)",
             lambda d=d: edge(clamped_curve(100 + d, d, False)), {})
        )
        cases.append(
            (f"curve_deg{d}_rational_clamped", f"degree {d}, rational (weights 0.5..2), clamped, "
             "non-uniform knots starting at -1.25",
             lambda d=d: edge(clamped_curve(200 + d, d, True)), {})
        )

    def uniform_unclamped():
        r = rng_for(301)
        poles = space_poles(r, 8)
        return edge(curve(poles, [1] * 12, [float(k) for k in range(12)], 3))

    def quasi_uniform():
        r = rng_for(302)
        poles = space_poles(r, 7)
        return edge(curve(poles, [4, 1, 1, 1, 4], [0.0, 1.0, 2.0, 3.0, 4.0], 3))

    def piecewise_bezier():
        r = rng_for(303)
        poles = space_poles(r, 10)
        return edge(curve(poles, [4, 3, 3, 4], [0.0, 1.0, 2.0, 3.0], 3))

    def periodic():
        r = rng_for(304)
        poles = ring(6, 20.0, 0.0, r, wobble=3.0)
        knots = increasing(r, 7, start=0.0)
        return edge(curve(poles, [1] * 7, knots, 3, periodic=True))

    def periodic_trimmed_edge():
        r = rng_for(304)
        poles = ring(6, 20.0, 0.0, r, wobble=3.0)
        knots = increasing(r, 7, start=0.0)
        return Part.Edge(curve(poles, [1] * 7, knots, 3, periodic=True), 1.0, 4.0)

    def periodic_rational():
        r = rng_for(305)
        poles = ring(7, 15.0, 5.0, r, wobble=2.0)
        knots = increasing(r, 8, start=0.5)
        weights = [round(r.uniform(0.6, 1.8), 6) for _ in range(7)]
        return edge(curve(poles, [1] * 8, knots, 2, weights, periodic=True))

    def interp_periodic():
        r = rng_for(306)
        pts = [V(*p) for p in ring(8, 12.0, 0.0, r, wobble=2.0)]
        c = Part.BSplineCurve()
        c.interpolate(Points=pts, PeriodicFlag=True)
        return edge(c)

    def closed_nonperiodic():
        r = rng_for(307)
        poles = ring(7, 10.0, 0.0, r, wobble=2.0)
        poles.append(poles[0])
        return edge(curve(poles, [4, 1, 1, 1, 1, 4], [0.0, 1.0, 2.0, 3.0, 4.0, 5.0], 3))

    def planar_tilted():
        r = rng_for(308)
        n = V(1, 2, 3)
        n.normalize()
        a = n.cross(V(0, 0, 1))
        a.normalize()
        b = n.cross(a)
        origin = V(5, -3, 2)
        poles = []
        for i in range(8):
            p = origin + a * (i * 6.0) + b * r.uniform(-10, 10)
            poles.append((p.x, p.y, p.z))
        return edge(curve(poles, [4, 1, 2, 1, 4], [0.0, 0.3, 0.55, 0.8, 1.0], 3))

    def circle():
        return edge(Part.Circle(V(1, 2, 3), V(0, 0, 1), 7.5).toNurbs())

    def circle_tilted_arc():
        c = Part.Circle(V(0, 0, 0), V(1, 1, 1), 4.0)
        return edge(Part.ArcOfCircle(c, 0.3, 4.0).toNurbs())

    def ellipse():
        return edge(Part.Ellipse(V(0, 0, 0), 12.0, 5.0).toNurbs())

    def parabola():
        p = Part.Parabola()
        p.Focal = 2.0
        return edge(Part.ArcOfParabola(p, -3.0, 4.0).toNurbs())

    cases += [
        ("curve_deg3_uniform_unclamped", "degree 3, 8 poles, 12 knots 0..11 all multiplicity 1 "
         "(uniform, unclamped ends; valid range [3, 8])", uniform_unclamped, {}),
        ("curve_deg3_quasi_uniform", "degree 3, knots 0..4, multiplicities (4,1,1,1,4)",
         quasi_uniform, {}),
        ("curve_deg3_piecewise_bezier", "degree 3, 10 poles, knots 0..3 multiplicities (4,3,3,4)",
         piecewise_bezier, {}),
        ("curve_deg3_periodic", "degree 3 periodic: buildFromPolesMultsKnots(6 poles, mults 1x7, "
         "non-uniform knots, periodic=True)", periodic, {}),
        ("curve_deg3_periodic_trimmed_edge", "the periodic curve of curve_deg3_periodic as "
         "an edge over the sub-range [1.0, 4.0] only", periodic_trimmed_edge, {}),
        ("curve_deg2_rational_periodic", "degree 2 rational periodic: 7 poles, knots from 0.5, "
         "mults 1x8, periodic=True", periodic_rational, {}),
        ("curve_deg3_interp_periodic", "interpolate(8 points, PeriodicFlag=True)",
         interp_periodic, {}),
        ("curve_deg3_closed_nonperiodic", "degree 3 clamped, last pole = first pole (closed but "
         "not periodic)", closed_nonperiodic, {}),
        ("curve_deg3_planar_tilted", "degree 3 clamped, all poles in the plane through (5,-3,2) "
         "with normal (1,2,3)", planar_tilted, {}),
        ("curve_deg5_tiny", "degree 5 rational clamped, coordinates scaled by 1e-6",
         lambda: edge(clamped_curve(309, 5, True, scale=1e-6)), {}),
        ("curve_deg5_huge", "degree 5 rational clamped, coordinates scaled by 1e6",
         lambda: edge(clamped_curve(310, 5, True, scale=1e6)), {}),
        ("curve_circle_nurbs", "Part.Circle(r=7.5 at (1,2,3)).toNurbs()", circle, {}),
        ("curve_arc_tilted_nurbs", "ArcOfCircle(r=4, normal (1,1,1), 0.3..4.0).toNurbs()",
         circle_tilted_arc, {}),
        ("curve_ellipse_nurbs", "Part.Ellipse(12 x 5).toNurbs()", ellipse, {}),
        ("curve_parabola_nurbs", "ArcOfParabola(focal 2, -3..4).toNurbs()", parabola, {}),
    ]
    return cases


def case_surfaces():
    def bicubic():
        r = rng_for(401)
        poles = grid_poles(r, 6, 5)
        return surface(poles, [4, 1, 1, 4], [4, 1, 4], [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0],
                       3, 3).toShape()

    def rational_nonuniform():
        r = rng_for(402)
        poles = grid_poles(r, 6, 5)
        w = [[round(r.uniform(0.5, 2.0), 6) for _ in range(5)] for _ in range(6)]
        return surface(poles, [4, 2, 4], [3, 1, 1, 3], [-0.5, 0.35, 1.5],
                       [2.0, 2.7, 3.1, 4.5], 3, 2, w).toShape()

    def deg2x5():
        r = rng_for(403)
        poles = grid_poles(r, 4, 7)
        return surface(poles, [3, 1, 3], [6, 1, 6], [0.0, 0.4, 1.0], [0.0, 0.6, 1.0],
                       2, 5).toShape()

    def poles4x3():
        # Poles chosen so that every index is visible in the coordinates:
        # pole[i][j] = (10 i, 100 j, i + 10 j) (+ small bumps) -- transpositions show at once.
        poles = [[(10.0 * i, 100.0 * j, i + 10.0 * j + (1.5 if (i, j) == (1, 2) else 0.0))
                  for j in range(3)] for i in range(4)]
        return surface(poles, [4, 4], [3, 3], [0.0, 1.0], [0.0, 1.0], 3, 2).toShape()

    def periodic_u():
        r = rng_for(404)
        rows = [ring(6, 10.0 + 2 * j, 8.0 * j, r, wobble=1.0) for j in range(4)]
        poles = [[rows[j][i] for j in range(4)] for i in range(6)]  # poles[u][v]
        uk = increasing(r, 7)
        return surface(poles, [1] * 7, [4, 4], uk, [0.0, 1.0], 3, 3, up=True).toShape()

    def periodic_v():
        r = rng_for(405)
        rows = [ring(5, 9.0 + 1.5 * i, 6.0 * i, r, wobble=1.0) for i in range(4)]
        poles = [[rows[i][j] for j in range(5)] for i in range(4)]  # v runs around
        vk = increasing(r, 6, start=1.0)
        return surface(poles, [3, 1, 3], [1] * 6, [0.0, 0.5, 1.0], vk, 2, 2, vp=True).toShape()

    def periodic_uv():
        r = rng_for(406)
        nu, nv = 7, 5
        big, small = 20.0, 5.0
        poles = []
        for i in range(nu):
            a = 2 * math.pi * i / nu
            row = []
            for j in range(nv):
                b = 2 * math.pi * j / nv
                rr = small + r.uniform(-0.5, 0.5)
                row.append(((big + rr * math.cos(b)) * math.cos(a),
                            (big + rr * math.cos(b)) * math.sin(a), rr * math.sin(b)))
            poles.append(row)
        w = [[round(r.uniform(0.8, 1.3), 6) for _ in range(nv)] for _ in range(nu)]
        return surface(poles, [1] * 8, [1] * 6, increasing(r, 8), increasing(r, 6), 3, 2, w,
                       up=True, vp=True).toShape()

    def periodic_u_trimmed():
        return periodic_u().Faces[0].Surface.toShape(1.0, 4.5, 0.1, 0.8)

    def sphere():
        return Part.makeSphere(10.0).Faces[0].toNurbs()

    def torus():
        return Part.makeTorus(20.0, 4.0).Faces[0].toNurbs()

    def cylinder():
        return Part.makeCylinder(5.0, 12.0).Faces[0].toNurbs()

    def loft():
        r = rng_for(407)
        wires = []
        for k in range(3):
            poles = [(x * 8.0, r.uniform(-3, 3) + 15.0 * k, r.uniform(-2, 2) + 4.0 * k)
                     for x in range(6)]
            wires.append(Part.Wire(edge(curve(poles, [4, 1, 1, 4], [0.0, 1.0, 2.0, 3.0], 3))))
        return Part.makeLoft(wires, False)

    def trimmed_hole():
        r = rng_for(408)
        poles = grid_poles(r, 5, 5, amp=1.0)
        s = surface(poles, [4, 1, 4], [4, 1, 4], [0.0, 0.5, 1.0], [0.0, 0.5, 1.0], 3, 3)
        face = s.toShape(0.1, 0.9, 0.05, 0.95)
        hole = Part.makeCylinder(5.0, 40.0, V(20.0, 16.0, -20.0), V(0, 0, 1))
        res = face.cut(hole)
        return res.Faces[0]

    def filleted_box():
        box = Part.makeBox(10.0, 8.0, 6.0)
        return box.makeFillet(1.5, box.Edges).toNurbs()

    return [
        ("surf_bicubic", "bicubic polynomial, 6x5 poles, clamped", bicubic, {}),
        ("surf_rational_nonuniform", "degrees (3,2), rational, non-uniform knots (u from -0.5 "
         "with a double knot, v from 2.0)", rational_nonuniform, {}),
        ("surf_deg2x5", "degrees (2,5), polynomial, 4x7 poles", deg2x5, {}),
        ("surf_poles4x3", "degrees (3,2), 4x3 poles (single Bezier patch); pole[i][j] = "
         "(10i, 100j, i+10j), +1.5 on z of pole[1][2]", poles4x3, {}),
        ("surf_periodic_u", "degree (3,3), periodic in u (6 poles around), clamped v",
         periodic_u, {}),
        ("surf_periodic_u_trimmed_face", "the surface of surf_periodic_u as a face over "
         "u 1.0..4.5, v 0.1..0.8 only", periodic_u_trimmed, {}),
        ("surf_periodic_v", "degree (2,2), periodic in v (5 poles around), clamped u",
         periodic_v, {}),
        ("surf_periodic_uv", "degree (3,2), rational, periodic in u and v (torus-like 7x5 net)",
         periodic_uv, {}),
        ("surf_sphere_nurbs", "sphere r=10 face, Shape.toNurbs()", sphere, {}),
        ("surf_torus_nurbs", "torus 20/4 face, Shape.toNurbs()", torus, {}),
        ("surf_cylinder_nurbs", "cylinder r=5 h=12 lateral face, Shape.toNurbs()", cylinder, {}),
        ("surf_loft", "Part.makeLoft of 3 cubic B-spline sections (ruled=False)", loft, {}),
        ("face_trimmed_hole", "bicubic face trimmed to u 0.1..0.9, v 0.05..0.95, with a "
         "circular hole (cut by a cylinder r=5)", trimmed_hole, {}),
        ("brep_filleted_box_nurbs", "box 10x8x6, all edges filleted r=1.5, whole solid "
         "converted with Shape.toNurbs()", filleted_box, {}),
    ]


def mixed():
    """One rational curve and one rational surface in a compound (unit/schema cases)."""
    c = clamped_curve(501, 3, True)
    r = rng_for(502)
    poles = grid_poles(r, 4, 4)
    w = [[round(r.uniform(0.5, 2.0), 6) for _ in range(4)] for _ in range(4)]
    s = surface(poles, [4, 4], [3, 1, 3], [0.0, 2.0], [0.0, 0.5, 1.0], 3, 2, w)
    return compound(edge(c), s.toShape())


def small_filleted_box():
    box = Part.makeBox(10.0, 8.0, 6.0)
    vertical = [e for e in box.Edges if abs(e.Vertexes[0].Point.z - e.Vertexes[1].Point.z) > 1]
    return box.makeFillet(2.0, vertical).toNurbs()


def mixed_surface():
    """The surface of mixed() alone (one named object for the IGES Import.export case)."""
    return compound(mixed().childShapes()[1])


def case_options():
    return [
        ("units_inch", "rational curve + rational surface, exported with Part.exportUnits('INCH')"
         " (write.step.unit / write.iges.unit = INCH)", mixed, {"units": "INCH"}),
        ("units_metre", "same geometry, exported with Part.exportUnits('M')", mixed,
         {"units": "M"}),
        ("schema_ap203", "same geometry, STEP with write.step.schema = AP203", mixed,
         {"schema": "AP203", "formats": ["step"]}),
        ("schema_ap242", "same geometry, STEP with write.step.schema = AP242DIS", mixed,
         {"schema": "AP242DIS", "formats": ["step"]}),
        ("iges_brep_filleted_box", "box 10x8x6 with its 4 vertical edges filleted r=2, "
         "Shape.toNurbs(), IGES with write.iges.brep.mode = 1 (186/514/510/508/504/502 B-rep "
         "entities)", small_filleted_box, {"brep": 1, "formats": ["iges"]}),
        ("iges_brep_trimmed_hole", "trimmed face with hole, IGES B-rep mode 1",
         lambda: case_surfaces()[-2][2](), {"brep": 1, "formats": ["iges"]}),
        ("import_export_named", "Import.export (XCAF) of two named document objects "
         "('NamedCurve', 'NamedSurface'); headless, so no colours; STEP only (the IGES order "
         "of several 406 name entities varies from run to run)", mixed,
         {"named": True, "formats": ["step"]}),
        ("import_export_named_iges", "Import.export (XCAF) of one named document object "
         "('NamedSurface', the rational surface of the cases above); IGES", mixed_surface,
         {"named": True, "formats": ["iges"]}),
    ]


# ----------------------------------------------------------------------------- export
def set_statics(opts):
    for k, v in DEFAULT_STATICS:
        Part.setStaticValue(k, v)
    if "units" in opts:
        Part.exportUnits(opts["units"])
    if "schema" in opts:
        Part.setStaticValue("write.step.schema", opts["schema"])
    if "brep" in opts:
        Part.setStaticValue("write.iges.brep.mode", opts["brep"])


def normalise_step(path):
    with open(path, "r", encoding="latin-1") as f:
        text = f.read()
    head, sep, rest = text.partition("ENDSEC;")
    head = re.sub(r"'\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d'", "'" + FIXED_STEP_STAMP + "'", head, 1)
    # AP203 (CONFIG_CONTROL_DESIGN) also records the export date and time in the DATA section.
    rest = re.sub(r"CALENDAR_DATE\(\s*\d+\s*,\s*\d+\s*,\s*\d+\s*\)",
                  "CALENDAR_DATE(2000,1,1)", rest)
    rest = re.sub(r"LOCAL_TIME\(\s*\d+\s*,\s*\d+\s*,\s*(\$|[0-9.E+-]+)\s*,",
                  "LOCAL_TIME(0,0,$,", rest)
    rest = re.sub(r"COORDINATED_UNIVERSAL_TIME_OFFSET\([^)]*\)",
                  "COORDINATED_UNIVERSAL_TIME_OFFSET(0,$,.EXACT.)", rest)
    # AP203 also names the exporting user and host (OCCT OSD_Host: 'IP<address>,<user>').
    rest = re.sub(r"= PERSON\('[^']*','[^']*','[^']*',", "= PERSON('user','','user',", rest)
    rest = re.sub(r"= ORGANIZATION\('[^']*',", "= ORGANIZATION('host',", rest)
    with open(path, "w", encoding="latin-1", newline="") as f:
        f.write(head + sep + rest)


def normalise_iges(path):
    """Rewrite the two Global-section dates keeping every record at 80 columns."""
    with open(path, "r", encoding="latin-1") as f:
        lines = f.read().split("\n")
    gidx = [i for i, ln in enumerate(lines) if len(ln) >= 73 and ln[72] == "G"]
    body = "".join(lines[i][:72] for i in gidx)
    new, n = re.subn(r"15H\d{8}\.\d{6}", "15H" + FIXED_IGES_STAMP, body)
    if n != 2:
        raise RuntimeError(f"{path}: expected 2 IGES dates, found {n}")
    assert len(new) == len(body)
    for k, i in enumerate(gidx):
        lines[i] = new[72 * k:72 * (k + 1)] + lines[i][72:]
    with open(path, "w", encoding="latin-1", newline="") as f:
        f.write("\n".join(lines))


def export(shape, path, opts):
    if opts.get("named"):
        doc = FreeCAD.newDocument("named")
        objs = []
        subs = shape.childShapes()
        names = ["NamedCurve", "NamedSurface"] if len(subs) == 2 else ["NamedSurface"]
        for name, sub in zip(names, subs):
            o = doc.addObject("Part::Feature", name)
            o.Shape = sub
            objs.append(o)
        doc.recompute()
        Import.export(objs, path)
        FreeCAD.closeDocument(doc.Name)
    elif path.endswith(".step"):
        shape.exportStep(path)
    else:
        shape.exportIges(path)
    if path.endswith(".step"):
        normalise_step(path)
    else:
        normalise_iges(path)


# ----------------------------------------------------------------------------- comparison
def _maxabs(a, b):
    return max((abs(x - y) for x, y in zip(a, b)), default=0.0)


def _flat(x):
    if isinstance(x, list):
        out = []
        for y in x:
            out.extend(_flat(y))
        return out
    return [x]


def _rel_digits(a, b):
    """Smallest number of agreeing significant digits over paired values (None = exact)."""
    worst = None
    for x, y in zip(a, b):
        if x == y:
            continue
        scale = max(abs(x), abs(y))
        d = -math.log10(abs(x - y) / scale) if scale > 0 else 0.0
        worst = d if worst is None else min(worst, d)
    return None if worst is None else round(worst, 2)


def compare_item(src, dst, kind, src_geom):
    """Differences between one source item and its re-imported counterpart."""
    out = {}
    if kind == "curve":
        keys = ["degree", "periodic", "rational", "closed"]
        knot_pairs = [("knots", "multiplicities")]
        range_src = [src["first_parameter"], src["last_parameter"]]
        range_dst = [dst["first_parameter"], dst["last_parameter"]]
    else:
        keys = ["u_degree", "v_degree", "u_periodic", "v_periodic", "u_rational", "v_rational",
                "u_closed", "v_closed", "nb_u_poles", "nb_v_poles"]
        knot_pairs = [("u_knots", "u_multiplicities"), ("v_knots", "v_multiplicities")]
        range_src, range_dst = src["bounds"], dst["bounds"]
    for k in keys:
        if src[k] != dst[k]:
            out[k] = [src[k], dst[k]]
    for kn, mu in knot_pairs:
        if src[kn] != dst[kn] or src[mu] != dst[mu]:
            if len(src[kn]) == len(dst[kn]) and src[mu] == dst[mu]:
                out[kn + "_max_abs_diff"] = _maxabs(src[kn], dst[kn])
            else:
                out[kn] = [src[kn], dst[kn]]
                out[mu] = [src[mu], dst[mu]]
    if range_src != range_dst:
        out["parameter_range"] = [range_src, range_dst]
    # Geometry: the difference at the same parameter, also under the parameter maps OCCT is
    # seen to apply (curve reversal; surface u- or v-reversal), and the distance of each
    # re-imported evaluation point to the untrimmed source geometry (the same-parameter
    # difference is an upper bound of that distance, so the smaller of the two is kept:
    # BRepExtrema is unreliable at 1e-6 scale).
    if kind == "curve":
        a, b = range_src
        maps = {"identity": lambda ev: (ev["t"],), "reversed": lambda ev: (a + b - ev["t"],)}
    else:
        u0, u1, v0, v1 = range_src
        maps = {
            "identity": lambda ev: (ev["u"], ev["v"]),
            "u_reversed": lambda ev: (u0 + u1 - ev["u"], ev["v"]),
            "v_reversed": lambda ev: (ev["u"], v0 + v1 - ev["v"]),
        }

    def inside(params):
        if kind == "curve":
            return range_src[0] - 1e-9 <= params[0] <= range_src[1] + 1e-9 or src["periodic"]
        return (u0 - 1e-9 <= params[0] <= u1 + 1e-9 or src["u_periodic"]) and (
            v0 - 1e-9 <= params[1] <= v1 + 1e-9 or src["v_periodic"]
        )

    diffs = {}
    for mname, fn in maps.items():
        worst = 0.0
        for ev in dst["evaluations"]:
            params = fn(ev)
            if not inside(params):
                worst = float("inf")
                break
            worst = max(worst, (src_geom.value(*params) - V(*ev["point"])).Length)
        diffs[mname] = worst
    same = diffs["identity"]
    scale = 1.0 + max(abs(x) for x in _flat(src["poles"]))
    good = [m for m in maps if diffs[m] <= 1e-6 * scale]
    out["parameter_map"] = good[0] if good else "other"
    dist = 0.0
    shp = src_geom.toShape()
    for ev in dst["evaluations"]:
        p = V(*ev["point"])
        params = maps["identity"](ev)
        d_same = (src_geom.value(*params) - p).Length if inside(params) else float("inf")
        dist = max(dist, min(d_same, shp.distToShape(Part.Vertex(p))[0]))
    ps, pd = _flat(src["poles"]), _flat(dst["poles"])
    ws, wd = _flat(src["weights"]), _flat(dst["weights"])
    if len(ps) == len(pd):
        if out["parameter_map"] == "reversed":
            ps = _flat(list(reversed(src["poles"])))
            ws = list(reversed(ws))
        elif out["parameter_map"] == "u_reversed":
            ps = _flat(list(reversed(src["poles"])))
            ws = _flat(list(reversed(src["weights"])))
        elif out["parameter_map"] == "v_reversed":
            ps = _flat([list(reversed(row)) for row in src["poles"]])
            ws = _flat([list(reversed(row)) for row in src["weights"]])
        out["poles_max_abs_diff"] = _maxabs(ps, pd)
        out["poles_min_significant_digits"] = _rel_digits(ps, pd)
        out["weights_min_significant_digits"] = _rel_digits(ws, wd)
    else:
        out["pole_count"] = [len(ps) // 3, len(pd) // 3]
    out["max_dist_to_source_geometry"] = dist
    out["max_point_diff_at_same_parameter"] = same if math.isfinite(same) else "outside source range"
    if out["parameter_map"] not in ("identity", "other"):
        out["max_point_diff_after_map"] = diffs[out["parameter_map"]]
    return out


def _bbox_ok(geom_shape, points):
    bb = geom_shape.BoundBox
    tol = 1e-6 * max(bb.DiagonalLength, 1e-12) + 1e-9
    bb.enlarge(tol)
    return all(bb.isInside(V(*p)) for p in points)


def match(d_item, kind, s_items, src_geoms):
    """Index into s_items of the source item nearest to the re-imported item."""
    pts = [ev["point"] for ev in d_item["evaluations"]]
    best, best_d = None, None
    for k, s_item in enumerate(s_items):
        g = src_geoms[k]
        shp = g.toShape()
        if not _bbox_ok(shp, pts):
            continue
        d = max(shp.distToShape(Part.Vertex(V(*p)))[0] for p in pts)
        if best_d is None or d < best_d:
            best, best_d = k, d
    return best


def compare(src_reading, dst_reading, src_shape):
    res = {
        "counts": [
            {k: src_reading["counts"][k] for k in ("bspline_curves", "bspline_surfaces")},
            {k: dst_reading["counts"][k] for k in ("bspline_curves", "bspline_surfaces")},
        ],
        "curves": [],
        "surfaces": [],
    }
    # Each re-imported item is matched to the source item whose (untrimmed) geometry is
    # nearest to its evaluation points: OCCT may reorder, split or duplicate edges/faces.
    for kind, key, idx, shapes in [
        ("curve", "curves", "edge_index", src_shape.Edges),
        ("surface", "surfaces", "face_index", src_shape.Faces),
    ]:
        s_items = src_reading[key]
        geoms = [
            shapes[s[idx]].Curve if kind == "curve" else shapes[s[idx]].Surface for s in s_items
        ]
        for d in dst_reading[key]:
            k = match(d, kind, s_items, geoms)
            entry = {idx: d[idx]}
            if k is None:
                entry["source"] = None
            else:
                entry["source_" + idx] = s_items[k][idx]
                entry.update(compare_item(s_items[k], d, kind, geoms[k]))
            res[key].append(entry)
    return res


def _g(x):
    return "-" if x is None else (x if isinstance(x, str) else f"{x:.2g}")


def comparison_markdown(comparison):
    """One table row per exported file, summarising comparison.json."""
    lines = [
        "# Source (built in FreeCAD) vs FreeCAD's re-import, per exported file",
        "",
        f"Generated by generate.py (FreeCAD {comparison['freecad_version']}, OCCT "
        f"{comparison['occt_version']}); details per item in comparison.json.",
        "",
        "Columns: B-spline curves / surfaces before -> after; `changed` = fields that differ "
        "for at least one matched item (flags, knot vectors, pole counts, ranges); `digits` = "
        "fewest agreeing significant digits of poles where the pole count is unchanged; "
        "`dist` = max distance of re-imported evaluation points to the source geometry; "
        "`same-t` = max |source(t) - reimport(t)| at the same parameter (large = "
        "re-parameterised or reversed); `MAP:reversed` / `MAP:u_reversed` = at least one item "
        "agrees with the source only after reversing its parameter (t -> a+b-t), `MAP:other` = "
        "agrees under none of identity/reversal (e.g. re-periodised origin or segmented "
        "piece evaluated outside the source range); digits are then computed after the map.",
        "",
        "| case | fmt | curves | surfaces | changed | digits | dist | same-t |",
        "|---|---|---|---|---|---|---|---|",
    ]
    skip = {"edge_index", "face_index", "source_edge_index", "source_face_index",
            "poles_max_abs_diff", "poles_min_significant_digits",
            "weights_min_significant_digits", "max_dist_to_source_geometry",
            "max_point_diff_at_same_parameter"}
    for name, fm in comparison["cases"].items():
        for fmt, r in fm.items():
            changed = set()
            digits, dist, same = None, 0.0, 0.0
            for key in ("curves", "surfaces"):
                for it in r[key]:
                    changed |= {k.replace("_max_abs_diff", "~") for k in it if k not in skip}
                    changed.discard("parameter_map")
                    changed.discard("max_point_diff_after_map")
                    if it.get("parameter_map", "identity") != "identity":
                        changed.add("MAP:" + it["parameter_map"])
                    pd = it.get("poles_min_significant_digits")
                    if pd is not None:
                        digits = pd if digits is None else min(digits, pd)
                    dist = max(dist, it.get("max_dist_to_source_geometry", 0.0))
                    st = it.get("max_point_diff_at_same_parameter", 0.0)
                    same = st if isinstance(st, str) or isinstance(same, str) else max(same, st)
            c0, c1 = r["counts"]
            lines.append(
                f"| {name} | {fmt} | {c0['bspline_curves']} -> {c1['bspline_curves']} | "
                f"{c0['bspline_surfaces']} -> {c1['bspline_surfaces']} | "
                f"{', '.join(sorted(changed)) or '-'} | {_g(digits)} | {_g(dist)} | "
                f"{_g(same)} |"
            )
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- main
def main():
    only = os.environ.get("NURBSX_ONLY")
    cases = case_curves() + case_surfaces() + case_options()
    names = [c[0] for c in cases]
    assert len(names) == len(set(names))
    fc, occt = evaluate.versions()
    comparison = {"freecad_version": fc, "occt_version": occt, "cases": {}}
    index = []
    for name, desc, build, opts in cases:
        if only and name not in only.split(","):
            continue
        shape = build()
        src = {
            "schema": evaluate.SCHEMA_ID,
            "file": None,
            "format": "in-memory",
            "reader": "in-memory shape before export",
            "freecad_version": fc,
            "occt_version": occt,
            "order_rule": evaluate.ORDER_RULE,
            "parameter_space": evaluate.PARAMETER_SPACE.replace(
                "AFTER re-import", "BEFORE export (as built in FreeCAD)"
            ),
            "case": name,
            "description": desc,
        }
        src.update(evaluate.describe_shape(shape))
        with open(os.path.join(HERE, name + ".source.json"), "w", encoding="utf-8") as f:
            f.write(evaluate.dumps(src))
        files = []
        for fmt in opts.get("formats", ["step", "iges"]):
            ext = ".step" if fmt == "step" else ".igs"
            path = os.path.join(HERE, name + ext)
            set_statics(opts)
            export(shape, path, opts)
            set_statics({})
            reading = evaluate.read_file(path)
            with open(path + ".json", "w", encoding="utf-8") as f:
                f.write(evaluate.dumps(reading))
            comparison["cases"].setdefault(name, {})[fmt] = compare(src, reading, shape)
            files.append({"file": name + ext, "counts": reading["counts"]})
        index.append({"case": name, "description": desc, "options": opts,
                      "source_counts": src["counts"], "files": files})
    if not only:
        with open(os.path.join(HERE, "comparison.json"), "w", encoding="utf-8") as f:
            f.write(evaluate.dumps(comparison))
        with open(os.path.join(HERE, "COMPARISON.md"), "w", encoding="utf-8") as f:
            f.write(comparison_markdown(comparison))
        with open(os.path.join(HERE, "index.json"), "w", encoding="utf-8") as f:
            f.write(evaluate.dumps({"freecad_version": fc, "occt_version": occt,
                                    "cases": index}))



# freecadcmd runs a script under the name of its file stem ("generate"), or "__main__" with
# some launchers; samples/freecad/analytic/generate.py loads this file under another module
# name to reuse its export and normalisation, so the corpus is not rewritten then.
if __name__ in ("__main__", "generate"):
    main()
