//! A cursor over the text of one instance body: the ISO 10303-21 tokens (clause 6.3) and
//! lists (clause 12.2) that the one-pass readers of [`Scanned::bspline`](super::Scanned::bspline)
//! and [`Scanned::geometry_item`](super::Scanned::geometry_item) take straight from the
//! text, counting parameters and nesting as the grammar does.
//!
//! Every method returns `None` for anything it does not read exactly as the grammar would
//! (a comment, an INTEGER where a REAL is expected, a malformed token, a limit reached); the
//! caller then declines the instance and its decoder takes the general path (the grammar,
//! then the attribute tables), which gives the record or the located error.

use super::grammar::{ParamLimits, decimal_u64, is_number_char};
use super::scan::RawInstance;
use super::schema::Logical;
use super::string::StepString;
use crate::real::step_real_at;

/// Most elements reserved ahead for one list (8 MiB of `u64`): the count comes from the
/// commas before the next `)`, which only a well-formed list makes exact; larger lists grow.
const MAX_RESERVE: usize = 1 << 20;

/// A cursor over one instance body, counting parameters as the general lexer does.
pub(super) struct Reader<'a> {
    pub(super) text: &'a str,
    pub(super) b: &'a [u8],
    pub(super) i: usize,
    /// Parameters read so far, counted like `Cursor::parameter_list` (every scalar and every
    /// nested list, over all partial records).
    pub(super) count: usize,
    pub(super) max_params: usize,
    pub(super) max_depth: usize,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `raw`'s body in `text` (the text scanned; its keyword first,
    /// for a simple instance), under the parameter limits the instance was scanned with.
    pub(super) fn new(text: &'a str, raw: &RawInstance<'a>, limits: ParamLimits) -> Self {
        let body = raw.body(text);
        Reader {
            text: body,
            b: body.as_bytes(),
            i: 0,
            count: 0,
            max_params: limits.max_params,
            max_depth: limits.max_depth,
        }
    }

    /// Skips the whitespace the general lexer skips (comments are not taken here).
    #[inline(always)]
    pub(super) fn ws(&mut self) {
        // Most calls find a token right away (compact text between list elements).
        if self.b.get(self.i).is_some_and(|&c| c > b' ') {
            return;
        }
        while let Some(&c) = self.b.get(self.i) {
            if matches!(c, b' ' | b'\t' | b'\r' | b'\n' | b'\x0c') {
                self.i += 1;
            } else {
                break;
            }
        }
    }

    /// Whitespace, then the byte `c`.
    #[inline(always)]
    pub(super) fn byte(&mut self, c: u8) -> Option<()> {
        self.ws();
        if self.b.get(self.i) == Some(&c) {
            self.i += 1;
            Some(())
        } else {
            None
        }
    }

    /// Counts one parameter against the limit.
    #[inline(always)]
    pub(super) fn param(&mut self) -> Option<()> {
        self.count += 1;
        (self.count <= self.max_params).then_some(())
    }

    /// A STRING parameter: the raw text between the apostrophes, `''` kept as written (as
    /// the general lexer's `string_end` delimits it).
    pub(super) fn string(&mut self) -> Option<StepString<'a>> {
        self.byte(b'\'')?;
        self.param()?;
        let start = self.i;
        // Most names are empty (`''`): no search for the closing apostrophe.
        if self.b.get(start) == Some(&b'\'') && self.b.get(start + 1) != Some(&b'\'') {
            self.i = start + 1;
            return self.text.get(start..start).map(StepString::new);
        }
        loop {
            let p = self.i + memchr::memchr(b'\'', self.b.get(self.i..)?)?;
            if self.b.get(p + 1) == Some(&b'\'') {
                self.i = p + 2;
            } else {
                self.i = p + 1;
                return self.text.get(start..p).map(StepString::new);
            }
        }
    }

    /// An INTEGER parameter (whitespace first).
    #[inline]
    pub(super) fn integer(&mut self) -> Option<i64> {
        self.ws();
        self.param()?;
        self.integer_token()
    }

    /// An INTEGER token at the cursor: unsigned digits only, ending where the general
    /// lexer's number token ends (so `3.` or `3E1`, reals there, are declined). Does not
    /// count the parameter.
    #[inline(always)]
    pub(super) fn integer_token(&mut self) -> Option<i64> {
        let start = self.i;
        let mut e = start;
        while self.b.get(e).is_some_and(u8::is_ascii_digit) {
            e += 1;
        }
        if self.b.get(e).is_some_and(|&c| is_number_char(c)) {
            return None;
        }
        let v = i64::try_from(decimal_u64(self.b.get(start..e)?)?).ok()?;
        self.i = e;
        Some(v)
    }

    /// An enumeration `.NAME.` (upper-case letter first, then upper case, digits, `_`).
    #[inline]
    pub(super) fn enumeration(&mut self) -> Option<&'a str> {
        self.byte(b'.')?;
        self.param()?;
        let start = self.i;
        if !self.b.get(start).is_some_and(u8::is_ascii_uppercase) {
            return None;
        }
        let mut e = start + 1;
        while self
            .b
            .get(e)
            .is_some_and(|&c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_')
        {
            e += 1;
        }
        if self.b.get(e) != Some(&b'.') {
            return None;
        }
        self.i = e + 1;
        self.text.get(start..e)
    }

    /// A LOGICAL: `.T.`, `.F.` or `.U.`.
    #[inline]
    pub(super) fn logical(&mut self) -> Option<Logical> {
        match self.enumeration()? {
            "T" => Some(Logical::True),
            "F" => Some(Logical::False),
            "U" => Some(Logical::Unknown),
            _ => None,
        }
    }

    /// A REAL token at the cursor (no whitespace skipped), ending where the general lexer's
    /// number token ends. Does not count the parameter.
    #[inline(always)]
    pub(super) fn real_token(&mut self) -> Option<f64> {
        // The general lexer reads a number only from a sign or a digit (a `.` there starts an
        // enumeration).
        if !self
            .b
            .get(self.i)
            .is_some_and(|&c| c.is_ascii_digit() || c == b'-' || c == b'+')
        {
            return None;
        }
        let (v, end) = step_real_at(self.b, self.i).ok()?;
        // The general lexer takes the maximal run of number characters as one token
        // (`1.5E3X` and `1.5.2` are one bad token, not a number and then something). Its
        // check (`is_number_char` after the real) is not repeated here because the only
        // caller, `list`, accepts nothing after an element but whitespace, `,` or `)`, none
        // of which is a number character: such a token is declined there.
        self.i = end;
        Some(v)
    }

    /// A reference `#digits` at the cursor (no whitespace skipped). Does not count.
    #[inline(always)]
    pub(super) fn reference_token(&mut self) -> Option<u64> {
        if self.b.get(self.i) != Some(&b'#') {
            return None;
        }
        let start = self.i + 1;
        // Ids of up to 7 digits (files under ten million instances) in one word; longer
        // runs byte by byte, checked (`decimal_u64`).
        if let Some((v, n)) = short_digit_run(self.b, start) {
            self.i = start + n;
            return Some(v);
        }
        let mut e = start;
        while self.b.get(e).is_some_and(u8::is_ascii_digit) {
            e += 1;
        }
        let v = decimal_u64(self.b.get(start..e)?)?;
        self.i = e;
        Some(v)
    }

    /// Opens a list parameter: whitespace, `(`, counted as one parameter at nesting `depth`
    /// (1 for a record's parameter, as the general lexer's stack length). Returns the
    /// number of elements to reserve: `hint` (the length of a list that should have the
    /// same, such as the multiplicities for the knots) or else the commas counted up to the
    /// next `)`. Only a capacity: a longer list grows.
    #[inline]
    pub(super) fn open_list(&mut self, depth: usize, hint: Option<usize>) -> Option<usize> {
        self.byte(b'(')?;
        self.param()?;
        if depth >= self.max_depth {
            return None;
        }
        // Elements are scalars here, so a well-formed list ends at the next `)`.
        let n = match hint {
            Some(n) => n,
            None => commas_before_close(self.b, self.i) + 1,
        };
        let remaining = self.max_params.saturating_sub(self.count);
        Some(n.min(remaining).min(MAX_RESERVE))
    }

    /// A list of scalars read by `token`, opened at nesting `depth`.
    #[inline(always)]
    pub(super) fn list<T>(
        &mut self,
        depth: usize,
        token: fn(&mut Self) -> Option<T>,
        hint: Option<usize>,
    ) -> Option<Vec<T>> {
        let reserve = self.open_list(depth, hint)?;
        let mut out = Vec::with_capacity(reserve);
        self.elements(token, |v| {
            out.push(v);
            Some(())
        })?;
        Some(out)
    }

    /// The elements of a list [`Reader::open_list`] opened, read by `token` up to its `)`
    /// and each given to `push`; `None` for any other shape, or when `push` refuses one.
    #[inline(always)]
    pub(super) fn elements<T>(
        &mut self,
        token: fn(&mut Self) -> Option<T>,
        mut push: impl FnMut(T) -> Option<()>,
    ) -> Option<()> {
        // Elements allowed before the general lexer's parameter limit (`open_list` checked
        // that `count <= max_params`).
        let budget = self.max_params - self.count;
        let mut n = 0;
        self.ws();
        if self.b.get(self.i) == Some(&b')') {
            self.i += 1;
            return Some(());
        }
        loop {
            self.ws();
            if n >= budget {
                return None;
            }
            push(token(self)?)?;
            n += 1;
            // Compact text (`#1,#2,...`) has the delimiter right after the token.
            let mut c = self.b.get(self.i);
            if !matches!(c, Some(b',' | b')')) {
                self.ws();
                c = self.b.get(self.i);
            }
            match c {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    self.count += n;
                    return Some(());
                }
                _ => return None,
            }
        }
    }

    /// A list of lists of scalars (a surface's poles or weights). `shape`: the expected
    /// rows and row length (the weights have the poles' shape); without it the first row's
    /// length is the capacity hint for the others.
    pub(super) fn grid<T>(
        &mut self,
        token: fn(&mut Self) -> Option<T>,
        shape: Option<(usize, usize)>,
    ) -> Option<Vec<Vec<T>>> {
        self.byte(b'(')?;
        self.param()?;
        if 1 >= self.max_depth {
            return None;
        }
        let (rows_hint, mut row_hint) = match shape {
            Some((r, n)) => (r, Some(n)),
            None => (8, None),
        };
        let mut rows = Vec::with_capacity(rows_hint.min(MAX_RESERVE));
        self.ws();
        if self.b.get(self.i) == Some(&b')') {
            self.i += 1;
            return Some(rows);
        }
        loop {
            let row = self.list(2, token, row_hint)?;
            row_hint = Some(row.len());
            rows.push(row);
            self.ws();
            match self.b.get(self.i) {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    return Some(rows);
                }
                _ => return None,
            }
        }
    }

    /// A partial record's keyword: `[A-Z_] { A-Z | 0-9 | _ }`, the maximal run (a
    /// following lower-case letter is then not the `(` expected next).
    pub(super) fn keyword(&mut self) -> Option<&'a str> {
        self.ws();
        let start = self.i;
        if !self
            .b
            .get(start)
            .is_some_and(|&c| c.is_ascii_uppercase() || c == b'_')
        {
            return None;
        }
        let mut e = start + 1;
        while self
            .b
            .get(e)
            .is_some_and(|&c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_')
        {
            e += 1;
        }
        self.i = e;
        self.text.get(start..e)
    }
}

