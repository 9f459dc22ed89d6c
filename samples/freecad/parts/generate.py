"""Deterministic generator of the whole-part sample corpus (STEP + IGES 144 + IGES 186).

Regenerate (any working directory):

    freecadcmd samples/freecad/parts/generate.py

Writes, into the directory of this script, for every part:
  <part>.step        STEP AP214 (Shape.exportStep; Import.export for the assembly)
  <part>.igs         IGES faces mode (write.iges.brep.mode = 0: 144 trimmed surfaces)
  <part>_brep.igs    IGES B-rep mode (write.iges.brep.mode = 1: 186 manifold solid B-rep)
  <file>.json        FreeCAD's reading of that file after RE-IMPORT (Part.read)
  <part>.source.json the same reading of the in-memory shape before export
and index.json (parts, files, counts, entity types) and freecad_roundtrip.json (FreeCAD's
own STEP -> IGES and IGES -> STEP conversions, re-imported). The reading is
scripts/freecad/part_reading.py (imported: one implementation); export, time-stamp / user /
host normalisation and the statics handling are those of samples/freecad/generate.py; the
trimmed B-spline face is that corpus's face_trimmed_hole. The JSON schema
("nurbsx-freecad-parts/1") is described in README.md next to this file.
NURBSX_ONLY=part1,part2 regenerates a subset (STEP PRODUCT counters then differ; experiments
only, index.json and freecad_roundtrip.json are not rewritten).
"""

import importlib.util
import json
import math
import os
import shutil
import tempfile

import FreeCAD
import Import
import Part

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))


# The one part reader (scripts/freecad/part_reading.py), loaded under a module name that does
# not run its command-line entry point; through it the B-spline corpus's export helpers.
_spec = importlib.util.spec_from_file_location(
    "nurbsx_freecad_part_reading", os.path.join(ROOT, "scripts", "freecad", "part_reading.py")
)
reading = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reading)
corpus = reading.analytic.corpus
evaluate = reading.evaluate

V = FreeCAD.Vector


def rot(axis, degrees):
    return FreeCAD.Rotation(V(*axis), degrees)


def placement(base, axis, degrees):
    return FreeCAD.Placement(V(*base), rot(axis, degrees))


# ----------------------------------------------------------------------------- parts
def box_fillet_chamfer_hole():
    box = Part.makeBox(40.0, 30.0, 20.0)
    vertical = [e for e in box.Edges
                if abs(e.Vertexes[0].Point.z - e.Vertexes[1].Point.z) > 1.0]
    box = box.makeFillet(4.0, vertical)
    bottom = [e for e in box.Edges
              if abs(e.Vertexes[0].Point.z) < 1e-9 and abs(e.Vertexes[-1].Point.z) < 1e-9]
    box = box.makeChamfer(1.5, bottom)
    return box.cut(Part.makeCylinder(5.0, 40.0, V(20.0, 15.0, -10.0), V(0, 0, 1)))


def boss_radial_hole():
    plate = Part.makeBox(40.0, 40.0, 8.0, V(-20.0, -20.0, 0.0))
    boss = Part.makeCylinder(10.0, 25.0, V(0, 0, 8.0), V(0, 0, 1))
    part = plate.fuse(boss).removeSplitter()
    part = part.cut(Part.makeCylinder(5.0, 50.0, V(0, 0, -5.0), V(0, 0, 1)))
    # radial hole from the axis outwards through one wall of the boss only
    return part.cut(Part.makeCylinder(3.0, 20.0, V(0, 0, 22.0), V(1, 0, 0)))


def flange():
    pts = [V(10, 0, 0), V(40, 0, 0), V(40, 0, 8), V(18, 0, 8), V(18, 0, 25), V(10, 0, 25),
           V(10, 0, 0)]
    solid = Part.Face(Part.makePolygon(pts)).revolve(V(0, 0, 0), V(0, 0, 1), 360.0)
    for k in range(6):
        a = 2.0 * math.pi * k / 6.0 + math.pi / 6.0
        solid = solid.cut(Part.makeCylinder(3.0, 20.0, V(30.0 * math.cos(a),
                                                          30.0 * math.sin(a), -5.0)))
    return solid


