//! Part 21 text from a syntax tree (ISO 10303-21 clauses 8-12), and a [`Builder`] that
//! creates instances with fresh ids.
//!
//! Output rules: reals through [`write_real`] (shortest round-trip digits, always a decimal
//! point); strings as their raw text (verbatim for parsed strings; [`StepString::from_text`]
//! escapes new ones to ASCII); the partial records of a complex instance in alphabetical
//! order of their keywords, byte-wise, as clause 12.2.5 requires (`BOUNDED_CURVE` before
//! `B_SPLINE_CURVE` because `O` < `_`). The output is pure ASCII when every string is.

use super::ast::{Body, Exchange, Instance, Parameter, Record};
use super::schema::{BSplineCurve, BSplineSurface, CartesianPoint, KnotSpec, Logical};
use super::string::StepString;
use crate::real::{NonFiniteReal, write_real};

/// Writes a whole exchange structure. Fails only on a non-finite real.
///
/// ```
/// # use nurbsx_parsers::step::{Builder, Exchange, DataSection, Parameter, Record, write_exchange};
/// let mut b = Builder::new();
/// let p = b.simple("CARTESIAN_POINT", vec![Parameter::text(""), Parameter::reals(&[0., 1.5, -2.])]);
/// let ex = Exchange { header: vec![], data: vec![DataSection { params: vec![], instances: b.into_instances() }] };
/// let text = write_exchange(&ex).unwrap();
/// assert!(text.contains("#1 = CARTESIAN_POINT('',(0.,1.5,-2.));"));
/// # let _ = p;
/// ```
pub fn write_exchange(exchange: &Exchange<'_>) -> Result<String, NonFiniteReal> {
    let mut out = String::with_capacity(4096);
    // One explicit stack for every parameter list of the file (no allocation per record).
    let mut stack = Vec::new();
    out.push_str("ISO-10303-21;\nHEADER;\n");
    for r in &exchange.header {
        write_record(&mut out, r)?;
        out.push_str(";\n");
    }
    out.push_str("ENDSEC;\n");
    for section in &exchange.data {
        out.push_str("DATA");
        if !section.params.is_empty() {
            write_params(&mut out, &section.params)?;
        }
        out.push_str(";\n");
        for inst in &section.instances {
            write_instance_with(&mut out, inst, &mut stack)?;
        }
        out.push_str("ENDSEC;\n");
    }
    out.push_str("END-ISO-10303-21;\n");
    Ok(out)
}

/// Writes `#id = body;` and a newline; complex partials sorted alphabetically.
pub fn write_instance(out: &mut String, inst: &Instance<'_>) -> Result<(), NonFiniteReal> {
    write_instance_with(out, inst, &mut Vec::new())
}

/// [`write_instance`] with a caller-provided (reused) parameter stack.
fn write_instance_with<'p, 'a>(
    out: &mut String,
    inst: &'p Instance<'a>,
    stack: &mut Vec<Item<'p, 'a>>,
) -> Result<(), NonFiniteReal> {
    out.push('#');
    push_u64(out, inst.id);
    out.push_str(" = ");
    match &inst.body {
        Body::Simple(r) => {
            out.push_str(r.keyword);
            write_params_with(out, &r.params, stack)?;
        }
        Body::Complex(rs) => {
            let mut sorted: Vec<&Record<'_>> = rs.iter().collect();
            sorted.sort_by(|a, b| a.keyword.as_bytes().cmp(b.keyword.as_bytes()));
            out.push_str("( ");
            for r in sorted {
                out.push_str(r.keyword);
                write_params_with(out, &r.params, stack)?;
                out.push(' ');
            }
            out.push(')');
        }
    }
    out.push_str(";\n");
    Ok(())
}

