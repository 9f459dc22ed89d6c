//! The IGES 5.3 writer: exact 80-column records (spec.md a.1-a.6; architecture.md 4.7).
//!
//! - S: free text in columns 1-72;
//! - G: the 26 parameters, strings as Hollerith, defaults left empty (`,,` for the default
//!   delimiters, as Open CASCADE writes them);
//! - D: two records per entity, ten right-justified 8-column fields, the status as 8
//!   digits, odd/even sequence numbers;
//! - P: data in columns 1-64, the DE back-pointer in 66-72; a parameter is never split
//!   across records except a Hollerith string, which fills its record and continues;
//! - T: the four section counts.
//!
//! Reals go through [`crate::real::write_real`]: shortest round-trip digits, always with a
//! decimal point, so read -> write -> read is bit-identical. Sequence numbers are
//! zero-padded (`P0000012`) as Open CASCADE writes them.

use std::fmt::Write as _;

use super::P_DATA_COLUMNS;
use super::directory::DirectoryEntry;
use super::error::WriteError;
use super::global::Global;
use crate::real::write_real;

/// One parameter to write.
#[derive(Debug, Clone, PartialEq)]
pub enum Param {
    /// Nothing between the delimiters (the default value).
    Empty,
    /// An integer (or pointer, or logical).
    Int(i64),
    /// A real, written with a decimal point and the shortest round-trip digits.
    Real(f64),
    /// A string, written as a Hollerith constant `nH...`.
    Text(String),
}

/// An entity to write: its Directory Entry fields and its parameters (entity type first).
///
/// The writer computes the DE pointer, parameter pointer and parameter line count; the
/// corresponding fields of `de` are ignored. `de.transform` must already hold the DE
/// pointer of a written 124 (entity `i` of the list gets pointer `2 i + 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct WriteEntity {
    /// Directory Entry fields (type, form, status, transform, label, subscript, ...).
    pub de: DirectoryEntry,
    /// Parameters, the entity type number first.
    pub params: Vec<Param>,
}

/// The DE pointer entity `index` (0-based position in the write list) receives.
pub fn pointer_of(index: usize) -> usize {
    2 * index + 1
}

