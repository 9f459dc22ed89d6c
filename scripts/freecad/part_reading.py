"""FreeCAD's reading of a whole part (solids, shells, faces, edges), as JSON.

Run headless; freecadcmd swallows argv (it tries to open arguments as documents), so the
paths come from environment variables:

    NURBSX_IN=part.step NURBSX_OUT=part.step.json freecadcmd scripts/freecad/part_reading.py

The file is re-imported with ``Part.read`` (OCCT STEPControl_Reader / IGESControl_Reader;
for a STEP assembly the reader applies the NEXT_ASSEMBLY_USAGE_OCCURRENCE placements and
gives one located copy per instance) and described by ``describe_part``: counts of solids,
shells, faces, wires, edges and vertices, every face (surface type, area, orientation,
wires, centre of mass), every shell (closed, valid), every solid (volume, centre of mass,
valid), the free edges (edges in no face), and totals (area, volume, area-weighted face
centroid). The schema ("nurbsx-freecad-parts/1") is described in
samples/freecad/parts/README.md. Exit status: 0 = reading written, 1 = the file could not be
read (the JSON then holds "error"), 2 = usage.

samples/freecad/parts/generate.py loads this file as a module and uses ``read_part`` and
``describe_part`` for every committed reading, so the corpus and a live reading of nurbsx's
output are produced by the same code.
"""

import importlib.util
import os

import FreeCAD  # noqa: F401  (provided by freecadcmd)
import Part

SCHEMA_ID = "nurbsx-freecad-parts/1"

_HERE = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.dirname(os.path.dirname(_HERE))


# The analytic corpus's file facts (entity counts, declared unit) and, through it, the one
# B-spline reader (JSON layout, versions, command-line handling) are reused, not copied.
# Loaded under a module name other than "generate" so that its main() does not run.
_spec = importlib.util.spec_from_file_location(
    "nurbsx_freecad_analytic", os.path.join(_ROOT, "samples", "freecad", "analytic", "generate.py")
)
analytic = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(analytic)
evaluate = analytic.evaluate

_vec = evaluate._vec


def _type(g):
    return type(g).__name__ if g is not None else "None"


def _curve_type(e):
    if e.Degenerated:
        return "Degenerated"
    try:
        return _type(e.Curve)
    except Exception:  # an edge without a 3-D curve
        return "None"


def _count(names):
    out = {}
    for n in names:
        out[n] = out.get(n, 0) + 1
    return dict(sorted(out.items()))


def _weighted(pairs):
    """sum(w_i * p_i) / sum(w_i) for (w, vector) pairs; None when the weights sum to 0."""
    total = sum(w for w, _ in pairs)
    if total == 0.0:
        return None
    return [sum(w * p[k] for w, p in pairs) / total for k in range(3)]


