#!/usr/bin/env python3
"""Derive malformed STEP and IGES files from samples/freecad, deterministically.

Run from the repository root: `python3 tests/bad_inputs/make.py`. For every case it writes
`<name>.step|.igs` (the bad input) and `<name>.expect` (what `nurbsx validate --format json`
must report): `code:` a prefix of the error diagnostic's code, then the location fields the
error must carry: STEP `line`, `column`, `entity` (#id); IGES `section`, `sequence`,
`entity` (D<n>). Locations are computed here from the position of the mutation, never
copied from the tool's output. tests/robustness.rs replays every case.
"""
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SAMPLES = os.path.join(ROOT, "samples", "freecad")


LOADED = {}


def read(name):
    with open(os.path.join(SAMPLES, name), "rb") as f:
        data = f.read()
    LOADED[name] = data
    return data


def source_of(data):
    """The sample a damaged file was derived from: the loaded sample sharing the longest
    prefix plus suffix with it, when that covers at least half of the file (whole-file
    damage such as an empty or a PDF file has no source). The test compares `convert`'s
    geometry with that sample's."""
    best, score = None, 0
    for name, orig in LOADED.items():
        n = min(len(orig), len(data))
        pre = 0
        while pre < n and orig[pre] == data[pre]:
            pre += 1
        suf = 0
        while suf < n - pre and orig[-1 - suf] == data[-1 - suf]:
            suf += 1
        if pre + suf > score:
            best, score = name, pre + suf
    return best if data and score * 2 >= len(data) else None


def clear():
    for n in os.listdir(HERE):
        if n.endswith((".step", ".igs", ".expect", ".bin")):
            os.remove(os.path.join(HERE, n))


def emit(name, ext, data, **expect):
    if isinstance(data, str):
        data = data.encode("latin-1")
    with open(os.path.join(HERE, name + ext), "wb") as f:
        f.write(data)
    src = source_of(data)
    if src is not None:
        expect.setdefault("source", src)
    with open(os.path.join(HERE, name + ".expect"), "w") as f:
        for k in ("code", "line", "column", "entity", "section", "sequence", "source"):
            if k in expect:
                f.write(f"{k}: {expect[k]}\n")


def line_col(data, offset):
    """1-based line and column of a byte offset."""
    line = data.count(b"\n", 0, offset) + 1
    col = offset - (data.rfind(b"\n", 0, offset) + 1) + 1
    return line, col


def inst_loc(data, eid):
    """Line/column of the start of instance `#eid =`."""
    m = re.search(rb"(?m)^#%d\s*=" % eid, data)
    assert m, eid
    return line_col(data, m.start())


def sub_in(data, eid, old, new, count=1):
    """Replace `old` by `new` inside the text of instance #eid (up to its `;`)."""
    m = re.search(rb"(?m)^#%d\s*=" % eid, data)
    end = data.index(b";", m.start())
    body = data[m.start():end]
    assert old in body, (eid, old, body)
    return data[:m.start()] + body.replace(old, new, count) + data[end:]


