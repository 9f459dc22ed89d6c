//! The IGES 5.3 writer: exact 80-column records (section 2.2.4).
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
//! Typed records in, text out: [`write_with`] takes each entity's record (anything that
//! [`WriteParams`], e.g. the records of [`super::records`]) and packs its parameters into
//! P lines in place, then fills in the D section. Reals go through
//! [`crate::real::write_real`]: shortest round-trip digits, always with a decimal point, so
//! read -> write -> read is bit-identical. Sequence numbers are zero-padded (`P0000012`) as
//! Open CASCADE writes them.

use std::fmt::Write as _;

use super::P_DATA_COLUMNS;
use super::directory::DirectoryEntry;
use super::error::WriteError;
use super::global::Global;
use crate::real::{NonFiniteReal, write_real};

/// A typed record that writes its parameters (entity type first) in the order of its
/// table in the standard.
pub trait WriteParams {
    /// Writes the parameters.
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal>;
}

/// The DE pointer entity `index` (0-based position in the write list) receives.
pub fn pointer_of(index: usize) -> usize {
    2 * index + 1
}

/// Writes a complete IGES file whose parameter data `params` writes straight into the
/// P section: `params(i, w)` gives entity `i`'s parameters (entity type first) to `w`,
/// usually by [`WriteParams::write_params`] of its record; `des` are the entities'
/// Directory Entries (the writer computes the DE pointer, parameter pointer and parameter
/// line count; `transform` must already hold the DE pointer of a written 124, entity `i`
/// getting pointer `2 i + 1`). `p_bytes` is an estimate of the P section's size (the output
/// is allocated once when it is not low).
///
/// Packing (section 2.2.4.5): a parameter is never split across records except a
/// Hollerith string, which fills its record and continues. Each token is formatted in place
/// and lines are closed with column arithmetic, with no parameter list, token buffer or
/// second copy of the P section; the result equals a plain pack of the same tokens
/// (tested against one).
pub fn write_with<F>(
    start: &str,
    global: &Global,
    des: &[DirectoryEntry],
    p_bytes: usize,
    mut params: F,
) -> Result<String, WriteError>
where
    F: FnMut(usize, &mut ParamWriter<'_>) -> Result<(), NonFiniteReal>,
{
    let (pd, rd) = delimiters(global)?;
    // Each DE record is 81 bytes while the sequence number fits 7 digits.
    let d_len = des.len().saturating_mul(2 * 81);
    let mut out = String::with_capacity(8192_usize.saturating_add(d_len).saturating_add(p_bytes));
    let s_count = write_start(&mut out, start);
    let g_count = write_global(&mut out, global)?;
    // Room for the D section, written once the P pointers are known.
    let d_start = out.len();
    pad(&mut out, b' ', d_len);
    let mut placements = Vec::with_capacity(des.len());
    let mut w = ParamWriter {
        line_start: out.len(),
        out: &mut out,
        de: 0,
        seq: 0,
        tail: *b"        P0000000\n",
        pd,
        rd,
        tokens: 0,
        scratch: String::new(),
    };
    for index in 0..des.len() {
        w.start_entity(pointer_of(index));
        let first = w.seq + 1;
        params(index, &mut w).map_err(|e| WriteError::NonFinite {
            entity: index,
            value: e.0,
        })?;
        w.end_entity();
        placements.push((first, w.seq + 1 - first));
    }
    let p_seq = w.seq;
    let mut d = String::with_capacity(d_len);
    write_directory(&mut d, des.iter(), &placements)?;
    // Same length (the usual case): an in-place copy; otherwise the tail moves.
    out.replace_range(d_start..d_start + d_len, &d);
    write_terminate(&mut out, s_count, g_count, 2 * des.len(), p_seq);
    Ok(out)
}

/// Writes one entity's parameters straight into the P section (see [`write_with`]).
#[derive(Debug)]
pub struct ParamWriter<'a> {
    out: &'a mut String,
    /// Where the current line's data begins in `out`.
    line_start: usize,
    /// The entity's DE pointer (columns 66-72).
    de: usize,
    /// The last P sequence number written.
    seq: usize,
    /// Columns 65-80 and the line end, ` {de:>7}P{seq:07}\n`: the DE pointer written once
    /// per entity, the sequence number counted up in place (while both fit 7 digits).
    tail: [u8; 17],
    pd: char,
    rd: char,
    /// Parameters written for the current entity.
    tokens: usize,
    /// A token moved to the next line.
    scratch: String,
}

