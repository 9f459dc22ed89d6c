#!/usr/bin/env python3
"""A stand-in for the nurbsx CLI, used only to test scripts/freecad/live_roundtrip.py.

It implements the two commands the live check calls, with nurbsx's interface:

    live_mock_nurbsx.py convert S -o OUT --to step|iges
    live_mock_nurbsx.py info --json [--geometry-only] OUT

"convert" does NOT parse S: it writes the B-spline curves and surfaces of FreeCAD's
committed reading of S (``S.json`` next to S) as loose geometry, the way nurbsx is specified
to write its output (STEP: curves in a GEOMETRIC_CURVE_SET of a
GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION, surfaces in a GEOMETRIC_SET of a
GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION; IGES: independent 126/128 entities),
with shortest round-trip reals.  Periodic items are written in their unperiodised
(unclamped, wrapped-pole) form, which is the same geometry over the same parameters.
"info" prints the entity list in nurbsx's `info --json` layout, from a sidecar file that
convert writes next to OUT (OUT.mock.json).

This lets the real-mode path of the live check (counts from `info`, loose edges vs. face
boundaries, the IGES C0 split rule, strict tolerances) run against real OCCT imports before
the nurbsx writers exist.  Negative controls (environment variables, for the self test in
live_roundtrip.sh):

    MOCK_NURBSX_PERTURB=r   move pole 1 of the first written curve by r * model size in x
    MOCK_NURBSX_PCURVE=1    also write a planar z = 0 curve (a 2-D pcurve) as 3-D geometry,
                            reported by info as dimension 2
    MOCK_NURBSX_DROP=1      omit the last surface from the file (info still lists it)
    MOCK_NURBSX_FAIL=1      exit 1 from convert
    MOCK_NURBSX_GARBAGE=1   write a file that is not STEP / IGES (exit 0)
    MOCK_NURBSX_NOCURVES=1  a reader that loses every curve: neither info nor convert has any
    MOCK_NURBSX_FROM_FILE=1 STEP->STEP / IGES->IGES copy S's own entities (see file mode)
"""

import json
import os
import sys


def real(x):
    """Shortest round-trip real with a decimal point and an upper-case exponent."""
    x = float(x)
    s = repr(x)
    if s in ("inf", "-inf", "nan"):
        raise ValueError("non-finite real %s" % s)
    if "e" in s:
        mant, exp = s.split("e")
        if "." not in mant:
            mant += "."
        return mant + "E" + exp
    if "." not in s:
        s += "."
    return s


def compress(flat):
    """Distinct knots and multiplicities of a flat knot vector."""
    knots, mults = [], []
    for k in flat:
        if knots and k == knots[-1]:
            mults[-1] += 1
        else:
            knots.append(k)
            mults.append(1)
    return knots, mults


def de_boor(p, knots, hpoles, t):
    """Point of a B-spline with homogeneous poles [wx, wy, wz, w] at t (de Boor)."""
    n = len(hpoles)
    span = p
    while span + 1 < n and knots[span + 1] <= t:
        span += 1
    d = [list(hpoles[span - p + j]) for j in range(p + 1)]
    for r in range(1, p + 1):
        for j in range(p, r - 1, -1):
            i = span - p + j
            den = knots[i + p + 1 - r] - knots[i]
            a = (t - knots[i]) / den if den else 0.0
            d[j] = [(1 - a) * x + a * y for x, y in zip(d[j - 1], d[j])]
    return d[p]


def _homog(poles, weights):
    return [[q[0] * w, q[1] * w, q[2] * w, w] for q, w in zip(poles, weights)]


def _unperiodise(items, p, nknots):
    """Candidate non-periodic pole lists: OCCT's periodic flat knot sequence needs
    nknots - p - 1 poles, the periodic ones repeated cyclically from some start index."""
    n = len(items)
    need = nknots - p - 1
    for start in range(n):
        yield [items[(start + i) % n] for i in range(need)]