/// Appends the decimal digits of `v` (as `{v}`, without the formatting machinery: ids and
/// integers are a large share of a STEP file's tokens).
fn push_u64(out: &mut String, mut v: u64) {
    let mut digits = [0u8; 20];
    let mut n = 0;
    loop {
        digits[19 - n] = b'0' + (v % 10) as u8;
        n += 1;
        v /= 10;
        if v == 0 || n == 20 {
            break;
        }
    }
    for &d in &digits[20 - n..] {
        out.push(char::from(d));
    }
}

/// Writes `KEYWORD(params)`.
pub fn write_record(out: &mut String, r: &Record<'_>) -> Result<(), NonFiniteReal> {
    out.push_str(r.keyword);
    write_params(out, &r.params)
}

/// Writes `(p1,p2,...)` without recursion (an explicit stack of what remains to print).
pub fn write_params(out: &mut String, params: &[Parameter<'_>]) -> Result<(), NonFiniteReal> {
    write_params_with(out, params, &mut Vec::new())
}

/// What remains to print in [`write_params`]: a parameter or fixed punctuation.
enum Item<'p, 'a> {
    Param(&'p Parameter<'a>),
    Text(&'static str),
}

/// Pushes a list's items (in reverse, so they pop in order) with its parentheses and commas.
fn push_list<'p, 'a>(stack: &mut Vec<Item<'p, 'a>>, list: &'p [Parameter<'a>]) {
    stack.push(Item::Text(")"));
    for (i, p) in list.iter().enumerate().rev() {
        stack.push(Item::Param(p));
        if i > 0 {
            stack.push(Item::Text(","));
        }
    }
    stack.push(Item::Text("("));
}

/// [`write_params`] with a caller-provided (reused) stack; leaves it empty on success.
fn write_params_with<'p, 'a>(
    out: &mut String,
    params: &'p [Parameter<'a>],
    stack: &mut Vec<Item<'p, 'a>>,
) -> Result<(), NonFiniteReal> {
    stack.clear();
    push_list(stack, params);
    while let Some(item) = stack.pop() {
        match item {
            Item::Text(t) => out.push_str(t),
            Item::Param(p) => match p {
                Parameter::Integer(i) => {
                    if *i < 0 {
                        out.push('-');
                    }
                    push_u64(out, i.unsigned_abs());
                }
                Parameter::Real(x) => write_real(out, *x)?,
                Parameter::String(s) => {
                    out.push('\'');
                    out.push_str(&s.raw);
                    out.push('\'');
                }
                Parameter::Enumeration(e) => {
                    out.push('.');
                    out.push_str(e);
                    out.push('.');
                }
                Parameter::Binary(b) => {
                    out.push('"');
                    out.push_str(b);
                    out.push('"');
                }
                Parameter::Reference(id) => {
                    out.push('#');
                    push_u64(out, *id);
                }
                Parameter::Null => out.push('$'),
                Parameter::Derived => out.push('*'),
                Parameter::Typed(k, inner) => {
                    out.push_str(k);
                    out.push('(');
                    stack.push(Item::Text(")"));
                    stack.push(Item::Param(inner));
                }
                Parameter::List(l) => push_list(stack, l),
            },
        }
    }
    Ok(())
}

/// Appends `#id = CARTESIAN_POINT('name',(x,y[,z]));` and a newline (ISO 10303-42
/// 4.4.2), the record's coordinates as they are.
///
/// ```
/// # use std::borrow::Cow;
/// # use nurbsx_parsers::step::{StepString, schema::CartesianPoint, writer::write_cartesian_point};
/// let mut out = String::new();
/// let p = CartesianPoint { name: Some(StepString::new("")), coordinates: Cow::Borrowed(&[0., 1.5, -2.]) };
/// write_cartesian_point(&mut out, 7, &p).unwrap();
/// assert_eq!(out, "#7 = CARTESIAN_POINT('',(0.,1.5,-2.));\n");
/// ```
pub fn write_cartesian_point(
    out: &mut String,
    id: u64,
    p: &CartesianPoint<'_>,
) -> Result<(), NonFiniteReal> {
    push_id(out, id);
    // Most of a file is points, nearly all unnamed: their head is one copy.
    match p.name.as_ref().map(|n| n.raw.as_ref()) {
        None | Some("") => out.push_str(" = CARTESIAN_POINT('',("),
        Some(name) => {
            out.push_str(" = CARTESIAN_POINT('");
            out.push_str(name);
            out.push_str("',(");
        }
    }
    for (k, &x) in p.coordinates.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        write_real(out, x)?;
    }
    out.push_str("));\n");
    Ok(())
}