/// Writes a complete IGES file.
pub fn write(start: &str, global: &Global, entities: &[WriteEntity]) -> Result<String, WriteError> {
    let pd = global.param_delimiter;
    let rd = global.record_delimiter;
    if pd == rd
        || !pd.is_ascii_graphic()
        || !rd.is_ascii_graphic()
        || pd.is_ascii_alphanumeric()
        || rd.is_ascii_alphanumeric()
        || matches!(pd, '.' | '+' | '-' | ' ')
        || matches!(rd, '.' | '+' | '-')
    {
        return Err(WriteError::Field(format!(
            "delimiters {pd:?} and {rd:?} cannot be written"
        )));
    }
    let mut out = String::with_capacity(4096 + entities.len() * 1024);
    // S
    let mut s_count = 0;
    for line in start.lines() {
        let mut rest: String = line
            .chars()
            .filter(|c| c.is_ascii() && !c.is_ascii_control())
            .collect();
        loop {
            let take = rest.len().min(72);
            let chunk: String = rest.drain(..take).collect();
            s_count += 1;
            record(&mut out, &chunk, 'S', s_count);
            if rest.is_empty() {
                break;
            }
        }
    }
    if s_count == 0 {
        s_count = 1;
        record(&mut out, "", 'S', 1);
    }
    // G
    let g = global_tokens(global)?;
    let g_lines = pack(&g, 72, pd, rd);
    for (k, l) in g_lines.iter().enumerate() {
        record(&mut out, l, 'G', k + 1);
    }
    // P first (into a buffer), to know the pointers and line counts. Tokens of an entity
    // go into one reused text buffer (no allocation per parameter or per line).
    let mut p_out = String::with_capacity(entities.len() * 1024);
    let mut p_seq = 0usize;
    let mut placements = Vec::with_capacity(entities.len());
    let mut toks = Tokens::default();
    let mut line = String::with_capacity(P_DATA_COLUMNS + 1);
    for (index, e) in entities.iter().enumerate() {
        toks.clear();
        for p in &e.params {
            toks.push_param(p).map_err(|value| WriteError::NonFinite {
                entity: index,
                value,
            })?;
        }
        let de = pointer_of(index);
        let first = p_seq + 1;
        pack_into(&toks, P_DATA_COLUMNS, pd, rd, &mut line, |l| {
            p_seq += 1;
            // `{l:<64} {de:>7}P{p_seq:07}` without the formatting machinery.
            p_out.push_str(l);
            pad(&mut p_out, b' ', P_DATA_COLUMNS.saturating_sub(l.len()));
            p_out.push(' ');
            push_uint(&mut p_out, de, 7, b' ');
            p_out.push('P');
            push_uint(&mut p_out, p_seq, 7, b'0');
            p_out.push('\n');
        });
        placements.push((first, p_seq + 1 - first));
    }
    // D
    for (index, (e, &(first, count))) in entities.iter().zip(&placements).enumerate() {
        let de = &e.de;
        let seq = pointer_of(index);
        let mut l1 = String::with_capacity(80);
        for v in [
            de.entity_type,
            to_i64(first),
            de.structure,
            de.line_font,
            de.level,
            de.view,
            de.transform,
            de.label_display,
        ] {
            field8(&mut l1, v)?;
        }
        l1.push_str(&de.status.to_digits());
        record(&mut out, &l1, 'D', seq);
        let mut l2 = String::with_capacity(80);
        for v in [
            de.entity_type,
            de.line_weight,
            de.color,
            to_i64(count),
            de.form,
        ] {
            field8(&mut l2, v)?;
        }
        for r in &de.reserved {
            let r: String = r.chars().filter(|c| c.is_ascii_graphic()).take(8).collect();
            let _ = write!(l2, "{r:>8}");
        }
        let label: String = de
            .label
            .chars()
            .filter(|c| c.is_ascii_graphic() || *c == ' ')
            .take(8)
            .collect();
        let _ = write!(l2, "{label:>8}");
        field8(&mut l2, de.subscript)?;
        record(&mut out, &l2, 'D', seq + 1);
    }
    out.push_str(&p_out);
    let d_count = 2 * entities.len();
    let t = format!("S{s_count:7}G{:7}D{d_count:7}P{p_seq:7}", g_lines.len());
    record(&mut out, &t, 'T', 1);
    Ok(out)
}

fn record(out: &mut String, data: &str, letter: char, seq: usize) {
    let _ = writeln!(out, "{data:<72}{letter}{seq:07}");
}

/// A count or pointer as an IGES integer; lengths of in-memory data are far below
/// `i64::MAX`, and a value that did not fit would fail the 8-column width check anyway.
fn to_i64(n: usize) -> i64 {
    i64::try_from(n).unwrap_or(i64::MAX)
}

fn field8(out: &mut String, v: i64) -> Result<(), WriteError> {
    let start = out.len();
    let _ = write!(out, "{v:>8}");
    if out.len() - start > 8 {
        return Err(WriteError::Field(format!(
            "{v} does not fit an 8-column DE field"
        )));
    }
    Ok(())
}

/// A parameter's text and whether it is a Hollerith string (which may be split).
fn param_token(p: &Param) -> Result<(String, bool), f64> {
    Ok(match p {
        Param::Empty => (String::new(), false),
        Param::Int(i) => (i.to_string(), false),
        Param::Real(x) => {
            let mut s = String::with_capacity(24);
            write_real(&mut s, *x).map_err(|e| e.0)?;
            (s, false)
        }
        Param::Text(t) => {
            let t: String = t
                .chars()
                .filter(|c| c.is_ascii() && !c.is_ascii_control())
                .collect();
            (format!("{}H{t}", t.len()), true)
        }
    })
}