def cone_frustum_bore():
    cone = Part.makeCone(20.0, 10.0, 25.0)
    return cone.cut(Part.makeCylinder(5.0, 40.0, V(0, 0, -5.0)))


def sphere_cap():
    return Part.makeSphere(20.0).common(Part.makeBox(60.0, 60.0, 60.0, V(-30.0, -30.0, 8.0)))


def pipe_elbow():
    return Part.makeTorus(30.0, 6.0, V(0, 0, 0), V(0, 0, 1), -180.0, 180.0, 90.0)


def closed_bspline(poles, degree=3):
    """A periodic B-spline through no particular point: poles around a closed profile."""
    n = len(poles)
    return corpus.curve(poles, [1] * (n + 1), [float(k) for k in range(n + 1)], degree,
                        periodic=True)


def section(radius_x, radius_y, z, bumps, n=8):
    return [(radius_x * (1.0 + bumps[k % len(bumps)]) * math.cos(2 * math.pi * k / n),
             radius_y * (1.0 + bumps[k % len(bumps)]) * math.sin(2 * math.pi * k / n), z)
            for k in range(n)]


def loft_bspline():
    sections = [
        closed_bspline(section(12.0, 8.0, 0.0, [0.0, 0.1])),
        closed_bspline(section(8.0, 8.0, 15.0, [0.05, -0.05, 0.0], n=9)),
        closed_bspline(section(10.0, 14.0, 30.0, [0.0, 0.15, 0.0, -0.1], n=10)),
    ]
    return Part.makeLoft([Part.Wire(c.toShape()) for c in sections], True, False)


def sweep_circle():
    path = corpus.curve([(0, 0, 0), (10, 0, 8), (25, 10, 12), (35, 25, 30), (40, 40, 35)],
                        [4, 1, 4], [0.0, 0.5, 1.0], 3)
    start = path.value(0.0)
    tangent = path.tangent(0.0)[0]
    circle = Part.Circle(start, tangent, 3.0).toShape()
    return Part.Wire(path.toShape()).makePipeShell([Part.Wire(circle)], True, True)


def revolution_profile():
    bs = corpus.curve([(10, 0, 0), (16, 0, 6), (9, 0, 14), (15, 0, 22), (10, 0, 30)],
                      [4, 1, 4], [0.0, 0.5, 1.0], 3)
    top, bottom = V(10, 0, 30), V(10, 0, 0)
    return Part.Face(Part.Wire([
        bs.toShape(),
        Part.LineSegment(top, V(4, 0, 30)).toShape(),
        Part.LineSegment(V(4, 0, 30), V(4, 0, 0)).toShape(),
        Part.LineSegment(V(4, 0, 0), bottom).toShape(),
    ]))


def revolve_bspline_270():
    return revolution_profile().revolve(V(0, 0, 0), V(0, 0, 1), 270.0)


def extrude_bspline():
    poles = [(12, 0, 0), (9, 9, 0), (0, 7, 0), (-10, 10, 0), (-12, 0, 0), (-6, -8, 0),
             (0, -12, 0), (9, -7, 0)]
    face = Part.Face(Part.Wire(closed_bspline(poles).toShape()))
    return face.extrude(V(0, 0, 15.0))


def steinmetz():
    a = Part.makeCylinder(10.0, 40.0, V(-20.0, 0, 0), V(1, 0, 0))
    b = Part.makeCylinder(10.0, 40.0, V(0, -20.0, 0), V(0, 1, 0))
    return a.common(b)


def cylinder_sphere():
    return Part.makeCylinder(6.0, 30.0).fuse(Part.makeSphere(10.0, V(0, 0, 30.0)))


def trimmed_face():
    builders = {c[0]: c[2] for c in corpus.case_surfaces()}
    return builders["face_trimmed_hole"]()


def free_edges():
    c = Part.Circle(V(0, 0, 0), V(0, 0, 1), 5.0)
    arc = Part.ArcOfCircle(Part.Circle(V(20, 0, 0), V(0, 1, 1), 4.0), 0.5, 3.5)
    ell = Part.Ellipse(V(0, 20, 0), 8.0, 3.0)
    spline = corpus.curve([(20, 20, 0), (25, 28, 4), (32, 18, -2), (40, 24, 3)], [4, 4],
                          [0.0, 1.0], 3)
    poly = Part.makePolygon([V(-20, 0, 0), V(-10, 2, 1), V(-12, 10, 3), V(-22, 12, 0)])
    return Part.Compound([
        Part.LineSegment(V(0, -20, 0), V(30, -15, 5)).toShape(),
        c.toShape(), arc.toShape(), ell.toShape(), spline.toShape(), poly,
    ])