/// Appends a B-spline curve instance and a newline: a simple instance of the knot subtype
/// (`B_SPLINE_CURVE_WITH_KNOTS`, `BEZIER_CURVE`, `UNIFORM_CURVE`, `QUASI_UNIFORM_CURVE`)
/// when it has no weights, else the complex instance of the rational curve (ISO 10303-42
/// 4.4.18) with its seven partial records in byte order of their keywords (ISO 10303-21
/// 12.2.5). The record's `entity_type` is not read: the shape follows from the data.
pub fn write_bspline_curve(
    out: &mut String,
    id: u64,
    c: &BSplineCurve<'_>,
) -> Result<(), NonFiniteReal> {
    let subtype = subtype_keyword(&c.knots, "CURVE");
    let bspline = |out: &mut String| {
        push_i64(out, c.degree);
        out.push(',');
        push_refs(out, &c.control_points);
        out.push(',');
        push_enum(out, c.curve_form);
        out.push(',');
        push_logical(out, c.closed_curve);
        out.push(',');
        push_logical(out, c.self_intersect);
    };
    match &c.weights {
        None => simple(out, id, subtype, c.name.as_ref(), bspline, |out| {
            knots(out, &c.knots)
        }),
        Some(w) => complex(
            out,
            id,
            &mut [
                ("BOUNDED_CURVE", Part::Empty),
                ("B_SPLINE_CURVE", Part::BSpline),
                (subtype, Part::Knots),
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
                Part::Knots => knots(out, &c.knots),
                Part::Weights => push_reals(out, w),
                Part::Name => {
                    push_name(out, c.name.as_ref());
                    Ok(())
                }
            },
        ),
    }
}

/// Appends a B-spline surface instance and a newline, as [`write_bspline_curve`] does for
/// curves (ISO 10303-42 4.4.39-4.4.45): control points and weights row by row (outer index
/// u, ISO 10303-42 4.4.39).
pub fn write_bspline_surface(
    out: &mut String,
    id: u64,
    sf: &BSplineSurface<'_>,
) -> Result<(), NonFiniteReal> {
    let subtype = subtype_keyword(&sf.knots, "SURFACE");
    let bspline = |out: &mut String| {
        push_i64(out, sf.u_degree);
        out.push(',');
        push_i64(out, sf.v_degree);
        out.push_str(",(");
        for (i, row) in sf.control_points.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            push_refs(out, row);
        }
        out.push_str("),");
        push_enum(out, sf.surface_form);
        out.push(',');
        push_logical(out, sf.u_closed);
        out.push(',');
        push_logical(out, sf.v_closed);
        out.push(',');
        push_logical(out, sf.self_intersect);
    };
    match &sf.weights {
        None => simple(out, id, subtype, sf.name.as_ref(), bspline, |out| {
            knots(out, &sf.knots)
        }),
        Some(w) => complex(
            out,
            id,
            &mut [
                ("BOUNDED_SURFACE", Part::Empty),
                ("B_SPLINE_SURFACE", Part::BSpline),
                (subtype, Part::Knots),
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
                Part::Knots => knots(out, &sf.knots),
                Part::Weights => {
                    out.push('(');
                    for (i, row) in w.iter().enumerate() {
                        if i > 0 {
                            out.push(',');
                        }
                        push_reals(out, row)?;
                    }
                    out.push(')');
                    Ok(())
                }
                Part::Name => {
                    push_name(out, sf.name.as_ref());
                    Ok(())
                }
            },
        ),
    }
}