def curve_entity(c):
    """Non-periodic (degree, flat knots, poles, weights) of a reading's curve."""
    p = c["degree"]
    knots = list(c["knot_sequence"])
    pw = list(zip([list(x) for x in c["poles"]], c["weights"]))
    cands = _unperiodise(pw, p, len(knots)) if c["periodic"] else [pw]
    for cand in cands:
        poles = [q for q, _ in cand]
        weights = [w for _, w in cand]
        if len(knots) != len(poles) + p + 1:
            continue
        # Keep the arrangement that reproduces FreeCAD's own evaluations.
        h = _homog(poles, weights)
        ok = True
        for ev in c["evaluations"]:
            x = de_boor(p, knots, h, ev["t"])
            q = [x[0] / x[3], x[1] / x[3], x[2] / x[3]]
            scale = 1.0 + max(abs(v) for v in ev["point"])
            if max(abs(u - v) for u, v in zip(q, ev["point"])) > 1e-9 * scale:
                ok = False
                break
        if ok:
            return {"degree": p, "knots": knots, "control_points": poles, "weights": weights}
    raise ValueError("cannot write curve edge %d of the reading" % c["edge_index"])


def surface_entity(s):
    """Non-periodic (degrees, flat knots, poles[i][j], weights) of a reading's surface."""
    pu, pv = s["u_degree"], s["v_degree"]
    ku, kv = list(s["u_knot_sequence"]), list(s["v_knot_sequence"])
    grid = [list(zip([list(x) for x in prow], wrow)) for prow, wrow in
            zip(s["poles"], s["weights"])]
    rows_c = list(_unperiodise(grid, pu, len(ku))) if s["u_periodic"] else [grid]
    for rows in rows_c:
        cols_c = (list(_unperiodise(list(range(len(rows[0]))), pv, len(kv)))
                  if s["v_periodic"] else [list(range(len(rows[0])))])
        for cols in cols_c:
            g = [[row[j] for j in cols] for row in rows]
            if len(ku) != len(g) + pu + 1 or len(kv) != len(g[0]) + pv + 1:
                continue
            ok = True
            for ev in s["evaluations"]:
                col = [de_boor(pv, kv, _homog([q for q, _ in row], [w for _, w in row]),
                               ev["v"]) for row in g]
                x = de_boor(pu, ku, col, ev["u"])
                q = [x[0] / x[3], x[1] / x[3], x[2] / x[3]]
                scale = 1.0 + max(abs(v) for v in ev["point"])
                if max(abs(u - v) for u, v in zip(q, ev["point"])) > 1e-9 * scale:
                    ok = False
                    break
            if ok:
                return {"degree_u": pu, "degree_v": pv, "knots_u": ku, "knots_v": kv,
                        "control_points": [[q for q, _ in row] for row in g],
                        "weights": [[w for _, w in row] for row in g]}
    raise ValueError("cannot write surface face %d of the reading" % s["face_index"])


def rational(weights):
    flat = [w for row in weights for w in (row if isinstance(row, list) else [row])]
    return any(w != flat[0] for w in flat) or flat[0] != 1.0


# ----------------------------------------------------------------------------------- STEP