def several_solids():
    return Part.Compound([
        Part.makeBox(10.0, 10.0, 10.0),
        Part.makeBox(8.0, 12.0, 6.0, V(20.0, 0, 0)),
        Part.makeCylinder(4.0, 10.0, V(0, 25.0, 0)),
    ])


def touching_solids():
    """Solids that touch without fusing: a sewing reader must keep them apart."""
    return Part.Compound([
        Part.makeBox(10.0, 10.0, 10.0),
        Part.makeBox(8.0, 10.0, 6.0, V(10.0, 0, 0)),
        Part.makeBox(10.0, 10.0, 4.0, V(0, 0, 10.0)),
        Part.makeCylinder(3.0, 5.0, V(5.0, 5.0, 14.0)),
    ])


def inch_plate():
    inch = 25.4
    plate = Part.makeBox(4 * inch, 2 * inch, 0.25 * inch)
    vertical = [e for e in plate.Edges
                if abs(e.Vertexes[0].Point.z - e.Vertexes[1].Point.z) > 1.0]
    plate = plate.makeFillet(0.25 * inch, vertical)
    for x in (0.75, 3.25):
        plate = plate.cut(Part.makeCylinder(0.125 * inch, inch, V(x * inch, inch, -inch / 2)))
    return plate


class Assembly:
    """An App::Part of App::Links with rotated placements; the bracket is used twice."""

    def __init__(self):
        self.doc = FreeCAD.newDocument("assembly")
        doc = self.doc
        bracket = doc.addObject("Part::Feature", "Bracket")
        bracket.Shape = Part.makeBox(20.0, 10.0, 5.0).cut(
            Part.makeCylinder(2.0, 10.0, V(10.0, 5.0, -2.0)))
        pin = doc.addObject("Part::Feature", "Pin")
        pin.Shape = Part.makeCylinder(2.0, 15.0)
        self.root = doc.addObject("App::Part", "Assembly")
        links = []
        for name, target, plc in [
            ("Bracket_1", bracket, placement((0, 0, 0), (0, 0, 1), 0.0)),
            ("Bracket_2", bracket, placement((40.0, 0, 0), (1, 1, 0), 30.0)),
            ("Pin_1", pin, placement((10.0, 5.0, -5.0), (0, 1, 0), 15.0)),
        ]:
            link = doc.addObject("App::Link", name)
            link.LinkedObject = target
            link.Placement = plc
            links.append(link)
        self.root.addObjects(links)
        doc.recompute()

    def shape(self):
        return Part.getShape(self.root)

    def export(self, path):
        """STEP through Import.export (XCAF: the product structure). IGES has no assembly
        structure in OCCT's writer either way, and Import.export writes the 406 name
        entities of the instances in an order that changes from run to run (hash order), so
        the IGES files are exported from the located compound instead (deterministic)."""
        if path.endswith(".step"):
            Import.export([self.root], path)
            corpus.normalise_step(path)
        else:
            corpus.export(self.shape(), path, {})

    def close(self):
        FreeCAD.closeDocument(self.doc.Name)


