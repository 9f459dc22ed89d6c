//! The ISO 10303-21:2016 grammar as nom rules: tokens (clause 6), the exchange structure's
//! keywords (clauses 8-10) and the entity instance with its parameters (clause 12).
//!
//! Every rule is a nom parser over the bytes of one statement (from its first byte to
//! before its `;`, as the scanner's special-byte search found it), named after the
//! production it reads and quoting it. The rules whose text is most of a file have fast
//! leaves inside them, not beside them: [`space`] answers at once when a token follows,
//! [`keyword`] reads upper-case runs eight bytes at a time, REALs are lexed and converted
//! in one pass (`crate::real`), and a list steps through blank-free runs of references and
//! reals in a tight loop. Nested lists recurse with their depth passed down and checked
//! against [`Limits::max_nesting_depth`](crate::Limits) before each nested rule starts, so
//! the input cannot make the recursion deeper than the configured limit (as der-parser's
//! `max_depth`).
//!
//! Failures are [`GrammarError`]s: the innermost rule names what it expected, and the
//! input left locates it; [`located`] turns one into `(kind, byte offset)`, which the
//! scanner turns into a line, column and `#id`.

use nom::bytes::complete::tag;
use nom::character::complete::char;
use nom::combinator::{cut, not, peek};
use nom::error::context;
use nom::sequence::{preceded, terminated};
use nom::{IResult, Parser};

use super::ast::{Body, Parameter, Record};
use super::error::ParseErrorKind;
use super::string::StepString;
use crate::grammar::{Cause, GrammarError};
use crate::real::parse_step_real;

/// The input of every rule: bytes of the statement being read.
pub(crate) type In<'a> = &'a [u8];
/// A rule's failure.
pub(crate) type Failure<'a> = GrammarError<'a, ParseErrorKind>;
/// A rule's result.
pub(crate) type Rule<'a, T> = IResult<In<'a>, T, Failure<'a>>;
/// A failure at a byte offset of the whole input.
pub(crate) type LexError = (ParseErrorKind, usize);
/// Result located by byte offset.
pub(crate) type LResult<T> = Result<T, LexError>;

/// Limits the parameter rules enforce.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParamLimits {
    pub(crate) max_depth: usize,
    pub(crate) max_params: usize,
}

impl From<&crate::Limits> for ParamLimits {
    fn from(limits: &crate::Limits) -> Self {
        ParamLimits {
            max_depth: limits
                .max_nesting_depth
                .clamp(1, crate::Limits::MAX_NESTING_DEPTH),
            max_params: limits.max_params_per_entity,
        }
    }
}

/// The parameter budget of one instance: every scalar, list and typed parameter counts,
/// at any depth.
struct Budget {
    limits: ParamLimits,
    count: usize,
}

/// "Expected `what`" at `at` (the rule that failed is named `what`).
fn expected<'a>(at: In<'a>, what: &'static str) -> nom::Err<Failure<'a>> {
    nom::Err::Failure(GrammarError {
        at,
        rule: what,
        cause: Cause::Syntax(nom::error::ErrorKind::Tag),
    })
}

/// A failure in the format's own terms at `at`.
fn fail(at: In<'_>, kind: ParseErrorKind) -> nom::Err<Failure<'_>> {
    nom::Err::Failure(GrammarError::format(at, kind))
}

/// `bytes` as text. Rules return slices that start and end at ASCII bytes of a `&str`,
/// which are always whole UTF-8 sequences.
fn text(bytes: &[u8]) -> &str {
    std::str::from_utf8(bytes).unwrap_or_default()
}

/// Turns a failure of a rule run on `input` (which ends at byte `end` of the whole file)
/// into a kind and the byte offset of the failure in the whole file.
pub(crate) fn located(e: nom::Err<Failure<'_>>, end: usize) -> LexError {
    match e {
        nom::Err::Error(f) | nom::Err::Failure(f) => {
            let offset = end.saturating_sub(f.at.len());
            let kind = match f.cause {
                Cause::Format(kind) => kind,
                Cause::Syntax(_) => ParseErrorKind::Expected {
                    expected: if f.rule.is_empty() {
                        "a parameter"
                    } else {
                        f.rule
                    },
                    found: describe(f.at),
                },
            };
            (kind, offset)
        }
        // The rules read complete input only.
        nom::Err::Incomplete(_) => (
            ParseErrorKind::Expected {
                expected: "`;`",
                found: "end of statement".to_owned(),
            },
            end,
        ),
    }
}

/// Runs `rule` on `bytes[from..end]`: its value and the offset where it stopped, or the
/// located failure.
pub(crate) fn run<'a, T>(
    bytes: &'a [u8],
    from: usize,
    end: usize,
    mut rule: impl Parser<In<'a>, Output = T, Error = Failure<'a>>,
) -> LResult<(T, usize)> {
    let input = bytes.get(from..end).unwrap_or_default();
    match rule.parse(input) {
        Ok((rest, value)) => Ok((value, end - rest.len())),
        Err(e) => Err(located(e, end)),
    }
}

