"""Live FreeCAD round trip of nurbsx conversions (run under freecadcmd).

For every sample S of samples/freecad (both .step and .igs) and every target format FMT in
{step, iges}, this script

1. runs ``nurbsx convert S -o OUT --to FMT`` (and ``nurbsx info --json OUT`` for the counts),
2. re-imports OUT with ``Part.read`` in this same FreeCAD process,
3. checks that FreeCAD finds as many B-spline curves / surfaces as nurbsx wrote,
4. compares OUT geometrically with FreeCAD's committed reading of the SOURCE, ``S.json``:
   every B-spline item of S.json must be reproduced by OUT's geometry at S.json's own
   parameters (points, first/second derivatives, surface partials and normals).

freecadcmd swallows argv, so everything is configured by environment variables:

    NURBSX_BIN      path of the nurbsx binary, or ``copy`` for the stand-in mode (below)
    NURBSX_SAMPLES  sample directory (default: <repo>/samples/freecad)
    NURBSX_WORK     scratch directory for converted files (default: a new temp dir)
    NURBSX_REPORT   JSON report path (default: <NURBSX_WORK>/live_report.json)
    NURBSX_ONLY     optional comma list of case names (file stems, e.g. surf_loft)
    NURBSX_CONVERSIONS  optional comma list of step->step, step->iges, iges->step, iges->iges

    NURBSX_BIN=target/debug/nurbsx freecadcmd scripts/freecad/live_roundtrip.py

Stand-in mode (``NURBSX_BIN=copy``): "converting" S to FMT copies FreeCAD's own committed file
of the same case in FMT (S.step -> the committed S.igs, ...).  This exercises Part.read,
matching, tolerances and counting against real OCCT behaviour before nurbsx can convert.
FreeCAD's files carry only 12 decimals (STEP) / ~10 significant digits (IGES) and OCCT
changes geometry on export (samples/README.md), so this mode uses the relaxed tolerances and
the re-parameterisation fallbacks documented in samples/README.md ("Live FreeCAD check");
the real mode does not.

Exit status: 0 = every conversion passed; 1 = at least one failure (each printed with the
sample, the conversion and the item); 2 = usage / environment error.  (freecadcmd exits 0
when a script raises, so the script ends with os._exit.)
"""

import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import traceback

import FreeCAD  # noqa: F401  (provided by freecadcmd)
import Part

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
# The one reader (scripts/freecad/evaluate.py), loaded under a module name other than
# "evaluate" so that its command-line entry point does not run.
_spec = importlib.util.spec_from_file_location(
    "nurbsx_freecad_reader", os.path.join(HERE, "evaluate.py")
)
evaluate = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(evaluate)

REPORT_SCHEMA = "nurbsx-freecad-live/1"
FORMATS = ("step", "iges")
EXT = {"step": ".step", "iges": ".igs"}
SRC_FORMAT = {".step": "step", ".igs": "iges"}

# Real mode: nurbsx writes exact digits, so OUT holds the very doubles OCCT read from S;
# only OCCT's own (identical) import arithmetic and unit scaling separate the two readings.
STRICT = {"point": 1e-12, "deriv": 1e-9}
# Stand-in mode across formats: FreeCAD's files lose digits (README item 1: IGES worst
# 8.3 significant digits, 4.6e-3 mm on the 1e6-scaled curve = 4.6e-9 of its size; IGES
# re-clamping moves geometry by 5e-10 mm, item 5), so points get 2e-8 of the model size and
# derivatives 1e-6 of their scale.  Same-format copies are byte-identical files: strict.
RELAXED = {"point": 2e-8, "deriv": 1e-6}
# Relative slack when deciding whether a parameter lies in a geometry's range.
RANGE_SLACK = 1e-9
# A candidate whose point misses by more than this many tolerances is not evaluated further.
REJECT = 1e6

CURVE_DERIVS = ("d1", "d2")
SURF_DERIVS = ("su", "sv", "suu", "suv", "svv")


class Failure(Exception):
    """A failed conversion check (message names sample, conversion and item)."""


# ----------------------------------------------------------------------------- helpers


def _vec(v):
    return [float(v.x), float(v.y), float(v.z)]


def _dist(a, b):
    return math.sqrt(sum((x - y) * (x - y) for x, y in zip(a, b)))


def _norm(a):
    return math.sqrt(sum(x * x for x in a))


def _neg(a):
    return [-x for x in a]


def _safe_vec(fn, *args):
    try:
        v = _vec(fn(*args))
    except Exception:  # OCCT raises when a derivative / normal is undefined
        return None
    if any(math.isnan(x) or math.isinf(x) for x in v):
        return None
    return v