# name, description, builder, options: genus (hand-stated, per closed shell summed; None for
# parts without a closed shell), units (export unit)
PARTS = [
    ("box_fillet_chamfer_hole", "box 40 x 30 x 20, the 4 vertical edges filleted r=4, the "
     "bottom edges chamfered 1.5, through hole r=5 along z", box_fillet_chamfer_hole,
     {"genus": 1}),
    ("boss_radial_hole", "plate 40 x 40 x 8 fused with a cylinder boss r=10 h=25, axial bore "
     "r=5 through plate and boss, radial hole r=3 through one wall of the boss into the bore",
     boss_radial_hole, {"genus": 2}),
    ("flange", "revolved polygon profile (hub r 10..18 h 25, disc r 10..40 h 8), 360 degrees, "
     "6 bolt holes r=3 on a circle r=30", flange, {"genus": 7}),
    ("cone_frustum_bore", "cone frustum r 20 -> 10, h=25, axial bore r=5", cone_frustum_bore,
     {"genus": 1}),
    ("sphere_cap", "sphere r=20 cut by the plane z=8 (the cap above it)", sphere_cap,
     {"genus": 0}),
    ("pipe_elbow", "torus segment solid (pipe elbow), major r=30, minor r=6, 90 degrees",
     pipe_elbow, {"genus": 0}),
    ("loft_bspline", "solid loft (makeLoft, not ruled) between 3 different closed periodic "
     "cubic B-spline sections (8, 9, 10 poles)", loft_bspline, {"genus": 0}),
    ("sweep_circle_bspline", "solid sweep of a circle r=3 along a cubic B-spline path "
     "(makePipeShell, Frenet)", sweep_circle, {"genus": 0}),
    ("revolve_bspline_270", "face bounded by a cubic B-spline and 3 lines (XZ plane, off the "
     "axis) revolved 270 degrees about z (solid)", revolve_bspline_270, {"genus": 0}),
    ("extrude_bspline", "face bounded by a closed periodic cubic B-spline (8 poles) extruded "
     "15 along z (solid)", extrude_bspline, {"genus": 0}),
    ("steinmetz", "boolean common of two cylinders r=10 with perpendicular axes (x and y)",
     steinmetz, {"genus": 0}),
    ("cylinder_sphere_fused", "cylinder r=6 h=30 fused with a sphere r=10 centred on its top",
     cylinder_sphere, {"genus": 0}),
    ("trimmed_face", "a single bicubic B-spline face trimmed to u 0.1..0.9, v 0.05..0.95 with "
     "a circular hole (samples/freecad face_trimmed_hole), as a lone face", trimmed_face,
     {"genus": None}),
    ("free_edges", "free edges, one of each kind: line segment, full circle, tilted arc, full "
     "ellipse, cubic B-spline, open polyline of 3 segments", free_edges, {"genus": None}),
    ("several_solids", "three disjoint solids in one compound: box 10^3, box 8 x 12 x 6, "
     "cylinder r=4 h=10", several_solids, {"genus": 0}),
    ("touching_solids", "four solids that touch and are not fused: box 10^3; box 8 x 10 x 6 "
     "against its x = 10 face (one edge in common); box 10 x 10 x 4 on its top face (the whole "
     "face in common); cylinder r=3 h=5 standing on that box", touching_solids, {"genus": 0}),
    ("assembly_links", "App::Part 'Assembly' of App::Links: 'Bracket' (box 20 x 10 x 5 with a "
     "hole r=2) used twice (Bracket_1 at the origin, Bracket_2 at (40,0,0) rotated 30 deg about "
     "(1,1,0)) and 'Pin' (cylinder r=2 h=15) at (10,5,-5) rotated 15 deg about y; "
     "STEP by Import.export, IGES by exportIges of the located compound", None,
     {"genus": 2, "assembly": True}),
    ("inch_plate", "plate 4 x 2 x 0.25 inch, vertical edges filleted 0.25 inch, two holes "
     "r=0.125 inch; exported with unit INCH", inch_plate, {"genus": 2, "units": "INCH"}),
]

FILES = [("", ".step", {}), ("", ".igs", {"brep": 0}), ("_brep", ".igs", {"brep": 1})]


def export_opts(opts, brep):
    return {"step_schema": "AP214IS", "unit": opts.get("units", "MM"), "iges_brep_mode": brep}


def write_json(path, obj):
    with open(path, "w", encoding="utf-8") as f:
        f.write(evaluate.dumps(obj))


def with_part(r, name, desc, opts, eopts):
    """The reading with the part's name, description and export options after `schema`."""
    out = {"schema": r["schema"], "part": name, "description": desc,
           "genus": opts.get("genus"), "export": eopts}
    for k, v in r.items():
        if k != "schema":
            out[k] = v
    return out


