//! Part 21 text from a syntax tree (ISO 10303-21 clauses 8-12), and a [`Builder`] that
//! creates instances with fresh ids.
//!
//! Output rules: reals through [`write_real`] (shortest round-trip digits, always a decimal
//! point); strings as their raw text (verbatim for parsed strings; [`StepString::from_text`]
//! escapes new ones to ASCII); the partial records of a complex instance in alphabetical
//! order of their keywords, byte-wise, as clause 12.2.5 requires (`BOUNDED_CURVE` before
//! `B_SPLINE_CURVE` because `O` < `_`). The output is pure ASCII when every string is.

use super::ast::{Body, Exchange, Instance, Parameter, Record};
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