impl ParamWriter<'_> {
    /// An empty parameter (the default value).
    pub fn empty(&mut self) {
        let start = self.out.len();
        self.place(start);
    }

    /// An integer (or pointer, or logical).
    #[inline]
    pub fn int(&mut self, i: i64) {
        let start = self.out.len();
        push_int(self.out, i);
        self.place(start);
    }

    /// A real, as [`crate::real::write_real`] writes it.
    #[inline]
    pub fn real(&mut self, x: f64) -> Result<(), NonFiniteReal> {
        let start = self.out.len();
        write_real(self.out, x)?;
        self.place(start);
        Ok(())
    }

    /// A string, written as a Hollerith constant `nH...` (non-ASCII and control characters
    /// dropped).
    pub fn text(&mut self, t: &str) {
        self.push_general(&hollerith(t), true);
    }

    /// Starts the parameters of the entity with DE pointer `de`.
    fn start_entity(&mut self, de: usize) {
        self.de = de;
        self.tokens = 0;
        self.tail[1..8].fill(b' ');
        if de < 10_000_000 {
            fill_digits(&mut self.tail[1..8], de);
        }
    }

    /// Columns used on the current line.
    fn cur(&self) -> usize {
        self.out.len() - self.line_start
    }

    /// A plain token just appended at `start`: keep it on this line when it fits with its
    /// delimiter, else re-place it by the general rules.
    #[inline]
    fn place(&mut self, start: usize) {
        let len = self.out.len() - start;
        if start - self.line_start + len < P_DATA_COLUMNS {
            self.out.push(self.pd);
            self.tokens += 1;
            return;
        }
        let mut token = std::mem::take(&mut self.scratch);
        token.clear();
        token.push_str(self.out.get(start..).unwrap_or_default());
        self.out.truncate(start);
        self.push_general(&token, false);
        self.scratch = token;
    }

    /// [`pack_into`]'s rules for one token, written in place.
    fn push_general(&mut self, t: &str, holl: bool) {
        let width = P_DATA_COLUMNS;
        let need = t.len() + 1;
        if self.cur() + need > width && self.cur() != 0 && (!holl || need <= width) {
            self.finish_line();
        }
        self.tokens += 1;
        if self.cur() + need <= width {
            self.out.push_str(t);
            self.out.push(self.pd);
            return;
        }
        // A Hollerith string longer than what is left: fill lines exactly.
        let mut rest = t;
        while self.cur() + rest.len() > width {
            let take = width.saturating_sub(self.cur());
            // Hollerith text is ASCII (filtered in `hollerith`), so any byte is a boundary.
            let (head, tail) = rest
                .split_at_checked(take.min(rest.len()))
                .unwrap_or((rest, ""));
            self.out.push_str(head);
            rest = tail;
            self.finish_line();
        }
        self.out.push_str(rest);
        if self.cur() + 1 > width {
            self.finish_line();
        }
        self.out.push(self.pd);
    }

    /// Ends the entity: the last delimiter becomes the record delimiter; closes the line.
    fn end_entity(&mut self) {
        if self.tokens > 0 && self.out.len() > self.line_start {
            self.out.pop();
        }
        self.out.push(self.rd);
        self.finish_line();
    }

    /// Pads the line to 64 columns and adds the DE pointer and the sequence number.
    fn finish_line(&mut self) {
        self.seq += 1;
        // The sequence digits follow `seq` (an ASCII counter: usually one digit changes).
        for d in self.tail[9..16].iter_mut().rev() {
            if *d == b'9' {
                *d = b'0';
            } else {
                *d += 1;
                break;
            }
        }
        let used = self.cur();
        pad(self.out, b' ', P_DATA_COLUMNS.saturating_sub(used));
        if self.de < 10_000_000 && self.seq < 10_000_000 {
            // Only ASCII is in `tail`; one validated copy is cheaper than 17 pushes here.
            self.out
                .push_str(std::str::from_utf8(&self.tail).unwrap_or_default());
        } else {
            self.out.push(' ');
            push_uint(self.out, self.de, 7, b' ');
            self.out.push('P');
            push_uint(self.out, self.seq, 7, b'0');
            self.out.push('\n');
        }
        self.line_start = self.out.len();
    }
}

/// Writes the digits of `v` right-aligned into `field` (which keeps its fill where no digit
/// goes); `v` must fit.
fn fill_digits(field: &mut [u8], mut v: usize) {
    for slot in field.iter_mut().rev() {
        // v % 10 < 10 fits in u8.
        #[allow(clippy::cast_possible_truncation)]
        let digit = (v % 10) as u8;
        *slot = b'0' + digit;
        v /= 10;
        if v == 0 {
            break;
        }
    }
}

