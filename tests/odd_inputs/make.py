#!/usr/bin/env python3
"""Derive valid but unusual STEP and IGES files from samples/freecad, deterministically.

Run from the repository root: `python3 tests/odd_inputs/make.py`. Every `<name>.step|.igs`
must validate (exit 0); `<name>.expect` holds `entities: N`, the number of curves
and surfaces it must read. tests/robustness.rs (odd_inputs_read) replays them.
"""
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = os.path.join(os.path.dirname(os.path.dirname(HERE)), "samples", "freecad")


def read(name):
    with open(os.path.join(SAMPLES, name), "rb") as f:
        return f.read().decode("latin-1")


def emit(name, ext, text, entities, same_as=None, warnings=None):
    """`same_as`: the sample this is a pure re-encoding of; its geometry must be identical.
    `warnings`: how many warnings validate must give (none: not checked)."""
    data = text.encode("latin-1") if isinstance(text, str) else text
    with open(os.path.join(HERE, name + ext), "wb") as f:
        f.write(data)
    with open(os.path.join(HERE, name + ".expect"), "w") as f:
        f.write(f"entities: {entities}\n")
        if same_as:
            f.write(f"same_as: {same_as}\n")
        if warnings is not None:
            f.write(f"warnings: {warnings}\n")


def outside_strings(text, fn):
    """Apply fn to each stretch of text outside '...' strings (Part 21 quoting)."""
    out, i, n = [], 0, len(text)
    while i < n:
        j = text.find("'", i)
        if j < 0:
            out.append(fn(text[i:]))
            break
        out.append(fn(text[i:j]))
        k = j + 1
        while True:
            k = text.index("'", k)
            if text[k + 1:k + 2] == "'":
                k += 2
                continue
            break
        out.append(text[j:k + 1])
        i = k + 1
    return "".join(out)


def replace_instance(text, eid, new):
    m = re.search(r"(?m)^#%d\s*=" % eid, text)
    end = text.index(";", m.start())
    return text[:m.start()] + new + text[end:]


