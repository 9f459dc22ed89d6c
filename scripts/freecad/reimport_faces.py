# FreeCAD's reading of whole parts: for every file named in NURBSX_FILES (separated by
# os.pathsep), Part.read (Open CASCADE's STEP / IGES reader, as FreeCAD's import does) and
# one JSON line "reimport_faces: {...}" with the number of faces, shells and solids, the
# total face area, the volume of the solids, whether the shape is valid, and the
# area-weighted centroid of the faces. Run by tests/iges_topology.rs.
#
# "area" is Open CASCADE's Face.Area. Its Gauss integration runs over a B-spline face's
# whole parameter range, so on a surface whose parameterisation is only C0 at a knot (the
# exact rational arcs of a cylinder or torus, joined with double knots) it is off by up to
# 1e-3 although the surface is exact. "area_spans" integrates the same faces cut at their
# surfaces' knot lines (each cut face lies in one knot span, where the integrand is smooth):
# the common of the face with each knot-span patch, summed; "spans_complete" is false when
# a cut face could not be made, then area_spans is not a measure of the face.
import json
import os

import FreeCAD as App  # noqa: F401  (initialises FreeCAD)
import Part


def span_faces(face):
    s = face.Surface
    if not isinstance(s, Part.BSplineSurface):
        return [face], True
    uk, vk = s.getUKnots(), s.getVKnots()
    if len(uk) == 2 and len(vk) == 2:
        return [face], True
    out = []
    for i in range(len(uk) - 1):
        for j in range(len(vk) - 1):
            patch = s.copy()
            patch.segment(uk[i], uk[i + 1], vk[j], vk[j + 1])
            out += face.common(Part.Face(patch)).Faces
    a = sum(f.Area for f in out)
    # A cell lost by the boolean shows as a large shortfall against the face's own area.
    return out, abs(a - face.Area) <= 1e-2 * face.Area


for path in [p for p in os.environ.get("NURBSX_FILES", "").split(os.pathsep) if p]:
    out = {"file": path}
    try:
        shape = Part.read(path)
        area = sum(f.Area for f in shape.Faces)
        c = [0.0, 0.0, 0.0]
        for f in shape.Faces:
            m = f.CenterOfMass
            for k in range(3):
                c[k] += f.Area * m[k]
        spans, complete = 0.0, True
        for f in shape.Faces:
            cut, ok = span_faces(f)
            spans += sum(g.Area for g in cut)
            complete = complete and ok
        out.update(
            faces=len(shape.Faces),
            shells=len(shape.Shells),
            solids=len(shape.Solids),
            area=area,
            area_spans=spans,
            spans_complete=complete,
            volume=sum(s.Volume for s in shape.Solids),
            valid=shape.isValid(),
            centroid=[x / area for x in c] if area > 0 else None,
        )
    except Exception as e:  # a file FreeCAD cannot read is a result, not a crash
        out["error"] = str(e)
    print("reimport_faces: " + json.dumps(out), flush=True)