/// The parameter and record delimiters, when they can be written.
fn delimiters(global: &Global) -> Result<(char, char), WriteError> {
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
    Ok((pd, rd))
}

/// The S section; returns its record count.
fn write_start(out: &mut String, start: &str) -> usize {
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
            record(out, &chunk, 'S', s_count);
            if rest.is_empty() {
                break;
            }
        }
    }
    if s_count == 0 {
        s_count = 1;
        record(out, "", 'S', 1);
    }
    s_count
}

/// The G section; returns its record count.
fn write_global(out: &mut String, global: &Global) -> Result<usize, WriteError> {
    let g = global_tokens(global)?;
    let g_lines = pack(&g, 72, global.param_delimiter, global.record_delimiter);
    for (k, l) in g_lines.iter().enumerate() {
        record(out, l, 'G', k + 1);
    }
    Ok(g_lines.len())
}

/// The D section: two records per entity, with the P pointer and line count of each.
fn write_directory<'d>(
    out: &mut String,
    des: impl Iterator<Item = &'d DirectoryEntry>,
    placements: &[(usize, usize)],
) -> Result<(), WriteError> {
    for (index, (de, &(first, count))) in des.zip(placements).enumerate() {
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
        record(out, &l1, 'D', seq);
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
            text8(&mut l2, &r);
        }
        let label: String = de
            .label
            .chars()
            .filter(|c| c.is_ascii_graphic() || *c == ' ')
            .take(8)
            .collect();
        text8(&mut l2, &label);
        field8(&mut l2, de.subscript)?;
        record(out, &l2, 'D', seq + 1);
    }
    Ok(())
}

/// The T record.
fn write_terminate(out: &mut String, s: usize, g: usize, d: usize, p: usize) {
    let t = format!("S{s:7}G{g:7}D{d:7}P{p:7}");
    record(out, &t, 'T', 1);
}

/// One 80-column record: `data` left-aligned in columns 1-72, the section letter, the
/// sequence number in columns 74-80 (IGES 5.3 section 2.1), as `{data:<72}{letter}{seq:07}`.
fn record(out: &mut String, data: &str, letter: char, seq: usize) {
    out.push_str(data);
    pad(out, b' ', 72usize.saturating_sub(data.chars().count()));
    out.push(letter);
    push_uint(out, seq, 7, b'0');
    out.push('\n');
}

/// A count or pointer as an IGES integer; lengths of in-memory data are far below
/// `i64::MAX`, and a value that did not fit would fail the 8-column width check anyway.
fn to_i64(n: usize) -> i64 {
    i64::try_from(n).unwrap_or(i64::MAX)
}

/// An integer right-aligned in an 8-column DE field (IGES 5.3 section 2.2.4.4), as
/// `{v:>8}` writes it; a value that needs more columns is refused.
fn field8(out: &mut String, v: i64) -> Result<(), WriteError> {
    let mut buf = [0u8; 20];
    let digits = decimal_digits(&mut buf, v.unsigned_abs());
    let width = digits.len() + usize::from(v < 0);
    if width > 8 {
        return Err(WriteError::Field(format!(
            "{v} does not fit an 8-column DE field"
        )));
    }
    pad(out, b' ', 8 - width);
    if v < 0 {
        out.push('-');
    }
    for &d in digits {
        out.push(char::from(d));
    }
    Ok(())
}

/// The decimal digits of `v` (ASCII, most significant first), in the end of `buf`.
fn decimal_digits(buf: &mut [u8; 20], mut v: u64) -> &[u8] {
    let mut n = 0;
    loop {
        // v % 10 < 10 fits in u8.
        #[allow(clippy::cast_possible_truncation)]
        let digit = (v % 10) as u8;
        buf[19 - n] = b'0' + digit;
        n += 1;
        v /= 10;
        if v == 0 || n == 20 {
            break;
        }
    }
    &buf[20 - n..]
}

/// Text of at most 8 characters right-aligned in an 8-column DE field, as `{t:>8}` writes it.
fn text8(out: &mut String, t: &str) {
    pad(out, b' ', 8usize.saturating_sub(t.len()));
    out.push_str(t);
}

/// A string as a Hollerith constant `nH...`, non-ASCII and control characters dropped.
fn hollerith(t: &str) -> String {
    let t: String = t
        .chars()
        .filter(|c| c.is_ascii() && !c.is_ascii_control())
        .collect();
    format!("{}H{t}", t.len())
}

