# FreeCAD's reading of STEP assemblies written by nurbsx with their product structure.
#
# For every input file (NURBSX_INPUTS, separated by os.pathsep) nurbsx writes STEP twice:
# with the product structure (the default) and flattened (--flatten-assemblies). FreeCAD /
# Open CASCADE reads the input and both outputs (Part.read, which transfers the product
# structure into a compound of located shapes) and this script writes, per file read, what
# the test (tests/step_assembly_write.rs) compares:
#   - solids: per solid its Volume, CenterOfMass and its vertices (sorted);
#   - parts: how many distinct solids there are (solids that are partners, the same shape
#     under another location, count once): the parts an assembly uses, each once;
#   - tree: the compound's nesting (depth and shape type of every sub-shape).
# The report is a JSON list of {input, file, role, solids, parts, tree}.
import json
import os
import subprocess

import FreeCAD as App  # noqa: F401  (initialises FreeCAD)
import Part

BIN = os.environ["NURBSX_BIN"]
INPUTS = [p for p in os.environ["NURBSX_INPUTS"].split(os.pathsep) if p]
WORK = os.environ["NURBSX_WORK"]
REPORT = os.environ["NURBSX_REPORT"]


def tree(shape, depth=0):
    out = []
    for child in shape.childShapes(False, False):
        out.append([depth, child.ShapeType])
        if child.ShapeType == "Compound":
            out += tree(child, depth + 1)
    return out


def reading(path):
    shape = Part.read(path)
    solids = shape.Solids
    distinct = []
    for s in solids:
        if not any(s.isPartner(d) for d in distinct):
            distinct.append(s)
    return {
        "solids": [
            {
                "volume": s.Volume,
                "center": list(s.CenterOfMass),
                "vertices": sorted(list(v.Point) for v in s.Vertexes),
            }
            for s in solids
        ],
        "parts": len(distinct),
        "tree": tree(shape),
    }


rows = []
for k, path in enumerate(INPUTS):
    outputs = [("input", path, None)]
    for role, flags in [("structure", []), ("flattened", ["--flatten-assemblies"])]:
        out = os.path.join(WORK, "%d_%s.step" % (k, role))
        subprocess.run([BIN, "convert", path, "-o", out] + flags, check=True)
        outputs.append((role, out, flags))
    for role, file, _ in outputs:
        r = reading(file)
        r.update({"input": path, "file": file, "role": role})
        rows.append(r)
        print("%-60s %-10s solids %3d parts %3d tree depth %d" % (
            os.path.basename(path), role, len(r["solids"]), r["parts"],
            max([d for d, _ in r["tree"]] + [0])))

with open(REPORT, "w") as f:
    json.dump(rows, f)
print("assembly_structure: %d readings" % len(rows))
