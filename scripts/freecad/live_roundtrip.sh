#!/bin/sh
# Live FreeCAD round trip of nurbsx conversions (samples/README.md, "Live FreeCAD check").
#
#   scripts/freecad/live_roundtrip.sh [path/to/nurbsx]   real run (default target/debug/nurbsx)
#   scripts/freecad/live_roundtrip.sh --copy             stand-in: FreeCAD's own files
#   scripts/freecad/live_roundtrip.sh --mock             stand-in: live_mock_nurbsx.py writer
#   scripts/freecad/live_roundtrip.sh --self-test        stand-ins must pass, and every
#                                                        negative control must fail
# NURBSX_ONLY=case1,case2 restricts the cases; NURBSX_WORK / NURBSX_REPORT are honoured.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
script="$here/live_roundtrip.py"
mock="$here/live_mock_nurbsx.py"
command -v freecadcmd >/dev/null 2>&1 || { echo "freecadcmd not on PATH (apt-get install freecad-python3)"; exit 2; }

run() { # run BIN [ENV=VALUE...]: the live check, output filtered of FreeCAD's banner
    bin=$1; shift
    env "$@" NURBSX_BIN="$bin" NURBSX_SAMPLES="${NURBSX_SAMPLES:-$root/samples/freecad}" \
        freecadcmd "$script" 2>&1 | grep -v 'Total number of loaded entities\|^.\[0m$'
}

case "${1:-}" in
--copy) run copy; exit ;;
--mock) run "$mock"; exit ;;
--self-test) ;;
*)
    bin=${1:-$root/target/debug/nurbsx}
    out=$(mktemp)
    env NURBSX_BIN="$bin" NURBSX_SAMPLES="${NURBSX_SAMPLES:-$root/samples/freecad}" \
        freecadcmd "$script" >"$out" 2>&1
    status=$?
    grep -v 'Total number of loaded entities\|^.\[0m$' "$out"
    rm -f "$out"
    exit $status ;;
esac

# ---- self test: the checker must pass on faithful stand-ins and fail on each defect.
fail=0
work=$(mktemp -d)
expect() { # expect pass|fail PATTERN NAME -- BIN [ENV...]
    want=$1 pattern=$2 name=$3; shift 4
    out="$work/$name.txt"
    run "$@" NURBSX_WORK="$work/$name" NURBSX_REPORT="$work/$name.json" >"$out" 2>&1
    summary=$(grep '^live_roundtrip: [0-9]* conversions checked' "$out")
    case "$want" in
    pass) echo "$summary" | grep -q ' 0 failed' && ok=1 || ok=0 ;;
    fail) grep -q "$pattern" "$out" && ! echo "$summary" | grep -q ' 0 failed' && ok=1 || ok=0 ;;
    esac
    if [ "$ok" = 1 ]; then echo "ok    $name: $summary"; else echo "WRONG $name (expected $want): see $out"; fail=1; fi
}
expect pass - copy-mode-all -- copy
# The mock writes FreeCAD's readings, so it also writes the sphere's seam, which OCCT built
# itself (no curve entity in surf_sphere_nurbs.step): the text scan must catch that.
expect pass - mock-mode -- "$mock" NURBSX_ONLY="${NURBSX_ONLY:-curve_deg1_clamped,curve_circle_nurbs,curve_deg3_periodic,curve_deg3_uniform_unclamped,surf_periodic_uv,face_trimmed_hole,units_inch,iges_brep_trimmed_hole}"
expect fail 'S holds 0 3-D B-spline curves and 1 surfaces (text scan), nurbsx info reads 1' mock-writes-sphere-seam -- "$mock" NURBSX_ONLY=surf_sphere_nurbs
# File mode: S's own curve / surface entities copied as loose geometry must read back exactly
# as FreeCAD read them inside S's faces (faces-mode IGES, B-rep IGES, the sphere's seam).
expect pass - mock-file-mode -- "$mock" MOCK_NURBSX_FROM_FILE=1 NURBSX_CONVERSIONS='step->step,iges->iges' NURBSX_ONLY=surf_bicubic,face_trimmed_hole,surf_sphere_nurbs,iges_brep_trimmed_hole
expect pass - perturb-below-tolerance -- "$mock" NURBSX_ONLY=curve_deg3_clamped MOCK_NURBSX_PERTURB=1e-13
expect fail 'is not reproduced' perturb-above-tolerance -- "$mock" NURBSX_ONLY=curve_deg3_clamped MOCK_NURBSX_PERTURB=3e-12
expect fail '2-D pcurve written as 3-D' pcurve-as-3d -- "$mock" NURBSX_ONLY=surf_bicubic MOCK_NURBSX_PCURVE=1
expect fail 'nurbsx wrote 4 curves and 1 surfaces' dropped-surface -- "$mock" NURBSX_ONLY=surf_bicubic MOCK_NURBSX_DROP=1
expect fail 'FreeCAD rejects' garbage-output -- "$mock" NURBSX_ONLY=surf_bicubic MOCK_NURBSX_GARBAGE=1
expect fail 'nurbsx dropped curves' reader-drops-curves -- "$mock" NURBSX_ONLY=surf_bicubic MOCK_NURBSX_NOCURVES=1
expect fail 'exited 1' convert-fails -- "$mock" NURBSX_ONLY=curve_deg3_clamped MOCK_NURBSX_FAIL=1
if [ "$fail" = 0 ]; then echo "self test passed ($work)"; rm -rf "$work"; else echo "self test FAILED ($work)"; fi
exit $fail