def step_cases():
    c2 = read("curve_deg2_clamped.step")  # #17 curve with poles #18..#24
    srf = read("surf_poles4x3.step")      # #32 surface with poles #33..#44
    emit("step_crlf", ".step", c2.replace("\n", "\r\n"), 1, "curve_deg2_clamped.step")
    emit("step_comments_everywhere", ".step",
         outside_strings(c2, lambda s: s.replace(",", "/* , */,/**/").replace("(", "(/* ( */")
                         .replace(";", "/*;*/;")), 1, "curve_deg2_clamped.step")
    # Every string escape of ISO 10303-21 7.3.3 in the curve's name.
    name = r"'it''s \\ \S\a \PE\\S\b \X\E9 \X2\00E9263A\X0\ \X4\0001F600\X0\ end'"
    emit("step_string_escapes", ".step", c2.replace("B_SPLINE_CURVE_WITH_KNOTS('',", f"B_SPLINE_CURVE_WITH_KNOTS({name},", 1), 1, "curve_deg2_clamped.step")
    # A string broken over lines (the line ends are not part of the string).
    emit("step_multiline_string", ".step", c2.replace(
        "#8 = PRODUCT_CONTEXT('',", "#8 = PRODUCT_CONTEXT('a string\nover\r\nthree lines',", 1), 1, "curve_deg2_clamped.step")
    # Two DATA sections, with references from the second into the first.
    cut = c2.index("#17 =")
    emit("step_two_data_sections", ".step", c2[:cut] + "ENDSEC;\nDATA;\n" + c2[cut:], 1, "curve_deg2_clamped.step")
    # Lower-case letters only inside strings and in the header's schema string.
    emit("step_whitespace_everywhere", ".step", outside_strings(
        c2, lambda s: s.replace(",", " ,\t").replace("=", " \t = ")), 1, "curve_deg2_clamped.step")

    pts = "(#18,#19,#20,#21,#22,#23,#24)"
    subtypes = {
        "bezier": f"BEZIER_CURVE('',6,{pts},.UNSPECIFIED.,.F.,.F.)",
        "uniform": f"UNIFORM_CURVE('',2,{pts},.UNSPECIFIED.,.F.,.F.)",
        "quasi_uniform": f"QUASI_UNIFORM_CURVE('',3,{pts},.UNSPECIFIED.,.F.,.F.)",
    }
    for kind, inst in subtypes.items():
        emit(f"step_{kind}_curve", ".step", replace_instance(c2, 17, "#17 = " + inst), 1)
        # Rational: the complex instance with RATIONAL_B_SPLINE_CURVE.
        deg = re.search(r"\('',(\d+),", inst).group(1)
        up = kind.upper() + "_CURVE"
        cplx = (f"#17 = ( BOUNDED_CURVE() B_SPLINE_CURVE({deg},{pts},.UNSPECIFIED.,.F.,.F.) "
                f"{up}() CURVE() GEOMETRIC_REPRESENTATION_ITEM() "
                f"RATIONAL_B_SPLINE_CURVE((1.,2.,0.5,1.,3.,1.,1.)) REPRESENTATION_ITEM('') )")
        emit(f"step_{kind}_curve_rational", ".step", replace_instance(c2, 17, cplx), 1)

    grid = "((#33,#34,#35),(#36,#37,#38),(#39,#40,#41),(#42,#43,#44))"
    ssub = {
        "bezier": f"BEZIER_SURFACE('',3,2,{grid},.UNSPECIFIED.,.F.,.F.,.F.)",
        "uniform": f"UNIFORM_SURFACE('',2,1,{grid},.UNSPECIFIED.,.F.,.F.,.F.)",
        "quasi_uniform": f"QUASI_UNIFORM_SURFACE('',2,2,{grid},.UNSPECIFIED.,.F.,.F.,.F.)",
    }
    for kind, inst in ssub.items():
        # The sample also holds 4 boundary p-curves: 5 B-splines in all.
        emit(f"step_{kind}_surface", ".step", replace_instance(srf, 32, "#32 = " + inst), 5)
        du, dv = re.search(r"\('',(\d+),(\d+),", inst).groups()
        up = kind.upper() + "_SURFACE"
        cplx = (f"#32 = ( BOUNDED_SURFACE() B_SPLINE_SURFACE({du},{dv},{grid},.UNSPECIFIED.,.F.,.F.,.F.) "
                f"{up}() GEOMETRIC_REPRESENTATION_ITEM() "
                f"RATIONAL_B_SPLINE_SURFACE(((1.,2.,1.),(1.,0.5,1.),(2.,1.,1.),(1.,1.,3.))) "
                f"REPRESENTATION_ITEM('') SURFACE() )")
        emit(f"step_{kind}_surface_rational", ".step", replace_instance(srf, 32, cplx), 5)


def unit_cases():
    """The standard ISO 10303-41 unit constructs as other systems write them (issue 21):
    degrees as a CONVERSION_BASED_UNIT over PLANE_ANGLE_MEASURE_WITH_UNIT, with blanks inside
    the records, the solid angle unit, and a DERIVED_UNIT no geometry uses."""
    c2 = read("curve_deg2_clamped.step")
    radian = "#29 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );"
    steradian = "#30 = ( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() );"
    assert radian in c2 and steradian in c2
    degree = (
        "#29 =( CONVERSION_BASED_UNIT ( 'DEGREE', #33 )NAMED_UNIT ( #34 )PLANE_ANGLE_UNIT ( ) );\n"
        "#33 = PLANE_ANGLE_MEASURE_WITH_UNIT ( PLANE_ANGLE_MEASURE ( 0.01745329251994330 ), #35 );\n"
        "#34 = DIMENSIONAL_EXPONENTS ( 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 );\n"
        "#35 =( NAMED_UNIT ( * )PLANE_ANGLE_UNIT ( )SI_UNIT ( $, .RADIAN. ) );")
    emit("step_plane_angle_degrees", ".step", c2.replace(radian, degree), 1, "curve_deg2_clamped.step", 0)
    derived = (
        "#30 =( NAMED_UNIT ( * )SI_UNIT ( $, .STERADIAN. )SOLID_ANGLE_UNIT ( ) );\n"
        "#36 = DERIVED_UNIT ( ( #37 ) );\n"
        "#37 = DERIVED_UNIT_ELEMENT ( #28, 2.0 );")
    emit("step_solid_angle_and_derived_units", ".step",
         c2.replace(radian, degree).replace(steradian, derived), 1, "curve_deg2_clamped.step", 0)


