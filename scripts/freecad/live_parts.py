# Live FreeCAD check of the whole-part samples (samples/freecad/parts): nurbsx converts each
# part's STEP, IGES faces-mode (144) and IGES B-rep-mode (186) file to STEP, to IGES 144 and to
# IGES 186 (--iges-brep), FreeCAD / Open CASCADE re-imports every output (Part.read, through
# scripts/freecad/part_reading.py: the reader that made the corpus), and the part it finds is
# compared with FreeCAD's reading of the part made in memory (<part>.source.json), which is
# independent of every file and of nurbsx:
#   - the same number of faces;
#   - total face area within 1e-6 relative;
#   - the area-weighted face centroid within 1e-6 of the part's size (placements, units);
#   - for a part with solids, written as STEP or IGES 186: as many solids, every one valid,
#     the total volume within 1e-6 relative.
# Prints one row per conversion (direction, faces, area error, centroid error, solids,
# volume error) and a summary line
#   live_parts: N conversions checked, M failed
# Run by tests/freecad_live.rs. NURBSX_ONLY=part1,part2 restricts the parts.
import importlib.util
import json
import os
import subprocess

import FreeCAD as App  # noqa: F401  (initialises FreeCAD)

BIN = os.environ["NURBSX_BIN"]
SAMPLES = os.environ["NURBSX_SAMPLES"]
WORK = os.environ["NURBSX_WORK"]
REPORT = os.environ.get("NURBSX_REPORT")
ONLY = [c for c in os.environ.get("NURBSX_ONLY", "").split(",") if c]
REL = 1e-6

_here = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location(
    "nurbsx_part_reading", os.path.join(_here, "part_reading.py"))
reading = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reading)

# (label, extension, extra nurbsx flags)
TARGETS = [("step", ".step", []), ("iges144", ".igs", []), ("iges186", ".igs", ["--iges-brep"])]


def kind_of(name):
    if name.endswith("_brep.igs"):
        return "iges186"
    return "step" if name.endswith(".step") else "iges144"


def convert(src, dst, flags):
    r = subprocess.run([BIN, "convert", src, "-o", dst] + flags, capture_output=True, text=True)
    return r.returncode, r.stderr.strip()


def rel(a, b):
    if a == 0 and b == 0:
        return 0.0
    return abs(b - a) / max(abs(a), 1e-300)


def compare(source, got):
    """Problems of the re-imported part `got` against the source reading, and the figures."""
    problems = []
    s_counts, g_counts = source["counts"], got["counts"]
    s_tot, g_tot = source["totals"], got["totals"]
    figures = {"faces": g_counts["faces"], "solids": g_counts["solids"]}
    if g_counts["faces"] != s_counts["faces"]:
        problems.append("faces %d, source %d" % (g_counts["faces"], s_counts["faces"]))
    figures["area"] = rel(s_tot["area"], g_tot["area"])
    if figures["area"] > REL:
        problems.append("area %.9g vs %.9g (relative %.1e)" % (g_tot["area"], s_tot["area"], figures["area"]))
    size = source["size"] or 1.0
    if s_tot["face_centroid"] and g_tot["face_centroid"]:
        d = sum((a - b) ** 2 for a, b in zip(s_tot["face_centroid"], g_tot["face_centroid"])) ** 0.5
        figures["centroid"] = d / size
        if figures["centroid"] > REL:
            problems.append("face centroid moved %.1e of the size" % figures["centroid"])
    return problems, figures


def check_solids(source, got, problems, figures):
    s_counts, g_counts = source["counts"], got["counts"]
    if g_counts["solids"] != s_counts["solids"]:
        problems.append("solids %d, source %d" % (g_counts["solids"], s_counts["solids"]))
        return
    if not all(s["valid"] for s in got["solids"]):
        problems.append("a solid is not valid")
    figures["volume"] = rel(source["totals"]["volume"] or 0.0, got["totals"]["volume"] or 0.0)
    if figures["volume"] > REL:
        problems.append("volume %.9g vs %.9g (relative %.1e)" % (
            got["totals"]["volume"] or 0.0, source["totals"]["volume"] or 0.0, figures["volume"]))


def main():
    index = json.load(open(os.path.join(SAMPLES, "index.json")))
    os.makedirs(WORK, exist_ok=True)
    rows, failed = [], 0
    print("%-26s %-8s -> %-8s %6s %9s %9s %7s %9s  %s" % (
        "part", "from", "to", "faces", "area", "centroid", "solids", "volume", "problems"))
    for part in index["parts"]:
        name = part["part"]
        if ONLY and name not in ONLY:
            continue
        source = json.load(open(os.path.join(SAMPLES, name + ".source.json")))
        for entry in part["files"]:
            src = os.path.join(SAMPLES, entry["file"])
            origin = kind_of(entry["file"])
            for label, ext, flags in TARGETS:
                out = os.path.join(WORK, "%s.%s.to_%s%s" % (name, origin, label, ext))
                code, err = convert(src, out, flags)
                row = {"part": name, "from": origin, "to": label}
                if code != 0 or not os.path.exists(out):
                    problems = ["nurbsx exited %d: %s" % (code, err[-300:])]
                    figures = {}
                else:
                    try:
                        got = reading.read_part(out)
                    except Exception as ex:  # FreeCAD could not read the output
                        got = None
                        problems, figures = ["FreeCAD cannot read the output: %r" % ex], {}
                    if got is not None:
                        problems, figures = compare(source, got)
                        if source["counts"]["solids"] and label in ("step", "iges186"):
                            check_solids(source, got, problems, figures)
                row.update(figures)
                row["problems"] = problems
                rows.append(row)
                failed += bool(problems)

                def f(k):
                    v = figures.get(k)
                    return "%9.1e" % v if isinstance(v, float) else "%9s" % "-"
                print("%-26s %-8s -> %-8s %6s %s %s %7s %s  %s" % (
                    name, origin, label, figures.get("faces", "-"), f("area"), f("centroid"),
                    figures.get("solids", "-"), f("volume"),
                    "ok" if not problems else "FAIL " + "; ".join(problems)))
    if REPORT:
        json.dump(rows, open(REPORT, "w"), indent=1)
    print("live_parts: %d conversions checked, %d failed" % (len(rows), failed))


main()