/// The number of commas in `b[from..]` before the first `)` (or the end), eight bytes at a
/// time: a list's element count, to size its vector once.
fn commas_before_close(b: &[u8], from: usize) -> usize {
    const LOW7: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    const ONES: u64 = 0x0101_0101_0101_0101;
    // 0x80 in each zero byte of `x` and nothing else (no borrow between bytes, so exact).
    let zero_bytes = |x: u64| !(((x & LOW7) + LOW7) | x | LOW7);
    let rest = b.get(from..).unwrap_or_default();
    let mut n = 0;
    let mut chunks = rest.chunks_exact(8);
    for c in &mut chunks {
        let Ok(word) = <[u8; 8]>::try_from(c) else {
            break;
        };
        let x = u64::from_le_bytes(word);
        let comma = zero_bytes(x ^ (ONES * u64::from(b',')));
        let close = zero_bytes(x ^ (ONES * u64::from(b')')));
        if close != 0 {
            // Bytes before the first `)` (little-endian: lower bytes come first).
            let before = (close & close.wrapping_neg()) - 1;
            return n + bytes_flagged(comma & before);
        }
        n += bytes_flagged(comma);
    }
    for &c in chunks.remainder() {
        match c {
            b')' => return n,
            b',' => n += 1,
            _ => {}
        }
    }
    n
}