def write_step(path, curves, surfaces):
    lines = []
    n = [0]

    def ent(text):
        n[0] += 1
        lines.append("#%d = %s;" % (n[0], text))
        return "#%d" % n[0]

    def point(p):
        return ent("CARTESIAN_POINT('',(%s))" % ",".join(real(x) for x in p))

    ctx = ent("APPLICATION_CONTEXT('core data for automotive mechanical design processes')")
    ent("APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,%s)"
        % ctx)
    pctx = ent("PRODUCT_CONTEXT('',%s,'mechanical')" % ctx)
    prod = ent("PRODUCT('mock','mock','',(%s))" % pctx)
    pdf = ent("PRODUCT_DEFINITION_FORMATION('','',%s)" % prod)
    pdc = ent("PRODUCT_DEFINITION_CONTEXT('part definition',%s,'design')" % ctx)
    pd = ent("PRODUCT_DEFINITION('design','',%s,%s)" % (pdf, pdc))
    pds = ent("PRODUCT_DEFINITION_SHAPE('','',%s)" % pd)
    lu = ent("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )")
    au = ent("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )")
    su = ent("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )")
    unc = ent("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),%s,"
              "'distance_accuracy_value','confusion accuracy')" % lu)
    gctx = ent("( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((%s)) "
               "GLOBAL_UNIT_ASSIGNED_CONTEXT((%s,%s,%s)) REPRESENTATION_CONTEXT('Context #1',"
               "'3D Context with UNIT and UNCERTAINTY') )" % (unc, lu, au, su))
    citems = []
    for c in curves:
        pts = ",".join(point(p) for p in c["control_points"])
        knots, mults = compress(c["knots"])
        ks = "(%s),(%s)" % (",".join(str(m) for m in mults), ",".join(real(k) for k in knots))
        if rational(c["weights"]):
            citems.append(ent(
                "( BOUNDED_CURVE() B_SPLINE_CURVE(%d,(%s),.UNSPECIFIED.,.F.,.F.) "
                "B_SPLINE_CURVE_WITH_KNOTS(%s,.UNSPECIFIED.) CURVE() "
                "GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE((%s)) "
                "REPRESENTATION_ITEM('') )"
                % (c["degree"], pts, ks, ",".join(real(w) for w in c["weights"]))))
        else:
            citems.append(ent("B_SPLINE_CURVE_WITH_KNOTS('',%d,(%s),.UNSPECIFIED.,.F.,.F.,%s,"
                              ".UNSPECIFIED.)" % (c["degree"], pts, ks)))
    sitems = []
    for s in surfaces:
        rows = ",".join("(%s)" % ",".join(point(p) for p in row) for row in s["control_points"])
        ku, mu = compress(s["knots_u"])
        kv, mv = compress(s["knots_v"])
        ks = "(%s),(%s),(%s),(%s)" % (
            ",".join(str(m) for m in mu), ",".join(str(m) for m in mv),
            ",".join(real(k) for k in ku), ",".join(real(k) for k in kv))
        if rational(s["weights"]):
            ws = ",".join("(%s)" % ",".join(real(w) for w in row) for row in s["weights"])
            sitems.append(ent(
                "( BOUNDED_SURFACE() B_SPLINE_SURFACE(%d,%d,(%s),.UNSPECIFIED.,.F.,.F.,.F.) "
                "B_SPLINE_SURFACE_WITH_KNOTS(%s,.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() "
                "RATIONAL_B_SPLINE_SURFACE((%s)) REPRESENTATION_ITEM('') SURFACE() )"
                % (s["degree_u"], s["degree_v"], rows, ks, ws)))
        else:
            sitems.append(ent(
                "B_SPLINE_SURFACE_WITH_KNOTS('',%d,%d,(%s),.UNSPECIFIED.,.F.,.F.,.F.,%s,"
                ".UNSPECIFIED.)" % (s["degree_u"], s["degree_v"], rows, ks)))
    if citems:
        gcs = ent("GEOMETRIC_CURVE_SET('',(%s))" % ",".join(citems))
        rep = ent("GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('',(%s),%s)"
                  % (gcs, gctx))
        ent("SHAPE_DEFINITION_REPRESENTATION(%s,%s)" % (pds, rep))
    if sitems:
        gs = ent("GEOMETRIC_SET('',(%s))" % ",".join(sitems))
        rep = ent("GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION('',(%s),%s)" % (gs, gctx))
        ent("SHAPE_DEFINITION_REPRESENTATION(%s,%s)" % (pds, rep))
    ent("PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(%s))" % prod)
    head = [
        "ISO-10303-21;", "HEADER;",
        "FILE_DESCRIPTION(('live_mock_nurbsx'),'2;1');",
        "FILE_NAME('mock','2000-01-01T00:00:00',(''),(''),'mock','mock','');",
        "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));",
        "ENDSEC;", "DATA;",
    ]
    with open(path, "w", encoding="ascii") as f:
        f.write("\n".join(head + lines + ["ENDSEC;", "END-ISO-10303-21;"]) + "\n")


# ----------------------------------------------------------------------------------- IGES


