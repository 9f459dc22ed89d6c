use nurbsx_parsers::real::{NonFiniteReal, write_real_fast};
use nurbsx_parsers::step::StepString;

use super::{
    CURVE_FORMS, KnotForm, SURFACE_FORMS, curve_closed, form_name, implicit_subtype, knot_form,
    occt_translates, surface_closed,
};
use crate::exchange::{Entity, ExportOptions};
use crate::nurbs::{NurbsCurve, NurbsSurface, Point3};

type Result = std::result::Result<(), NonFiniteReal>;

/// Appends the decimal digits of `v` (no formatting machinery: ids are a large share of
/// a STEP file's tokens).
fn push_u64(out: &mut String, mut v: u64) {
    let mut digits = [b'0'; 20];
    let mut i = digits.len();
    while i > 0 {
        i -= 1;
        // v % 10 < 10.
        digits[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    // Pushed one by one: cheaper than validating and copying a few bytes.
    for &d in &digits[i..] {
        out.push(char::from(d));
    }
}

fn push_id(out: &mut String, id: u64) {
    out.push('#');
    push_u64(out, id);
}

/// `(#first,#first+1,...)` for `n` ids.
fn push_id_range(out: &mut String, first: u64, n: usize) {
    out.push('(');
    for (k, id) in (first..).take(n).enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_id(out, id);
    }
    out.push(')');
}

fn push_reals(out: &mut String, values: &[f64]) -> Result {
    out.push('(');
    for (k, &x) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        write_real_fast(out, x)?;
    }
    out.push(')');
    Ok(())
}

fn push_counts(out: &mut String, values: &[usize]) {
    out.push('(');
    for (k, &m) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_u64(out, u64::try_from(m).unwrap_or(u64::MAX));
    }
    out.push(')');
}

fn push_enum(out: &mut String, e: &str) {
    out.push('.');
    out.push_str(e);
    out.push('.');
}

fn push_logical(out: &mut String, v: bool) {
    out.push_str(if v { ".T." } else { ".F." });
}

fn push_name(out: &mut String, e: &Entity) {
    out.push('\'');
    out.push_str(&StepString::from_text(e.meta.name.as_deref().unwrap_or("")).raw);
    out.push('\'');
}

/// `#id = CARTESIAN_POINT('',(x,y[,z]));` with the first `dim` coordinates, scaled.
fn point(out: &mut String, id: u64, p: &Point3, dim: usize, scale: f64) -> Result {
    push_id(out, id);
    out.push_str(" = CARTESIAN_POINT('',(");
    for (k, x) in p.iter().take(dim).enumerate() {
        if k > 0 {
            out.push(',');
        }
        write_real_fast(out, x * scale)?;
    }
    out.push_str("));\n");
    Ok(())
}

/// One partial record of a complex instance: which parameters it holds.
#[derive(Clone, Copy)]
enum Part {
    Empty,
    BSpline,
    Knots,
    Weights,
    Name,
}