def planar_case():
    """A planar 126 (PROP1 = 1) whose poles lie on x + 2y + 2z = 30 as exactly as doubles
    allow, written with 12 digits, and whose unit normal (1, 2, 2) / 3 is written with 8,
    as SolidWorks does: the poles are ~1e-7 from the plane of the normal as written, within
    what 8 digits carry over the curve's 70 mm (issue 21: no PROP1 warning)."""
    base = read("curve_deg2_clamped.igs").splitlines()
    xy = [(1.5, 2.25), (10.125, -3.5), (20.75, 5.0), (30.25, -1.5), (38.5, 7.25), (50.0, 0.5), (58.875, 3.0)]
    pts = [(x, y, (30 - x - 2 * y) / 2) for x, y in xy]
    fmt = lambda v: ("%.12g" % v) + ("." if "." not in "%.12g" % v and "e" not in "%.12g" % v else "")
    n = [1 / 3, 2 / 3, 2 / 3]
    vals = ["126", "6", "2", "1", "0", "1", "0"]
    vals += ["-1.25"] * 3 + ["-0.672195", "0.466963", "0.466963", "1.070586"] + ["2.325594"] * 3
    vals += ["1."] * 7
    vals += [fmt(c) for p in pts for c in p]
    vals += ["-1.25", "2.325594"] + ["%.8f" % c for c in n]
    # Distance of the poles from the plane of the written normal, for the record.
    nw = [float("%.8f" % c) for c in n]
    dev = max(abs(sum((p[i] - pts[0][i]) * nw[i] for i in range(3))) for p in pts)
    assert 1e-8 < dev < 1e-6, dev
    data = ",".join(vals) + ";"
    lines, line = [], ""
    for tok in re.split("(?<=,)", data):
        if len(line) + len(tok) > 64:
            lines.append(line)
            line = ""
        line += tok
    lines.append(line)
    p = [f"{l:<64} {1:>7}P{i + 1:>7}" for i, l in enumerate(lines)]
    recs = [r for r in base if r[72] in "SGD"]
    d2 = [i for i, r in enumerate(recs) if r[72] == "D"][1]
    recs[d2] = recs[d2][:24] + f"{len(p):>8}" + recs[d2][32:]
    emit("iges_planar_normal_8_digits", ".igs", "\n".join(with_counts(recs + p)) + "\n", 1, warnings=0)


def iges_records(text):
    return text.splitlines()


def reflow(data, letter, delim):
    """Global data -> 72-column records, breaking only after a parameter delimiter."""
    out, line = [], ""
    for tok in re.split(f"(?<={re.escape(delim)})", data):
        if len(line) + len(tok) > 72:
            out.append(line)
            line = ""
        line += tok
    out.append(line)
    return [f"{l:<72}{letter}{i + 1:>7}" for i, l in enumerate(out)]


def with_counts(recs):
    counts = {c: sum(1 for r in recs if r[72] == c) for c in "SGDP"}
    body = [r for r in recs if r[72] != "T"]
    t = f"S{counts['S']:>7}G{counts['G']:>7}D{counts['D']:>7}P{counts['P']:>7}"
    return body + [f"{t:<72}T{1:>7}"]


def iges_cases():
    c2 = read("curve_deg2_clamped.igs")
    # CR LF after 80-column records: IGES 5.3 section 2.1 fixes the record, not the line
    # terminator, so no warning (an informational note only).
    emit("iges_crlf", ".igs", c2.replace("\n", "\r\n"), 1, "curve_deg2_clamped.igs", 0)
    recs = iges_records(c2)
    # Custom delimiters: '/' between parameters, '#' ends a record.
    g = "".join(r[:72] for r in recs if r[72] == "G").rstrip()
    assert g.startswith(",,")
    g = "1H/,1H#," + g[2:]
    # Holleriths here hold no ',' or ';': every remaining one is a delimiter.
    head, rest = g[:8], g[8:]
    g = "1H//1H#/" + rest.replace(",", "/").replace(";", "#")
    del head
    out = [r for r in recs if r[72] == "S"] + reflow(g, "G", "/")
    out += [r for r in recs if r[72] == "D"]
    out += [r[:64].replace(",", "/").replace(";", "#") + r[64:] for r in recs if r[72] == "P"]
    emit("iges_custom_delimiters", ".igs", "\n".join(with_counts(out)) + "\n", 1, "curve_deg2_clamped.igs")
    # Comments after the record delimiter (IGES 5.3 2.2.4.4: text after it is ignored).
    recs = iges_records(c2)
    last = max(i for i, r in enumerate(recs) if r[72] == "P")
    data = recs[last][:64].rstrip()
    recs[last] = f"{data + ' comment: ignored, 1,2,3;':<64}" + recs[last][64:]
    emit("iges_comment_after_terminator", ".igs", "\n".join(recs) + "\n", 1, "curve_deg2_clamped.igs")
    # A surface, a rational curve and the trimmed face, untouched but with CRLF and
    # trailing blanks removed (short lines).
    for name, n in (("surf_poles4x3.igs", 9), ("curve_deg2_rational_clamped.igs", 1)):
        t = read(name)
        emit("iges_short_lines_" + name[:-4], ".igs", "\n".join(r.rstrip() if r[72:73] != "P" else r for r in t.splitlines()) + "\n", n, name)