def _records(text, letter, width=72):
    """Split free-format text into fixed records (cols 1-width), sequence-numbered."""
    out = []
    while text:
        out.append(text[:width])
        text = text[width:]
    return ["%-72s%s%7d" % (r, letter, i + 1) for i, r in enumerate(out)]


def _params(fields, de):
    """Parameter-data records for one entity: cols 1-64 data, 66-72 DE pointer."""
    lines, cur = [], ""
    for i, f in enumerate(fields):
        tok = f + (";" if i == len(fields) - 1 else ",")
        if len(cur) + len(tok) > 64:
            lines.append(cur)
            cur = ""
        cur += tok
    lines.append(cur)
    return ["%-64s %7d" % (l, de) for l in lines]


def write_iges(path, curves, surfaces):
    ents = []
    for c in curves:
        n = len(c["control_points"])
        p = c["degree"]
        k = c["knots"]
        rat = rational(c["weights"])
        f = ["126", str(n - 1), str(p), "0", "0", "0" if rat else "1", "0"]
        f += [real(x) for x in k]
        f += [real(w) for w in c["weights"]]
        for q in c["control_points"]:
            f += [real(x) for x in q]
        f += [real(k[p]), real(k[n]), "0.", "0.", "0."]
        ents.append((126, 0, f))
    for s in surfaces:
        pts = s["control_points"]
        nu, nv = len(pts), len(pts[0])
        pu, pv = s["degree_u"], s["degree_v"]
        rat = rational(s["weights"])
        f = ["128", str(nu - 1), str(nv - 1), str(pu), str(pv), "0", "0", "0" if rat else "1",
             "0", "0"]
        f += [real(x) for x in s["knots_u"]] + [real(x) for x in s["knots_v"]]
        # IGES order: first index (u) varies fastest.
        for j in range(nv):
            for i in range(nu):
                f.append(real(s["weights"][i][j]))
        for j in range(nv):
            for i in range(nu):
                f += [real(x) for x in pts[i][j]]
        ku, kv = s["knots_u"], s["knots_v"]
        f += [real(ku[pu]), real(ku[nu]), real(kv[pv]), real(kv[nv])]
        ents.append((128, 0, f))
    d_lines, p_lines = [], []
    for idx, (etype, form, fields) in enumerate(ents):
        de = 2 * idx + 1
        plines = _params(fields, de)
        start = len(p_lines) + 1
        p_lines += plines
        d1 = "%8d%8d%8d%8d%8d%8d%8d%8d%8s" % (etype, start, 0, 0, 0, 0, 0, 0, "00000000")
        d2 = "%8d%8d%8d%8d%8d%8s%8s%8s%8d" % (etype, 0, 0, len(plines), form, "", "", "", 0)
        d_lines += [d1, d2]
    g = ",".join([
        "1H,", "1H;", "4Hmock", "8Hmock.igs", "4Hmock", "4Hmock", "32", "38", "6", "308", "15",
        "4Hmock", "1.", "2", "2HMM", "1", "1.", "15H20000101.000000", "1.E-07", "0.",
        "0H", "0H", "11", "0", "15H20000101.000000"]) + ";"
    s_rec = _records("live_mock_nurbsx stand-in for nurbsx (tests only)", "S")
    g_rec = _records(g, "G")
    d_rec = ["%-72sD%7d" % (l, i + 1) for i, l in enumerate(d_lines)]
    p_rec = ["%sP%7d" % (l, i + 1) for i, l in enumerate(p_lines)]
    t = "S%7dG%7dD%7dP%7d" % (len(s_rec), len(g_rec), len(d_rec), len(p_rec))
    with open(path, "w", encoding="ascii") as f:
        f.write("\n".join(s_rec + g_rec + d_rec + p_rec + ["%-72sT%7d" % (t, 1)]) + "\n")