/// The 26 Global parameters as tokens (defaults empty).
fn global_tokens(g: &Global) -> Result<Vec<(String, bool)>, WriteError> {
    let s = |v: &Option<String>| match v {
        Some(t) => param_token(&Param::Text(t.clone())).unwrap_or_default(),
        None => (String::new(), false),
    };
    let i = |v: Option<i64>| v.map_or((String::new(), false), |x| (x.to_string(), false));
    let r = |v: Option<f64>| -> Result<(String, bool), WriteError> {
        match v {
            Some(x) => param_token(&Param::Real(x))
                .map_err(|value| WriteError::NonFinite { entity: 0, value }),
            None => Ok((String::new(), false)),
        }
    };
    let delim = |c: char, default: char| {
        if c == default {
            (String::new(), false)
        } else {
            (format!("1H{c}"), true)
        }
    };
    Ok(vec![
        delim(g.param_delimiter, ','),
        delim(g.record_delimiter, ';'),
        s(&g.product_id_sender),
        s(&g.file_name),
        s(&g.native_system_id),
        s(&g.preprocessor_version),
        i(g.integer_bits),
        i(g.single_max_power),
        i(g.single_digits),
        i(g.double_max_power),
        i(g.double_digits),
        s(&g.product_id_receiver),
        r(g.model_scale)?,
        i(g.units_flag),
        s(&g.units_name),
        i(g.line_weight_gradations),
        r(g.max_line_width)?,
        s(&g.date),
        r(g.resolution)?,
        r(g.max_coordinate)?,
        s(&g.author),
        s(&g.organization),
        i(g.version_flag),
        i(g.drafting_standard),
        s(&g.modified_date),
        s(&g.application_protocol),
    ])
}

/// The parameter tokens of one entity: their text in one buffer, and for each token its
/// byte range and whether it is a Hollerith string (which may be split).
#[derive(Default)]
struct Tokens {
    text: String,
    spans: Vec<(usize, usize, bool)>,
}

impl Tokens {
    fn clear(&mut self) {
        self.text.clear();
        self.spans.clear();
    }

    /// Appends a parameter's text (as [`param_token`] would produce it).
    fn push_param(&mut self, p: &Param) -> Result<(), f64> {
        let start = self.text.len();
        let holl = match p {
            Param::Empty => false,
            Param::Int(i) => {
                push_int(&mut self.text, *i);
                false
            }
            Param::Real(x) => {
                write_real(&mut self.text, *x).map_err(|e| e.0)?;
                false
            }
            Param::Text(_) => {
                let (t, holl) = param_token(p)?;
                self.text.push_str(&t);
                holl
            }
        };
        self.spans.push((start, self.text.len(), holl));
        Ok(())
    }

    fn push_token(&mut self, t: &str, holl: bool) {
        let start = self.text.len();
        self.text.push_str(t);
        self.spans.push((start, self.text.len(), holl));
    }
}

/// Appends `n` copies of the ASCII byte `c`.
fn pad(out: &mut String, c: u8, n: usize) {
    out.extend(std::iter::repeat_n(char::from(c), n));
}

/// Appends `v` right-justified in `width` columns, padded with `fill` (as `{v:>w}` or
/// `{v:0w}`; wider values are written in full).
fn push_uint(out: &mut String, mut v: usize, width: usize, fill: u8) {
    let mut digits = [0u8; 20];
    let mut n = 0;
    loop {
        // v % 10 < 10 fits in u8.
        #[allow(clippy::cast_possible_truncation)]
        let digit = (v % 10) as u8;
        digits[19 - n] = b'0' + digit;
        n += 1;
        v /= 10;
        if v == 0 || n == 20 {
            break;
        }
    }
    pad(out, fill, width.saturating_sub(n));
    for &d in &digits[20 - n..] {
        out.push(char::from(d));
    }
}

/// Appends a signed integer as `{i}` does.
fn push_int(out: &mut String, i: i64) {
    if i < 0 {
        out.push('-');
    }
    let Ok(v) = usize::try_from(i.unsigned_abs()) else {
        let _ = write!(out, "{}", i.unsigned_abs());
        return;
    };
    push_uint(out, v, 0, b' ');
}

