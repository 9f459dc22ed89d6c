# Makes the FreeCAD fixtures in this folder. Run from this folder with:
#   freecadcmd make_fixtures.py
# (FreeCAD 0.20.2 / Open CASCADE 7.6.3 were used.) Each geometry is built with Part, exported
# with Shape.exportStep, and its evaluations are not stored: the tests compare the file's
# geometry with the same construction written here by hand.
import FreeCAD as App
import Part
from FreeCAD import Vector as V

# 1. A rational quadratic B-spline: a quarter circle of radius 10 (exact weights) + a cubic
#    polynomial curve, in one compound (two edges).
arc = Part.BSplineCurve()
arc.buildFromPolesMultsKnots([V(10, 0, 0), V(10, 10, 0), V(0, 10, 0)], [3, 3], [0.0, 1.0], False, 2,
                             [1.0, 0.7071067811865476, 1.0])
cub = Part.BSplineCurve()
cub.buildFromPolesMultsKnots([V(0, 0, 0), V(1, 2, 0), V(3, 2, 1), V(4, 0, 1), V(6, -1, 0)],
                             [4, 1, 4], [0.0, 0.5, 1.0], False, 3)
Part.Compound([arc.toShape(), cub.toShape()]).exportStep("freecad_curves.step")

# 2. A rational bi-quadratic x cubic surface face, exported in inches.
poles = [[V(i * 10, j * 10, ((i * 7 + j * 3) % 5) - 2) for j in range(4)] for i in range(3)]
weights = [[1.0, 0.8, 1.2, 1.0], [0.9, 1.5, 1.1, 1.0], [1.0, 1.0, 0.7, 1.3]]
srf = Part.BSplineSurface()
srf.buildFromPolesMultsKnots(poles, [3, 3], [4, 4], [0.0, 1.0], [0.0, 2.0], False, False, 2, 3, weights)
Part.exportUnits("INCH")
srf.toShape().exportStep("freecad_surface_inch.step")
Part.exportUnits("MM")