def model_size(reading):
    """Diagonal of the bounding box of every evaluated point of a reading (mm)."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for item in reading["curves"] + reading["surfaces"]:
        for e in item["evaluations"]:
            for k in range(3):
                lo[k] = min(lo[k], e["point"][k])
                hi[k] = max(hi[k], e["point"][k])
    if lo[0] == math.inf:
        return 1.0
    size = _dist(lo, hi)
    return size if size > 0 else 1.0


def _slack(a, b):
    return RANGE_SLACK * max(1.0, abs(a), abs(b), abs(b - a))


def _in_range(t, a, b, period):
    """t mapped into [a, b] (clamped within slack, or shifted by the period), else None."""
    s = _slack(a, b)
    if a - s <= t <= b + s:
        # Inside the range: evaluate as is (a periodic curve at its last parameter gives
        # the left-hand derivatives there, not those at the first parameter).
        return min(max(t, a), b)
    if period:
        # Periodic geometry: the same point is reached at t + k*period.
        k = math.floor((t - a) / period)
        for kk in (k, k + 1, k - 1):
            tt = t - kk * period
            if a - s <= tt <= b + s:
                return min(max(tt, a), b)
        return None
    return None


# ----------------------------------------------------------------- OUT shape inventory


class CurveGeom:
    """One B-spline 3D curve of the re-imported OUT shape."""

    def __init__(self, index, edge_index, curve, loose):
        self.index = index
        self.edge_index = edge_index
        self.geom = curve
        self.loose = loose
        self.first = float(curve.FirstParameter)
        self.last = float(curve.LastParameter)
        self.period = float(curve.period()) if curve.isPeriodic() else 0.0
        # Interior knots: derivatives there may be one-sided (C0/C1 joins).
        s = _slack(self.first, self.last)
        self.inner_knots = [
            float(k) for k in curve.getKnots() if self.first + s < k < self.last - s
        ]
        self._sides = {}

    def one_sided(self, t):
        """Left and right restrictions of the curve at an interior knot t (copies)."""
        if t not in self._sides:
            pieces = []
            for a, b in ((self.first, t), (t, self.last)):
                try:
                    c = self.geom.copy()
                    c.segment(a, b)
                    pieces.append(c)
                except Exception:
                    pass
            self._sides[t] = pieces
        return self._sides[t]

    def values(self, t):
        """[(point, {d1, d2})] at t: the plain evaluation plus one-sided ones at knots."""
        g = self.geom
        out = [(_vec(g.value(t)), {"d1": _safe_vec(g.getDN, t, 1), "d2": _safe_vec(g.getDN, t, 2)})]
        s = _slack(self.first, self.last)
        for k in self.inner_knots:
            if abs(k - t) <= s:
                for c in self.one_sided(k):
                    out.append(
                        (out[0][0], {"d1": _safe_vec(c.getDN, k, 1), "d2": _safe_vec(c.getDN, k, 2)})
                    )
        return out


class SurfGeom:
    """One B-spline surface of the re-imported OUT shape."""

    def __init__(self, index, face_index, surface):
        self.index = index
        self.face_index = face_index
        self.geom = surface
        self.bounds = [float(x) for x in surface.bounds()]
        self.uperiod = float(surface.UPeriod()) if surface.isUPeriodic() else 0.0
        self.vperiod = float(surface.VPeriod()) if surface.isVPeriodic() else 0.0

    def values(self, u, v):
        g = self.geom
        d = {
            "su": _safe_vec(g.getDN, u, v, 1, 0),
            "sv": _safe_vec(g.getDN, u, v, 0, 1),
            "suu": _safe_vec(g.getDN, u, v, 2, 0),
            "suv": _safe_vec(g.getDN, u, v, 1, 1),
            "svv": _safe_vec(g.getDN, u, v, 0, 2),
            "normal": _safe_vec(g.normal, u, v),
        }
        return [(_vec(g.value(u, v)), d)]


def inventory(shape):
    """B-spline curves (with 'loose' = edge in no face) and surfaces of a shape."""
    in_face = set()
    for f in shape.Faces:
        for e in f.Edges:
            in_face.add(e.hashCode())
    curves = []
    for i, e in enumerate(shape.Edges):
        try:
            g = e.Curve
        except Exception:  # degenerated edge: no 3D curve
            continue
        if isinstance(g, Part.BSplineCurve):
            curves.append(CurveGeom(len(curves), i, g, e.hashCode() not in in_face))
    surfaces = []
    for i, f in enumerate(shape.Faces):
        g = f.Surface
        if isinstance(g, Part.BSplineSurface):
            surfaces.append(SurfGeom(len(surfaces), i, g))
    return curves, surfaces


# -------------------------------------------------------------------------- expected counts


def pieces_after_iges_import(degree, knots, domain):
    """Edges OCCT's IGES reader makes of one curve: 1 + distinct interior knots of the
    domain whose multiplicity is >= the degree (it splits at C0 knots, README item 7)."""
    a, b = domain
    mult = {}
    for k in knots:
        if a < k < b:
            mult[k] = mult.get(k, 0) + 1
    return 1 + sum(1 for m in mult.values() if m >= degree)


def iges_boundary_curves(path):
    """DE pointers of the model-space face boundary curves of an IGES file: the C(t) of every
    142 (IGES 5.3 section 4.22) and the curves of every 504 edge list, with the members of a
    102 composite; FreeCAD reads them as the edges of faces, not as loose curves."""
    with open(path, encoding="latin-1") as f:
        lines = [l.rstrip("\r\n") for l in f]
    d = [l for l in lines if len(l) >= 73 and l[72] == "D"]
    params = {}
    for l in lines:
        if len(l) >= 73 and l[72] == "P":
            de = int(l[64:72])
            params[de] = params.get(de, "") + l[:64]
    types = {i + 1: int(d[i][0:8]) for i in range(0, len(d) - 1, 2)}
    fields = {de: [x.strip() for x in t.split(";")[0].split(",")] for de, t in params.items()}
    out = set()
    for de, t in types.items():
        f = fields.get(de, [])
        if t == 142 and len(f) > 4 and int(f[4]) != 0:
            out.add(int(f[4]))
        elif t == 504 and len(f) > 1:
            for k in range(int(f[1])):
                out.add(int(f[2 + 5 * k]))
    todo = list(out)
    while todo:
        de = todo.pop()
        f = fields.get(de, [])
        if types.get(de) == 102 and len(f) > 1:
            for x in f[2:2 + int(f[1])]:
                if int(x) not in out:
                    out.add(int(x))
                    todo.append(int(x))
    return out


def expected_from_info(info, fmt, boundary=frozenset()):
    """Expected (curves, surfaces, notes) FreeCAD should find in OUT, from nurbsx info; the
    curves whose DE pointer is in `boundary` bound faces and are not loose curves."""
    ents = info.get("entities", [])
    surfaces = sum(1 for e in ents if e.get("kind") == "surface")
    curves3 = [e for e in ents if e.get("kind") == "curve" and e.get("dimension") == 3
               and not (e.get("id", "").startswith("D") and int(e["id"][1:]) in boundary)]
    curves2 = [e for e in ents if e.get("kind") == "curve" and e.get("dimension") != 3]
    if fmt == "step":
        curves = len(curves3)
    else:
        curves = 0
        for e in curves3:
            geom = e["geometry"]
            p = int(geom["degree"])
            knots = [float(k) for k in geom["knots"]]
            n = len(geom["control_points"])
            # The entity's own domain (IGES V0, V1) when info gives it, else the knot domain.
            dom = e.get("domain") or [[knots[p], knots[n]]]
            curves += pieces_after_iges_import(p, knots, (float(dom[0][0]), float(dom[0][1])))
    return curves, surfaces, len(curves2)


def step_bspline_entities(path):
    """(3-D B-spline curves, B-spline surfaces) of a STEP file, counted from its text with no
    nurbsx code: an instance holding B_SPLINE_CURVE_WITH_KNOTS (simple, or complex with
    B_SPLINE_CURVE(p,(#first,...)) is 3-D when its first control point has 3 coordinates."""
    import re

    with open(path, encoding="latin-1") as f:
        text = f.read()
    data = text[text.find("DATA;"):]
    inst = {}
    for m in re.finditer(r"#(\d+)\s*=\s*(.*?);\s*(?=#\d+\s*=|ENDSEC)", data, re.S):
        inst[m.group(1)] = m.group(2)
    curves = surfaces = 0
    for body in inst.values():
        if "B_SPLINE_SURFACE_WITH_KNOTS" in body:
            surfaces += 1
        elif "B_SPLINE_CURVE_WITH_KNOTS" in body:
            m = re.search(r"B_SPLINE_CURVE(?:_WITH_KNOTS)?\(\s*(?:'[^']*'\s*,)?\s*\d+\s*,"
                          r"\s*\(\s*#(\d+)", body)
            if not m or m.group(1) not in inst:
                raise Failure("%s: cannot read the control points of %s" % (path, body[:80]))
            pt = re.search(r"CARTESIAN_POINT\(\s*'[^']*'\s*,\s*\(([^)]*)\)", inst[m.group(1)])
            if pt and len(pt.group(1).split(",")) == 3:
                curves += 1
    return curves, surfaces


def iges_curve_pieces(path):
    """Edges OCCT should make of the 3-D 126 curves of an IGES file, counted from its text
    with no nurbsx code: 126 entities that are not parameter-space curves (BPTR of a 142,
    directly or as a member of a 102 composite; pcurve of a 508 loop), each
    1 + its interior C0 knots (pieces_after_iges_import)."""
    with open(path, encoding="latin-1") as f:
        lines = [l.rstrip("\r\n") for l in f]
    d = [l for l in lines if len(l) >= 73 and l[72] == "D"]
    params = {}
    for l in lines:
        if len(l) >= 73 and l[72] == "P":
            de = int(l[64:72])
            params[de] = params.get(de, "") + l[:64]
    types = {}
    for i in range(0, len(d) - 1, 2):
        types[i + 1] = int(d[i][0:8])
    fields = {}
    for de, text in params.items():
        text = text.split(";")[0]
        fields[de] = [x.strip() for x in text.split(",")]
    two_d = set()
    for de, t in types.items():
        f = fields.get(de, [])
        if t == 142 and len(f) > 3:
            two_d.add(int(f[3]))
        elif t == 508 and len(f) > 1:
            k = 2
            for _ in range(int(f[1])):
                nk = int(f[k + 4])
                for j in range(nk):
                    two_d.add(int(f[k + 6 + 2 * j]))
                k += 5 + 2 * nk
    # A BPTR may be a 102 composite curve: its members are parameter-space curves too.
    todo = list(two_d)
    while todo:
        de = todo.pop()
        f = fields.get(de, [])
        if types.get(de) == 102 and len(f) > 1:
            for x in f[2:2 + int(f[1])]:
                if int(x) not in two_d:
                    two_d.add(int(x))
                    todo.append(int(x))
    pieces = 0
    for de, t in types.items():
        if t != 126 or de in two_d:
            continue
        f = fields[de]
        kk, m = int(f[1]), int(f[2])
        knots = [float(x.replace("D", "E")) for x in f[7:7 + kk + m + 2]]
        v = 7 + (kk + m + 2) + 4 * (kk + 1)
        v0, v1 = float(f[v].replace("D", "E")), float(f[v + 1].replace("D", "E"))
        pieces += pieces_after_iges_import(m, knots, (v0, v1))
    return pieces


# ------------------------------------------------------------------------------ matching


def _scales(item, names, size):
    """Per-derivative magnitude scale on an item (max norm over its evaluations).

    A second derivative that is (numerically) zero on the whole item -- suv of a ruled
    surface, d2 of a line -- would otherwise get a scale made of round-off noise, so second
    derivatives are floored at the value they would have on a curve of radius `size` at the
    item's speed: |d1|^2 / size, |su|^2 / size, |su||sv| / size, |sv|^2 / size."""
    raw = {}
    for n in names:
        m = 0.0
        for e in item["evaluations"]:
            if e.get(n) is not None:
                m = max(m, _norm(e[n]))
        raw[n] = m
    floor = {
        "d2": ("d1", "d1"), "suu": ("su", "su"), "suv": ("su", "sv"), "svv": ("sv", "sv"),
    }
    out = {}
    for n in names:
        m = raw[n]
        if n in floor:
            a, b = floor[n]
            m = max(m, raw.get(a, 0.0) * raw.get(b, 0.0) / size)
        # A first derivative that vanishes everywhere (degenerate item): use the size.
        out[n] = m if m > 0 else size
    return out


def _compare(ev, got_point, got_d, names, tol, scales, size, signs):
    """Normalised error (1 = at tolerance) and raw deviations of one evaluation."""
    dev = {"point": _dist(ev["point"], got_point) / size}
    err = dev["point"] / tol["point"]
    for n in names:
        want = ev.get(n)
        have = got_d.get(n)
        if want is None and have is None:
            continue
        if want is None or have is None:
            return math.inf, dev
        if signs.get(n, 1) < 0:
            have = _neg(have)
        r = _dist(want, have) / scales[n]
        dev[n] = r
        err = max(err, r / tol["deriv"])
    return err, dev


def _item_range(kind, item):
    if kind == "curve":
        return (item["first_parameter"], item["last_parameter"])
    return tuple(item["bounds"])


def _eval_candidate(kind, cand, params, mapping, rng):
    """Values of cand at S's parameters under a parameter map, or None (out of range).

    rng is S's item range: "reversed" / "reversed_segment" map t to first + last - t of
    the S item (the whole item was reversed, then split or segmented); "reversed_piece"
    maps t to first + last - t of the candidate (a segment of the item was reversed)."""
    if kind == "curve":
        (t,) = params
        if mapping in ("reversed", "reversed_segment"):
            t = rng[0] + rng[1] - t
        elif mapping == "reversed_piece":
            t = cand.first + cand.last - t
        tt = _in_range(t, cand.first, cand.last, cand.period)
        if tt is None:
            return None
        return cand.values(tt)
    u, v = params
    u0, u1, v0, v1 = rng
    if mapping in ("u_reversed", "uv_reversed"):
        u = u0 + u1 - u
    if mapping in ("v_reversed", "uv_reversed"):
        v = v0 + v1 - v
    c0, c1, d0, d1 = cand.bounds
    uu = _in_range(u, c0, c1, cand.uperiod)
    vv = _in_range(v, d0, d1, cand.vperiod)
    if uu is None or vv is None:
        return None
    return cand.values(uu, vv)


SIGNS = {
    "identity": {},
    "segment": {},
    "reversed": {"d1": -1},
    "reversed_piece": {"d1": -1},
    "reversed_segment": {"d1": -1},
    "u_reversed": {"su": -1, "suv": -1, "normal": -1},
    "v_reversed": {"sv": -1, "suv": -1, "normal": -1},
    "uv_reversed": {"su": -1, "sv": -1},
    "trimmed": {},
}
# Maps tried in stand-in mode after "identity"; those marked partial accept evaluations of
# S that lie outside every candidate (OUT holds only a segment of S's geometry).
REMAPS = {
    "curve": [("reversed", False), ("segment", True), ("reversed_piece", True),
              ("reversed_segment", True)],
    "surface": [("u_reversed", False), ("v_reversed", False), ("uv_reversed", False)],
}


def match_parametric(kind, item, cands, mapping, tol, size, partial=False):
    """Per evaluation of item: the best candidate at the (mapped) same parameter.

    Returns a list (one per evaluation) of (err, dev, cand_index) or None when no candidate
    holds the parameter.  With partial (OUT holds segments of S), only candidates that
    reproduce every S evaluation inside their own range (at least two) are considered, so
    that an unrelated curve that happens to contain a parameter cannot spoil the match."""
    names = CURVE_DERIVS if kind == "curve" else SURF_DERIVS + ("normal",)
    scales = _scales(item, names, size)
    scales["normal"] = 1.0
    signs = SIGNS[mapping]
    rng = _item_range(kind, item)
    evs = item["evaluations"]
    table = []
    for c in cands:
        row = []
        for ev in evs:
            params = (ev["t"],) if kind == "curve" else (ev["u"], ev["v"])
            vals = _eval_candidate(kind, c, params, mapping, rng)
            best = None
            for point, d in vals or []:
                if _dist(ev["point"], point) / size > REJECT * tol["point"]:
                    err, dev = math.inf, {"point": _dist(ev["point"], point) / size}
                else:
                    err, dev = _compare(ev, point, d, names, tol, scales, size, signs)
                if best is None or err < best[0]:
                    best = (err, dev, c.index)
            row.append(best)
        inside = [r for r in row if r is not None]
        if partial and (len(inside) < 2 or any(not r[0] <= 1.0 for r in inside)):
            continue
        table.append(row)
    results = []
    for i in range(len(evs)):
        best = None
        for row in table:
            r = row[i]
            if r is not None and (best is None or r[0] < best[0]):
                best = r
        results.append(best)
    return results


def match_projection(kind, item, cands, tol, size):
    """Points only: distance from each S point to its projection on the best candidate."""
    results = []
    for ev in item["evaluations"]:
        p = FreeCAD.Vector(*ev["point"])
        best = None
        for c in cands:
            try:
                if kind == "curve":
                    t = float(c.geom.parameter(p))
                    q = _vec(c.geom.value(t))
                else:
                    u, v = c.geom.parameter(p)
                    q = _vec(c.geom.value(float(u), float(v)))
            except Exception:
                continue
            d = _dist(ev["point"], q) / size
            if best is None or d < best[1]["point"]:
                best = (d / tol["point"], {"point": d}, c.index)
        results.append(best)
    return results


def summarise(results, partial=False):
    """(ok, worst deviations, candidate indices used, uncovered evaluation count).

    With partial, evaluations that no candidate holds are allowed (counted in uncovered)
    provided at least two evaluations are covered."""
    worst = {}
    used = set()
    uncovered = 0
    ok = True
    for r in results:
        if r is None:
            uncovered += 1
            if not partial:
                ok = False
            continue
        err, dev, ci = r
        used.add(ci)
        if not err <= 1.0:
            ok = False
        for k, x in dev.items():
            worst[k] = max(worst.get(k, 0.0), x)
    if partial and len(results) - uncovered < 2:
        ok = False
    return ok, worst, sorted(used), uncovered


def match_item(kind, item, cands, tol, size, allow_remap, allow_trimmed=False):
    """Match one S.json item against OUT geometry; returns a result dict (with 'ok').

    Real mode (allow_remap False): only the identity map, every evaluation covered; with
    allow_trimmed (S is a STEP file with TRIMMED_CURVEs, which nurbsx reads as the trimmed
    piece while FreeCAD's reading evaluates the untrimmed basis), then the identity map on
    the evaluations inside a candidate's range (at least two, every one reproduced).
    Stand-in mode: then the reversals / segments of REMAPS, then point projection."""
    tries = [("identity", False)]
    if allow_trimmed and kind == "curve":
        tries.append(("trimmed", True))
    if allow_remap:
        tries += REMAPS[kind]
    first = None
    for mapping, partial in tries:
        res = match_parametric(kind, item, cands, mapping, tol, size, partial)
        ok, worst, used, uncovered = summarise(res, partial)
        out = {"method": mapping, "ok": ok, "worst": worst, "matched": used,
               "uncovered": uncovered}
        if first is None:
            first = out
        if ok:
            return out
    # Last resort: distance of S's points to OUT's geometry (points only, no derivatives).
    res = match_projection(kind, item, cands, tol, size)
    ok, worst, used, uncovered = summarise(res)
    proj = {"method": "projection", "ok": ok, "worst": worst, "matched": used,
            "uncovered": uncovered, "parametric": first}
    if allow_remap and ok:
        return proj
    first = dict(first)
    first["projection"] = proj
    first["ok"] = False
    return first


# ----------------------------------------------------------------------------- conversion


def run_nurbsx(args, what):
    try:
        p = subprocess.run(args, capture_output=True, text=True, timeout=300)
    except (OSError, subprocess.TimeoutExpired) as ex:
        raise Failure("%s: could not run %s: %s" % (what, " ".join(args), ex))
    if p.returncode != 0:
        raise Failure(
            "%s: `%s` exited %d\n  stderr: %s"
            % (what, " ".join(args), p.returncode, p.stderr.strip()[:2000])
        )
    return p.stdout


def convert(binary, samples, src, fmt, work, what):
    """Produce OUT; returns (out_path, expected dict, notes) or None (no stand-in file)."""
    case, sext = os.path.splitext(os.path.basename(src))
    out = os.path.join(work, "%s.%s-to-%s%s" % (case, SRC_FORMAT[sext], fmt, EXT[fmt]))
    if os.path.exists(out):
        os.remove(out)
    if binary == "copy":
        stand_in = os.path.join(samples, case + EXT[fmt])
        if not os.path.exists(stand_in):
            return None
        shutil.copyfile(stand_in, out)
        with open(stand_in + ".json", encoding="utf-8") as f:
            counts = json.load(f)["counts"]
        return out, {"curves": counts["bspline_curves"], "surfaces": counts["bspline_surfaces"],
                     "curves_2d": 0, "scope": "all edges (committed reading)"}, []
    # The geometry path (every curve and surface as loose exact NURBS, --geometry-only):
    # this check compares curves and surfaces point by point with FreeCAD's own reading.
    # Whole parts (faces, shells, solids) are checked by tests/step_topology.rs,
    # tests/iges_topology.rs and scripts/freecad/live_parts.py.
    run_nurbsx([binary, "convert", src, "-o", out, "--to", fmt, "--geometry-only"], what)
    if not os.path.exists(out):
        raise Failure("%s: nurbsx convert exited 0 but wrote no %s" % (what, out))
    text = run_nurbsx([binary, "info", "--json", out], what + " (info)")
    try:
        info = json.loads(text)
    except ValueError as ex:
        raise Failure("%s: `nurbsx info --json` printed no JSON: %s" % (what, ex))
    errors = [d for d in info.get("diagnostics", []) if d.get("severity") == "error"]
    if errors:
        raise Failure("%s: nurbsx info reports errors on its own output: %s" % (what, errors[:3]))
    try:
        boundary = iges_boundary_curves(out) if fmt == "iges" else frozenset()
        curves, surfaces, curves2 = expected_from_info(info, fmt, boundary)
        # nurbsx must write every 3-D curve and surface it reads from S (in the same reading,
        # geometry only: a whole-part reading carries sewn twins and pcurves in its edges) ...
        n_out = expected_from_info(info, "step")
        src_info = json.loads(run_nurbsx([binary, "info", "--json", "--geometry-only", src],
                                         what + " (info S)"))
        n_src = expected_from_info(src_info, "step")
    except (KeyError, IndexError, TypeError, ValueError) as ex:
        raise Failure("%s: cannot read entity list of `nurbsx info --json`: %r" % (what, ex))
    notes = []
    if n_out[:2] != n_src[:2]:
        notes.append("%s: nurbsx reads %d 3-D curves and %d surfaces from S but writes %d and "
                     "%d" % (what, n_src[0], n_src[1], n_out[0], n_out[1]))
    # ... and, for STEP, read all that a plain text scan of S finds (no nurbsx code).
    if sext == ".step":
        scan = step_bspline_entities(src)
        if scan != n_src[:2]:
            notes.append("%s: S holds %d 3-D B-spline curves and %d surfaces (text scan), "
                         "nurbsx info reads %d and %d" % (what, scan[0], scan[1], n_src[0],
                                                           n_src[1]))
    return out, {"curves": curves, "surfaces": surfaces, "curves_2d": curves2,
                 "boundary_curves": len(boundary),
                 "scope": "loose edges (not in a face)"}, notes


def check_conversion(binary, samples, src, reading, fmt, work):
    """Convert src to fmt, re-import, count and match; returns the per-conversion record."""
    case, sext = os.path.splitext(os.path.basename(src))
    what = "%s%s -> %s" % (case, sext, fmt)
    copy_mode = binary == "copy"
    same_format = SRC_FORMAT[sext] == fmt
    tol = RELAXED if copy_mode and not same_format else STRICT
    rec = {"sample": os.path.basename(src), "conversion": "%s->%s" % (SRC_FORMAT[sext], fmt),
           "tolerance": tol, "failures": []}
    t0 = time.time()
    conv = convert(binary, samples, src, fmt, work, what)
    if conv is None:
        rec["skipped"] = "no committed %s file for this case (stand-in mode)" % fmt
        return rec
    out, expected, notes = conv
    rec["out"] = out
    rec["expected"] = expected
    rec["failures"].extend(notes)
    try:
        shape = Part.read(out)
    except Exception as ex:
        raise Failure("%s: FreeCAD rejects %s: %s" % (what, out, ex))
    curves, surfaces = inventory(shape)
    # A STEP part nurbsx wrote with its faces (ADVANCED_FACE): its 3-D curves are the faces'
    # edge curves, each written once, so they stand where the loose edges stand otherwise.
    with open(out, encoding="utf-8", errors="replace") as f:
        faces_out = fmt == "step" and not copy_mode and "ADVANCED_FACE(" in f.read()
    loose = curves if faces_out else [c for c in curves if c.loose]
    if copy_mode:
        found_curves = len(curves)
    else:
        found_curves = len(loose)
    rec["found"] = {"curves": found_curves, "surfaces": len(surfaces),
                    "face_boundary_curves": len(curves) - len(loose)}
    expected_curves = expected["curves"]
    if faces_out and sext == ".step":
        # Edges Open CASCADE adds to the faces itself (a sphere's seam): FreeCAD's curves of
        # S minus the file's 3-D curve entities, as below.
        expected_curves += max(len(reading["curves"]) - step_bspline_entities(src)[0], 0)
    if found_curves != expected_curves or len(surfaces) != expected["surfaces"]:
        msg = ("%s: FreeCAD finds %d B-spline curves and %d surfaces in %s (%s), nurbsx wrote "
               "%d curves and %d surfaces" % (what, found_curves, len(surfaces), out,
                                              expected["scope"], expected["curves"],
                                              expected["surfaces"]))
        if expected["curves_2d"]:
            msg += " (and %d 2-D curves, which must not be written as 3-D geometry)" % (
                expected["curves_2d"])
        rec["failures"].append(msg)

    if copy_mode and fmt == "iges" and reading["counts"]["faces"] == 0:
        # Check the IGES counting rule used in real mode against what OCCT really did with
        # FreeCAD's own IGES file: lone curves only (faces-mode IGES duplicates edges).
        predicted = 0
        for c in reading["curves"]:
            flat = [k for k, m in zip(c["knots"], c["multiplicities"]) for _ in range(m)]
            predicted += pieces_after_iges_import(
                c["degree"], flat, (c["first_parameter"], c["last_parameter"]))
        rec["iges_count_rule"] = {"predicted": predicted, "found": found_curves}
        if predicted != found_curves:
            rec["failures"].append(
                "%s: IGES counting rule predicts %d curves from %s, OCCT made %d"
                % (what, predicted, os.path.basename(src), found_curves))
    size = model_size(reading)
    rec["model_size"] = size
    with open(src, encoding="utf-8", errors="replace") as f:
        trimmed_source = sext == ".step" and "TRIMMED_CURVE(" in f.read()
    items = []
    # Real mode: S's curves are matched first against the curves nurbsx wrote (loose edges);
    # a curve OCCT built itself for S (e.g. the sphere's seam: an iso-curve of a face with no
    # curve entity in the file) may instead match the same iso-curve of OUT's face.
    curve_sets = [curves] if copy_mode else [loose, curves]
    for kind, src_items, cand_sets in (
        ("curve", reading["curves"], curve_sets),
        ("surface", reading["surfaces"], [surfaces]),
    ):
        for item in src_items:
            res = None
            for n, cands in enumerate(cand_sets):
                r = match_item(kind, item, cands, tol, size, allow_remap=copy_mode,
                               allow_trimmed=trimmed_source)
                if n > 0:
                    r["via"] = "face boundary (no curve entity written for it)"
                if res is None or r["ok"]:
                    res = r
                if r["ok"]:
                    break
            key = "edge_index" if kind == "curve" else "face_index"
            res["item"] = "%s %s=%d" % (kind, key, item[key])
            items.append(res)
            if not res["ok"]:
                rec["failures"].append(
                    "%s: %s of FreeCAD's reading of %s is not reproduced: %s"
                    % (what, res["item"], os.path.basename(src), _describe(res, tol))
                )
    # Only curves OCCT built itself may match OUT's face boundaries instead of a written
    # curve.  Their number is known without nurbsx: FreeCAD's curves minus the edges the
    # file's 3-D curve entities give (1 for the sphere's STEP seam, 0 for every other file).
    if not copy_mode:
        if sext == ".step":
            written = step_bspline_entities(src)[0]
        else:
            written = iges_curve_pieces(src)
        # Curves nurbsx wrote as face boundaries (142 C(t), 504 edges) are matched as such.
        allowed = len(reading["curves"]) - written + expected.get("boundary_curves", 0)
        via = [r["item"] for r in items if "via" in r]
        if len(via) > max(allowed, 0):
            rec["failures"].append(
                "%s: %d curves of %s match only face boundaries of OUT (%s), but the file has "
                "curve entities for all but %d of them: nurbsx dropped curves?"
                % (what, len(via), os.path.basename(src), ", ".join(via), max(allowed, 0)))
    # Every curve nurbsx wrote must be some curve of S (catches pcurves written as 3-D).
    if not copy_mode:
        used = set()
        for r in items:
            if r["item"].startswith("curve") and "via" not in r:
                used.update(r["matched"])
        for c in loose:
            if c.index not in used and not _covers_source(c, reading, size, tol):
                flat = all(abs(p.z) == 0.0 for p in c.geom.getPoles())
                rec["failures"].append(
                    "%s: loose curve (edge %d) of %s matches no curve of %s%s"
                    % (what, c.edge_index, out, os.path.basename(src),
                       " -- all poles have z = 0: a 2-D pcurve written as 3-D geometry?"
                       if flat else "")
                )
    rec["items"] = items
    rec["seconds"] = round(time.time() - t0, 3)
    worst = {}
    for r in items:
        for k, x in r["worst"].items():
            worst[k] = max(worst.get(k, 0.0), x)
    rec["worst"] = worst
    rec["methods"] = sorted(set(r["method"] for r in items))
    return rec


def _covers_source(c, reading, size, tol):
    """Whether OUT curve c reproduces the points of some S curve at the S parameters that
    lie in c's range (c may be a piece of it, split at a C0 knot by the IGES reader)."""
    for item in reading["curves"]:
        total = 0
        hits = 0
        for ev in item["evaluations"]:
            tt = _in_range(ev["t"], c.first, c.last, c.period)
            if tt is None:
                continue
            total += 1
            if _dist(_vec(c.geom.value(tt)), ev["point"]) / size <= tol["point"]:
                hits += 1
        if total and hits == total:
            return True
    return False


def _describe(res, tol):
    w = res.get("worst", {})
    parts = ["method %s" % res["method"]]
    if res.get("uncovered"):
        parts.append("%d evaluation(s) outside every candidate's range" % res["uncovered"])
    for k in sorted(w):
        lim = tol["point"] if k == "point" else tol["deriv"]
        parts.append("%s %.3g (tol %.0e)" % (k, w[k], lim))
    if res.get("matched") is not None:
        parts.append("candidates %s" % res["matched"])
    if "projection" in res:
        p = res["projection"]
        if "point" in p["worst"]:
            parts.append("projection fallback: point %.3g" % p["worst"]["point"])
        else:
            parts.append("no B-spline geometry in OUT to project on")
    return "; ".join(parts)


# ----------------------------------------------------------------------------------- main


def _cases(samples, only):
    out = []
    for name in sorted(os.listdir(samples)):
        stem, ext = os.path.splitext(name)
        if ext not in SRC_FORMAT:
            continue
        if only and stem not in only:
            continue
        out.append(os.path.join(samples, name))
    return out


def _line(rec):
    if "skipped" in rec:
        return "SKIP %-40s %-10s %s" % (rec["sample"], rec["conversion"], rec["skipped"])
    w = rec.get("worst", {})
    dmax = max([w.get(k, 0.0) for k in CURVE_DERIVS + SURF_DERIVS] + [0.0])
    status = "PASS" if not rec["failures"] else "FAIL"
    return "%s %-40s %-10s items %3d  point %.2e  deriv %.2e  normal %.2e  %s  %.2fs" % (
        status, rec["sample"], rec["conversion"], len(rec.get("items", [])),
        w.get("point", 0.0), dmax, w.get("normal", 0.0), ",".join(rec.get("methods", [])),
        rec.get("seconds", 0.0))


def main():
    binary = os.environ.get("NURBSX_BIN")
    if not binary:
        print("usage: NURBSX_BIN=path/to/nurbsx|copy [NURBSX_SAMPLES=dir] [NURBSX_WORK=dir] "
              "[NURBSX_REPORT=report.json] [NURBSX_ONLY=case,...] "
              "freecadcmd scripts/freecad/live_roundtrip.py")
        return 2
    if binary != "copy" and not os.access(binary, os.X_OK):
        print("live_roundtrip: NURBSX_BIN=%s is not an executable" % binary)
        return 2
    samples = os.environ.get("NURBSX_SAMPLES") or os.path.join(ROOT, "samples", "freecad")
    work = os.environ.get("NURBSX_WORK") or tempfile.mkdtemp(prefix="nurbsx-live-")
    os.makedirs(work, exist_ok=True)
    report_path = os.environ.get("NURBSX_REPORT") or os.path.join(work, "live_report.json")
    only = set(x.strip() for x in os.environ.get("NURBSX_ONLY", "").split(",") if x.strip())
    pairs = set(
        x.strip() for x in os.environ.get("NURBSX_CONVERSIONS", "").split(",") if x.strip())
    bad = pairs - set("%s->%s" % (a, b) for a in FORMATS for b in FORMATS)
    if bad:
        print("live_roundtrip: unknown NURBSX_CONVERSIONS %s" % sorted(bad))
        return 2
    cases = _cases(samples, only)
    if not cases:
        print("live_roundtrip: no samples in %s (NURBSX_ONLY=%s)" % (samples, sorted(only)))
        return 2
    fc, occt = evaluate.versions()
    mode = "stand-in (copy FreeCAD's own file)" if binary == "copy" else "nurbsx " + binary
    print("live_roundtrip: FreeCAD %s, OCCT %s, %s, %d samples, work dir %s"
          % (fc, occt, mode, len(cases), work))
    t_start = time.time()
    records = []
    failures = []
    for src in cases:
        with open(src + ".json", encoding="utf-8") as f:
            reading = json.load(f)
        for fmt in FORMATS:
            pair = "%s->%s" % (SRC_FORMAT[os.path.splitext(src)[1]], fmt)
            if pairs and pair not in pairs:
                continue
            try:
                rec = check_conversion(binary, samples, src, reading, fmt, work)
            except Failure as ex:
                rec = {"sample": os.path.basename(src),
                       "conversion": "%s->%s" % (SRC_FORMAT[os.path.splitext(src)[1]], fmt),
                       "failures": [str(ex)]}
            except Exception:  # a bug here must not pass silently
                rec = {"sample": os.path.basename(src),
                       "conversion": "%s->%s" % (SRC_FORMAT[os.path.splitext(src)[1]], fmt),
                       "failures": ["internal error:\n" + traceback.format_exc()]}
            records.append(rec)
            print(_line(rec))
            for msg in rec["failures"]:
                print("    " + msg.replace("\n", "\n    "))
                failures.append(msg)
            sys.stdout.flush()
    elapsed = time.time() - t_start
    checked = [r for r in records if "skipped" not in r]
    summary = {
        "conversions": len(records),
        "checked": len(checked),
        "skipped": len(records) - len(checked),
        "passed": sum(1 for r in checked if not r["failures"]),
        "failed": sum(1 for r in checked if r["failures"]),
        "seconds": round(elapsed, 1),
    }
    report = {"schema": REPORT_SCHEMA, "freecad_version": fc, "occt_version": occt,
              "mode": "copy" if binary == "copy" else "nurbsx", "nurbsx": binary,
              "samples": samples, "tolerances": {"strict": STRICT, "relaxed_copy": RELAXED},
              "summary": summary, "conversions": records}
    with open(report_path, "w", encoding="utf-8") as f:
        json.dump(report, f, indent=1, allow_nan=True)
        f.write("\n")
    print("live_roundtrip: %(checked)d conversions checked, %(passed)d passed, %(failed)d "
          "failed, %(skipped)d skipped, %(seconds).1f s" % summary)
    print("live_roundtrip: report %s" % report_path)
    return 1 if failures else 0


if __name__ in ("__main__", "live_roundtrip"):
    try:
        status = main()
    except Exception:
        traceback.print_exc()
        status = 2
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