/// A short rendering of the input where a rule failed (up to 16 characters of its first
/// token), for "expected X, found Y".
pub(crate) fn describe(at: In<'_>) -> String {
    if at.is_empty() {
        return "end of statement".to_owned();
    }
    let head = String::from_utf8_lossy(at.get(..at.len().min(80)).unwrap_or_default());
    let token: String = head
        .chars()
        .take_while(|c| !c.is_whitespace())
        .take(16)
        .collect();
    format!("`{token}`")
}

/// `space = { SPACE | comment }`: whitespace and comments, allowed between any two tokens
/// (clause 6.5). Most calls find a token right away and return without a loop.
#[inline]
pub(crate) fn space(i: In<'_>) -> Rule<'_, ()> {
    match i.first() {
        Some(&c) if c > b' ' && c != b'/' => return Ok((i, ())),
        None => return Ok((i, ())),
        // One blank before a token, or the line break between two statements.
        Some(b' ' | b'\n') => {
            if let Some(&c) = i.get(1) {
                if c > b' ' && c != b'/' {
                    return Ok((i.get(1..).unwrap_or_default(), ()));
                }
            }
        }
        _ => {}
    }
    space_run(i)
}

/// [`space`] once whitespace or a `/` was seen.
fn space_run(mut i: In<'_>) -> Rule<'_, ()> {
    loop {
        match i.first() {
            Some(b' ' | b'\t' | b'\r' | b'\n' | b'\x0c') => i = i.get(1..).unwrap_or_default(),
            Some(b'/') if i.get(1) == Some(&b'*') => (i, ()) = comment(i)?,
            _ => return Ok((i, ())),
        }
    }
}

/// `comment = "/*" { character } "*/"` (clause 6.5).
fn comment(i: In<'_>) -> Rule<'_, ()> {
    let body = i.get(2..).unwrap_or_default();
    match memchr::memmem::find(body, b"*/") {
        Some(p) => Ok((body.get(p + 2..).unwrap_or_default(), ())),
        None => Err(fail(i, ParseErrorKind::UnterminatedComment)),
    }
}

/// A structure keyword (`ISO-10303-21`, `HEADER`, `DATA`, `ENDSEC` ...) followed by a byte
/// that cannot continue a keyword.
pub(crate) fn structure_keyword<'a>(
    kw: &'static str,
) -> impl Parser<In<'a>, Output = (), Error = Failure<'a>> {
    terminated(tag(kw.as_bytes()), not(peek(keyword_byte))).map(|_| ())
}

/// One byte that may continue a structure keyword (letters, digits, `_`, `-`).
fn keyword_byte(i: In<'_>) -> Rule<'_, u8> {
    match i.first() {
        Some(&c) if c.is_ascii_alphanumeric() || c == b'_' || c == b'-' => {
            Ok((i.get(1..).unwrap_or_default(), c))
        }
        _ => Err(nom::Err::Error(GrammarError {
            at: i,
            rule: "",
            cause: Cause::Syntax(nom::error::ErrorKind::Char),
        })),
    }
}

/// `keyword_statement = keyword ";"` (`HEADER;`, `ENDSEC;`, `END-ISO-10303-21;`): after
/// the keyword, optional space, then the `;`.
pub(crate) fn end_of_keyword_statement(i: In<'_>) -> Rule<'_, ()> {
    preceded(space, context("`;`", char(';')).map(|_| ())).parse(i)
}

/// `keyword = user_defined_keyword | standard_keyword`;
/// `standard_keyword = UPPER { UPPER | DIGIT }` (`_` counts as UPPER);
/// `user_defined_keyword = "!" standard_keyword` (clause 6.4). A keyword with lower-case
/// letters is a located error.
pub(crate) fn keyword(i: In<'_>) -> Rule<'_, &str> {
    let bang = usize::from(i.first() == Some(&b'!'));
    match i.get(bang) {
        Some(c) if c.is_ascii_alphabetic() || *c == b'_' => {}
        _ => {
            return Err(nom::Err::Error(GrammarError {
                at: i,
                rule: "a keyword",
                cause: Cause::Syntax(nom::error::ErrorKind::Alpha),
            }));
        }
    }
    // Upper-case runs eight bytes at a time; the loop then only sees the byte that stopped
    // the run (and the rest of a keyword with lower-case letters).
    let mut e = super::keyword_run::keyword_run(i, bang, i.len());
    let mut lower = false;
    while let Some(&c) = i.get(e) {
        match KEYWORD_CLASS[usize::from(c)] {
            KW_OK => e += 1,
            KW_LOWER => {
                lower = true;
                e += 1;
            }
            _ => break,
        }
    }
    let kw = text(i.get(..e).unwrap_or_default());
    if lower {
        return Err(fail(i, ParseErrorKind::LowercaseKeyword(kw.to_owned())));
    }
    Ok((i.get(e..).unwrap_or_default(), kw))
}

/// `simple_record = keyword "(" [ parameter_list ] ")"` (clause 12.2.3).
pub(crate) fn simple_record<'a>(i: In<'a>, limits: ParamLimits) -> Rule<'a, Record<'a>> {
    record(i, &mut Budget { limits, count: 0 })
}

fn record<'a>(i: In<'a>, budget: &mut Budget) -> Rule<'a, Record<'a>> {
    let (i, keyword) = keyword(i)?;
    let (i, _) = space(i)?;
    let (i, _) = cut(context("`(`", char('('))).parse(i)?;
    let (i, params) = list_rest(i, budget, 1)?;
    Ok((i, Record { keyword, params }))
}

/// `entity_instance_body = simple_record | "(" simple_record { simple_record } ")"`
/// (clauses 12.2.1, 12.2.5), followed by nothing but space up to the statement's `;`.
pub(crate) fn entity_instance_body<'a>(i: In<'a>, limits: ParamLimits) -> Rule<'a, Body<'a>> {
    let mut budget = Budget { limits, count: 0 };
    let (i, _) = space(i)?;
    let (i, body) = match i.strip_prefix(b"(") {
        Some(mut i) => {
            let mut records = Vec::new();
            loop {
                (i, ()) = space(i)?;
                match i.first() {
                    Some(b')') if !records.is_empty() => {
                        break (i.get(1..).unwrap_or_default(), Body::Complex(records));
                    }
                    None => return Err(expected(i, "`)` closing the complex instance")),
                    _ => {
                        let (rest, r) = cut(|i| record(i, &mut budget)).parse(i)?;
                        records.push(r);
                        i = rest;
                    }
                }
            }
        }
        None => {
            let (i, r) = cut(|i| record(i, &mut budget)).parse(i)?;
            (i, Body::Simple(r))
        }
    };
    let (i, _) = space(i)?;
    if !i.is_empty() {
        return Err(expected(i, "`;`"));
    }
    Ok((i, body))
}

/// `"(" [ parameter { "," parameter } ] ")"`: a whole list, the `(` included.
pub(crate) fn parameter_list<'a>(i: In<'a>, limits: ParamLimits) -> Rule<'a, Vec<Parameter<'a>>> {
    let (i, _) = context("`(`", char('(')).parse(i)?;
    list_rest(i, &mut Budget { limits, count: 0 }, 1)
}

/// A list after its `(`: `[ parameter { "," parameter } ] ")"` (clause 12.2.2). `depth` is
/// this list's nesting (1 for a record's parameter list).
fn list_rest<'a>(mut i: In<'a>, budget: &mut Budget, depth: usize) -> Rule<'a, Vec<Parameter<'a>>> {
    let mut values: Vec<Parameter<'a>> = Vec::new();
    (i, ()) = space(i)?;
    match i.first() {
        Some(b')') => return Ok((i.get(1..).unwrap_or_default(), values)),
        None => return Err(expected(i, "`)`")),
        _ => {}
    }
    loop {
        let (rest, v) = parameter(i, budget, depth)?;
        values.push(v);
        i = scalar_run(rest, &mut values, budget)?;
        (i, ()) = space(i)?;
        match i.first() {
            Some(b')') => return Ok((i.get(1..).unwrap_or_default(), values)),
            Some(b',') => {
                (i, ()) = space(i.get(1..).unwrap_or_default())?;
                match i.first() {
                    Some(b')') => return Err(expected(i, "a parameter after `,`")),
                    None => return Err(expected(i, "`)`")),
                    _ => {}
                }
            }
            None => return Err(expected(i, "`)`")),
            _ => return Err(expected(i, "`,` or `)`")),
        }
    }
}