def associativity_cases():
    """Valid 402 Associativity Instances (a group, a planar associativity without a
    transformation) and 406 Properties (a name, definition levels) that point at the
    sample's entities: their pointers are declared and checked, and must give no finding.
    The entities are appended by the bad-input generator's `add_entity`."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "bad_inputs_make", os.path.join(os.path.dirname(HERE), "bad_inputs", "make.py"))
    bad = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bad)
    recs = iges_records(read("surf_poles4x3.igs"))
    bad.add_entity(recs, 402, 7, "402,3,1,3,17;")
    bad.add_entity(recs, 402, 16, "402,1,2,0,9,11;")
    bad.add_entity(recs, 406, 15, "406,1,4HSURF;")
    bad.add_entity(recs, 406, 1, "406,2,1,2;")
    bad.add_entity(recs, 402, 18, "402,2,1,0,0,1,0,0,0,0,27,8HPIPE RUN;")
    emit("iges_associativities_and_properties", ".igs", "\n".join(recs) + "\n", 9, "surf_poles4x3.igs", 0)


def data_tables_case():
    """Valid records whose layouts come from their data (IGES 5.3 sections 4.79, 4.107,
    4.123, 4.141): a 322 Attribute Table Definition in each form, a 422 Attribute Table
    Instance (form 1, two rows) following the form 0 one, a 406 form 27 Generic Data and a
    406 form 11 Tabular Data, appended to surf_poles4x3.igs (D3 a 128, D9 a 110): each is
    read by its layout and its pointers checked, and must give no finding."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "bad_inputs_make", os.path.join(os.path.dirname(HERE), "bad_inputs", "make.py"))
    bad = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bad)
    recs = iges_records(read("surf_poles4x3.igs"))
    # NAME, ATYP 0, NA = 2: (AT 10, AVT 4 pointer, AVC 1), (AT 11, AVT 2 real, AVC 2).
    table = bad.add_entity(recs, 322, 0, "322,5HTABLE,0,2,10,4,1,11,2,2;")
    # NR = 2 rows of (pointer, real, real).
    instance = bad.add_entity(recs, 422, 1, "422,2,3,1.,2.,9,3.,4.;")
    bad.setfield(recs, bad.didx(recs, instance), 3, -table)
    # NP = 10, NAME, TNUM = 4: (1, 42), (2, 2.5), (3, "OK"), (4, D3).
    bad.add_entity(recs, 406, 27, "406,10,4HDATA,4,1,42,2,2.5,3,2HOK,4,3;")
    # NP = 11, PTYPE 1, NDEP 1, NIND 1, TYPIND 1, NVALIN 3, 3 + 1 x 3 reals.
    bad.add_entity(recs, 406, 11, "406,11,1,1,1,1,3,0.,1.,2.,5.,6.,7.;")
    template = bad.add_entity(recs, 312, 0, "312,1.,2.,1,1.5708,0.,0,0,0.,0.,0.;")
    # Form 2: NA = 1, (AT 1, AVT 4, AVC 1): D3 shown by the 312.
    bad.add_entity(recs, 322, 2, f"322,3HTXT,1,1,1,4,1,3,{template};")
    # Form 1: NA = 2, (AT 1, AVT 1, AVC 2): 5, 7; (AT 3, AVT 6, AVC 1): true.
    bad.add_entity(recs, 322, 1, "322,4HATTS,1,2,1,1,2,5,7,3,6,1,1;")
    emit("iges_data_tables", ".igs", "\n".join(recs) + "\n", 9, "surf_poles4x3.igs", 0)