/// The keyword of the knot subtype partial (`kind` is `CURVE` or `SURFACE`).
fn subtype_keyword(k: &KnotSpec<'_>, kind: &str) -> &'static str {
    match (k, kind) {
        (KnotSpec::Explicit { .. }, "CURVE") => "B_SPLINE_CURVE_WITH_KNOTS",
        (KnotSpec::Bezier, "CURVE") => "BEZIER_CURVE",
        (KnotSpec::Uniform, "CURVE") => "UNIFORM_CURVE",
        (KnotSpec::QuasiUniform, "CURVE") => "QUASI_UNIFORM_CURVE",
        (KnotSpec::Explicit { .. }, _) => "B_SPLINE_SURFACE_WITH_KNOTS",
        (KnotSpec::Bezier, _) => "BEZIER_SURFACE",
        (KnotSpec::Uniform, _) => "UNIFORM_SURFACE",
        (KnotSpec::QuasiUniform, _) => "QUASI_UNIFORM_SURFACE",
    }
}

/// The knot attributes of `..._WITH_KNOTS` (every direction's multiplicities, then every
/// direction's knots, then `knot_spec`); nothing for the implicit subtypes.
fn knots(out: &mut String, k: &KnotSpec<'_>) -> Result<(), NonFiniteReal> {
    if let KnotSpec::Explicit {
        multiplicities,
        knots,
        knot_spec,
    } = k
    {
        for m in multiplicities {
            push_integers(out, m);
            out.push(',');
        }
        for values in knots {
            push_reals(out, values)?;
            out.push(',');
        }
        push_enum(out, knot_spec);
    }
    Ok(())
}

/// One partial record of a complex instance: which attributes it holds.
#[derive(Clone, Copy)]
enum Part {
    Empty,
    BSpline,
    Knots,
    Weights,
    Name,
}

/// `#id = ( A(...) B(...) );` with the partials in byte-wise keyword order (ISO 10303-21
/// clause 12.2.5), each part's attributes written by `params`.
fn complex(
    out: &mut String,
    id: u64,
    parts: &mut [(&'static str, Part)],
    mut params: impl FnMut(&mut String, Part) -> Result<(), NonFiniteReal>,
) -> Result<(), NonFiniteReal> {
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

/// `#id = KEYWORD('name',<B-spline attributes>[,<knot attributes>]);` (the knot attributes
/// only for `..._WITH_KNOTS`; the implicit subtypes have none).
fn simple(
    out: &mut String,
    id: u64,
    keyword: &str,
    name: Option<&StepString<'_>>,
    bspline: impl FnOnce(&mut String),
    knots: impl FnOnce(&mut String) -> Result<(), NonFiniteReal>,
) -> Result<(), NonFiniteReal> {
    push_id(out, id);
    out.push_str(" = ");
    out.push_str(keyword);
    out.push('(');
    push_name(out, name);
    out.push(',');
    bspline(out);
    if keyword.ends_with("_WITH_KNOTS") {
        out.push(',');
        knots(out)?;
    }
    out.push_str(");\n");
    Ok(())
}

fn push_id(out: &mut String, id: u64) {
    out.push('#');
    push_u64(out, id);
}

fn push_i64(out: &mut String, v: i64) {
    if v < 0 {
        out.push('-');
    }
    push_u64(out, v.unsigned_abs());
}

/// `(#a,#b,...)`.
fn push_refs(out: &mut String, ids: &[u64]) {
    out.push('(');
    for (k, &id) in ids.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_id(out, id);
    }
    out.push(')');
}

/// `(x,y,...)`, each real by [`write_real`].
fn push_reals(out: &mut String, values: &[f64]) -> Result<(), NonFiniteReal> {
    out.push('(');
    for (k, &x) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        write_real(out, x)?;
    }
    out.push(')');
    Ok(())
}

/// `(1,2,...)`.
fn push_integers(out: &mut String, values: &[i64]) {
    out.push('(');
    for (k, &m) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_i64(out, m);
    }
    out.push(')');
}

fn push_enum(out: &mut String, e: &str) {
    out.push('.');
    out.push_str(e);
    out.push('.');
}

fn push_logical(out: &mut String, v: Logical) {
    out.push_str(match v {
        Logical::True => ".T.",
        Logical::False => ".F.",
        Logical::Unknown => ".U.",
    });
}

/// `'raw text'` (an absent name is written empty).
fn push_name(out: &mut String, name: Option<&StepString<'_>>) {
    out.push('\'');
    out.push_str(name.map_or("", |n| &n.raw));
    out.push('\'');
}

impl Parameter<'static> {
    /// A string parameter holding `text` (escaped by [`StepString::from_text`]).
    pub fn text(text: &str) -> Self {
        Parameter::String(StepString::from_text(text))
    }

    /// A list of reals.
    pub fn reals(values: &[f64]) -> Self {
        Parameter::List(values.iter().map(|&x| Parameter::Real(x)).collect())
    }

    /// A list of references.
    pub fn refs(ids: &[u64]) -> Self {
        Parameter::List(ids.iter().map(|&id| Parameter::Reference(id)).collect())
    }

    /// A list of integers.
    pub fn integers(values: &[i64]) -> Self {
        Parameter::List(values.iter().map(|&i| Parameter::Integer(i)).collect())
    }

    /// `.T.` or `.F.`.
    pub fn logical(value: bool) -> Self {
        Parameter::Enumeration(if value { "T" } else { "F" })
    }
}