/// `parameter = typed_parameter | untyped_parameter | omitted_parameter` (clause 12.2.2),
/// chosen by its first byte. A list or typed parameter opens a level of nesting, refused
/// at the limit before its rule runs.
fn parameter<'a>(i: In<'a>, budget: &mut Budget, depth: usize) -> Rule<'a, Parameter<'a>> {
    let Some(&c) = i.first() else {
        return Err(expected(i, "`)`"));
    };
    budget.count += 1;
    if budget.count > budget.limits.max_params {
        return Err(fail(
            i,
            ParseErrorKind::TooManyParameters(budget.limits.max_params),
        ));
    }
    let opens = c == b'(' || c == b'!' || c.is_ascii_alphabetic();
    if opens && depth >= budget.limits.max_depth {
        return Err(fail(
            i,
            ParseErrorKind::NestingTooDeep(budget.limits.max_depth),
        ));
    }
    if c == b'(' {
        let (i, items) = list_rest(i.get(1..).unwrap_or_default(), budget, depth + 1)?;
        Ok((i, Parameter::List(items)))
    } else if opens {
        typed_parameter(i, budget, depth + 1)
    } else {
        scalar(i)
    }
}

/// `typed_parameter = keyword "(" parameter ")"` (clause 12.2.2): exactly one parameter.
fn typed_parameter<'a>(i: In<'a>, budget: &mut Budget, depth: usize) -> Rule<'a, Parameter<'a>> {
    let start = i;
    let (i, kw) = keyword(i)?;
    let (i, _) = space(i)?;
    let (i, _) = cut(context("`(` after a typed parameter's keyword", char('('))).parse(i)?;
    let (i, mut items) = list_rest(i, budget, depth)?;
    match (items.pop(), items.is_empty()) {
        (Some(v), true) => Ok((i, Parameter::Typed(kw, Box::new(v)))),
        _ => Err(fail(start, ParseErrorKind::TypedArity(kw.to_owned()))),
    }
}