def check_file(fname, r, opts, brep, fmt):
    """Refuse a file that does not hold what it is said to hold."""
    unit = opts.get("units", "MM")
    if r["unit"]["name"] != unit:
        raise RuntimeError(f"{fname}: declares {r['unit']}, exported as {unit}")
    ents = r["file_entities"]
    if fmt == "iges" and r["counts"]["faces"]:
        key = "186" if brep and r["counts"]["solids"] else ("510" if brep else "144")
        if key not in ents:
            raise RuntimeError(f"{fname}: no IGES {key} entity ({sorted(ents)})")
        if not brep and ("186" in ents or "510" in ents):
            raise RuntimeError(f"{fname}: B-rep entities in a faces-mode file")


# ----------------------------------------------------------------------------- round trip
def rel(a, b):
    if a is None or b is None:
        return None
    return abs(a - b) / abs(b) if b else abs(a - b)


def max_face_error(src_faces, faces):
    """Largest relative area error of a face against the source face nearest to its centre of
    mass (None when the face counts differ)."""
    if len(src_faces) != len(faces) or not faces:
        return None
    worst = 0.0
    for f in faces:
        s = min(src_faces, key=lambda g: math.dist(g["center_of_mass"], f["center_of_mass"]))
        worst = max(worst, rel(f["area"], s["area"]))
    return worst


def convert(src, dst, brep):
    """FreeCAD's own conversion: Part.read, then exportStep / exportIges with the statics."""
    shape = Part.read(src)
    corpus.set_statics({"brep": brep} if brep else {})
    if dst.endswith(".step"):
        shape.exportStep(dst)
    else:
        shape.exportIges(dst)
    corpus.set_statics({})


def roundtrip(name, src_reading, work):
    """STEP -> IGES (144, 186) -> re-import and IGES (144, 186) -> STEP -> re-import."""
    out = []
    for src_file, dst_file, brep in [
        (name + ".step", "step_to_iges.igs", 0),
        (name + ".step", "step_to_iges_brep.igs", 1),
        (name + ".igs", "iges_to_step.step", 0),
        (name + "_brep.igs", "iges_brep_to_step.step", 0),
    ]:
        dst = os.path.join(work, dst_file)
        convert(os.path.join(HERE, src_file), dst, brep)
        r = reading.read_part(dst)
        s_tot, r_tot = src_reading["totals"], r["totals"]
        size = src_reading["size"]
        centroid = None
        if s_tot["face_centroid"] and r_tot["face_centroid"]:
            centroid = math.dist(s_tot["face_centroid"], r_tot["face_centroid"]) / size
        out.append({
            "from": src_file,
            "to": {"step_to_iges.igs": "iges (144)", "step_to_iges_brep.igs": "iges (186)",
                   "iges_to_step.step": "step", "iges_brep_to_step.step": "step"}[dst_file],
            "faces": [src_reading["counts"]["faces"], r["counts"]["faces"]],
            "solids": [src_reading["counts"]["solids"], r["counts"]["solids"]],
            "area_rel_error": rel(r_tot["area"], s_tot["area"]),
            "volume_rel_error": rel(r_tot["volume"], s_tot["volume"]),
            "face_centroid_error_per_size": centroid,
            "max_face_area_rel_error": max_face_error(src_reading["faces"], r["faces"]),
            "free_edge_length_rel_error": rel(r_tot["free_edge_length"],
                                              s_tot["free_edge_length"]),
            "surface_types": r["surface_types"],
            "valid": r_tot["valid"],
        })
    return out


# ----------------------------------------------------------------------------- README tables
TABLES_BEGIN = "<!-- generated by generate.py: begin -->"
TABLES_END = "<!-- generated by generate.py: end -->"

# STEP instances every file has (product, context, units, points, directions, placements)
STEP_BOILERPLATE = (
    "APPLICATION_", "AXIS2_PLACEMENT_3D", "CARTESIAN_POINT", "DIRECTION", "PRODUCT_",
    "PRODUCT_DEFINITION", "SHAPE_DEFINITION_REPRESENTATION", "PRODUCT_RELATED",
    "PRODUCT_CONTEXT", "MECHANICAL_CONTEXT", "DESIGN_CONTEXT", "UNCERTAINTY_MEASURE_WITH_UNIT",
    "(GEOMETRIC_REPRESENTATION_CONTEXT", "(LENGTH_UNIT NAMED_UNIT SI_UNIT)",
    "(NAMED_UNIT PLANE_ANGLE_UNIT SI_UNIT)", "(NAMED_UNIT SI_UNIT SOLID_ANGLE_UNIT)",
    "(NAMED_UNIT PLANE_ANGLE_UNIT", "PLANE_ANGLE_MEASURE_WITH_UNIT", "DIMENSIONAL_EXPONENTS",
    "VECTOR", "DEFINITIONAL_REPRESENTATION",
)