# --------------------------------------------------------- file mode (same format only)
#
# MOCK_NURBSX_FROM_FILE=1: for STEP->STEP and IGES->IGES the mock copies the B-spline
# entities of S itself (their text, so their exact digits) into loose geometry, instead of
# writing FreeCAD's reading.  This tests what the real nurbsx relies on: that OCCT reads a
# curve / surface entity the same way standalone as inside S's topology (faces-mode IGES
# 142 boundaries, STEP EDGE_CURVEs).


def _step_instances(text):
    import re

    data = text[text.find("DATA;"):]
    out = {}
    for m in re.finditer(r"#(\d+)\s*=\s*(.*?);\s*(?=#\d+\s*=|ENDSEC)", data, re.S):
        out[int(m.group(1))] = m.group(2)
    return out


def step_from_file(src, out):
    """Loose copy of S's 3-D B-spline curves and surfaces; None if S is not a one-shape file."""
    import re

    with open(src, encoding="latin-1") as f:
        text = f.read()
    inst = _step_instances(text)
    sdr = [i for i, b in inst.items() if b.startswith("SHAPE_DEFINITION_REPRESENTATION(")]
    if len(sdr) != 1:
        return None
    pds, rep = re.findall(r"#(\d+)", inst[sdr[0]])[:2]
    ctx = re.findall(r"#(\d+)", inst[int(rep)])[-1]
    curves, surfaces = [], []
    for i, b in sorted(inst.items()):
        if "B_SPLINE_SURFACE_WITH_KNOTS" in b:
            surfaces.append(i)
        elif "B_SPLINE_CURVE_WITH_KNOTS" in b:
            m = re.search(r"B_SPLINE_CURVE(?:_WITH_KNOTS)?\(\s*(?:'[^']*'\s*,)?\s*\d+\s*,"
                          r"\s*\(\s*#(\d+)", b)
            pt = re.search(r"\(([^()]*)\)\s*\)\s*$", inst[int(m.group(1))])
            if pt and len(pt.group(1).split(",")) == 3:
                curves.append(i)
    nid = max(inst) + 1
    extra = []
    if curves:
        extra += ["#%d = GEOMETRIC_CURVE_SET('',(%s));" % (nid, ",".join("#%d" % c for c in curves)),
                  "#%d = GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('',(#%d),#%s);"
                  % (nid + 1, nid, ctx),
                  "#%d = SHAPE_DEFINITION_REPRESENTATION(#%s,#%d);" % (nid + 2, pds, nid + 1)]
        nid += 3
    if surfaces:
        extra += ["#%d = GEOMETRIC_SET('',(%s));" % (nid, ",".join("#%d" % c for c in surfaces)),
                  "#%d = GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION('',(#%d),#%s);"
                  % (nid + 1, nid, ctx),
                  "#%d = SHAPE_DEFINITION_REPRESENTATION(#%s,#%d);" % (nid + 2, pds, nid + 1)]
    # Drop S's own shape link, so that only the loose geometry is a transfer root.
    text = re.sub(r"#%d\s*=\s*SHAPE_DEFINITION_REPRESENTATION\([^;]*;\s*" % sdr[0], "", text)
    end = text.rfind("ENDSEC;")
    text = text[:end] + "\n".join(extra) + "\n" + text[end:]
    with open(out, "w", encoding="latin-1") as f:
        f.write(text)
    ents = [{"id": c, "kind": "curve", "dimension": 3} for c in curves]
    ents += [{"id": c, "kind": "surface", "dimension": 3} for c in surfaces]
    return {"format": "step", "schema": None, "units": None, "entities": ents,
            "diagnostics": []}