/// After a scalar, the rest of a blank-free run `,#12,#13,...` or `,1.5,-2.E-3,...`
/// (pole lists, knots and weights are most of a B-spline's text), read in a tight loop.
/// It stops before the `,` at anything else (a blank, a comment, a `)`, a malformed
/// token), which [`list_rest`] then reads, so values and errors are the same as without it.
#[inline]
fn scalar_run<'a>(
    mut i: In<'a>,
    values: &mut Vec<Parameter<'a>>,
    budget: &mut Budget,
) -> Result<In<'a>, nom::Err<Failure<'a>>> {
    loop {
        if i.len() < 2 || i.first() != Some(&b',') {
            return Ok(i);
        }
        let (value, end) = match i.get(1) {
            Some(b'#') => {
                let digits = i.get(2..).unwrap_or_default();
                let n = digits.iter().take_while(|c| c.is_ascii_digit()).count();
                match digits.get(..n).and_then(decimal_u64) {
                    Some(id) => (Parameter::Reference(id), n + 2),
                    None => return Ok(i),
                }
            }
            Some(c) if c.is_ascii_digit() || *c == b'-' || *c == b'+' => {
                match crate::real::step_real_at(i, 1) {
                    Ok((v, e)) => (Parameter::Real(v), e),
                    _ => return Ok(i),
                }
            }
            _ => return Ok(i),
        };
        // The token must end where the general rule's token would (`#12A`, `1.5.2` and
        // `1.5E3X` are left to it for the error).
        if i.get(end).is_some_and(|&c| is_number_char(c)) {
            return Ok(i);
        }
        budget.count += 1;
        if budget.count > budget.limits.max_params {
            return Err(fail(
                i.get(1..).unwrap_or_default(),
                ParseErrorKind::TooManyParameters(budget.limits.max_params),
            ));
        }
        values.push(value);
        i = i.get(end..).unwrap_or_default();
    }
}