/// Packs tokens into lines of at most `width` columns, each token followed by the
/// parameter delimiter (the last by the record delimiter). Only Hollerith tokens are split:
/// they fill their line to exactly `width` columns and continue on the next.
fn pack(tokens: &[(String, bool)], width: usize, pd: char, rd: char) -> Vec<String> {
    let mut toks = Tokens::default();
    for (t, holl) in tokens {
        toks.push_token(t, *holl);
    }
    let mut lines = Vec::new();
    let mut cur = String::with_capacity(width + 1);
    pack_into(&toks, width, pd, rd, &mut cur, |l| lines.push(l.to_owned()));
    lines
}

/// [`pack`] over a [`Tokens`] buffer, giving each line to `emit`; `cur` is scratch space.
fn pack_into(
    tokens: &Tokens,
    width: usize,
    pd: char,
    rd: char,
    cur: &mut String,
    mut emit: impl FnMut(&str),
) {
    cur.clear();
    let n = tokens.spans.len();
    for (k, &(a, b, holl)) in tokens.spans.iter().enumerate() {
        let t = tokens.text.get(a..b).unwrap_or_default();
        let d = if k + 1 == n { rd } else { pd };
        let need = t.len() + 1;
        if cur.len() + need > width && !cur.is_empty() && (!holl || need <= width) {
            emit(cur);
            cur.clear();
        }
        if cur.len() + need <= width {
            cur.push_str(t);
            cur.push(d);
            continue;
        }
        // A Hollerith string longer than what is left: fill lines exactly.
        let mut rest = t;
        while cur.len() + rest.len() > width {
            let take = width - cur.len();
            // Hollerith text is ASCII (filtered in `param_token`), so any byte is a boundary.
            let (head, tail) = rest.split_at(take.min(rest.len()));
            cur.push_str(head);
            rest = tail;
            emit(cur);
            cur.clear();
        }
        cur.push_str(rest);
        if cur.len() + 1 > width {
            emit(cur);
            cur.clear();
        }
        cur.push(d);
    }
    if n == 0 {
        cur.push(rd);
    }
    if !cur.is_empty() {
        emit(cur);
        cur.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_fields_match_std_formatting() {
        let mut vals: Vec<i64> = (-1000..1000).collect();
        for k in 0..19 {
            let p = 10i64.pow(k);
            vals.extend([p - 1, p, p + 1, -p, 1 - p]);
        }
        vals.extend([i64::MAX, i64::MIN, i64::MIN + 1]);
        for v in vals {
            let mut s = String::new();
            push_int(&mut s, v);
            assert_eq!(s, format!("{v}"));
            if let Ok(u) = usize::try_from(v) {
                let (mut a, mut b) = (String::new(), String::new());
                push_uint(&mut a, u, 7, b' ');
                push_uint(&mut b, u, 7, b'0');
                assert_eq!(a, format!("{u:>7}"));
                assert_eq!(b, format!("{u:07}"));
            }
        }
    }

    #[test]
    fn pack_never_splits_plain_tokens() {
        let toks: Vec<(String, bool)> = (0..40)
            .map(|k| (format!("{}.5", k * 1000), false))
            .collect();
        let lines = pack(&toks, 64, ',', ';');
        for l in &lines {
            assert!(l.len() <= 64);
            assert!(l.ends_with(',') || l.ends_with(';'), "{l}");
        }
        assert_eq!(lines.concat().matches(',').count(), 39);
    }

    #[test]
    fn hollerith_fills_lines_exactly() {
        let long = format!("70H{}", "x".repeat(70));
        let toks = vec![("1".to_owned(), false), (long.clone(), true)];
        let lines = pack(&toks, 64, ',', ';');
        assert_eq!(lines[0].len(), 64);
        assert_eq!(lines.concat(), format!("1,{long};"));
    }
}
