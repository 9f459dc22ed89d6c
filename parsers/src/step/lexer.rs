//! The Part 21 token rules (ISO 10303-21:2016 clause 6) and the parameter grammar
//! (clause 12.2), written as a hand-rolled byte scanner over one instance at a time.
//!
//! Why not nom combinators here: this is the hot loop of the reader (a target of
//! 300 MB/s), and nested lists must be parsed without recursion so the input cannot
//! control the stack depth. The scanner keeps an explicit stack of open lists, checked
//! against [`Limits::max_nesting_depth`](crate::Limits), and allocates only the parameter
//! vectors. Every failure is returned as `(kind, byte offset)`; the caller turns the offset
//! into a line and column.

use super::ast::{Body, Parameter, Record};
use super::error::ParseErrorKind;
use super::string::StepString;
use crate::real::parse_step_real;

/// A failure at a byte offset of the whole input.
pub(crate) type LexError = (ParseErrorKind, usize);
/// Result of a lexer rule.
pub(crate) type LResult<T> = Result<T, LexError>;

/// A position in the input, bounded by `end` (the `;` of the statement being parsed).
pub(crate) struct Cursor<'a> {
    pub(crate) text: &'a str,
    pub(crate) pos: usize,
    pub(crate) end: usize,
}

/// Limits the parameter parser enforces.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParamLimits {
    pub(crate) max_depth: usize,
    pub(crate) max_params: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor over `text[pos..end]`.
    pub(crate) fn new(text: &'a str, pos: usize, end: usize) -> Self {
        Cursor { text, pos, end }
    }

    fn bytes(&self) -> &'a [u8] {
        self.text.as_bytes()
    }

    /// The next byte, if before `end`.
    pub(crate) fn peek(&self) -> Option<u8> {
        if self.pos < self.end {
            self.bytes().get(self.pos).copied()
        } else {
            None
        }
    }

    /// Whether the remaining input starts with `s`.
    pub(crate) fn starts_with(&self, s: &str) -> bool {
        self.bytes()
            .get(self.pos..self.end)
            .is_some_and(|r| r.starts_with(s.as_bytes()))
    }

    /// Skips whitespace and `/* ... */` comments (clause 6.5: allowed between any tokens).
    #[inline]
    pub(crate) fn skip_ws(&mut self) -> LResult<()> {
        // Most calls find a token character right away: answer without entering the loop.
        match self.peek() {
            Some(c) if c > b' ' && c != b'/' => return Ok(()),
            None => return Ok(()),
            // One blank before a token (`#1 = A(...)`), or the line break between two
            // statements: step over it without the loop.
            Some(b' ' | b'\n') => {
                if let Some(&c) = self.bytes().get(self.pos + 1) {
                    if c > b' ' && c != b'/' && self.pos + 1 < self.end {
                        self.pos += 1;
                        return Ok(());
                    }
                }
            }
            _ => {}
        }
        self.skip_ws_slow()
    }

    /// [`Cursor::skip_ws`] once whitespace or a `/` was seen.
    fn skip_ws_slow(&mut self) -> LResult<()> {
        loop {
            match self.peek() {
                Some(b' ' | b'\t' | b'\r' | b'\n' | b'\x0c') => self.pos += 1,
                Some(b'/') if self.bytes().get(self.pos + 1) == Some(&b'*') => {
                    let from = self.pos + 2;
                    let hay = self.bytes().get(from..self.end).unwrap_or_default();
                    match memchr::memmem::find(hay, b"*/") {
                        Some(p) => self.pos = from + p + 2,
                        None => return Err((ParseErrorKind::UnterminatedComment, self.pos)),
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    /// An error "expected X" at the current position, describing what is there.
    pub(crate) fn expected(&self, expected: &'static str) -> LexError {
        (
            ParseErrorKind::Expected {
                expected,
                found: self.describe(),
            },
            self.pos,
        )
    }

    /// A short rendering of the input at the cursor.
    pub(crate) fn describe(&self) -> String {
        let rest = self.text.get(self.pos..self.end).unwrap_or_default();
        if rest.is_empty() {
            return "end of statement".to_owned();
        }
        let token: String = rest
            .chars()
            .take_while(|c| !c.is_whitespace())
            .take(16)
            .collect();
        format!("`{token}`")
    }

    /// Consumes `b` or fails with "expected `what`".
    pub(crate) fn expect_byte(&mut self, b: u8, what: &'static str) -> LResult<()> {
        if self.peek() == Some(b) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.expected(what))
        }
    }

    /// `keyword = user_defined_keyword | standard_keyword`;
    /// `standard_keyword = UPPER { UPPER | DIGIT }` (`_` counts as UPPER);
    /// `user_defined_keyword = "!" standard_keyword`. Lower case is a located error.
    pub(crate) fn keyword(&mut self) -> LResult<&'a str> {
        let start = self.pos;
        if self.peek() == Some(b'!') {
            self.pos += 1;
        }
        match self.peek() {
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {}
            _ => {
                self.pos = start;
                return Err(self.expected("a keyword"));
            }
        }
        let mut lower = false;
        let b = self.bytes();
        // Upper-case runs eight bytes at a time; the loop below then only sees the byte
        // that stopped the run (and the rest of a keyword with lower-case letters).
        let mut i = super::swar::keyword_run(b, self.pos, self.end);
        while i < self.end {
            let Some(&c) = b.get(i) else { break };
            match KEYWORD_CLASS[usize::from(c)] {
                KW_OK => i += 1,
                KW_LOWER => {
                    lower = true;
                    i += 1;
                }
                _ => break,
            }
        }
        self.pos = i;
        let kw = self.text.get(start..self.pos).unwrap_or_default();
        if lower {
            return Err((ParseErrorKind::LowercaseKeyword(kw.to_owned()), start));
        }
        Ok(kw)
    }

    /// `simple_record = keyword "(" [ parameter_list ] ")"`.
    pub(crate) fn record(&mut self, limits: ParamLimits, count: &mut usize) -> LResult<Record<'a>> {
        let keyword = self.keyword()?;
        self.skip_ws()?;
        if self.peek() != Some(b'(') {
            return Err(self.expected("`(`"));
        }
        let params = self.parameter_list(limits, count)?;
        Ok(Record { keyword, params })
    }

    /// `entity_instance_body = simple_record | "(" simple_record { simple_record } ")"`,
    /// followed by nothing but whitespace up to the statement's `;`.
    pub(crate) fn body(&mut self, limits: ParamLimits) -> LResult<Body<'a>> {
        let mut count = 0usize;
        self.skip_ws()?;
        let body = if self.peek() == Some(b'(') {
            self.pos += 1;
            let mut records = Vec::new();
            loop {
                self.skip_ws()?;
                match self.peek() {
                    Some(b')') if !records.is_empty() => {
                        self.pos += 1;
                        break;
                    }
                    None => return Err(self.expected("`)` closing the complex instance")),
                    _ => records.push(self.record(limits, &mut count)?),
                }
            }
            Body::Complex(records)
        } else {
            Body::Simple(self.record(limits, &mut count)?)
        };
        self.skip_ws()?;
        if self.pos < self.end {
            return Err(self.expected("`;`"));
        }
        Ok(body)
    }

    /// `"(" [ parameter { "," parameter } ] ")"`, iteratively: the cursor is on the `(`.
    ///
    /// Values of all open lists share one stack; a closing `)` moves its list's values out
    /// with `split_off`, so each list costs exactly one allocation of its final size.
    pub(crate) fn parameter_list(
        &mut self,
        limits: ParamLimits,
        count: &mut usize,
    ) -> LResult<Vec<Parameter<'a>>> {
        #[derive(Clone, Copy, PartialEq)]
        enum State {
            Start,
            AfterValue,
            AfterComma,
        }
        #[derive(Clone, Copy)]
        struct Frame<'a> {
            typed: Option<(&'a str, usize)>,
            start: usize,
            state: State,
        }
        self.pos += 1;
        let mut values: Vec<Parameter<'a>> = Vec::with_capacity(16);
        let mut stack: Vec<Frame<'a>> = Vec::with_capacity(4);
        stack.push(Frame {
            typed: None,
            start: 0,
            state: State::Start,
        });
        loop {
            self.skip_ws()?;
            let Some(c) = self.peek() else {
                return Err(self.expected("`)`"));
            };
            let depth = stack.len();
            let Some(top) = stack.last_mut() else {
                return Err(self.expected("a parameter"));
            };
            match c {
                b')' => {
                    if top.state == State::AfterComma {
                        return Err(self.expected("a parameter after `,`"));
                    }
                    self.pos += 1;
                    let frame = *top;
                    stack.pop();
                    let items = values.split_off(frame.start.min(values.len()));
                    let value = match frame.typed {
                        None => Parameter::List(items),
                        Some((kw, at)) => {
                            let mut items = items;
                            match (items.pop(), items.is_empty()) {
                                (Some(v), true) => Parameter::Typed(kw, Box::new(v)),
                                _ => return Err((ParseErrorKind::TypedArity(kw.to_owned()), at)),
                            }
                        }
                    };
                    match stack.last_mut() {
                        None => {
                            return match value {
                                Parameter::List(items) => Ok(items),
                                _ => Err(self.expected("a parameter list")),
                            };
                        }
                        Some(parent) => {
                            values.push(value);
                            parent.state = State::AfterValue;
                        }
                    }
                }
                b',' => {
                    if top.state != State::AfterValue {
                        return Err(self.expected("a parameter"));
                    }
                    top.state = State::AfterComma;
                    self.pos += 1;
                }
                _ => {
                    if top.state == State::AfterValue {
                        return Err(self.expected("`,` or `)`"));
                    }
                    *count += 1;
                    if *count > limits.max_params {
                        return Err((
                            ParseErrorKind::TooManyParameters(limits.max_params),
                            self.pos,
                        ));
                    }
                    let opens = c == b'(' || c == b'!' || c.is_ascii_alphabetic();
                    if opens && depth >= limits.max_depth {
                        return Err((ParseErrorKind::NestingTooDeep(limits.max_depth), self.pos));
                    }
                    if c == b'(' {
                        self.pos += 1;
                        stack.push(Frame {
                            typed: None,
                            start: values.len(),
                            state: State::Start,
                        });
                    } else if opens {
                        let at = self.pos;
                        let kw = self.keyword()?;
                        self.skip_ws()?;
                        self.expect_byte(b'(', "`(` after a typed parameter's keyword")?;
                        stack.push(Frame {
                            typed: Some((kw, at)),
                            start: values.len(),
                            state: State::Start,
                        });
                    } else {
                        top.state = State::AfterValue;
                        let v = self.scalar()?;
                        values.push(v);
                        self.scalar_run(&mut values, limits, count)?;
                    }
                }
            }
        }
    }

    /// After a scalar: the rest of a run `,#12,#13,...` or `,1.5,-2.E-3,...` with no
    /// blanks, read in a tight loop (pole lists, knots and weights are most of a B-spline's
    /// text). Stops, leaving the cursor before the `,`, at anything else (a blank, a
    /// comment, a `)`, a malformed token), which the general loop then handles, so the
    /// values and errors are the same as without this loop.
    #[inline]
    fn scalar_run(
        &mut self,
        values: &mut Vec<Parameter<'a>>,
        limits: ParamLimits,
        count: &mut usize,
    ) -> LResult<()> {
        let b = self.bytes();
        loop {
            let at = self.pos + 1;
            if self.pos + 2 >= self.end || b.get(self.pos) != Some(&b',') {
                return Ok(());
            }
            let (value, end) = match b.get(at) {
                Some(b'#') => {
                    let mut e = at + 1;
                    while e < self.end && b.get(e).is_some_and(u8::is_ascii_digit) {
                        e += 1;
                    }
                    match b.get(at + 1..e).and_then(decimal_u64) {
                        Some(id) => (Parameter::Reference(id), e),
                        None => return Ok(()),
                    }
                }
                Some(c) if c.is_ascii_digit() || *c == b'-' || *c == b'+' => {
                    match crate::real::step_real_at(b, at) {
                        Ok((v, e)) if e <= self.end => (Parameter::Real(v), e),
                        _ => return Ok(()),
                    }
                }
                _ => return Ok(()),
            };
            // The token must end where the general lexer's token would (`#12A`, `1.5.2`
            // and `1.5E3X` are left to it for the error).
            if b.get(end).is_some_and(|&c| is_number_char(c)) {
                return Ok(());
            }
            *count += 1;
            if *count > limits.max_params {
                return Err((ParseErrorKind::TooManyParameters(limits.max_params), at));
            }
            values.push(value);
            self.pos = end;
        }
    }

    /// One untyped, non-list parameter: string, binary, enumeration, reference, `$`, `*`,
    /// INTEGER or REAL.
    fn scalar(&mut self) -> LResult<Parameter<'a>> {
        let start = self.pos;
        let b = self.bytes();
        match self.peek() {
            Some(b'\'') => {
                let end = string_end(b, start, self.end)?;
                self.pos = end + 1;
                Ok(Parameter::String(StepString::new(
                    self.text.get(start + 1..end).unwrap_or_default(),
                )))
            }
            Some(b'"') => {
                let hay = b.get(start + 1..self.end).unwrap_or_default();
                let Some(len) = memchr::memchr(b'"', hay) else {
                    return Err((ParseErrorKind::InvalidBinary, start));
                };
                let digits = self
                    .text
                    .get(start + 1..start + 1 + len)
                    .unwrap_or_default();
                let ok = digits.bytes().all(|d| d.is_ascii_hexdigit())
                    && matches!(digits.bytes().next(), Some(b'0'..=b'3'));
                if !ok {
                    return Err((ParseErrorKind::InvalidBinary, start));
                }
                self.pos = start + len + 2;
                Ok(Parameter::Binary(digits))
            }
            Some(b'.') => {
                self.pos += 1;
                let from = self.pos;
                while let Some(c) = self.peek() {
                    if c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_' {
                        self.pos += 1;
                    } else {
                        break;
                    }
                }
                let value = self.text.get(from..self.pos).unwrap_or_default();
                if !value.as_bytes().first().is_some_and(u8::is_ascii_uppercase) {
                    self.pos = from;
                    return Err(self.expected("an upper-case enumeration value"));
                }
                if self.peek() != Some(b'.') {
                    return Err(self.expected("`.` closing the enumeration"));
                }
                self.pos += 1;
                Ok(Parameter::Enumeration(value))
            }
            Some(b'#') => {
                self.pos += 1;
                let id = self.digits();
                match decimal_u64(id.as_bytes()) {
                    Some(v) => Ok(Parameter::Reference(v)),
                    None => Err((ParseErrorKind::InvalidId(id.to_owned()), start)),
                }
            }
            Some(b'$') => {
                self.pos += 1;
                Ok(Parameter::Null)
            }
            Some(b'*') => {
                self.pos += 1;
                Ok(Parameter::Derived)
            }
            Some(c) if c == b'+' || c == b'-' || c.is_ascii_digit() => self.number(),
            _ => Err(self.expected("a parameter")),
        }
    }

    /// A run of ASCII digits.
    fn digits(&mut self) -> &'a str {
        let from = self.pos;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.pos += 1;
        }
        self.text.get(from..self.pos).unwrap_or_default()
    }

    /// `INTEGER = [ SIGN ] DIGIT { DIGIT }` or `REAL` (checked by [`parse_step_real`]).
    /// The token is the maximal run of characters that can belong to a number (letters
    /// included), so `1.52.3` and `1.e5` are one bad token, not a number and garbage.
    fn number(&mut self) -> LResult<Parameter<'a>> {
        let start = self.pos;
        // Fast path, one pass: a well-formed REAL followed by a delimiter. Anything else
        // (integers, malformed tokens) takes the token-then-check path below, which gives
        // the same values and the errors.
        if let Ok((v, end)) = crate::real::step_real_at(self.bytes(), start) {
            if end <= self.end && !self.bytes().get(end).is_some_and(|&c| is_number_char(c)) {
                self.pos = end;
                return Ok(Parameter::Real(v));
            }
        }
        self.pos += 1;
        while self.peek().is_some_and(is_number_char) {
            self.pos += 1;
        }
        let token = self.text.get(start..self.pos).unwrap_or_default();
        if token.contains(['.', 'E', 'e']) {
            parse_step_real(token)
                .map(Parameter::Real)
                .map_err(|e| (ParseErrorKind::from((e, token.to_owned())), start))
        } else {
            let digits = token.strip_prefix(['+', '-']).unwrap_or(token);
            if digits.is_empty() || !digits.bytes().all(|d| d.is_ascii_digit()) {
                return Err((
                    ParseErrorKind::Expected {
                        expected: "a number",
                        found: format!("`{token}`"),
                    },
                    start,
                ));
            }
            let magnitude = decimal_u64(digits.as_bytes()).and_then(|m| i64::try_from(m).ok());
            if let Some(m) = magnitude {
                return Ok(Parameter::Integer(if token.starts_with('-') {
                    -m
                } else {
                    m
                }));
            }
            // i64::MIN and overflow: std decides and reports.
            token
                .parse::<i64>()
                .map(Parameter::Integer)
                .map_err(|_| (ParseErrorKind::IntegerOverflow(token.to_owned()), start))
        }
    }
}