RATIONAL_NAMES = {
    "(BOUNDED_CURVE B_SPLINE_CURVE B_SPLINE_CURVE_WITH_KNOTS CURVE "
    "GEOMETRIC_REPRESENTATION_ITEM RATIONAL_B_SPLINE_CURVE REPRESENTATION_ITEM)":
        "rational B_SPLINE_CURVE",
    "(BOUNDED_SURFACE B_SPLINE_SURFACE B_SPLINE_SURFACE_WITH_KNOTS "
    "GEOMETRIC_REPRESENTATION_ITEM RATIONAL_B_SPLINE_SURFACE REPRESENTATION_ITEM SURFACE)":
        "rational B_SPLINE_SURFACE",
    "(REPRESENTATION_RELATIONSHIP REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION "
    "SHAPE_REPRESENTATION_RELATIONSHIP)": "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
    "(CONVERSION_BASED_UNIT LENGTH_UNIT NAMED_UNIT)": "CONVERSION_BASED_UNIT",
}


def _entities_text(fname, ents):
    items = []
    for k, n in ents.items():
        if fname.endswith(".step"):
            if k.startswith(STEP_BOILERPLATE) and k not in RATIONAL_NAMES:
                continue
            k = RATIONAL_NAMES.get(k, k)
        items.append(k if n == 1 else f"{k}×{n}")
    return ", ".join(items)


def _e(x):
    return "–" if x is None else ("0" if x == 0 else f"{x:.1e}")


def tables(index, trips):
    """Markdown tables of the parts, their file entities and FreeCAD's own conversions."""
    out = [TABLES_BEGIN, "", "### Parts: what FreeCAD reads back (per file)", "",
           "Faces = `counts.faces`; solids = `counts.solids`; area and volume of the "
           "in-memory source (mm², mm³); `dA`, `dV` = |reading − source| / source for the "
           "`.step`, faces-mode `.igs` and `_brep.igs` readings (– = no solid read); genus "
           "= the hand-stated genus (README: checks).", "",
           "| part | faces src/step/igs/brep | solids src/step/igs/brep | area | dA step / igs "
           "/ brep | volume | dV step / brep | genus | unit |",
           "|---|---|---|---|---|---|---|---|---|"]
    for entry in index:
        name = entry["part"]
        src = _read_json(os.path.join(HERE, name + ".source.json"))
        rs = [_read_json(os.path.join(HERE, f["file"] + ".json")) for f in entry["files"]]
        faces = "/".join(str(r["counts"]["faces"]) for r in [src] + rs)
        solids = "/".join(str(r["counts"]["solids"]) for r in [src] + rs)
        da = " / ".join(_e(rel(r["totals"]["area"], src["totals"]["area"])) for r in rs)
        dv = " / ".join(_e(rel(r["totals"]["volume"], src["totals"]["volume"]))
                        for r in (rs[0], rs[2]))
        vol = src["totals"]["volume"]
        out.append(f"| `{name}` | {faces} | {solids} | {src['totals']['area']:.6f} | {da} | "
                   f"{'–' if vol is None else f'{vol:.6f}'} | {dv} | "
                   f"{'–' if entry['genus'] is None else entry['genus']} | "
                   f"{rs[0]['unit']['name']} |")
    out += ["", "### Entity types in each file", "",
            "STEP: instances other than the product/context/unit boilerplate, points, "
            "directions, placements, vectors and DEFINITIONAL_REPRESENTATION (all in "
            "`file_entities`); complex instances named by their main type. IGES: Directory "
            "Entry types. `×n` = count.", "",
            "| file | entities |", "|---|---|"]
    for entry in index:
        for f in entry["files"]:
            out.append(f"| `{f['file']}` | {_entities_text(f['file'], f['file_entities'])} |")
    out += ["", "### FreeCAD's own conversions (`freecad_roundtrip.json`)", "",
            "`Part.read` of the committed file, `exportIges` (brep mode 0 or 1) / "
            "`exportStep`, `Part.read` of the result; errors against the source: total "
            "area, volume (– = no solid read), largest face-area error (each face against the "
            "source face nearest its centre of mass), area-weighted face centroid distance / "
            "part size, free-edge length.", "",
            "| part | conversion | faces | solids | dA | dV | max face dA | centroid | "
            "free-edge length |", "|---|---|---|---|---|---|---|---|---|"]
    for name, rows in trips.items():
        for t in rows:
            out.append(
                f"| `{name}` | `{t['from']}` → {t['to']} | {t['faces'][0]} → {t['faces'][1]} "
                f"| {t['solids'][0]} → {t['solids'][1]} | {_e(t['area_rel_error'])} | "
                f"{_e(t['volume_rel_error'])} | {_e(t['max_face_area_rel_error'])} | "
                f"{_e(t['face_centroid_error_per_size'])} | "
                f"{_e(t['free_edge_length_rel_error'])} |")
    out += ["", TABLES_END]
    return "\n".join(out)