def iges_from_file(src, out):
    """Independent copies of S's 3-D 126 and all 128 entities (same parameter text)."""
    with open(src, encoding="latin-1") as f:
        lines = [l.rstrip("\r\n") for l in f]
    sec = {k: [l for l in lines if len(l) >= 73 and l[72] == k] for k in "SGDP"}
    params = {}
    for l in sec["P"]:
        de = int(l[64:72])
        params[de] = params.get(de, "") + l[:64]
    d = sec["D"]
    types, forms = {}, {}
    for i in range(0, len(d) - 1, 2):
        types[i + 1] = int(d[i][0:8])
        forms[i + 1] = int(d[i + 1][32:40] or 0)
    fields = {de: [x.strip() for x in t.split(";")[0].split(",")] for de, t in params.items()}
    two_d = set()
    for de, t in types.items():
        f = fields.get(de, [])
        if t == 142:
            two_d.add(int(f[3]))
        elif t == 508:
            k = 2
            for _ in range(int(f[1])):
                nk = int(f[k + 4])
                for j in range(nk):
                    two_d.add(int(f[k + 6 + 2 * j]))
                k += 5 + 2 * nk
    todo = list(two_d)
    while todo:
        de = todo.pop()
        if types.get(de) == 102:
            for x in fields[de][2:2 + int(fields[de][1])]:
                if int(x) not in two_d:
                    two_d.add(int(x))
                    todo.append(int(x))
    keep = [de for de, t in sorted(types.items())
            if (t == 126 and de not in two_d) or t == 128]
    d_lines, p_lines, ents = [], [], []
    for idx, de in enumerate(keep):
        f = fields[de]
        nde = 2 * idx + 1
        plines = _params(f, nde)
        start = len(p_lines) + 1
        p_lines += plines
        d_lines += ["%8d%8d%8d%8d%8d%8d%8d%8d%8s" % (types[de], start, 0, 0, 0, 0, 0, 0,
                                                     "00000000"),
                    "%8d%8d%8d%8d%8d%8s%8s%8s%8d" % (types[de], 0, 0, len(plines), forms[de],
                                                     "", "", "", 0)]
        num = lambda x: float(x.replace("D", "E"))  # noqa: E731
        if types[de] == 126:
            kk, m = int(f[1]), int(f[2])
            knots = [num(x) for x in f[7:7 + kk + m + 2]]
            v = 7 + (kk + m + 2) + 4 * (kk + 1)
            ents.append({"id": nde, "kind": "curve", "dimension": 3, "domain": [[num(f[v]),
                                                                                   num(f[v + 1])]],
                         "geometry": {"degree": m, "knots": knots,
                                      "control_points": [[0.0, 0.0, 0.0]] * (kk + 1)}})
        else:
            ents.append({"id": nde, "kind": "surface", "dimension": 3})
    d_rec = ["%-72sD%7d" % (l, i + 1) for i, l in enumerate(d_lines)]
    p_rec = ["%sP%7d" % (l, i + 1) for i, l in enumerate(p_lines)]
    t = "S%7dG%7dD%7dP%7d" % (len(sec["S"]), len(sec["G"]), len(d_rec), len(p_rec))
    with open(out, "w", encoding="ascii") as f:
        f.write("\n".join(sec["S"] + sec["G"] + d_rec + p_rec + ["%-72sT%7d" % (t, 1)]) + "\n")
    return {"format": "iges", "schema": None, "units": None, "entities": ents,
            "diagnostics": []}


# ------------------------------------------------------------------------------------ CLI


def read_entities(src):
    """(curves, surfaces) of FreeCAD's reading of src, in writable (non-periodic) form."""
    with open(src + ".json", encoding="utf-8") as f:
        reading = json.load(f)
    curves = [curve_entity(c) for c in reading["curves"]]
    surfaces = [surface_entity(s) for s in reading["surfaces"]]
    if os.environ.get("MOCK_NURBSX_NOCURVES") == "1":
        curves = []
    return [dict(c, dimension=3) for c in curves], surfaces


def info_json(entities, fmt):
    """nurbsx `info --json` layout for (curves, surfaces)."""
    curves, surfaces = entities
    ents = []
    for c in curves:
        ents.append({"id": len(ents) + 1, "kind": "curve", "dimension": c["dimension"],
                     "degree": [c["degree"]], "poles": [len(c["control_points"])],
                     "rational": rational(c["weights"]),
                     "geometry": {k: c[k] for k in ("degree", "knots", "control_points",
                                                    "weights")}})
    for s in surfaces:
        ents.append({"id": len(ents) + 1, "kind": "surface", "dimension": 3,
                     "degree": [s["degree_u"], s["degree_v"]],
                     "poles": [len(s["control_points"]), len(s["control_points"][0])],
                     "rational": rational(s["weights"]), "geometry": s})
    return {"format": fmt, "schema": None, "units": {"name": "mm", "to_mm": 1.0},
            "entities": ents, "diagnostics": []}