/// `#id = ( A(...) B(...) );` with the partials in byte-wise keyword order (ISO
/// 10303-21 clause 12.2.5), each part's parameters written by `params`.
fn complex(
    out: &mut String,
    id: u64,
    parts: &mut [(&'static str, Part)],
    mut params: impl FnMut(&mut String, Part) -> Result,
) -> Result {
    parts.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    push_id(out, id);
    out.push_str(" = ( ");
    for &(keyword, part) in parts.iter() {
        out.push_str(keyword);
        out.push('(');
        params(out, part)?;
        out.push_str(") ");
    }
    out.push_str(");\n");
    Ok(())
}

/// A curve's poles and its B-spline instance; `id` is the next free id.
/// A polynomial B-spline as a simple instance: `#id = KEYWORD('name',<B-spline attributes>
/// [,<knot attributes>]);` (the knot attributes only for `..._WITH_KNOTS`; the implicit
/// subtypes have none).
fn simple(
    out: &mut String,
    id: u64,
    keyword: &str,
    e: &Entity,
    with_knots: bool,
    bspline: impl FnOnce(&mut String),
    knots: impl FnOnce(&mut String) -> Result,
) -> Result {
    push_id(out, id);
    out.push_str(" = ");
    out.push_str(keyword);
    out.push('(');
    push_name(out, e);
    out.push(',');
    bspline(out);
    if with_knots {
        out.push(',');
        knots(out)?;
    }
    out.push_str(");\n");
    Ok(())
}

pub(super) fn curve(
    out: &mut String,
    id: &mut u64,
    c: &NurbsCurve,
    e: &Entity,
    scale: f64,
    options: &ExportOptions,
) -> Result {
    let dim = c.dimension();
    let first = *id;
    for p in c.control_points() {
        point(out, *id, p, dim, scale)?;
        *id += 1;
    }
    let cid = *id;
    *id += 1;
    let closed = curve_closed(c);
    let form = form_name(e.meta.form.as_ref(), CURVE_FORMS);
    let self_intersect = e.meta.self_intersect.unwrap_or(false);
    let n = c.num_poles();
    let bspline = |out: &mut String| {
        push_u64(out, u64::try_from(c.degree()).unwrap_or(u64::MAX));
        out.push(',');
        push_id_range(out, first, n);
        out.push(',');
        push_enum(out, form);
        out.push(',');
        push_logical(out, closed);
        out.push(',');
        push_logical(out, self_intersect);
    };
    let subtype = if options.use_implicit_knot_subtypes {
        implicit_subtype(c.degree(), n, c.knots())
            .filter(|&f| occt_translates(f, c.is_rational(), &[(c.degree(), n)]))
    } else {
        None
    };
    let sub_keyword = match subtype {
        Some(KnotForm::Bezier) => "BEZIER_CURVE",
        Some(KnotForm::Uniform) => "UNIFORM_CURVE",
        Some(KnotForm::QuasiUniform) => "QUASI_UNIFORM_CURVE",
        None => "B_SPLINE_CURVE_WITH_KNOTS",
    };
    let knots = |out: &mut String| -> Result {
        if subtype.is_none() {
            let (values, mults) = crate::nurbs::knots::to_distinct(c.knots());
            push_counts(out, &mults);
            out.push(',');
            push_reals(out, &values)?;
            out.push(',');
            push_enum(out, knot_form(c.degree(), c.knots()));
        }
        Ok(())
    };
    match c.weights() {
        None => simple(out, cid, sub_keyword, e, subtype.is_none(), bspline, knots),
        Some(w) => complex(
            out,
            cid,
            &mut [
                ("BOUNDED_CURVE", Part::Empty),
                ("B_SPLINE_CURVE", Part::BSpline),
                (sub_keyword, Part::Knots),
                ("CURVE", Part::Empty),
                ("GEOMETRIC_REPRESENTATION_ITEM", Part::Empty),
                ("RATIONAL_B_SPLINE_CURVE", Part::Weights),
                ("REPRESENTATION_ITEM", Part::Name),
            ],
            |out, part| match part {
                Part::Empty => Ok(()),
                Part::BSpline => {
                    bspline(out);
                    Ok(())
                }
                Part::Knots => knots(out),
                Part::Weights => push_reals(out, w),
                Part::Name => {
                    push_name(out, e);
                    Ok(())
                }
            },
        ),
    }
}

/// A surface's poles (row by row) and its B-spline instance; `id` is the next free id.
pub(super) fn surface(
    out: &mut String,
    id: &mut u64,
    sf: &NurbsSurface,
    e: &Entity,
    scale: f64,
    options: &ExportOptions,
) -> Result {
    let dim = sf.dimension();
    let net = sf.control_points();
    let (nu, nv) = (net.nu(), net.nv());
    let first = *id;
    for i in 0..nu {
        for p in net.row(i) {
            point(out, *id, p, dim, scale)?;
            *id += 1;
        }
    }
    let sid = *id;
    *id += 1;
    let (closed_u, closed_v) = surface_closed(sf);
    let form = form_name(e.meta.form.as_ref(), SURFACE_FORMS);
    let self_intersect = e.meta.self_intersect.unwrap_or(false);
    let bspline = |out: &mut String| {
        push_u64(out, u64::try_from(sf.degree_u()).unwrap_or(u64::MAX));
        out.push(',');
        push_u64(out, u64::try_from(sf.degree_v()).unwrap_or(u64::MAX));
        out.push_str(",(");
        let mut row_first = first;
        for i in 0..nu {
            if i > 0 {
                out.push(',');
            }
            let len = net.row(i).len();
            push_id_range(out, row_first, len);
            row_first += u64::try_from(len).unwrap_or(u64::MAX);
        }
        out.push_str("),");
        push_enum(out, form);
        out.push(',');
        push_logical(out, closed_u);
        out.push(',');
        push_logical(out, closed_v);
        out.push(',');
        push_logical(out, self_intersect);
    };
    let subtype = if options.use_implicit_knot_subtypes {
        let su = implicit_subtype(sf.degree_u(), nu, sf.knots_u());
        let sv = implicit_subtype(sf.degree_v(), nv, sf.knots_v());
        let dims = [(sf.degree_u(), nu), (sf.degree_v(), nv)];
        if su == sv {
            su.filter(|&f| occt_translates(f, sf.is_rational(), &dims))
        } else {
            None
        }
    } else {
        None
    };
    let sub_keyword = match subtype {
        Some(KnotForm::Bezier) => "BEZIER_SURFACE",
        Some(KnotForm::Uniform) => "UNIFORM_SURFACE",
        Some(KnotForm::QuasiUniform) => "QUASI_UNIFORM_SURFACE",
        None => "B_SPLINE_SURFACE_WITH_KNOTS",
    };
    let knots = |out: &mut String| -> Result {
        if subtype.is_none() {
            let (ku, mu) = crate::nurbs::knots::to_distinct(sf.knots_u());
            let (kv, mv) = crate::nurbs::knots::to_distinct(sf.knots_v());
            push_counts(out, &mu);
            out.push(',');
            push_counts(out, &mv);
            out.push(',');
            push_reals(out, &ku)?;
            out.push(',');
            push_reals(out, &kv)?;
            out.push(',');
            let fu = knot_form(sf.degree_u(), sf.knots_u());
            let fv = knot_form(sf.degree_v(), sf.knots_v());
            push_enum(out, if fu == fv { fu } else { "UNSPECIFIED" });
        }
        Ok(())
    };
    match sf.weights() {
        None => simple(out, sid, sub_keyword, e, subtype.is_none(), bspline, knots),
        Some(w) => complex(
            out,
            sid,
            &mut [
                ("BOUNDED_SURFACE", Part::Empty),
                ("B_SPLINE_SURFACE", Part::BSpline),
                (sub_keyword, Part::Knots),
                ("GEOMETRIC_REPRESENTATION_ITEM", Part::Empty),
                ("RATIONAL_B_SPLINE_SURFACE", Part::Weights),
                ("REPRESENTATION_ITEM", Part::Name),
                ("SURFACE", Part::Empty),
            ],
            |out, part| match part {
                Part::Empty => Ok(()),
                Part::BSpline => {
                    bspline(out);
                    Ok(())
                }
                Part::Knots => knots(out),
                Part::Weights => {
                    out.push('(');
                    for i in 0..nu {
                        if i > 0 {
                            out.push(',');
                        }
                        push_reals(out, w.row(i))?;
                    }
                    out.push(')');
                    Ok(())
                }
                Part::Name => {
                    push_name(out, e);
                    Ok(())
                }
            },
        ),
    }
}