/// Creates entity instances with fresh, increasing ids (`#1`, `#2`, ...), for writers that
/// build a file from a model.
#[derive(Debug, Default)]
pub struct Builder {
    next: u64,
    instances: Vec<Instance<'static>>,
}

impl Builder {
    /// A builder whose first id is `#1`.
    pub fn new() -> Self {
        Builder {
            next: 1,
            instances: Vec::new(),
        }
    }

    /// Reserves an id for an instance whose body is given later with [`Builder::set`]
    /// (for forward references).
    pub fn reserve(&mut self) -> u64 {
        let id = self.next;
        self.next += 1;
        id
    }

    /// The id the next [`Builder::reserve`] returns.
    pub fn next_id(&self) -> u64 {
        self.next
    }

    /// Reserves `n` consecutive ids for instances the caller writes itself (outside the
    /// builder, e.g. straight to text) and returns the first.
    pub fn reserve_many(&mut self, n: u64) -> u64 {
        let id = self.next;
        self.next = self.next.saturating_add(n);
        id
    }

    /// Gives the body of a reserved id.
    pub fn set(&mut self, id: u64, body: Body<'static>) {
        self.instances.push(Instance { id, body });
    }

    /// Adds `#id = KEYWORD(params);` and returns the id.
    pub fn simple(&mut self, keyword: &'static str, params: Vec<Parameter<'static>>) -> u64 {
        let id = self.reserve();
        self.set(id, Body::Simple(Record { keyword, params }));
        id
    }

    /// Adds a complex instance (partials sorted alphabetically) and returns its id.
    pub fn complex(&mut self, mut records: Vec<Record<'static>>) -> u64 {
        records.sort_by(|a, b| a.keyword.as_bytes().cmp(b.keyword.as_bytes()));
        let id = self.reserve();
        self.set(id, Body::Complex(records));
        id
    }

    /// The instances, sorted by id.
    pub fn into_instances(mut self) -> Vec<Instance<'static>> {
        self.instances.sort_by_key(|i| i.id);
        self.instances
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_u64_matches_std_formatting() {
        let mut vals: Vec<u64> = (0..2000).collect();
        for k in 0..20 {
            let p = 10u64.pow(k);
            vals.extend([p - 1, p, p + 1]);
        }
        vals.push(u64::MAX);
        for v in vals {
            let mut s = String::new();
            push_u64(&mut s, v);
            assert_eq!(s, v.to_string());
        }
    }
}
