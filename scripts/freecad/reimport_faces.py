# FreeCAD's reading of whole parts: for every file named in NURBSX_FILES (separated by
# os.pathsep), Part.read (Open CASCADE's STEP / IGES reader, as FreeCAD's import does) and
# one JSON line "reimport_faces: {...}" with the number of faces, shells and solids, the
# total face area, the volume of the solids, whether the shape and its solids are valid,
# and the area-weighted centroid of the faces. Run by tests/iges_topology.rs and
# tests/step_topology.rs.
#
# "area" is Open CASCADE's Face.Area. Its Gauss integration runs over a B-spline face's
# whole parameter range, so on a surface whose parameterisation is only C0 at a knot (the
# exact rational arcs of a cylinder or torus, joined with double knots) it is off by up to
# 1e-3 although the surface is exact. Two figures bound that measuring error:
# "single_span" says whether every face lies on one knot span (or an analytic surface),
# where the integration is accurate; "nurbs_area" / "nurbs_volume" measure the same shape
# converted to NURBS by Open CASCADE itself, so their difference from "area" / "volume" is
# the measuring error on NURBS geometry.
import json
import os

import FreeCAD as App  # noqa: F401  (initialises FreeCAD)
import Part


def single_span(face):
    s = face.Surface
    if not isinstance(s, Part.BSplineSurface):
        return True
    return len(s.getUKnots()) == 2 and len(s.getVKnots()) == 2


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
        nurbs = shape.toNurbs()
        out.update(
            faces=len(shape.Faces),
            shells=len(shape.Shells),
            solids=len(shape.Solids),
            area=area,
            single_span=all(single_span(f) for f in shape.Faces),
            volume=sum(s.Volume for s in shape.Solids),
            valid=bool(shape.isValid()),
            solids_valid=all(s.isValid() for s in shape.Solids),
            centroid=[x / area for x in c] if area > 0 else None,
            nurbs_area=sum(f.Area for f in nurbs.Faces),
            nurbs_volume=sum(s.Volume for s in nurbs.Solids),
        )
    except Exception as e:  # a file FreeCAD cannot read is a result, not a crash
        out["error"] = str(e)
    print("reimport_faces: " + json.dumps(out), flush=True)