def views_and_back_pointers_case():
    """Associativities that point at their members while the members point back, by design
    (IGES 5.3 section 2.2.4.5.2 back pointers; DE view and label display fields naming a
    402 form 3, 4 or 5 that lists the entity): a group with back pointers (form 1) whose
    two lines carry the group in their associativity pointers, Views Visible (form 3) and
    Views Visible with attributes (form 4, its color a negated pointer to a 314) named by
    lines' DE view fields, an Entity Label Display (form 5) named by a line's DE label
    display field, and a Segmented Views Visible (form 19) whose color and line font are a
    negated 314 pointer and a value; and a drawing (404) of a linear dimension (216) with
    its general note (212, its font a negated 310 pointer) and leaders (214), drawing size
    and units properties (406 forms 16, 17) and a pattern line font (304 form 2). None of
    these pairs is a pointer cycle, and every pointer names an entity of the type its field
    allows: no finding."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "bad_inputs_make", os.path.join(os.path.dirname(HERE), "bad_inputs", "make.py"))
    bad = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bad)
    recs = iges_records(read("surf_poles4x3.igs"))
    next_de = lambda: sum(1 for r in recs if r[72:73] == "D") + 1
    group = next_de()
    # The lines at D9 and D11 (P8, P9) get the group as their one associativity pointer.
    for seq in (8, 9):
        i = bad.pidx(recs, seq)
        bad.setp(recs, i, recs[i][:64].rstrip().rstrip(";") + f",1,{group};")
    assert bad.add_entity(recs, 402, 1, "402,2,9,11;") == group
    view = bad.add_entity(recs, 410, 0, "410,1,1.,0,0,0,0,0,0;")
    color = bad.add_entity(recs, 314, 0, "314,100.,0.,0.;")
    leader = bad.add_entity(recs, 214, 1, "214,1,1.,1.,0.,0.,0.,1.,1.;")
    visible = bad.add_entity(recs, 402, 3, f"402,1,1,{view},13;")
    attributes = bad.add_entity(recs, 402, 4, f"402,1,1,{view},1,0,-{color},1,15;")
    label = bad.add_entity(recs, 402, 5, f"402,1,{view},0.,0.,0.,{leader},0,19;")
    bad.add_entity(recs, 402, 19, f"402,1,{view},0.5,0,-{color},1,0;")
    # A drawing of a linear dimension: its note (font a negated pointer to a 310 Text Font
    # Definition), two leaders, in a view of a drawing, with drawing size and units
    # properties and a dashed line font.
    font = bad.add_entity(recs, 310, 0, "310,1,5HSTICK,0,0,0;")
    note = bad.add_entity(recs, 212, 0, f"212,1,5,10.,2.,-{font},1.5707963267948966,0.,0,0,0.,0.,0.,5HHELLO;")
    second = bad.add_entity(recs, 214, 1, "214,1,1.,1.,0.,5.,0.,6.,1.;")
    dimension = bad.add_entity(recs, 216, 0, f"216,{note},{leader},{second},0,0;")
    bad.add_entity(recs, 404, 0, f"404,1,{view},0.,0.,1,{dimension};")
    bad.add_entity(recs, 406, 16, "406,2,841.,594.;")
    bad.add_entity(recs, 406, 17, "406,2,2,2HMM;")
    bad.add_entity(recs, 304, 2, "304,2,1.,0.5,1H3;")

    def de_field(de, field, value):
        i = bad.didx(recs, de)
        col = 8 * (field - 1)
        recs[i] = recs[i][:col] + f"{value:>8}" + recs[i][col + 8:]

    de_field(13, 6, visible)
    de_field(15, 6, attributes)
    de_field(19, 8, label)
    emit("iges_views_and_back_pointers", ".igs", "\n".join(recs) + "\n", 9, "surf_poles4x3.igs", 0)


if __name__ == "__main__":
    for n in os.listdir(HERE):
        if n.endswith((".step", ".igs", ".expect")):
            os.remove(os.path.join(HERE, n))
    step_cases()
    unit_cases()
    iges_cases()
    planar_case()
    associativity_cases()
    views_and_back_pointers_case()
    data_tables_case()
    print(len([x for x in os.listdir(HERE) if x.endswith(".expect")]), "cases")