/// `untyped_parameter` other than a list, or `omitted_parameter`: STRING, BINARY,
/// ENUMERATION, entity instance name, `$`, `*`, INTEGER or REAL (clause 12.2.2).
fn scalar(i: In<'_>) -> Rule<'_, Parameter<'_>> {
    match i.first() {
        Some(b'\'') => string(i),
        Some(b'"') => binary(i),
        Some(b'.') => enumeration(i),
        Some(b'#') => entity_instance_name(i).map(|(r, id)| (r, Parameter::Reference(id))),
        Some(b'$') => Ok((i.get(1..).unwrap_or_default(), Parameter::Null)),
        Some(b'*') => Ok((i.get(1..).unwrap_or_default(), Parameter::Derived)),
        Some(&c) if c == b'+' || c == b'-' || c.is_ascii_digit() => number(i),
        _ => Err(expected(i, "a parameter")),
    }
}

/// `STRING = "'" { special | digit | space | lower | upper | high_codepoint | "''" |
/// control_directive } "'"` (clause 6.3.4), kept raw (decoded by [`StepString::decode`]).
fn string(i: In<'_>) -> Rule<'_, Parameter<'_>> {
    let end = string_end(i)?;
    let raw = text(i.get(1..end).unwrap_or_default());
    Ok((
        i.get(end + 1..).unwrap_or_default(),
        Parameter::String(StepString::new(raw)),
    ))
}