def convert(src, out, fmt):
    if os.environ.get("MOCK_NURBSX_FAIL") == "1":
        print("mock: conversion refused (MOCK_NURBSX_FAIL=1)", file=sys.stderr)
        return 1
    sfmt = "step" if src.lower().endswith((".step", ".stp")) else "iges"
    if os.environ.get("MOCK_NURBSX_FROM_FILE") == "1" and sfmt == fmt:
        info = step_from_file(src, out) if fmt == "step" else iges_from_file(src, out)
        if info is not None:
            with open(out + ".mock.json", "w", encoding="utf-8") as f:
                json.dump(info, f)
            return 0
    info_curves, surfaces = read_entities(src)
    curves = [dict(c) for c in info_curves]
    perturb = float(os.environ.get("MOCK_NURBSX_PERTURB", "0") or 0)
    if perturb and curves:
        size = 0.0
        for c in curves:
            for q in c["control_points"]:
                size = max(size, max(abs(x) for x in q))
        c0 = curves[0]
        c0["control_points"] = [list(q) for q in c0["control_points"]]
        c0["control_points"][1][0] += perturb * max(size, 1.0)
    if os.environ.get("MOCK_NURBSX_PCURVE") == "1":
        pc = {"degree": 1, "knots": [0.0, 0.0, 1.0, 1.0],
              "control_points": [[0.25, 0.5, 0.0], [0.75, 0.5, 0.0]], "weights": [1.0, 1.0]}
        curves.append(pc)
        info_curves = info_curves + [dict(pc, dimension=2)]
    written_surfaces = surfaces
    if os.environ.get("MOCK_NURBSX_DROP") == "1" and surfaces:
        written_surfaces = surfaces[:-1]
    if os.environ.get("MOCK_NURBSX_GARBAGE") == "1":
        with open(out, "w", encoding="ascii") as f:
            f.write("this is not a CAD file\n")
    elif fmt == "step":
        write_step(out, curves, written_surfaces)
    elif fmt == "iges":
        write_iges(out, curves, written_surfaces)
    else:
        print("mock: unknown format %s" % fmt, file=sys.stderr)
        return 2
    with open(out + ".mock.json", "w", encoding="utf-8") as f:
        json.dump(info_json((info_curves, surfaces), fmt), f)
    return 0


def main(argv):
    if len(argv) >= 5 and argv[0] == "convert" and argv[2] == "-o" and argv[4] == "--to":
        return convert(argv[1], argv[3], argv[5] if len(argv) > 5 else "")
    # `--geometry-only` changes nothing here: the mock's reading is geometry only anyway.
    if argv[:3] == ["info", "--json", "--geometry-only"]:
        argv = argv[:2] + argv[3:]
    if len(argv) == 3 and argv[0] == "info" and argv[1] == "--json":
        if os.path.exists(argv[2] + ".mock.json"):  # a file the mock wrote
            with open(argv[2] + ".mock.json", encoding="utf-8") as f:
                sys.stdout.write(f.read())
        elif os.environ.get("MOCK_NURBSX_FROM_FILE") == "1":  # a sample, read as a file
            import tempfile

            with tempfile.TemporaryDirectory() as tmp:
                src = argv[2]
                if src.lower().endswith((".step", ".stp")):
                    info = step_from_file(src, os.path.join(tmp, "x.step"))
                else:
                    info = iges_from_file(src, os.path.join(tmp, "x.igs"))
            if info is None:
                info = info_json(read_entities(src), "?")
            json.dump(info, sys.stdout)
        else:  # a sample: its entities are those of FreeCAD's reading
            json.dump(info_json(read_entities(argv[2]), "?"), sys.stdout)
        return 0
    print("usage: live_mock_nurbsx.py convert S -o OUT --to step|iges | info --json "
          "[--geometry-only] OUT",
          file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
