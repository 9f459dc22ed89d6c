# Regenerates freecad_arc_surface.igs and freecad_arc_surface.json with FreeCAD:
#   cd tests/data/iges && freecadcmd make_freecad_samples.py
# Made with FreeCAD 0.20.2 / OCCT 7.6.3. The JSON holds FreeCAD's evaluations of the
# geometry it built BEFORE export (an independent reference for our IGES reader).
import json, math
import FreeCAD, Part
from FreeCAD import Vector as V

# A tilted rational quadratic arc (weights 1, cos(45deg), 1) with an interior knot.
arc = Part.BSplineCurve()
h = math.sqrt(0.5)
poles = [V(2, 0, 0.5), V(2, 2, 1.0), V(0, 2, 1.5), V(-2, 2, 2.0), V(-2, 0, 2.5)]
arc.buildFromPolesMultsKnots(poles, [3, 2, 3], [0.0, 0.6, 1.0], False, 2, [1, h, 1, h, 1])

# A non-square 4 x 3 rational surface, degrees (2, 1), non-uniform knots.
surf = Part.BSplineSurface()
net = [[V(i * 1.5, j * 2.0, 0.3 * i * j + 0.1 * i * i) for j in range(3)] for i in range(4)]
w = [[1.0 + 0.25 * i + 0.5 * j for j in range(3)] for i in range(4)]
surf.buildFromPolesMultsKnots(net, [3, 1, 3], [2, 1, 2], [0.0, 0.35, 1.0], [0.0, 0.5, 2.0],
                              False, False, 2, 1, w)

shape = Part.Compound([arc.toShape(), Part.Face(surf)])
shape.exportIges("freecad_arc_surface.igs")

out = {"curve": [], "surface": []}
for k in range(11):
    t = k / 10.0
    out["curve"].append([t] + list(arc.value(t)))
for i in range(5):
    for j in range(5):
        u = i / 4.0
        v = 2.0 * j / 4.0
        out["surface"].append([u, v] + list(surf.value(u, v)))
json.dump(out, open("freecad_arc_surface.json", "w"), indent=1)