/// The index of the apostrophe closing the string that opens at `i[0]` (a doubled
/// apostrophe belongs to the string).
fn string_end(i: In<'_>) -> Result<usize, nom::Err<Failure<'_>>> {
    let mut from = 1;
    loop {
        // The empty string `''` (most names in real files) needs no search.
        let found = if i.get(from) == Some(&b'\'') {
            Some(0)
        } else {
            memchr::memchr(b'\'', i.get(from..).unwrap_or_default())
        };
        match found {
            None => return Err(fail(i, ParseErrorKind::UnterminatedString)),
            Some(p) => {
                let q = from + p;
                if i.get(q + 1) == Some(&b'\'') {
                    from = q + 2;
                } else {
                    return Ok(q);
                }
            }
        }
    }
}

/// `BINARY = """" ( "0" | "1" | "2" | "3" ) { HEX } """"` (clause 6.3.6): the hex digits.
fn binary(i: In<'_>) -> Rule<'_, Parameter<'_>> {
    let body = i.get(1..).unwrap_or_default();
    let Some(len) = memchr::memchr(b'"', body) else {
        return Err(fail(i, ParseErrorKind::InvalidBinary));
    };
    let digits = body.get(..len).unwrap_or_default();
    let ok =
        digits.iter().all(u8::is_ascii_hexdigit) && matches!(digits.first(), Some(b'0'..=b'3'));
    if !ok {
        return Err(fail(i, ParseErrorKind::InvalidBinary));
    }
    Ok((
        body.get(len + 1..).unwrap_or_default(),
        Parameter::Binary(text(digits)),
    ))
}

/// `ENUMERATION = "." UPPER { UPPER | DIGIT } "."` (clause 6.3.5): the value without dots.
fn enumeration(i: In<'_>) -> Rule<'_, Parameter<'_>> {
    let body = i.get(1..).unwrap_or_default();
    let n = body
        .iter()
        .take_while(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || **c == b'_')
        .count();
    if !body.first().is_some_and(u8::is_ascii_uppercase) {
        return Err(expected(body, "an upper-case enumeration value"));
    }
    let rest = body.get(n..).unwrap_or_default();
    match rest.strip_prefix(b".") {
        Some(after) => Ok((
            after,
            Parameter::Enumeration(text(body.get(..n).unwrap_or_default())),
        )),
        None => Err(expected(rest, "`.` closing the enumeration")),
    }
}

/// `entity_instance_name = "#" DIGIT { DIGIT }` (clause 6.3.7), at most `u64::MAX`.
pub(crate) fn entity_instance_name(i: In<'_>) -> Rule<'_, u64> {
    let digits = i.get(1..).unwrap_or_default();
    let n = digits.iter().take_while(|c| c.is_ascii_digit()).count();
    let run = digits.get(..n).unwrap_or_default();
    match decimal_u64(run) {
        Some(id) => Ok((digits.get(n..).unwrap_or_default(), id)),
        None => Err(fail(i, ParseErrorKind::InvalidId(text(run).to_owned()))),
    }
}

/// `INTEGER = [ SIGN ] DIGIT { DIGIT }` or `REAL = [ SIGN ] DIGIT { DIGIT } "." { DIGIT }
/// [ "E" [ SIGN ] DIGIT { DIGIT } ]` (clauses 6.3.2, 6.3.3). The token is the maximal run
/// of characters that can belong to a number (letters included), so `1.52.3` and `1.e5`
/// are one bad token, not a number and garbage.
fn number(i: In<'_>) -> Rule<'_, Parameter<'_>> {
    // One pass for a well-formed REAL followed by a delimiter; integers and malformed
    // tokens take the token-then-check path, which gives the same values and the errors.
    if let Ok((v, end)) = crate::real::step_real_at(i, 0) {
        if !i.get(end).is_some_and(|&c| is_number_char(c)) {
            return Ok((i.get(end..).unwrap_or_default(), Parameter::Real(v)));
        }
    }
    let len = 1 + i
        .get(1..)
        .unwrap_or_default()
        .iter()
        .take_while(|&&c| is_number_char(c))
        .count();
    let token = text(i.get(..len).unwrap_or_default());
    let rest = i.get(len..).unwrap_or_default();
    if token.contains(['.', 'E', 'e']) {
        return match parse_step_real(token) {
            Ok(v) => Ok((rest, Parameter::Real(v))),
            Err(e) => Err(fail(i, ParseErrorKind::from((e, token.to_owned())))),
        };
    }
    let digits = token.strip_prefix(['+', '-']).unwrap_or(token);
    if digits.is_empty() || !digits.bytes().all(|d| d.is_ascii_digit()) {
        return Err(fail(
            i,
            ParseErrorKind::Expected {
                expected: "a number",
                found: format!("`{token}`"),
            },
        ));
    }
    let magnitude = decimal_u64(digits.as_bytes()).and_then(|m| i64::try_from(m).ok());
    if let Some(m) = magnitude {
        let v = if token.starts_with('-') { -m } else { m };
        return Ok((rest, Parameter::Integer(v)));
    }
    // i64::MIN and overflow: std decides and reports.
    match token.parse::<i64>() {
        Ok(v) => Ok((rest, Parameter::Integer(v))),
        Err(_) => Err(fail(i, ParseErrorKind::IntegerOverflow(token.to_owned()))),
    }
}

/// Where the scanner stands in the input, between statements: the byte position and the
/// end it may not pass. The grammar rules run from here ([`Cursor::rule`]) and move it.
pub(crate) struct Cursor<'a> {
    pub(crate) text: &'a str,
    pub(crate) pos: usize,
    pub(crate) end: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor over `text[pos..end]`.
    pub(crate) fn new(text: &'a str, pos: usize, end: usize) -> Self {
        Cursor { text, pos, end }
    }

    /// The next byte, if before `end`.
    pub(crate) fn peek(&self) -> Option<u8> {
        if self.pos < self.end {
            self.text.as_bytes().get(self.pos).copied()
        } else {
            None
        }
    }

    /// Whether the remaining input starts with `s`.
    pub(crate) fn starts_with(&self, s: &str) -> bool {
        self.text
            .as_bytes()
            .get(self.pos..self.end)
            .is_some_and(|r| r.starts_with(s.as_bytes()))
    }

    /// Runs `rule` here; on success the cursor moves past what it read.
    pub(crate) fn rule<T>(
        &mut self,
        rule: impl Parser<In<'a>, Output = T, Error = Failure<'a>>,
    ) -> LResult<T> {
        let (value, pos) = run(self.text.as_bytes(), self.pos, self.end, rule)?;
        self.pos = pos;
        Ok(value)
    }

    /// Whether `rule` matches here (the cursor does not move).
    pub(crate) fn matches<T>(
        &self,
        mut rule: impl Parser<In<'a>, Output = T, Error = Failure<'a>>,
    ) -> bool {
        let input = self
            .text
            .as_bytes()
            .get(self.pos..self.end)
            .unwrap_or_default();
        rule.parse(input).is_ok()
    }

    /// Skips [`space`]. Between statements the next byte is nearly always a token or the
    /// one line break: answered here without running the rule.
    #[inline]
    pub(crate) fn skip_ws(&mut self) -> LResult<()> {
        match self.peek() {
            Some(c) if c > b' ' && c != b'/' => return Ok(()),
            None => return Ok(()),
            Some(b'\n') => {
                if let Some(&c) = self.text.as_bytes().get(self.pos + 1) {
                    if c > b' ' && c != b'/' && self.pos + 1 < self.end {
                        self.pos += 1;
                        return Ok(());
                    }
                }
            }
            _ => {}
        }
        self.rule(space)
    }

    /// An error "expected `what`" here, describing what is there.
    pub(crate) fn expected(&self, what: &'static str) -> LexError {
        let rest = self
            .text
            .as_bytes()
            .get(self.pos..self.end)
            .unwrap_or_default();
        (
            ParseErrorKind::Expected {
                expected: what,
                found: describe(rest),
            },
            self.pos,
        )
    }
}

/// `header_entity = simple_record ";"` (clause 9): one record, then only space up to the
/// statement's `;`.
pub(crate) fn header_entity<'a>(i: In<'a>, limits: ParamLimits) -> Rule<'a, Record<'a>> {
    let (i, r) = simple_record(i, limits)?;
    let (i, _) = space(i)?;
    if !i.is_empty() {
        return Err(expected(i, "`;`"));
    }
    Ok((i, r))
}