# ---------------------------------------------------------------- STEP
def step_cases():
    c2 = read("curve_deg2_clamped.step")  # #17 B_SPLINE_CURVE_WITH_KNOTS, poles #18..#24
    rat = read("curve_circle_nurbs.step")  # #17 complex rational curve
    srf = read("surf_poles4x3.step")       # #32 B_SPLINE_SURFACE_WITH_KNOTS

    def ent(name, data, eid, code):
        line, col = inst_loc(data, eid)
        emit(name, ".step", data, code=code, line=line, column=col, entity=f"#{eid}")

    # --- whole-file damage
    # Not recognisable as STEP at all: refused before parsing, at line 1.
    emit("step_empty", ".step", b"", code="format.empty", line=1)
    emit("step_binary_garbage", ".step", bytes((i * 131 + 7) % 256 for i in range(4096)), code="format.binary", line=1)
    emit("step_utf16", ".step", c2.decode("latin-1").encode("utf-16"), code="encoding.utf16", line=1)
    # What the file is instead, named at line 1 (ISO 10303-21 clause 5: 8-bit text that
    # starts with ISO-10303-21;).
    emit("step_utf16be_no_bom", ".step", c2.decode("latin-1").encode("utf-16-be"), code="encoding.utf16", line=1)
    emit("step_utf32", ".step", c2.decode("latin-1").encode("utf-32"), code="encoding.utf32", line=1)
    emit("step_whitespace_only", ".step", b" \r\n\t\n", code="format.empty", line=1)
    emit("step_is_pdf", ".step", b"%PDF-1.7\n%\xe2\xe3\xcf\xd3\n1 0 obj\n<<>>\nendobj\n", code="format.other", line=1)
    emit("step_is_dxf", ".step", b"  0\r\nSECTION\r\n  2\r\nHEADER\r\n  0\r\nENDSEC\r\n  0\r\nEOF\r\n", code="format.other", line=1)
    emit("step_is_ascii_stl", ".step", b"solid part\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid part\n", code="format.other", line=1)
    emit("step_is_binary_stl", ".step", b"binary stl".ljust(80, b" ") + (1).to_bytes(4, "little") + bytes(50), code="format.other", line=1)
    emit("step_is_zip", ".step", b"PK\x03\x04\x14\x00\x00\x00\x08\x00" + bytes(20), code="format.other", line=1)
    emit("step_is_gzip", ".step", b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03" + bytes(20), code="format.other", line=1)
    emit("step_is_step_xml", ".step", b'<?xml version="1.0" encoding="UTF-8"?>\n<iso_10303_28 version="2.0"></iso_10303_28>\n', code="format.other", line=1)
    emit("step_is_html", ".step", b"<!DOCTYPE html>\n<html><body>404 Not Found</body></html>\n", code="format.other", line=1)
    # Truncation at several offsets inside DATA: the instance cut short is unterminated.
    data_at = c2.index(b"DATA;")
    for frac in (10, 35, 60, 85, 99):
        cut = data_at + (len(c2) - data_at) * frac // 100
        t = c2[:cut]
        # The error is at the first token after the last complete statement: the cut
        # instance (`#n = ...` without its `;`), or the cut `ENDSEC`.
        at = t.rindex(b";") + 1
        while t[at:at + 1].isspace():
            at += 1
        line, col = line_col(t, at)
        m = re.match(rb"#(\d+)", t[at:])
        extra = {"entity": f"#{int(m.group(1))}"} if m else {}
        emit(f"step_truncated_{frac}pct", ".step", t, code="step.syntax",
             line=line, column=col, **extra)
    t = c2[: c2.index(b"ENDSEC;", data_at)]
    emit("step_truncated_no_endsec", ".step", t, code="step.structure", line=t.count(b"\n") + 1, column=1)
    t = c2[: c2.index(b"DATA;")]
    emit("step_no_data_section", ".step", t, code="step.structure", line=t.count(b"\n") + 1, column=1)
    h = c2[: c2.index(b"HEADER;")] + c2[c2.index(b"DATA;"):]
    emit("step_no_header", ".step", h, code="step.structure", line=2, column=1)
    # NUL byte in the middle of a point
    d = sub_in(c2, 19, b"10.265", b"10.\x00265")
    line, col = line_col(d, d.index(b"\x00"))
    emit("step_nul_byte", ".step", d, code="step.syntax", line=line, column=col, entity="#19")

    # --- B-spline semantics (entity-level errors)
    ent("step_knot_mult_sum_mismatch", sub_in(c2, 17, b"(3,1,2,1,3)", b"(3,1,2,1,2)"), 17, "knot_count_mismatch")
    ent("step_mult_count_mismatch", sub_in(c2, 17, b"(3,1,2,1,3)", b"(3,1,2,4)"), 17, "knots")
    ent("step_knots_decreasing", sub_in(c2, 17, b"0.466963,1.070586", b"1.070586,0.466963"), 17, "knots.invalid")
    def at(name, data, needle, eid, code, delta=0):
        line, col = line_col(data, data.index(needle) + delta)
        emit(name, ".step", data, code=code, line=line, column=col, entity=f"#{eid}")

    at("step_knot_overflow", sub_in(c2, 17, b"-0.672195", b"1.E400"), b"1.E400", 17, "step.syntax")
    ent("step_zero_multiplicity", sub_in(c2, 17, b"(3,1,2,1,3)", b"(3,1,0,3,3)"), 17, "knots")
    ent("step_negative_multiplicity", sub_in(c2, 17, b"(3,1,2,1,3)", b"(3,1,-2,5,3)"), 17, "knots")
    ent("step_degree_zero", sub_in(c2, 17, b"('',2,", b"('',0,"), 17, "geometry")
    ent("step_degree_negative", sub_in(c2, 17, b"('',2,", b"('',-2,"), 17, "geometry")
    ent("step_degree_too_high", sub_in(c2, 17, b"('',2,", b"('',26,"), 17, "limit.degree")
    ent("step_degree_huge", sub_in(c2, 17, b"('',2,", b"('',2147483647,"), 17, "limit.degree")
    ent("step_degree_real", sub_in(c2, 17, b"('',2,", b"('',2.5,"), 17, "step.schema")
    ent("step_too_few_poles", sub_in(c2, 17, b"#18,#19,#20,", b""), 17, "knot_count_mismatch")
    ent("step_weight_zero", sub_in(rat, 17, b"RATIONAL_B_SPLINE_CURVE((3.,", b"RATIONAL_B_SPLINE_CURVE((0.,"), 17, "weights")
    ent("step_weight_negative", sub_in(rat, 17, b"RATIONAL_B_SPLINE_CURVE((3.,", b"RATIONAL_B_SPLINE_CURVE((-3.,"), 17, "weights")
    at("step_weight_overflow", sub_in(rat, 17, b"RATIONAL_B_SPLINE_CURVE((3.,", b"RATIONAL_B_SPLINE_CURVE((1.E400,"), b"1.E400", 17, "step.syntax")
    ent("step_weight_count", sub_in(rat, 17, b"RATIONAL_B_SPLINE_CURVE((3.,", b"RATIONAL_B_SPLINE_CURVE(("), 17, "weights")
    ent("step_weight_string", sub_in(rat, 17, b"RATIONAL_B_SPLINE_CURVE((3.,", b"RATIONAL_B_SPLINE_CURVE(('w',"), 17, "step.schema")
    at("step_point_overflow", sub_in(c2, 19, b"10.265009748379", b"1.E400"), b"1.E400", 19, "step.syntax")
    ent("step_point_2d", sub_in(c2, 19, b",0.301182608529\n    )", b")"), 17, "points")
    # Wrong entity type behind a reference: reported on the B-spline that cannot load.
    ent("step_pole_is_direction", sub_in(c2, 17, b"#18,#19", b"#13,#19"), 17, "step.reference")
    ent("step_pole_dangling", sub_in(c2, 17, b"#18,#19", b"#9999,#19"), 17, "step.reference")
    ent("step_pole_self_reference", sub_in(c2, 17, b"#18,#19", b"#17,#19"), 17, "step.reference_cycle")
    at("step_pole_oversized_id", sub_in(c2, 17, b"#18,#19", b"#99999999999999999999999,#19"), b"#999", 17, "step.syntax")
    ent("step_pole_is_unset", sub_in(c2, 17, b"#18,#19", b"$,#19"), 17, "step.schema")
    ent("step_knots_not_a_list", sub_in(c2, 17, b"(3,1,2,1,3)", b"3"), 17, "step.schema")
    ent("step_missing_attribute", sub_in(c2, 17, b".UNSPECIFIED.,.F.,.F.,", b".UNSPECIFIED.,.F.,"), 17, "step.schema")
    ent("step_bad_enum", sub_in(c2, 17, b".F.,.F.,(3", b".MAYBE.,.F.,(3"), 17, "step.schema")
    # surface: row lengths disagree
    ent("step_surface_ragged_grid", sub_in(srf, 32, b",(#39,#40,#41)", b",(#39,#40)"), 32, "points")
    ent("step_surface_u_knots_wrong", sub_in(srf, 32, b"(4,4),(3,3)", b"(4,3),(3,3)"), 32, "knot_count_mismatch")
    # circular reference: a point that is its own poles... make #18 a complex of refs
    d = sub_in(c2, 18, b"CARTESIAN_POINT('',(0.43132997103,-1.850600446128,1.174976336145)\n  )",
               b"CARTESIAN_POINT('',(#25,0.,0.))")
    d = sub_in(d, 25, b"CARTESIAN_POINT('',(0.43132997103,-1.850600446128,1.174976336145)\n  )",
               b"CARTESIAN_POINT('',(#18,0.,0.))")
    # The cycle is reported on the B-spline whose control point enters it.
    ent("step_circular_reference", d, 17, "step.reference_cycle")

    # A reference cycle through 5000 instances (found iteratively, reported shortened).
    chain = "".join(f"#{i} = CARTESIAN_POINT('',(#{i + 1},0.,0.));\n" for i in range(100000, 105000))
    chain += "#105000 = CARTESIAN_POINT('',(#18,0.,0.));\n"
    d = sub_in(c2, 18, b"CARTESIAN_POINT('',(0.43132997103,-1.850600446128,1.174976336145)\n  )",
               b"CARTESIAN_POINT('',(#100000,0.,0.))")
    d = d.replace(b"ENDSEC;\nEND-ISO", chain.encode() + b"ENDSEC;\nEND-ISO")
    ent("step_long_reference_cycle", d, 17, "step.reference_cycle")

    # --- syntax
    d = c2.replace(b"#17 = B_SPLINE_CURVE_WITH_KNOTS(", b"#17 = b_spline_curve_with_knots(")
    line, col = inst_loc(d, 17)
    # ISO 10303-21 clause 6.4: keywords are upper case; reported at the keyword (validate:
    # error; convert reads it upper-cased, with a warning).
    emit("step_lowercase_keyword", ".step", d, code="step.syntax.lowercase_keyword", line=line, column=col + 6, entity="#17")
    # A lower-case typed parameter (LENGTH_MEASURE) inside an upper-case instance.
    d = sub_in(c2, 31, b"LENGTH_MEASURE(1.E-07)", b"length_measure(1.E-07)")
    at("step_lowercase_typed_parameter", d, b"length_measure", 31, "step.syntax.lowercase_keyword")
    # A lower-case header keyword.
    d = c2.replace(b"FILE_SCHEMA((", b"File_Schema((", 1)
    line, col = line_col(d, d.index(b"File_Schema"))
    emit("step_lowercase_header_keyword", ".step", d, code="step.syntax.lowercase_keyword", line=line, column=col)
    nest = b"(" * 100000 + b")" * 100000
    d = sub_in(c2, 19, b"(10.265009748379", nest + b",(10.265009748379")
    line, col = inst_loc(d, 19)
    # `CARTESIAN_POINT(` is depth 1, nest[0] depth 2: nest[63] opens the 65th level.
    line, col = line_col(d, d.index(nest) + 63)
    emit("step_nested_parens_100k", ".step", d, code="limit.nesting_depth", line=line, column=col, entity="#19")
    d = c2.replace(b"#19 = CARTESIAN", b"#99999999999999999999 = CARTESIAN")
    line, col = inst_loc(d, 99999999999999999999) if False else line_col(d, d.index(b"#99999999999999999999 ="))
    emit("step_oversized_instance_id", ".step", d, code="step.syntax", line=line, column=col)
    d = c2.replace(b"#19 = CARTESIAN", b"#20 = CARTESIAN")
    # The second definition is the error; the first one wins.
    line, col = line_col(d, d.rindex(b"#20 = CARTESIAN"))
    emit("step_duplicate_id", ".step", d, code="step.structure", line=line, column=col, entity="#20")
    d = c2[: c2.index(b"'Open CASCADE STEP translator 7.6 3',") + 10]
    line, col = line_col(d, d.index(b"'Open CASC", d.index(b"#7 =")))
    emit("step_unterminated_string", ".step", d, code="step.syntax", line=line, column=col, entity="#7")
    d = sub_in(c2, 19, b"10.265009748379", b"10.26.5")
    line, col = line_col(d, d.index(b"10.26.5"))
    emit("step_bad_real", ".step", d, code="step.syntax", line=line, column=col, entity="#19")
    d = sub_in(c2, 19, b"(10.265009748379", b"(10.265009748379))")
    at("step_unbalanced_parens", d, b",-7.308443936789", 19, "step.syntax")
    d = c2.replace(b"#19 = CARTESIAN_POINT('',(", b"#19 = CARTESIAN_POINT('',(/* open comment ")
    d = d[: d.index(b"ENDSEC;", d.index(b"DATA;"))]
    at("step_unterminated_comment", d, b"/* open", 19, "step.syntax")
    d = sub_in(c2, 20, b"20.47863277037", b"\"0F\"")
    ent("step_binary_where_real", d, 17, "step.reference")

    # --- issue 21: what used to pass in silence
    # An empty instance is a syntax error (ISO 10303-21 clause 10), at its `;`.
    m = re.search(rb"(?ms)^#17 =.*?;", c2)
    d = c2[:m.start()] + b"#17 = ;" + c2[m.end():]
    at("step_empty_instance", d, b"#17 = ;", 17, "step.syntax", delta=6)
    m = re.search(rb"(?ms)^#13 =.*?;", c2)
    d = c2[:m.start()] + b"#13 = ;" + c2[m.end():]
    at("step_empty_instance_not_geometry", d, b"#13 = ;", 13, "step.syntax", delta=6)
    # ISO 10303-42 constraints_param_b_spline: distinct knots strictly increasing,
    # multiplicities bounded.
    ent("step_knot_repeated", sub_in(c2, 17, b"(3,1,2,1,3),(-1.25,-0.672195,0.466963,1.070586",
                                     b"(3,1,1,1,1,3),(-1.25,-0.672195,0.466963,0.466963,1.070586"), 17, "knots.repeated")
    # 0.466963 twice, multiplicities 2 and 1: one knot of multiplicity 3 > degree 2.
    ent("step_knot_repeated_over_degree", sub_in(c2, 17, b"(3,1,2,1,3),(-1.25,-0.672195,0.466963,1.070586",
                                                 b"(3,1,2,1,3),(-1.25,-0.672195,0.466963,0.466963"), 17, "knots.invalid")
    ent("step_interior_multiplicity", sub_in(c2, 17, b"(3,1,2,1,3),(-1.25,-0.672195,0.466963,1.070586,",
                                             b"(3,1,3,3),(-1.25,-0.672195,0.466963,"), 17, "knots.invalid")
    ent("step_end_multiplicity", sub_in(c2, 17, b"(3,1,2,1,3),(-1.25,-0.672195,0.466963,1.070586,",
                                        b"(4,2,1,3),(-1.25,0.466963,1.070586,"), 17, "knots.invalid")
    ent("step_knots_equal_all", sub_in(c2, 17, b"(-1.25,-0.672195,0.466963,1.070586,\n    2.325594)",
                                       b"(-1.25,-1.25,-1.25,-1.25,-1.25)"), 17, "knots")
    ent("step_surface_v_knot_repeated", sub_in(srf, 32, b"(4,4),(3,3),(0.,1.),(0.,1.)", b"(4,4),(3,3),(0.,1.),(0.,0.)"), 32, "knots")
    # Enumeration values outside their EXPRESS type.
    ent("step_knot_spec_unknown", sub_in(c2, 17, b"2.325594),.UNSPECIFIED.", b"2.325594),.FOO_KNOTS."), 17, "step.enumeration")
    ent("step_curve_form_unknown", sub_in(c2, 17, b".UNSPECIFIED.,.F.,.F.", b".SPIRAL_FORM.,.F.,.F."), 17, "step.enumeration")
    ent("step_surface_form_unknown", sub_in(srf, 32, b".UNSPECIFIED.,.F.,.F.,.F.", b".BLOB_SURF.,.F.,.F.,.F."), 32, "step.enumeration")
    ent("step_closed_not_logical", sub_in(c2, 17, b".UNSPECIFIED.,.F.,.F.", b".UNSPECIFIED.,.X.,.F."), 17, "step.schema")
    ent("step_self_intersect_not_logical", sub_in(c2, 17, b".UNSPECIFIED.,.F.,.F.", b".UNSPECIFIED.,.F.,5"), 17, "step.schema")
    # Rational weights (ISO 10303-42 RATIONAL_B_SPLINE_CURVE WR2: weights > 0).
    ent("step_weight_zero_last", sub_in(rat, 17, b"1.,3.))", b"1.,0.))"), 17, "weights")
    # References anywhere in the file, through instances nurbsx does not convert.
    ent("step_dangling_product", sub_in(c2, 4, b"'','',#5)", b"'','',#9999)"), 4, "step.reference")
    ent("step_dangling_context", sub_in(c2, 8, b"#2,'mechanical'", b"#777,'mechanical'"), 8, "step.reference")
    ent("step_dangling_unit", sub_in(c2, 31, b"LENGTH_MEASURE(1.E-07),#28", b"LENGTH_MEASURE(1.E-07),#2800"), 31, "step.reference")
    # A cycle #5 -> #6 -> #5: the depth-first search from the first instance enters it at
    # #5 and meets the back edge in #6, the mutated instance.
    ent("step_cycle_products", sub_in(c2, 6, b"'','',#7)", b"'','',#5)"), 6, "step.reference_cycle")
    ent("step_cycle_self_context", sub_in(c2, 8, b"#2,'mechanical'", b"#8,'mechanical'"), 8, "step.reference_cycle")
    # Attribute counts of entities the schema tables know (DIRECTION: name, ratios).
    ent("step_direction_extra_attribute", sub_in(c2, 13, b"(0.,0.,1.))", b"(0.,0.,1.),5.)"), 13, "step.schema")
    ent("step_point_missing_attribute", sub_in(c2, 12, b"CARTESIAN_POINT('',(0.,0.,0.))", b"CARTESIAN_POINT((0.,0.,0.))"), 12, "step.schema")
    # References to an instance of a type the attribute does not allow (ISO 10303-21
    # clause 11; the attribute types of ISO 10303-41/-42/-43, subtypes admitted), through
    # the topology, geometry and product structure of a FreeCAD part and assembly. Each is
    # reported on the instance holding the reference.
    bx = read("parts/sphere_cap.step")
    # #15 MANIFOLD_SOLID_BREP -> #16 CLOSED_SHELL -> #17 ADVANCED_FACE (#18 FACE_BOUND,
    # #33 SPHERICAL_SURFACE); #18 -> #19 EDGE_LOOP -> #20 ORIENTED_EDGE -> #21 EDGE_CURVE
    # (#22, #24 VERTEX_POINT, #26 SEAM_CURVE (#27 CIRCLE; #32, #44 PCURVE)); #32 PCURVE
    # (#33, #38 DEFINITIONAL_REPRESENTATION of #39 LINE); #34 AXIS2_PLACEMENT_3D (#35
    # point, #36/#37 directions).
    for name, eid, old, new in (
        ("face_bound_to_vertex", 18, b"('',#19,", b"('',#22,"),
        ("edge_loop_to_edge_curve", 19, b"(#20,", b"(#21,"),
        ("oriented_edge_to_vertex", 20, b"*,#21,", b"*,#22,"),
        ("edge_start_to_point", 21, b"('',#22,", b"('',#23,"),
        ("edge_geometry_to_point", 21, b",#26,", b",#23,"),
        ("vertex_geometry_to_direction", 22, b"#23)", b"#13)"),
        ("face_geometry_to_curve", 17, b",#33,", b",#27,"),
        ("face_bounds_to_loop", 17, b"(#18)", b"(#19)"),
        ("shell_face_to_loop", 16, b"(#17,", b"(#19,"),
        ("solid_outer_to_face", 15, b"#16)", b"#17)"),
        ("seam_curve_3d_to_surface", 26, b"('',#27,", b"('',#33,"),
        ("seam_curve_associated_to_line", 26, b"(#32,#44)", b"(#32,#27)"),
        ("pcurve_basis_to_curve", 32, b"('',#33,", b"('',#27,"),
        ("pcurve_reference_to_line", 32, b",#38)", b",#39)"),
        ("sphere_position_to_point", 33, b"('',#34,", b"('',#35,"),
        ("circle_position_to_direction", 27, b"('',#28,", b"('',#30,"),
        ("axis_to_point", 34, b",#36,", b",#35,"),
        ("line_dir_to_direction", 39, b",#41)", b",#42)"),
        ("representation_context_to_point", 10, b",#83)", b",#12)"),
        ("representation_item_product", 10, b"(#11,#15)", b"(#11,#7)"),
        ("product_definition_formation", 5, b",#6,", b",#7,"),
        ("formation_of_product", 6, b"#7)", b"#5)"),
        ("used_representation_product", 3, b"(#4,#10)", b"(#4,#5)"),
    ):
        ent(f"step_ref_{name}", sub_in(bx, eid, old, new), eid, "step.reference.type")
    # Units and the representation context (ISO 10303-41 `unit` = SELECT (named_unit,
    # derived_unit); ISO 10303-43 global_unit/uncertainty contexts), through the complex
    # context instance #27 and the uncertainty #31 of curve_deg2_clamped.step.
    for name, eid, old, new in (
        ("context_unit_is_point", 27, b"(#28,#29,#30)", b"(#28,#29,#26)"),
        ("context_uncertainty_is_unit", 27, b"((#31))", b"((#30))"),
        ("uncertainty_unit_is_point", 31, b"1.E-07),#28,", b"1.E-07),#26,"),
    ):
        ent(f"step_ref_{name}", sub_in(c2, eid, old, new), eid, "step.reference.type")
    asm = read("parts/assembly_links.step")
    # #464 NEXT_ASSEMBLY_USAGE_OCCURRENCE(#5, #35 PRODUCT_DEFINITION); #461 complex
    # SHAPE_REPRESENTATION_RELATIONSHIP(#40, #10 representations; #462 transformation);
    # #460 CONTEXT_DEPENDENT_SHAPE_REPRESENTATION(#461, #463 PRODUCT_DEFINITION_SHAPE).
    for name, eid, old, new in (
        ("nauo_related_formation", 464, b"#5,#35,$", b"#5,#36,$"),
        ("relationship_rep_product", 461, b"('','',#40,#10)", b"('','',#40,#5)"),
        ("relationship_transformation", 461, b"WITH_TRANSFORMATION(#462)", b"WITH_TRANSFORMATION(#463)"),
        ("cdsr_relation", 460, b"(#461,#463)", b"(#462,#463)"),
        ("cdsr_product_relation", 460, b"(#461,#463)", b"(#461,#464)"),
        ("transformation_item", 462, b"('','',#11,", b"('','',#10,"),
    ):
        ent(f"step_ref_{name}", sub_in(asm, eid, old, new), eid, "step.reference.type")
    # The header's three entities (ISO 10303-21 clause 8.2), reported at HEADER.
    hl, hc = line_col(c2, c2.index(b"HEADER;"))
    d = re.sub(rb"(?s)FILE_NAME\(.*?\);\n", b"", c2, count=1)
    emit("step_header_no_file_name", ".step", d, code="step.header", line=hl, column=hc)
    d = c2.replace(b"FILE_DESCRIPTION(('FreeCAD Model'),'2;1');", b"FILE_DESCRIPTION(('FreeCAD Model'));", 1)
    emit("step_header_description_short", ".step", d, code="step.header", line=hl, column=hc)
    # Legacy-encoded (GBK) bytes in a name: read, but not ISO 10303-21 (clause 5: strings
    # carry other characters only through \X\ escapes); at the first such byte.
    d = sub_in(c2, 7, b"PRODUCT('Open", b"PRODUCT('\xd2\xc6\xb6\xaf Open")
    line, col = line_col(d, d.index(b"\xd2\xc6"))
    emit("step_gbk_name", ".step", d, code="encoding.not_utf8", line=line, column=col)



# ---------------------------------------------------------------- IGES
def records(data):
    return data.decode("latin-1").splitlines()


def join(recs):
    return ("\n".join(recs) + "\n").encode("latin-1")


def add_entity(recs, etype, form, params):
    """Append an entity (IGES 5.3 sections 2.2.4.4, 2.2.4.5): its two DE records after the
    last D record, its P records (`params`, cut at commas into 64-column lines) after the
    last P record, and the Terminate counts updated. Returns its DE sequence number."""
    count = lambda s: sum(1 for r in recs if r[72:73] == s)
    de, pstart = count("D") + 1, count("P") + 1
    lines, text = [], params
    while text:
        cut = len(text) if len(text) <= 64 else text.rindex(",", 0, 64) + 1
        lines.append(text[:cut])
        text = text[cut:]
    d1 = f"{etype:>8}{pstart:>8}" + f"{0:>8}" * 6 + f"{'00000000':>8}D{de:07d}"
    d2 = f"{etype:>8}{0:>8}{0:>8}{len(lines):>8}{form:>8}" + " " * 24 + f"{0:>8}D{de + 1:07d}"
    plines = [f"{l:<64} {de:07d}P{pstart + i:07d}" for i, l in enumerate(lines)]
    last_d = max(i for i, r in enumerate(recs) if r[72:73] == "D")
    recs[last_d + 1:last_d + 1] = [d1, d2]
    last_p = max(i for i, r in enumerate(recs) if r[72:73] == "P")
    recs[last_p + 1:last_p + 1] = plines
    t = next(i for i, r in enumerate(recs) if r[72:73] == "T")
    recs[t] = f"S{count('S'):7d}G{count('G'):7d}D{count('D'):7d}P{count('P'):7d}".ljust(72) + "T0000001"
    return de


def setp(recs, idx, text):
    """Replace columns 1-64 of a P record (keeping the DE back pointer and sequence)."""
    r = recs[idx]
    recs[idx] = f"{text:<64}" + r[64:]


def pidx(recs, n):
    """Index of P record with sequence number n."""
    for i, r in enumerate(recs):
        if r[72:73] == "P" and int(r[73:80]) == n:
            return i
    raise KeyError(n)


def didx(recs, n):
    for i, r in enumerate(recs):
        if r[72:73] == "D" and int(r[73:80]) == n:
            return i
    raise KeyError(n)


def setfield(recs, i, field, value):
    """Set 8-column field `field` (1-based) of record i."""
    r = recs[i]
    a = (field - 1) * 8
    recs[i] = r[:a] + f"{value:>8}"[:8] + r[a + 8:]


def param_seq(recs, de, index):
    """P sequence number of the line holding parameter `index` (the entity type is 0) of
    the entity at DE `de`, counted from the joined data columns 1-64 (no Hollerith strings
    in the records this is used on)."""
    lines = [r for r in recs if r[72:73] == "P" and int(r[64:72]) == de]
    data = "".join(r[:64] for r in lines)
    pos, k = 0, 0
    while k < index:
        pos = data.index(",", pos) + 1
        k += 1
    while data[pos] == " ":
        pos += 1
    return int(lines[pos // 64][73:80])


def iges_cases():
    c2 = read("curve_deg2_clamped.igs")  # one 126 at D1, P1..P8
    base = records(c2)
    p1 = base[pidx(base, 1)][:64].rstrip()   # "126,6,2,0,0,1,0,-1.25,-1.25,-1.25,-0.672195,0.466963,0.466963,"

    def ent(name, recs, seq, code, section="P", de=1):
        emit(name, ".igs", join(recs), code=code, section=section, sequence=seq, entity=f"D{de}")

    def p1_with(new):
        recs = list(base)
        setp(recs, pidx(recs, 1), new)
        return recs

    # 128 surface (surf_poles4x3.igs: the 128 is D3, its data starts on P2) with hostile
    # K1/K2/M1: refused from the header, before any allocation.
    srf = records(read("surf_poles4x3.igs"))
    for name, new in (("k1k2_overflow", "128,2147483647,2147483647,3,2,"),
                      ("k2_negative", "128,3,-2,3,2,"),
                      ("m1_huge", "128,3,2,2147483647,2,")):
        recs = list(srf)
        i = pidx(recs, 2)
        assert recs[i].startswith("128,3,2,3,2,")
        setp(recs, i, (new + recs[i][len("128,3,2,3,2,"):64]).rstrip()[:64])
        emit(f"iges_surface_{name}", ".igs", join(recs), code="iges.entity", section="P", sequence=2, entity="D3")

    emit("iges_empty", ".igs", b"", code="format.empty", line=1)
    emit("iges_binary_garbage", ".igs", bytes((i * 197 + 3) % 256 for i in range(8192)), code="format.binary", line=1)
    emit("iges_utf16", ".igs", c2.decode("latin-1").encode("utf-16"), code="encoding.utf16", line=1)
    # IGES 5.3 section 2.1: 80-column records, section letter in column 73; the compressed
    # form (C, appendix B) is not read.
    emit("iges_79_columns", ".igs", b"".join(l[:71] + l[72:] for l in c2.splitlines(keepends=True)), code="format.mismatch", line=1)
    emit("iges_compressed_form", ".igs", c2.replace(b"S0000001", b"C0000001", 1), code="format.mismatch", line=1)
    emit("iges_nul_bytes", ".igs", c2.replace(b"1.070586,2.325594", b"1.070586\x00\x00325594"), code="iges", section="P", sequence=2, entity="D1")
    # truncations: whole records cut off and a record cut in half
    for keep in (3, 6, 9, 14):
        t = join(base[:keep])
        # The error names the first section that is missing entirely.
        present = {r[72:73] for r in base[:keep]}
        missing = next(s for s in "GDPT" if s not in present)
        emit(f"iges_truncated_{keep}_records", ".igs", t, code="iges.syntax", section=missing)
    t = join(base)[: len(join(base[:9])) + 30]
    # The cut record has no columns 73-80: its section is inferred, its number unknown.
    emit("iges_truncated_mid_record", ".igs", t, code="iges.syntax", line=10, column=73, section="P")
    # missing sections
    emit("iges_missing_global", ".igs", join([r for r in base if r[72:73] != "G"]), code="iges.syntax", section="G")
    emit("iges_missing_directory", ".igs", join([r for r in base if r[72:73] != "D"]), code="iges.syntax", section="D")
    emit("iges_missing_terminate", ".igs", join([r for r in base if r[72:73] != "T"]), code="iges.syntax", section="T")
    # B-spline semantics: K=6, M=2 in P1
    # K/M inconsistent with the data: the values shift, the knot vector read is invalid;
    # geometric errors are located at the entity's directory entry.
    # (K or M one off: see the issue 21 cases below, iges_k_raised ... iges_m_lowered.)
    # A huge K is refused before any allocation: the record ends (P8) long before the
    # 10^10 values it declares.
    ent("iges_k_huge", p1_with(p1.replace("126,6,2,0,0,1,0,-1.25,-1.25,", "126,2147483647,2,0,0,1,0,", 1)), 8, "iges.entity")
    ent("iges_k_negative", p1_with(p1.replace("126,6,2,", "126,-3,2,", 1)), 1, "iges")
    ent("iges_m_too_high", p1_with(p1.replace("126,6,2,", "126,6,26,", 1)), 1, "iges.entity")
    ent("iges_m_zero", p1_with(p1.replace("126,6,2,", "126,6,0,", 1)), 1, "iges")
    ent("iges_k_real", p1_with(p1.replace("126,6,2,", "126,6.5,2,", 1)), 1, "iges")
    ent("iges_knots_decreasing", p1_with(p1.replace("-0.672195,0.466963", "0.466963,-0.672195", 1)), 1, "geometry", section="D")
    ent("iges_knot_overflow", p1_with(p1.replace("-0.672195", "1.D400", 1)), 1, "iges")
    # Weights of a rational curve (PROP3 = 0): curve_deg2_rational_clamped.igs
    rat = records(read("curve_deg2_rational_clamped.igs"))
    for name, w in (("zero", "0."), ("negative", "-0.5")):
        recs = list(rat)
        i = pidx(recs, 2)
        text = recs[i][:64]
        # P2 holds the last 4 of the 10 knots, then the first weights
        vals = text.rstrip().rstrip(",").split(",")
        vals[4] = w
        setp(recs, i, ",".join(vals) + ",")
        ent(f"iges_weight_{name}", recs, 1, "geometry", section="D")
    recs = list(base)
    setp(recs, pidx(recs, 2), "1.070586,2.325594,2.325594,2.325594,1.,1.E400,1.,1.,1.,1.,1.,")
    ent("iges_weight_overflow", recs, 2, "iges")
    recs = list(base)
    setp(recs, pidx(recs, 2), "1.070586,2.325594,2.325594,2.325594,1.,NaN,1.,1.,1.,1.,1.,")
    ent("iges_weight_nan", recs, 2, "iges")
    recs = list(base)
    setp(recs, pidx(recs, 3), "1HX,-1.850600446,1.174976336,10.265009748,-7.308443937,")
    ent("iges_string_where_real", recs, 3, "iges")
    recs = list(base)
    setp(recs, pidx(recs, 3), "9HX,-1.850600446,1.174976336,10.265009748,-7.308443937,")
    ent("iges_hollerith_too_long", recs, 3, "iges")
    # Hollerith in the Global section with a wrong length (31H... -> 45H...)
    recs = list(base)
    recs[1] = recs[1].replace("31HOpen", "45HOpen", 1)
    emit("iges_global_hollerith_length", ".igs", join(recs), code="iges.syntax", section="G", sequence=1)
    recs = list(base)
    recs[1] = recs[1].replace("31HOpen", "0HOpen", 1)
    emit("iges_global_hollerith_zero", ".igs", join(recs), code="iges.syntax", section="G", sequence=1)
    # bad DE and parameter pointers
    recs = list(base)
    setfield(recs, didx(recs, 1), 2, 99)
    ent("iges_de_param_pointer_past_end", recs, 1, "iges", section="D")
    recs = list(base)
    setfield(recs, didx(recs, 1), 2, 0)
    ent("iges_de_param_pointer_zero", recs, 1, "iges", section="D")
    recs = list(base)
    setfield(recs, didx(recs, 1), 2, -5)
    ent("iges_de_param_pointer_negative", recs, 1, "iges", section="D")
    recs = list(base)
    setfield(recs, didx(recs, 1), 2, "abc")
    ent("iges_de_pointer_not_a_number", recs, 1, "iges", section="D")
    recs = list(base)
    r = recs[pidx(recs, 4)]
    recs[pidx(recs, 4)] = r[:65] + "      9" + r[72:]
    ent("iges_p_back_pointer_wrong", recs, 4, "iges.entity")
    recs = list(base)
    recs[didx(recs, 1)] = recs[didx(recs, 1)][:72] + "X0000001"
    emit("iges_bad_section_letter", ".igs", join(recs), code="iges.syntax", section="X", sequence=1)
    recs = list(base)
    recs[didx(recs, 1)] = recs[didx(recs, 1)][:60]
    emit("iges_short_record", ".igs", join(recs), code="iges.syntax", line=6, column=73)
    # --- issue 21: counts against the parameter count (IGES 5.3 section 4.23 and 2.2.4.5.2)
    # K raised by one: the 43 values after PROP4 read as a complete K = 7 curve without its
    # V(0), V(1) and normal, and as the complete K = 6 one: refused at the entity.
    ent("iges_k_raised", p1_with(p1.replace("126,6,2,", "126,7,2,", 1)), 1, "iges.entity", section="D")
    # K lowered: parameter 45 would be the associativity count; it holds a real.
    ent("iges_k_lowered", p1_with(p1.replace("126,6,2,", "126,5,2,", 1)), param_seq(base, 1, 45), "iges.entity")
    # M raised: the record ends inside the normal (parameter 48 starts it).
    ent("iges_m_raised", p1_with(p1.replace("126,6,2,", "126,6,3,", 1)), param_seq(base, 1, 48), "iges.entity")
    # M lowered: parameter 49 would be the associativity count.
    ent("iges_m_lowered", p1_with(p1.replace("126,6,2,", "126,6,1,", 1)), param_seq(base, 1, 49), "iges.entity")
    # K and M both lowered by one: six parameters too many.
    ent("iges_k_m_lowered", p1_with(p1.replace("126,6,2,", "126,5,1,", 1)), param_seq(base, 1, 44), "iges.entity")
    # Trailing associativity/property groups: a valid pair of empty groups is read; a
    # count larger than the pointers that follow is not.
    recs = list(base)
    i = pidx(recs, 8)
    setp(recs, i, "0.986200164,0.164130733,2,1;")
    ent("iges_assoc_count_too_big", recs, 8, "iges.entity")
    recs = list(base)
    setp(recs, i, "0.986200164,0.164130733,0,0,7.5;")
    ent("iges_after_property_group", recs, 8, "iges.entity")
    # 128 (surf_poles4x3.igs, D3 from P2, K1 = M1 = 3, K2 = M2 = 2): M1 raised or K1
    # lowered breaks M1 <= K1, an error at the record's first line; M1 or M2 lowered leaves
    # parameter 75 where the associativity count would be.
    for name, new, seq in (("m1_raised", "128,3,2,4,2,", 2),
                           ("m1_lowered", "128,3,2,2,2,", param_seq(srf, 3, 75)),
                           ("m2_lowered", "128,3,2,3,1,", param_seq(srf, 3, 75)),
                           ("k1_lowered", "128,2,2,3,2,", 2)):
        recs = list(srf)
        i = pidx(recs, 2)
        setp(recs, i, (new + recs[i][len("128,3,2,3,2,"):64]).rstrip()[:64])
        emit(f"iges_surface_{name}", ".igs", join(recs), code="iges.entity", section="P", sequence=seq, entity="D3")
    # --- pointers of every entity (surf_poles4x3.igs: 144 D1 -> 128 D3, 142 D5; 142 D5 ->
    # 128 D3, 102 D7, 102 D17; 102 D7 -> 110 D9..D15)
    def sp(name, seq, text, code, de):
        recs = list(srf)
        setp(recs, pidx(recs, seq), text)
        emit(name, ".igs", join(recs), code=code, section="D", sequence=de, entity=f"D{de}")
    sp("iges_pointer_missing_de", 1, "144,3,1,0,99;", "pointer.invalid", 1)
    sp("iges_pointer_even_de", 1, "144,4,1,0,5;", "pointer.invalid", 1)
    sp("iges_pointer_wrong_type", 1, "144,9,1,0,5;", "pointer.invalid", 1)
    sp("iges_pointer_negative_past_end", 6, "142,0,3,7,-999,3;", "pointer.invalid", 5)
    sp("iges_pointer_cycle_self", 7, "102,4,7,11,13,15;", "pointer.cycle", 7)
    # 102 D7 -> 102 D17 -> 102 D7: the search from D1 (through the 142 D5) enters at D7 and
    # meets the back edge in D17.
    recs = list(srf)
    setp(recs, pidx(recs, 7), "102,4,17,11,13,15;")
    setp(recs, pidx(recs, 12), "102,4,7,21,23,25;")
    emit("iges_pointer_cycle_two", ".igs", join(recs), code="pointer.cycle", section="D", sequence=17, entity="D17")
    sp("iges_pointer_assoc_missing", 8, "110,0.,1.,0.,0.,0.,0.,1,77;", "pointer.invalid", 9)
    sp("iges_pointer_property_even", 8, "110,0.,1.,0.,0.,0.,0.,0,1,4;", "pointer.invalid", 9)
    # DE pointer fields: transformation matrix (field 7) to a 128, and past the end.
    for name, value in (("iges_de_transform_wrong_type", 3), ("iges_de_transform_missing", 61)):
        recs = list(srf)
        setfield(recs, didx(recs, 9), 7, value)
        emit(name, ".igs", join(recs), code="pointer.invalid", section="D", sequence=9, entity="D9")
    # --- 402 Associativity Instance and 406 Property pointers (IGES 5.3 type 402 forms 1,
    # 7, 9, 12-16, 18-21; type 406 forms 1 and 15, with the trailing pointer groups of
    # section 2.2.4.5.2), appended to surf_poles4x3.igs (D1 144, D3 128, D5 142, D7 102,
    # D9..D15 110): each reported on the 402/406's directory entry.
    def appended(name, etype, form, params, code, section, sequence):
        """`params` appended to surf_poles4x3.igs as D27 (P21), its error expected at
        `section` `sequence`."""
        recs = list(srf)
        de = add_entity(recs, etype, form, params)
        assert de == 27
        emit(name, ".igs", join(recs), code=code, section=section, sequence=sequence, entity=f"D{de}")

    def assoc(name, etype, form, params, code):
        appended(name, etype, form, params.replace("SELF", str(2 * 13 + 1)), code, "D", 27)
    assoc("iges_402_group_missing_member", 402, 7, "402,2,1,99;", "pointer.invalid")
    assoc("iges_402_group_even_member", 402, 1, "402,2,1,4;", "pointer.invalid")
    assoc("iges_402_ordered_group_cycle", 402, 14, "402,2,3,SELF;", "pointer.cycle")
    assoc("iges_402_single_parent_missing_child", 402, 9, "402,1,2,1,3,77;", "pointer.invalid")
    assoc("iges_402_external_index_missing", 402, 12, "402,1,3HABC,55;", "pointer.invalid")
    assoc("iges_402_dimensioned_geometry_even", 402, 13, "402,1,1,2,3;", "pointer.invalid")
    assoc("iges_402_planar_transform_not_124", 402, 16, "402,1,1,3,1;", "pointer.invalid")
    assoc("iges_402_flow_connect_not_132", 402, 18, "402,2,0,1,0,0,0,0,0,0,1;", "pointer.invalid")
    assoc("iges_402_segmented_view_not_410", 402, 19, "402,1,1,0.5,0,0,0,0;", "pointer.invalid")
    assoc("iges_402_piping_flow_missing", 402, 20, "402,1,1,0,0,0,0,0,0,91;", "pointer.invalid")
    assoc("iges_402_new_dimensioned_geometry_missing", 402, 21, "402,1,1,0,0,0.,99,0.,0.,0.;", "pointer.invalid")
    assoc("iges_406_name_property_pointer_missing", 406, 15, "406,1,4HNAME,0,1,99;", "pointer.invalid")
    # Forms 3-5 (views visible, with attributes, label display) and the negated color and
    # line font pointers of forms 4 and 19 (IGES 5.3 section 2.2.4.4.4, .13): D3 is a 128.
    assoc("iges_402_views_visible_view_not_410", 402, 3, "402,1,1,3,13;", "pointer.invalid")
    assoc("iges_402_views_visible_color_not_314", 402, 4, "402,1,1,0,1,0,-3,1,15;", "pointer.invalid")
    assoc("iges_402_views_visible_font_definition_not_304", 402, 4, "402,1,1,0,0,3,0,1,15;", "pointer.invalid")
    assoc("iges_402_label_display_leader_not_214", 402, 5, "402,1,0,0.,0.,0.,3,0,19;", "pointer.invalid")
    assoc("iges_402_label_display_entity_missing", 402, 5, "402,1,0,0.,0.,0.,0,0,97;", "pointer.invalid")
    assoc("iges_402_segmented_view_font_missing", 402, 19, "402,1,0,0.5,0,0,-99,0;", "pointer.invalid")
    assoc("iges_402_segmented_view_color_not_314", 402, 19, "402,1,0,0.5,0,-3,0,0;", "pointer.invalid")
    # Annotation, drawing and property declarations (D3 is a 128, D9 a 110).
    assoc("iges_212_font_not_310", 212, 0, "212,1,5,10.,2.,-3,1.5707963267948966,0.,0,0,0.,0.,0.,5HHELLO;", "pointer.invalid")
    assoc("iges_216_note_not_212", 216, 0, "216,9,0,0,0,0;", "pointer.invalid")
    assoc("iges_404_view_not_410", 404, 0, "404,1,3,0.,0.,0;", "pointer.invalid")
    assoc("iges_410_clipping_plane_not_108", 410, 0, "410,1,1.,3,0,0,0,0,0;", "pointer.invalid")
    assoc("iges_304_template_not_308", 304, 1, "304,0,3,1.,1.;", "pointer.invalid")
    # Records shorter than their declaration: the error is at their P line.
    for name, etype, form, params in (
        ("iges_406_drawing_size_short", 406, 16, "406,2,841.;"),
        ("iges_214_segments_short", 214, 1, "214,2,1.,1.,0.,0.,0.,1.,1.;"),
    ):
        recs = list(srf)
        de = add_entity(recs, etype, form, params)
        emit(name, ".igs", join(recs), code="iges.entity", section="P", sequence=21, entity=f"D{de}")
    # An associativity back pointer (section 2.2.4.5.2) naming a line, not a 402.
    assoc("iges_associativity_pointer_not_402", 406, 15, "406,1,4HNAME,1,9,0;", "pointer.invalid")
    # A count larger than the pointers that follow: the record ends early, at its only line.
    recs = list(srf)
    de = add_entity(recs, 402, 7, "402,3,1,3;")
    emit("iges_402_group_count_too_big", ".igs", join(recs), code="iges.entity", section="P", sequence=21, entity=f"D{de}")
    recs = list(srf)
    de = add_entity(recs, 406, 1, "406,3,1,2;")
    emit("iges_406_levels_count_too_big", ".igs", join(recs), code="iges.entity", section="P", sequence=21, entity=f"D{de}")
    # --- layouts read from the data (IGES 5.3 sections 4.79, 4.107, 4.123, 4.141), appended
    # to surf_poles4x3.igs (D3 a 128, D9 a 110) at D27 (P21). The 406 form 27 Generic Data:
    # NP, NAME, TNUM, then TNUM (TYPE, VALUE) pairs, each value of its type code (0 none,
    # 1 integer, 2 real, 3 string, 4 pointer, 5 not used, 6 logical), NP = 2 + 2 TNUM. The
    # 406 form 11 Tabular Data: NP, PTYPE, NDEP, NIND, NIND types, NIND counts NVALIN, their
    # sum of independent values, then dependent values (reals) up to NP. The 322
    # Attribute Table Definition: NAME, ATYP, NA, then per attribute AT, AVT (a type code),
    # AVC, with its AVC values (form 1) each followed by a 312 pointer (form 2). The 422
    # Attribute Table Instance: (form 1: NR rows of) the values of the 322 its DE structure
    # field names, negated.
    for name, etype, form, params in (
        # TNUM = 2 (NP = 6) before three pairs: the third pair is left over.
        ("iges_406_generic_data_pairs_over", 406, 27, "406,6,4HDATA,2,1,42,2,2.5,3,2HOK;"),
        # A type code outside 0-6.
        ("iges_406_generic_data_type_code", 406, 27, "406,4,4HDATA,1,9,42;"),
        # A real where its type code 1 declares an integer.
        ("iges_406_generic_data_value_type", 406, 27, "406,4,4HDATA,1,1,4.5;"),
        # NP = 4 for TNUM = 2.
        ("iges_406_generic_data_np", 406, 27, "406,4,4HDATA,2,1,42,2,2.5;"),
        # NVALIN = 4 and NP = 13 (four independent values, four dependent) over six values.
        ("iges_406_tabular_data_values_short", 406, 11, "406,13,1,1,1,1,4,0.,1.,2.,5.,6.,7.;"),
        # NP = 5 where the three independent values alone need NP >= 8.
        ("iges_406_tabular_data_np", 406, 11, "406,5,1,1,1,1,3,0.,1.,2.,5.,6.,7.;"),
        # 322 form 1: AVT 7.
        ("iges_322_value_type_code", 322, 1, "322,4HATTS,1,1,1,7,1,5;"),
        # 322 form 1: AVC = 3 over two integers.
        ("iges_322_values_short", 322, 1, "322,4HATTS,1,1,1,1,3,5,7;"),
    ):
        appended(name, etype, form, params, "iges.entity", "P", 21)
    for name, etype, form, params in (
        # A pointer value (type code 4) to the second line of D9.
        ("iges_406_generic_data_pointer_even", 406, 27, "406,4,4HDATA,1,4,10;"),
        # A pointer value past the directory.
        ("iges_406_generic_data_pointer_missing", 406, 27, "406,6,4HDATA,2,3,2HOK,4,99;"),
        # 322 form 2: the value's 312 Text Display Template pointer names the 128 at D3.
        ("iges_322_template_not_312", 322, 2, "322,3HTXT,1,1,1,1,1,5,3;"),
    ):
        assoc(name, etype, form, params, "pointer.invalid")
    # A Generic Data whose pointer value names itself: a cycle.
    assoc("iges_406_generic_data_pointer_cycle", 406, 27, "406,4,4HDATA,1,4,SELF;", "pointer.cycle")
    # 422 following a 322 form 0 (D27: a pointer, then two reals) at D29 (P22).
    for name, params, structure, code, section in (
        # One real short: the error is at the 422's P line.
        ("iges_422_values_short", "422,9,1.5;", -27, "iges.entity", "P"),
        # Its pointer value names no directory entry.
        ("iges_422_pointer_missing", "422,99,1.5,2.5;", -27, "pointer.invalid", "D"),
        # Its structure field names no 322: no layout, an error at its DE line.
        ("iges_422_no_definition", "422,9,1.5,2.5;", 0, "iges.entity", "D"),
        ("iges_422_definition_not_322", "422,9,1.5,2.5;", -9, "iges.entity", "D"),
    ):
        recs = list(srf)
        assert add_entity(recs, 322, 0, "322,5HTABLE,0,2,10,4,1,11,2,2;") == 27
        de = add_entity(recs, 422, 0, params)
        assert de == 29
        setfield(recs, didx(recs, de), 3, structure)
        emit(name, ".igs", join(recs), code=code, section=section, sequence=22 if section == "P" else de, entity=f"D{de}")
    # --- DE fields in range (IGES 5.3 section 2.2.4.4), on the 126 at D1/D2 of
    # curve_deg2_clamped.igs (Global parameter 16, line weight gradations, is 1). Each at
    # the DE line holding the field (field 9 status digit pairs: blank, subordinate,
    # entity use, hierarchy).
    for name, line, field, value in (
        ("entity_type_undefined", 1, 1, 999),
        ("structure_positive", 1, 3, 5),
        ("line_font_range", 1, 4, 6),
        ("view_negative", 1, 6, -3),
        ("transform_negative", 1, 7, -3),
        ("label_display_negative", 1, 8, -1),
        ("status_blank", 1, 9, "02000000"),
        ("status_subordinate", 1, 9, "00040000"),
        ("status_use_flag", 1, 9, "00000700"),
        ("status_hierarchy", 1, 9, "00000003"),
        ("line_weight_range", 2, 2, 2),
        ("line_weight_negative", 2, 2, -1),
        ("color_range", 2, 3, 9),
        ("form_undefined", 2, 5, 7),
    ):
        recs = list(base)
        setfield(recs, didx(recs, line), field, value)
        if field == 1:
            setfield(recs, didx(recs, 2), 1, value)  # field 11 repeats the type
        emit(f"iges_de_{name}", ".igs", join(recs), code="iges.directory_field", section="D", sequence=line, entity="D1")
    # A form number (DE field 15) the entity's section of IGES 5.3 does not give, on its
    # second DE line: the 104 Conic Arc of analytic/ellipse_arc.igs (D1, form 1 ellipse;
    # section 4.5 gives forms 0-3) in form 4; and, appended to surf_poles4x3.igs as D27,
    # a 212 General Note in form 9 (section 4.60: 0-8, 100-102, 105), a 214 Leader in form 0
    # (section 4.62: 1-12), a 228 General Symbol in form 4 (section 4.67: 0-3, and
    # 5001-9999 implementor-defined) and a 312 Text Display Template in form 2 (section
    # 4.75: 0 and 1), each record well formed.
    recs = records(read("analytic/ellipse_arc.igs"))
    setfield(recs, didx(recs, 2), 5, 4)
    emit("iges_104_form_undefined", ".igs", join(recs), code="iges.directory_field", section="D", sequence=2, entity="D1")
    for name, etype, form, params in (
        ("iges_212_form_undefined", 212, 9, "212,1,5,10.,2.,1,1.5707963267948966,0.,0,0,0.,0.,0.,5HHELLO;"),
        ("iges_214_form_undefined", 214, 0, "214,1,1.,1.,0.,0.,0.,1.,1.;"),
        ("iges_228_form_undefined", 228, 4, "228,0,0,0;"),
        ("iges_312_form_undefined", 312, 2, "312,1.,2.,1,1.5708,0.,0,0,0.,0.,0.;"),
    ):
        appended(name, etype, form, params, "iges.directory_field", "D", 28)
    # DE pointer fields (negated for line font, level, color): to no entry, to an entity
    # of another type, or of the right type and the wrong form (a level names a 406 form 1,
    # a label display a 402 form 5). surf_poles4x3.igs, on the 110 at D9.
    for name, field, value, extra in (
        ("line_font_pointer_missing", 4, -99, None),
        ("level_pointer_missing", 5, -99, None),
        ("color_pointer_not_314", 13, -3, None),
        ("view_not_410", 6, 3, None),
        ("level_pointer_wrong_form", 5, -27, (406, 15, "406,1,4HNAME;")),
        ("label_display_wrong_form", 8, 27, (402, 7, "402,1,3;")),
    ):
        recs = list(srf)
        if extra:
            assert add_entity(recs, *extra) == 27
        if field == 13:
            setfield(recs, didx(recs, 10), 3, value)
        else:
            setfield(recs, didx(recs, 9), field, value)
        # (Changed in the middle and at the end: named as the source explicitly.)
        emit(f"iges_de_{name}", ".igs", join(recs), code="pointer.invalid", section="D", sequence=9, entity="D9",
             source="surf_poles4x3.igs")
    # --- record structure (IGES 5.3 section 2.1): all errors for validate.
    recs = list(base)
    r = recs[pidx(recs, 3)]
    recs[pidx(recs, 3)] = r[:73] + "0000009"
    emit("iges_sequence_gap", ".igs", join(recs), code="sequence", section="P", sequence=9)
    recs = list(base)
    recs[-1] = recs[-1].replace("P      8", "P      9")
    emit("iges_terminate_count", ".igs", join(recs), code="terminate_count", section="T", sequence=1)
    recs = list(base)
    setfield(recs, didx(recs, 2), 4, 7)
    emit("iges_de_param_line_count", ".igs", join(recs), code="param_line_count", section="D", sequence=2, entity="D1")
    recs = list(base)
    recs[pidx(recs, 4)] = recs[pidx(recs, 4)][:64] + recs[pidx(recs, 4)][65:]
    emit("iges_one_line_79_columns", ".igs", join(recs), code="short_line", section="P", sequence=4)
    recs = list(base)
    recs[pidx(recs, 5)] = recs[pidx(recs, 5)] + "X"
    emit("iges_one_line_81_columns", ".igs", join(recs), code="long_line", section="P", sequence=5)
    emit("iges_no_start_section", ".igs", join([r for r in base if r[72:73] != "S"]), code="missing_start", section="S")
    # Global Hollerith count wrong: the error is the count, on its own line.
    recs = list(base)
    recs[2] = recs[2].replace("16HOpen CASCADE 7.6", "18HOpen CASCADE 7.6", 1)
    emit("iges_global_hollerith_count_g2", ".igs", join(recs), code="iges.syntax", section="G", sequence=2, line=3, column=1)
    # Legacy-encoded bytes in a Global string (same length: counts and columns stay).
    d = c2.replace(b"13HFilename.iges", b"13H\xc9\xe9\xe8ename.iges", 1)
    line, col = line_col(d, d.index(b"\xc9"))
    emit("iges_latin1_global", ".igs", d, code="encoding.not_utf8", line=line, column=col)
    # --- what the file is instead (line 1)
    emit("iges_is_pdf", ".igs", b"%PDF-1.4\n1 0 obj\n<<>>\nendobj\n", code="format.other", line=1)
    emit("iges_is_dxf", ".igs", b"  0\nSECTION\n  2\nENTITIES\n  0\nENDSEC\n  0\nEOF\n", code="format.other", line=1)
    emit("iges_is_ascii_stl", ".igs", b"solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n", code="format.other", line=1)
    emit("iges_is_binary_stl", ".igs", b"STL binary".ljust(80, b"\0") + (2).to_bytes(4, "little") + bytes(100), code="format.other", line=1)
    emit("iges_utf32", ".igs", c2.decode("latin-1").encode("utf-32"), code="encoding.utf32", line=1)
    emit("iges_whitespace_only", ".igs", b"\n\n   \n", code="format.empty", line=1)

    # Global delimiters: parameter and record delimiter the same character
    recs = list(base)
    recs[1] = "1H;,1H;," + recs[1][2:66] + recs[1][72:]
    emit("iges_same_delimiters", ".igs", join(recs), code="iges.syntax", section="G", sequence=1)


if __name__ == "__main__":
    clear()
    step_cases()
    iges_cases()
    n = len([x for x in os.listdir(HERE) if x.endswith(".expect")])
    print(f"{n} cases")
