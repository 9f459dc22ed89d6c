# Reads STEP/IGES files with FreeCAD (Part.read, Open CASCADE's reader) and prints one JSON
# line per file: faces, shells, solids, total area, volume, validity, area-weighted face
# centroid, and the area and volume of the shape converted to NURBS by Open CASCADE.
# Usage: freecadcmd reimport_faces.py -- FILE... (paths also taken from the
# REIMPORT_FILES environment variable, separated by os.pathsep, since freecadcmd passes
# script arguments inconsistently between versions).
import json
import os
import sys

import Part

files = [a for a in sys.argv[1:] if os.path.isfile(a) and not a.endswith(".py")]
files += [p for p in os.environ.get("REIMPORT_FILES", "").split(os.pathsep) if p]
for path in files:
    try:
        shape = Part.read(path)
        area = sum(f.Area for f in shape.Faces)
        centroid = [0.0, 0.0, 0.0]
        for f in shape.Faces:
            c = f.CenterOfMass
            for k in range(3):
                centroid[k] += f.Area * c[k]
        if area > 0:
            centroid = [x / area for x in centroid]
        out = {
            "file": path,
            "faces": len(shape.Faces),
            "shells": len(shape.Shells),
            "solids": len(shape.Solids),
            "area": area,
            "volume": sum(s.Volume for s in shape.Solids),
            "valid": bool(shape.isValid()),
            "solids_valid": all(s.isValid() for s in shape.Solids),
            "centroid": centroid,
        }
        # The same shape converted to NURBS by Open CASCADE itself and measured the same
        # way: Open CASCADE integrates rational B-spline faces with a fixed Gauss rule, so
        # the difference between this and "area" is the measuring error on NURBS geometry.
        nurbs = shape.toNurbs()
        out["nurbs_area"] = sum(f.Area for f in nurbs.Faces)
        out["nurbs_volume"] = sum(s.Volume for s in nurbs.Solids)
    except Exception as e:  # a file FreeCAD cannot read is reported, not fatal
        out = {"file": path, "error": str(e)}
    print("REIMPORT " + json.dumps(out))