def _read_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def update_readme(text_of_tables):
    path = os.path.join(HERE, "README.md")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    head, sep, rest = text.partition(TABLES_BEGIN)
    _, sep2, tail = rest.partition(TABLES_END)
    if not sep or not sep2:
        raise RuntimeError("README.md: table markers missing")
    with open(path, "w", encoding="utf-8") as f:
        f.write(head + text_of_tables + tail)


# ----------------------------------------------------------------------------- main
def main():
    only = os.environ.get("NURBSX_ONLY")
    names = [p[0] for p in PARTS]
    assert len(names) == len(set(names))
    fc, occt = evaluate.versions()
    index, trips = [], {}
    work = tempfile.mkdtemp(prefix="nurbsx_parts_")
    try:
        for name, desc, build, opts in PARTS:
            if only and name not in only.split(","):
                continue
            asm = Assembly() if opts.get("assembly") else None
            shape = asm.shape() if asm else build()
            src = reading.header(None, "in-memory", "in-memory shape before export")
            src["unit"] = None
            src["file_entities"] = None
            src.update(reading.describe_part(shape))
            src = with_part(src, name, desc, opts, export_opts(opts, 0))
            write_json(os.path.join(HERE, name + ".source.json"), src)
            entry = {"part": name, "description": desc, "genus": opts.get("genus"),
                     "source_counts": src["counts"], "files": []}
            for suffix, ext, extra in FILES:
                fname = name + suffix + ext
                path = os.path.join(HERE, fname)
                brep = extra.get("brep", 0)
                eopts = dict(extra)
                if "units" in opts:
                    eopts["units"] = opts["units"]
                corpus.set_statics(eopts)
                if asm:
                    asm.export(path)
                else:
                    corpus.export(shape, path, {})
                corpus.set_statics({})
                fmt = "step" if ext == ".step" else "iges"
                r = reading.read_part(path)
                check_file(fname, r, opts, brep, fmt)
                r = with_part(r, name, desc, opts, export_opts(opts, brep if fmt == "iges" else 0))
                write_json(path + ".json", r)
                entry["files"].append({"file": fname, "export": r["export"],
                                       "unit": r["unit"]["name"], "counts": r["counts"],
                                       "file_entities": r["file_entities"]})
            if asm:
                asm.close()
            index.append(entry)
            trips[name] = roundtrip(name, src, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if not only:
        write_json(os.path.join(HERE, "index.json"),
                   {"schema": reading.SCHEMA_ID, "freecad_version": fc, "occt_version": occt,
                    "parts": index})
        write_json(os.path.join(HERE, "freecad_roundtrip.json"),
                   {"schema": reading.SCHEMA_ID, "freecad_version": fc, "occt_version": occt,
                    "conversion": "Part.read(file), then Shape.exportIges / exportStep "
                                  "(write.iges.brep.mode 0 or 1), then Part.read again; "
                                  "errors relative to the part's source.json",
                    "parts": trips})
        update_readme(tables(index, trips))


# freecadcmd runs a script under the name of its file stem ("generate") or "__main__".
if __name__ in ("__main__", "generate"):
    reading.analytic.run_as_script(main)