/// `entity_instance_head = entity_instance_name "=" [ keyword ]` (clause 12.1): the id and
/// the input at the body (after `=` and space), with the keyword of a simple instance
/// (`None` for a complex one, whose body opens with `(`). The scanner's fixed-shape reader
/// answers first for the usual `#12 = KEYWORD(`; this rule reads every other shape.
pub(crate) fn entity_instance_head(i: In<'_>) -> Rule<'_, (u64, In<'_>, Option<&str>)> {
    if i.first() != Some(&b'#') {
        return Err(expected(i, "`#` starting an entity instance, or ENDSEC;"));
    }
    let (i, id) = entity_instance_name(i)?;
    let (i, _) = (
        space,
        cut(context("`=` after the instance name", char('='))),
        space,
    )
        .parse(i)?;
    let body = i;
    match i.first() {
        Some(b) if b.is_ascii_uppercase() || *b == b'!' => {
            let (i, k) = keyword(i)?;
            Ok((i, (id, body, Some(k))))
        }
        _ => Ok((i, (id, body, None))),
    }
}

/// [`KEYWORD_CLASS`] values: not a keyword character, an upper-case letter / digit / `_`,
/// a lower-case letter (an error, reported by [`keyword`]).
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

/// Whether `c` can be part of a number token (the maximal run of these is one token).
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse_list(text: &str) -> Result<Vec<Parameter<'_>>, ParseErrorKind> {
        let limits = ParamLimits {
            max_depth: 8,
            max_params: 1000,
        };
        run(text.as_bytes(), 0, text.len(), |i| {
            parameter_list(i, limits)
        })
        .map(|(v, _)| v)
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

    /// A token the list rule must see: references, reals, integers, and malformed ones
    /// that must be reported the same way.
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
        /// The tight loop for blank-free runs (`scalar_run`) reads exactly what the list
        /// rule reads token by token: the same list with a blank after every comma (which
        /// disables the tight loop) gives the same values, or the same error.
        #[test]
        fn compact_runs_read_like_spaced_ones(tokens in prop::collection::vec(token(), 1..30)) {
            let compact = format!("({})", tokens.join(","));
            let spaced = format!("({})", tokens.join(", "));
            prop_assert_eq!(parse_list(&compact), parse_list(&spaced), "{}", compact);
        }

        /// `space` (with its one-blank shortcut) skips exactly what the plain definition
        /// does: the longest prefix of blanks and complete comments.
        #[test]
        fn space_matches_its_definition(parts in prop::collection::vec(prop_oneof![
            Just(" "), Just("\n"), Just("\t"), Just("\r\n"), Just("/* c */"), Just("/**/"),
            Just("A"), Just("/"), Just("*"), Just("/*"),
        ], 0..12)) {
            let s = parts.concat();
            let b = s.as_bytes();
            let mut j = 0;
            let want: Result<usize, ()> = loop {
                match b.get(j) {
                    Some(b' ' | b'\t' | b'\r' | b'\n' | b'\x0c') => j += 1,
                    Some(b'/') if b.get(j + 1) == Some(&b'*') => {
                        match b.get(j + 2..).and_then(|r| r.windows(2).position(|w| w == b"*/")) {
                            Some(p) => j += 2 + p + 2,
                            None => break Err(()),
                        }
                    }
                    _ => break Ok(j),
                }
            };
            let got = space(b).map(|(rest, ())| b.len() - rest.len()).map_err(|_| ());
            prop_assert_eq!(got, want, "{:?}", s);
        }
    }

    /// The deepest nesting the limit allows, on a thread with a 1 MiB stack (half of what
    /// rayon's and tokio's blocking threads have), and the ceiling applied to larger limits.
    #[test]
    fn the_nesting_ceiling_fits_a_small_stack() {
        let deep = std::thread::Builder::new()
            .stack_size(1 << 20)
            .spawn(|| {
                let limits = ParamLimits::from(&crate::Limits {
                    max_nesting_depth: usize::MAX,
                    ..crate::Limits::default()
                });
                assert_eq!(limits.max_depth, crate::Limits::MAX_NESTING_DEPTH);
                let n = crate::Limits::MAX_NESTING_DEPTH;
                let ok = format!("{}1{}", "(".repeat(n), ")".repeat(n));
                let typed = format!("{}1{}", "(A".repeat(n - 1) + "(", ")".repeat(n));
                let over = format!("{}1{}", "(".repeat(n + 1), ")".repeat(n + 1));
                let run_on = |t: &str| {
                    run(t.as_bytes(), 0, t.len(), |i| parameter_list(i, limits)).map(|_| ())
                };
                (run_on(&ok).is_ok(), run_on(&typed).is_ok(), run_on(&over))
            })
            .unwrap()
            .join()
            .unwrap();
        assert_eq!(
            deep,
            (
                true,
                true,
                Err((
                    ParseErrorKind::NestingTooDeep(crate::Limits::MAX_NESTING_DEPTH),
                    128
                ))
            )
        );
    }

    #[test]
    fn nesting_is_refused_at_the_limit_before_recursing() {
        let limits = ParamLimits {
            max_depth: 3,
            max_params: 1000,
        };
        // Three levels of lists, the record's own list included.
        let ok = "(((1)))";
        assert!(run(ok.as_bytes(), 0, ok.len(), |i| parameter_list(i, limits)).is_ok());
        let deep = "((((1))))";
        let err = run(deep.as_bytes(), 0, deep.len(), |i| {
            parameter_list(i, limits)
        });
        assert_eq!(err.unwrap_err(), (ParseErrorKind::NestingTooDeep(3), 3));
        // A typed parameter opens a level too.
        let typed = "((A(B(1))))";
        let err = run(typed.as_bytes(), 0, typed.len(), |i| {
            parameter_list(i, limits)
        });
        assert_eq!(err.unwrap_err(), (ParseErrorKind::NestingTooDeep(3), 4));
        // A million open parentheses: refused at the limit, no stack overflow.
        let huge = "(".repeat(1_000_000);
        let err = run(huge.as_bytes(), 0, huge.len(), |i| {
            parameter_list(i, limits)
        });
        assert_eq!(err.unwrap_err(), (ParseErrorKind::NestingTooDeep(3), 3));
    }
}