/// [`KEYWORD_CLASS`] values: not a keyword character, an upper-case letter / digit / `_`,
/// a lower-case letter (an error, reported by the caller).
const KW_NO: u8 = 0;
const KW_OK: u8 = 1;
const KW_LOWER: u8 = 2;

/// Character classes for keyword scanning, one table lookup per byte.
static KEYWORD_CLASS: [u8; 256] = {
    let mut t = [KW_NO; 256];
    let mut c = 0;
    while c < 256 {
        // c < 256: the cast is exact.
        #[allow(clippy::cast_possible_truncation)]
        let b = c as u8;
        t[c] = if b.is_ascii_uppercase() || b.is_ascii_digit() || b == b'_' {
            KW_OK
        } else if b.is_ascii_lowercase() {
            KW_LOWER
        } else {
            KW_NO
        };
        c += 1;
    }
    t
};

/// Whether `c` can be part of a number token (the lexer takes the maximal run of these as
/// one token, so `1.52.3` and `1.e5` are one bad token, not a number and garbage).
#[inline]
pub(crate) fn is_number_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'.' | b'+' | b'-' | b'_')
}

/// The value of a non-empty run of ASCII digits, `None` if empty, not all digits, or above
/// `u64::MAX`. Inline arithmetic: ids and integers are the most frequent tokens.
#[inline]
pub(crate) fn decimal_u64(digits: &[u8]) -> Option<u64> {
    if digits.is_empty() {
        return None;
    }
    let mut v: u64 = 0;
    if digits.len() <= 19 {
        // At most 19 digits cannot overflow a u64.
        for &c in digits {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                return None;
            }
            v = v * 10 + u64::from(d);
        }
        return Some(v);
    }
    for &c in digits {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(u64::from(d))?;
    }
    Some(v)
}