/// The 26 Global parameters as tokens (defaults empty).
fn global_tokens(g: &Global) -> Result<Vec<(String, bool)>, WriteError> {
    let s = |v: &Option<String>| match v {
        Some(t) => (hollerith(t), true),
        None => (String::new(), false),
    };
    let i = |v: Option<i64>| v.map_or((String::new(), false), |x| (x.to_string(), false));
    let r = |v: Option<f64>| -> Result<(String, bool), WriteError> {
        match v {
            Some(x) => {
                let mut t = String::with_capacity(24);
                write_real(&mut t, x).map_err(|e| WriteError::NonFinite {
                    entity: 0,
                    value: e.0,
                })?;
                Ok((t, false))
            }
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

/// Appends `n` copies of the ASCII byte `c` (spaces and zeros from a constant: padding is
/// a fifth of every P record).
fn pad(out: &mut String, c: u8, n: usize) {
    const SPACES: &str = "                                                                ";
    const ZEROS: &str = "0000000000000000000000000000000000000000000000000000000000000000";
    let run = match c {
        b' ' => SPACES,
        b'0' => ZEROS,
        _ => {
            out.extend(std::iter::repeat_n(char::from(c), n));
            return;
        }
    };
    let mut n = n;
    while n > 0 {
        let k = n.min(run.len());
        out.push_str(run.get(..k).unwrap_or_default());
        n -= k;
    }
}

/// Appends `v` right-justified in `width` columns, padded with `fill` (as `{v:>w}` or
/// `{v:0w}`; wider values are written in full).
fn push_uint(out: &mut String, v: usize, width: usize, fill: u8) {
    let mut buf = [0u8; 20];
    let digits = decimal_digits(&mut buf, v as u64);
    pad(out, fill, width.saturating_sub(digits.len()));
    for &d in digits {
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
    let mut lines = Vec::new();
    let mut cur = String::with_capacity(width + 1);
    let n = tokens.len();
    for (k, (t, holl)) in tokens.iter().enumerate() {
        let d = if k + 1 == n { rd } else { pd };
        let need = t.len() + 1;
        if cur.len() + need > width && !cur.is_empty() && (!holl || need <= width) {
            lines.push(std::mem::take(&mut cur));
        }
        if cur.len() + need <= width {
            cur.push_str(t);
            cur.push(d);
            continue;
        }
        // A Hollerith string longer than what is left: fill lines exactly.
        let mut rest = t.as_str();
        while cur.len() + rest.len() > width {
            let take = width - cur.len();
            // Hollerith text is ASCII (filtered in `hollerith`), so any byte is a boundary.
            let (head, tail) = rest
                .split_at_checked(take.min(rest.len()))
                .unwrap_or((rest, ""));
            cur.push_str(head);
            rest = tail;
            lines.push(std::mem::take(&mut cur));
        }
        cur.push_str(rest);
        if cur.len() + 1 > width {
            lines.push(std::mem::take(&mut cur));
        }
        cur.push(d);
    }
    if n == 0 {
        cur.push(rd);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
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

    /// One parameter of the plain reference writer below.
    #[derive(Debug, Clone)]
    enum Param {
        Empty,
        Int(i64),
        Real(f64),
        Text(String),
    }

    fn param_strategy() -> impl proptest::strategy::Strategy<Value = Param> {
        use proptest::prelude::*;
        prop_oneof![
            Just(Param::Empty),
            any::<i64>().prop_map(Param::Int),
            (-1000i64..1000).prop_map(Param::Int),
            any::<u64>()
                .prop_map(f64::from_bits)
                .prop_filter("finite", |x| x.is_finite())
                .prop_map(Param::Real),
            (-4000i32..4000).prop_map(|k| Param::Real(f64::from(k) / 8.0)),
            prop::sample::select(vec![0.0, -0.0, 1e-300, 1e300, 5e-324, 2.2e-310, f64::MAX])
                .prop_map(Param::Real),
            "[ -~]{0,150}".prop_map(Param::Text),
            "\\PC{0,80}".prop_map(Param::Text),
        ]
    }

    /// The plain definition of the file (section 2.2.4): each entity's tokens packed by
    /// [`pack`] into 64 columns, each line followed by the back-pointer and sequence number
    /// with `format!`; the D section after the P pointers are known.
    fn reference(
        start: &str,
        global: &Global,
        entities: &[(DirectoryEntry, Vec<Param>)],
    ) -> Result<String, WriteError> {
        let (pd, rd) = delimiters(global)?;
        let mut out = String::new();
        let s_count = write_start(&mut out, start);
        let g_count = write_global(&mut out, global)?;
        let mut p = String::new();
        let mut seq = 0;
        let mut placements = Vec::new();
        for (index, (_, params)) in entities.iter().enumerate() {
            let mut toks = Vec::new();
            for param in params {
                toks.push(match param {
                    Param::Empty => (String::new(), false),
                    Param::Int(i) => (i.to_string(), false),
                    Param::Real(x) => {
                        let mut t = String::new();
                        write_real(&mut t, *x).map_err(|e| WriteError::NonFinite {
                            entity: index,
                            value: e.0,
                        })?;
                        (t, false)
                    }
                    Param::Text(t) => (hollerith(t), true),
                });
            }
            let first = seq + 1;
            for l in pack(&toks, P_DATA_COLUMNS, pd, rd) {
                seq += 1;
                p += &format!("{l:<64} {:>7}P{seq:07}\n", pointer_of(index));
            }
            placements.push((first, seq + 1 - first));
        }
        write_directory(&mut out, entities.iter().map(|e| &e.0), &placements)?;
        out += &p;
        write_terminate(&mut out, s_count, g_count, 2 * entities.len(), seq);
        Ok(out)
    }

    fn fast(
        start: &str,
        global: &Global,
        entities: &[(DirectoryEntry, Vec<Param>)],
    ) -> Result<String, WriteError> {
        let des: Vec<DirectoryEntry> = entities.iter().map(|e| e.0.clone()).collect();
        write_with(start, global, &des, 0, |i, w| {
            for p in &entities[i].1 {
                match p {
                    Param::Empty => w.empty(),
                    Param::Int(v) => w.int(*v),
                    Param::Real(x) => w.real(*x)?,
                    Param::Text(t) => w.text(t),
                }
            }
            Ok(())
        })
    }

    fn global_for(pd: char, rd: char) -> Global {
        Global {
            param_delimiter: pd,
            record_delimiter: rd,
            file_name: Some("x.igs".to_owned()),
            max_coordinate: Some(12.5),
            ..Global::default()
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(500))]
        /// [`write_with`] writes the bytes of the plain definition, for any parameters
        /// (long Hollerith strings, empty entities, odd reals) and delimiters.
        #[test]
        fn write_with_equals_the_plain_definition(
            lists in proptest::collection::vec(proptest::collection::vec(param_strategy(), 0..40), 0..6),
            delims in proptest::sample::select(vec![(',', ';'), ('/', '!'), (';', ',')]),
            start in "\\PC{0,200}",
        ) {
            let global = global_for(delims.0, delims.1);
            let entities: Vec<(DirectoryEntry, Vec<Param>)> = lists
                .into_iter()
                .enumerate()
                .map(|(k, params)| (
                    DirectoryEntry {
                        entity_type: 126,
                        label: format!("L{k}"),
                        ..DirectoryEntry::default()
                    },
                    params,
                ))
                .collect();
            proptest::prop_assert_eq!(reference(&start, &global, &entities), fast(&start, &global, &entities));
        }
    }

    proptest::proptest! {
        /// The DE fields and 80-column records are written as `std::fmt` pads them
        /// (`{v:>8}`, `{t:>8}`, `{data:<72}{letter}{seq:07}`), and a value wider than 8
        /// columns is refused.
        #[test]
        fn fields_and_records_are_padded_as_fmt_pads_them(
            v in proptest::prelude::any::<i64>(),
            small in -9_999_999i64..=99_999_999,
            t in "[ -~]{0,8}",
            data in "[ -~]{0,72}",
            seq in 0usize..100_000_000,
        ) {
            for v in [v, small] {
                let mut out = String::from("x");
                let wide = format!("{v:>8}");
                match field8(&mut out, v) {
                    Ok(()) => proptest::prop_assert_eq!(&out[1..], wide.as_str()),
                    Err(_) => proptest::prop_assert!(wide.len() > 8),
                }
            }
            let mut out = String::new();
            text8(&mut out, &t);
            proptest::prop_assert_eq!(out, format!("{t:>8}"));
            let mut out = String::new();
            record(&mut out, &data, 'D', seq);
            proptest::prop_assert_eq!(out, format!("{data:<72}D{seq:07}\n"));
        }
    }

    #[test]
    fn write_with_reports_the_same_non_finite_value() {
        let global = global_for(',', ';');
        let entities = vec![
            (DirectoryEntry::default(), vec![Param::Int(1)]),
            (
                DirectoryEntry::default(),
                vec![
                    Param::Int(126),
                    Param::Real(1.0),
                    Param::Real(f64::INFINITY),
                ],
            ),
        ];
        let fast = fast("s", &global, &entities);
        assert_eq!(fast, reference("s", &global, &entities));
        assert!(matches!(fast, Err(WriteError::NonFinite { entity: 1, .. })));
    }
}