def describe_part(shape):
    """The reading of a shape (from shape_type on; README: schema)."""
    faces = []
    for i, f in enumerate(shape.Faces):
        faces.append({
            "index": i,
            "surface_type": _type(f.Surface),
            "area": float(f.Area),
            "orientation": f.Orientation,
            "wires": len(f.Wires),
            "center_of_mass": _vec(f.CenterOfMass),
        })
    shells = []
    for i, s in enumerate(shape.Shells):
        shells.append({"index": i, "faces": len(s.Faces), "closed": bool(s.isClosed()),
                       "valid": bool(s.isValid())})
    solids = []
    for i, s in enumerate(shape.Solids):
        solids.append({"index": i, "shells": len(s.Shells), "faces": len(s.Faces),
                       "volume": float(s.Volume), "area": float(s.Area),
                       "center_of_mass": _vec(s.CenterOfMass), "valid": bool(s.isValid())})
    # Edges that bound no face: OCCT's map of edges to their faces (TopExp::MapShapesAndAncestors).
    in_faces = set()
    for f in shape.Faces:
        for e in f.Edges:
            in_faces.add(e.hashCode())
    free = []
    for e in shape.Edges:
        if e.hashCode() in in_faces:
            continue
        free.append({"curve_type": _curve_type(e), "length": float(e.Length),
                     "closed": bool(e.isClosed()),
                     "vertices": [_vec(v.Point) for v in e.Vertexes]})
    empty = shape.isNull() or not (shape.Faces or shape.Edges)
    bb = None if empty else shape.BoundBox
    area = sum(f["area"] for f in faces)
    volume = sum(s["volume"] for s in solids) if solids else None
    return {
        "shape_type": shape.ShapeType if not shape.isNull() else "Null",
        "counts": {
            "solids": len(shape.Solids),
            "shells": len(shape.Shells),
            "closed_shells": sum(1 for s in shells if s["closed"]),
            "faces": len(shape.Faces),
            "wires": len(shape.Wires),
            "face_wires": sum(f["wires"] for f in faces),
            "edges": len(shape.Edges),
            "degenerated_edges": sum(1 for e in shape.Edges if e.Degenerated),
            "free_edges": len(free),
            "vertices": len(shape.Vertexes),
        },
        "curve_types": _count(_curve_type(e) for e in shape.Edges),
        "surface_types": _count(f["surface_type"] for f in faces),
        "bound_box": None if empty else [float(bb.XMin), float(bb.YMin), float(bb.ZMin),
                                         float(bb.XMax), float(bb.YMax), float(bb.ZMax)],
        "size": None if empty else float(bb.DiagonalLength),
        "totals": {
            "area": area,
            "volume": volume,
            "face_centroid": _weighted([(f["area"], f["center_of_mass"]) for f in faces]),
            "center_of_mass": _weighted([(s["volume"], s["center_of_mass"]) for s in solids])
            if solids else None,
            "free_edge_length": sum(e["length"] for e in free),
            "valid": bool(shape.isValid()) if not shape.isNull() else False,
        },
        "faces": faces,
        "shells": shells,
        "solids": solids,
        "free_edges": free,
    }


def file_facts(path):
    """Declared length unit and entity counts of a STEP or IGES file (from its text; the scans
    go by the extensions .step and .igs). A unit the scan does not recognise is
    {"name": None, ..., "evidence": why}; entity counts it cannot take are None."""
    if not path.endswith((".step", ".igs")):
        why = "not scanned: the text scans know the extensions .step and .igs"
        return {"name": None, "mm_per_unit": None, "evidence": why}, None
    try:
        unit = analytic.declared_unit(path)
    except Exception as ex:  # a unit form the text scan does not know: say so
        unit = {"name": None, "mm_per_unit": None, "evidence": f"not recognised: {ex!r}"}
    try:
        entities = analytic.file_entities(path)
    except Exception:  # a record layout the scan does not know
        entities = None
    return unit, entities


def header(path, fmt, reader):
    fc, occt = evaluate.versions()
    return {
        "schema": SCHEMA_ID,
        "file": os.path.basename(path) if path else None,
        "format": fmt,
        "reader": reader,
        "freecad_version": fc,
        "occt_version": occt,
    }


def file_format(path):
    ext = os.path.splitext(path)[1].lower()
    return {".step": "step", ".stp": "step", ".igs": "iges", ".iges": "iges"}.get(ext, ext)


def read_part(path):
    """Re-import path (STEP or IGES) with Part.read and describe it."""
    shape = Part.read(path)
    out = header(path, file_format(path), "Part.read")
    unit, entities = file_facts(path)
    out["unit"] = unit
    out["file_entities"] = entities
    out.update(describe_part(shape))
    return out


def main():
    evaluate.run_cli(read_part, SCHEMA_ID, "part_reading.py")


# freecadcmd runs a script under the name of its file stem ("part_reading"), or "__main__";
# generate.py loads this file under another module name, so it does not run.
if __name__ in ("__main__", "part_reading"):
    main()