/// The index of the apostrophe closing the string that opens at `b[start]` (doubled
/// apostrophes are part of the string).
pub(crate) fn string_end(b: &[u8], start: usize, end: usize) -> LResult<usize> {
    let mut i = start + 1;
    loop {
        // The empty string `''` (most names in real files) needs no search.
        let found = if i < end && b.get(i) == Some(&b'\'') {
            Some(0)
        } else {
            memchr::memchr(b'\'', b.get(i..end).unwrap_or_default())
        };
        match found {
            None => return Err((ParseErrorKind::UnterminatedString, start)),
            Some(p) => {
                let q = i + p;
                if b.get(q + 1) == Some(&b'\'') && q + 1 < end {
                    i = q + 2;
                } else {
                    return Ok(q);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse_list(text: &str) -> Result<Vec<Parameter<'_>>, ParseErrorKind> {
        let mut c = Cursor::new(text, 0, text.len());
        let mut count = 0;
        let limits = ParamLimits {
            max_depth: 8,
            max_params: 1000,
        };
        c.parameter_list(limits, &mut count)
            .map_err(|(k, _)| match k {
                // `found` quotes the text up to the next blank, which differs between the
                // compact and spaced renderings; what was expected must not.
                ParseErrorKind::Expected { expected, .. } => ParseErrorKind::Expected {
                    expected,
                    found: String::new(),
                },
                other => other,
            })
    }

    /// A token the general lexer must see: references, reals, integers, and malformed
    /// ones that must be reported the same way.
    fn token() -> impl Strategy<Value = String> {
        prop_oneof![
            (0u64..100_000).prop_map(|i| format!("#{i}")),
            any::<f64>()
                .prop_filter("finite", |x| x.is_finite())
                .prop_map(|x| crate::real::format_real(x).unwrap()),
            (-1000i64..1000).prop_map(|i| i.to_string()),
            Just("#12A".to_owned()),
            Just("1.5.2".to_owned()),
            Just("1.E".to_owned()),
            Just("-".to_owned()),
            Just("1.5E3X".to_owned()),
            Just("#".to_owned()),
            Just("$".to_owned()),
        ]
    }

    proptest! {
        /// The tight loop for blank-free runs (`scalar_run`) reads exactly what the general
        /// loop reads: the same list with a blank after every comma (which disables the
        /// tight loop) gives the same values, or the same error.
        #[test]
        fn compact_runs_read_like_spaced_ones(tokens in prop::collection::vec(token(), 1..30)) {
            let compact = format!("({})", tokens.join(","));
            let spaced = format!("({})", tokens.join(", "));
            prop_assert_eq!(parse_list(&compact), parse_list(&spaced), "{}", compact);
        }
    }
}