/// The digit run at `b[i..]` if it has 1 to 7 digits followed by a non-digit:
/// `(value, digit count)`; `None` otherwise (no digit, or eight or more), for the byte loop
/// to decide. One word through the shared reader [`digit_word`](crate::real::digit_word)
/// (a SWAR non-digit mask and a multiply-shift conversion).
#[inline(always)]
fn short_digit_run(b: &[u8], i: usize) -> Option<(u64, usize)> {
    let (v, n) = crate::real::digit_word(b, i);
    (1..8).contains(&n).then_some((v, n))
}

/// How many bytes of a [`commas_before_close`] mask have their 0x80 flag: the flags moved
/// to bit 0 of each byte are summed into the top byte by one multiplication (at most 8, so
/// no carry; cheaper than `count_ones` without a POPCNT instruction in the baseline target).
#[inline(always)]
fn bytes_flagged(mask: u64) -> usize {
    let sum = ((mask >> 7).wrapping_mul(0x0101_0101_0101_0101)) >> 56;
    // At most 8.
    sum as usize
}
#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The word-at-a-time comma count equals a byte loop.
        #[test]
        fn comma_count_matches_a_byte_loop(
            text in prop::collection::vec(prop::sample::select(b",)#1 (\xac\xa9\x00\x2d\x28".to_vec()), 0..40),
            from in 0usize..40,
        ) {
            let mut expect = 0;
            for &c in text.get(from..).unwrap_or_default() {
                if c == b')' {
                    break;
                }
                expect += usize::from(c == b',');
            }
            prop_assert_eq!(commas_before_close(&text, from), expect);
        }
    }

    proptest! {
        /// The one-word digit run equals the byte loop and `decimal_u64`.
        #[test]
        fn short_digit_run_matches_a_byte_loop(
            text in prop::collection::vec(prop_oneof![
                4 => b'0'..=b'9', 1 => prop::sample::select(b",)/:#A \xff".to_vec())
            ], 0..14),
            from in 0usize..14,
        ) {
            let rest = text.get(from..).unwrap_or_default();
            let n = rest.iter().take_while(|c| c.is_ascii_digit()).count();
            let expect = (1..=7).contains(&n).then(|| (decimal_u64(&rest[..n]).unwrap(), n));
            prop_assert_eq!(short_digit_run(&text, from), expect);
        }
    }

    proptest! {
        /// A STRING is the text up to the first apostrophe not doubled (ISO 10303-21
        /// 6.3.4), with or without the empty-name shortcut: a byte loop says where.
        #[test]
        fn strings_end_at_the_first_single_apostrophe(
            body in prop::collection::vec(prop::sample::select(b"'a,)".to_vec()), 0..12),
        ) {
            let text = format!("'{}", String::from_utf8(body).unwrap());
            let b = text.as_bytes();
            let mut expect = None;
            let mut k = 1;
            while k < b.len() {
                if b[k] == b'\'' {
                    if b.get(k + 1) == Some(&b'\'') {
                        k += 2;
                        continue;
                    }
                    expect = Some((&text[1..k], k + 1));
                    break;
                }
                k += 1;
            }
            let mut r = Reader { text: &text, b, i: 0, count: 0, max_params: 10, max_depth: 4 };
            let got = r.string().map(|s| (s.raw.into_owned(), r.i));
            prop_assert_eq!(got, expect.map(|(s, i)| (s.to_owned(), i)));
        }
    }

    #[test]
    fn integers_are_not_step_reals() {
        // `integer_token` relies on a bare digit run not being a STEP REAL (ISO 10303-21
        // 6.3.3: the point is required), as the general lexer's number fast path does.
        assert!(step_real_at(b"3)", 0).is_err());
        assert!(step_real_at(b"3,", 0).is_err());
    }
}
