//! Free-format parameter data (IGES 5.3 section 2.2.3; data types section 2.2.2): the rules
//! of the Global and Parameter Data sections, parameterised by the file's two delimiters.
//!
//! ```text
//! record     = { parameter parameter-delimiter } parameter record-delimiter [ comment ]
//! parameter  = blanks ( default | hollerith | value ) blanks
//! default    = (nothing: the next byte is a delimiter)
//! hollerith  = digits ( "H" | "h" ) n-characters          (section 2.2.2.4)
//! value      = text up to the next delimiter, blanks trimmed (integer, real, pointer)
//! ```
//!
//! [`real_parameter`] is the fast leaf of the hot path: a 126/128 record is nearly all
//! reals, and this leaf converts each one where it stands ([`iges_real_at`], one pass over
//! the bytes) instead of first cutting a token; where it cannot, it answers as
//! [`parameter`] followed by [`parse_iges_real`] would (tested below).

use nom::branch::alt;
use nom::bytes::complete::{take, take_while, take_while1};
use nom::combinator::map;
use nom::error::context;
use nom::{IResult, Parser};

use super::super::error::ErrorKind;
use crate::grammar::GrammarError;
use crate::real::{iges_real_at, parse_iges_real};

/// The error of every IGES rule: the shared grammar error with the IGES error kind.
pub type Error<'a> = GrammarError<'a, ErrorKind>;

/// What every IGES rule returns.
pub type Rule<'a, T> = IResult<&'a [u8], T, Error<'a>>;

/// The parameter and record delimiters (Global parameters 1 and 2; section 2.2.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Delimiters {
    /// Parameter delimiter (default `,`).
    pub param: u8,
    /// Record delimiter (default `;`).
    pub record: u8,
}

/// One parameter as the grammar cuts it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameter<'a> {
    /// Nothing between two delimiters: the default value.
    Default,
    /// A Hollerith string's characters (without the `nH` prefix).
    String(&'a str),
    /// Anything else (integer, real, pointer, logical): the trimmed text.
    Value(&'a [u8]),
}

impl Parameter<'_> {
    /// The text as an error message shows it (`<empty>` for the default).
    pub fn shown(&self) -> String {
        match self {
            Parameter::Default => "<empty>".to_owned(),
            Parameter::String(s) => s.chars().take(40).collect(),
            Parameter::Value(v) => String::from_utf8_lossy(v).chars().take(40).collect(),
        }
    }
}

/// Which delimiter ended a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// The parameter delimiter: another parameter follows.
    Parameter,
    /// The record delimiter: the record is complete (what follows is a comment).
    Record,
}

/// `{ " " }`: blanks around a parameter are not part of it.
pub fn blanks(i: &[u8]) -> Rule<'_, &[u8]> {
    take_while(|c| c == b' ')(i)
}

/// `digits ("H" | "h") n-characters` (section 2.2.2.4): a Hollerith string. The characters
/// may be delimiters; the count must not run past the data, and a string that ends inside a
/// multi-byte character is refused (the file is ASCII).
pub fn hollerith(i: &[u8]) -> Rule<'_, &str> {
    let (rest, digits) = take_while1(|c: u8| c.is_ascii_digit())(i)?;
    let (rest, _) = alt((
        nom::bytes::complete::tag(&b"H"[..]),
        nom::bytes::complete::tag(&b"h"[..]),
    ))
    .parse(rest)?;
    let available = rest.len();
    let declared = digits.iter().try_fold(0usize, |n, &d| {
        n.checked_mul(10)?.checked_add(usize::from(d - b'0'))
    });
    let Some(n) = declared.filter(|&n| n <= available) else {
        return Err(nom::Err::Failure(Error::format(
            i,
            ErrorKind::HollerithTooLong {
                declared: declared.unwrap_or(usize::MAX),
                available,
            },
        )));
    };
    let (after, chars) = take(n)(rest)?;
    match std::str::from_utf8(chars) {
        Ok(s) => Ok((after, s)),
        Err(_) => Err(nom::Err::Failure(Error::format(
            after,
            ErrorKind::Garbage("non-ASCII text in Hollerith string".into()),
        ))),
    }
}

/// `value`: the text up to the next delimiter (found with a SIMD byte search), trailing
/// blanks trimmed. Never empty (the caller tried [`default`] first).
fn value(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, &[u8]> {
    move |i: &[u8]| {
        let k = memchr::memchr2(d.param, d.record, i).unwrap_or(i.len());
        let (text, rest) = i.split_at(k);
        let trimmed = text.len() - text.iter().rev().take_while(|&&c| c == b' ').count();
        Ok((rest, &text[..trimmed]))
    }
}

/// `default`: the next byte is a delimiter (consumes nothing).
fn default(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, ()> {
    move |i: &[u8]| match i.first() {
        Some(&c) if c == d.param || c == d.record => Ok((i, ())),
        _ => Err(nom::Err::Error(nom::error::ParseError::from_error_kind(
            i,
            nom::error::ErrorKind::Char,
        ))),
    }
}

/// `blanks (parameter-delimiter | record-delimiter)`: what ends a parameter. Anything else
/// is [`ErrorKind::Garbage`]; the end of the data is [`ErrorKind::Unterminated`].
pub fn separator(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, End> {
    move |i: &[u8]| {
        let (i, _) = blanks(i)?;
        match i.first() {
            Some(&c) if c == d.param => Ok((&i[1..], End::Parameter)),
            Some(&c) if c == d.record => Ok((&i[1..], End::Record)),
            Some(_) => {
                let shown = std::str::from_utf8(&i[..char_len(i)]).unwrap_or("?");
                Err(nom::Err::Failure(Error::format(
                    i,
                    ErrorKind::Garbage(shown.to_owned()),
                )))
            }
            None => Err(nom::Err::Failure(Error::format(
                i,
                ErrorKind::Unterminated(char::from(d.record)),
            ))),
        }
    }
}

/// The length of the UTF-8 character at the start of `i` (1 for ASCII or a broken byte).
fn char_len(i: &[u8]) -> usize {
    (1..=i.len().min(4))
        .find(|&n| std::str::from_utf8(&i[..n]).is_ok())
        .unwrap_or(1)
}

/// `parameter`, then what ends it (section 2.2.3): a default, a Hollerith string or a value.
pub fn parameter(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, (Parameter<'_>, End)> {
    move |i: &[u8]| {
        context(
            "parameter",
            (
                nom::sequence::preceded(
                    blanks,
                    alt((
                        map(default(d), |()| Parameter::Default),
                        map(hollerith, Parameter::String),
                        map(value(d), Parameter::Value),
                    )),
                ),
                separator(d),
            ),
        )
        .parse(i)
    }
}

/// `[ "+" | "-" ] digit { digit }` (section 2.2.2.2): an integer value of at most 18 digits.
pub fn integer(text: &[u8]) -> Option<i64> {
    let (neg, digits) = match text.first() {
        Some(b'-') => (true, &text[1..]),
        Some(b'+') => (false, &text[1..]),
        _ => (false, text),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v: i64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + i64::from(c - b'0');
    }
    Some(if neg { -v } else { v })
}

/// A real parameter and what ends it, the fast leaf of the P section (section 2.2.2.3:
/// sign, digits, decimal point, `E` or `D` exponent; an integer is accepted, as Open
/// CASCADE does): a default reads as 0.0 (the IGES default), a value is converted in place.
/// A parameter that is not a real fails with [`ErrorKind::BadParameter`] (index and name
/// left for the caller) when [`parameter`] reads it, else with [`parameter`]'s error.
#[inline(always)]
pub fn real_parameter(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, (f64, End)> {
    move |i: &[u8]| match real_value(d, i, 0) {
        Some((v, n, end, _)) => Ok((&i[n..], (v, end))),
        None => not_a_real(d, i),
    }
}

/// The first offset at or after `k` that is not a blank. A parameter usually starts at
/// once; the blanks that pad each record's data columns to 64 (section 2.2.4.5; every
/// record of a long entity ends with some) are skipped eight at a time.
#[inline(always)]
fn skip_blanks(b: &[u8], mut k: usize) -> usize {
    if b.get(k) != Some(&b' ') {
        return k;
    }
    while let Some(w) = b.get(k..k + 8).and_then(|c| <[u8; 8]>::try_from(c).ok()) {
        // Zero bytes are blanks; the lowest non-zero byte is the first other character.
        let x = u64::from_le_bytes(w) ^ 0x2020_2020_2020_2020;
        if x != 0 {
            return k + (x.trailing_zeros() / 8) as usize;
        }
        k += 8;
    }
    while b.get(k) == Some(&b' ') {
        k += 1;
    }
    k
}

/// The success path of [`real_parameter`] without its error, on `b` from `start`: the
/// value, the offset after its delimiter, which delimiter, and whether the parameter was
/// a default (read as 0.0; [`at_default`] of the same text); `None` where
/// [`real_parameter`] fails or the text is not the usual shape (then [`real_parameter`]
/// decides).
#[inline(always)]
fn real_value(d: Delimiters, b: &[u8], start: usize) -> Option<(f64, usize, End, bool)> {
    let k = skip_blanks(b, start);
    let delimiter = |c: u8| {
        if c == d.param {
            Some(End::Parameter)
        } else if c == d.record {
            Some(End::Record)
        } else {
            None
        }
    };
    if let Some(end) = delimiter(*b.get(k)?) {
        return Some((0.0, k + 1, end, true));
    }
    let (v, mut e) = iges_real_at(b, k).ok()?;
    // Usually the delimiter follows at once; blanks may come first.
    while b.get(e) == Some(&b' ') {
        e += 1;
    }
    let end = delimiter(*b.get(e)?)?;
    Some((v, e + 1, end, false))
}

/// The success path of [`integer_parameter`] for the usual shape (blanks, an optional sign
/// and 1 to 18 digits, blanks, a delimiter, or a default): the value, the offset after its
/// delimiter, and which delimiter; `None` for anything else (then [`integer_parameter`]
/// decides).
#[inline]
fn integer_value(d: Delimiters, b: &[u8]) -> Option<(Option<i64>, usize, End)> {
    let mut k = 0;
    while b.get(k) == Some(&b' ') {
        k += 1;
    }
    let start = k;
    if matches!(b.get(k), Some(b'+' | b'-')) {
        k += 1;
    }
    while b.get(k).is_some_and(u8::is_ascii_digit) {
        k += 1;
    }
    let value = if k == start {
        None
    } else {
        Some(integer(&b[start..k])?)
    };
    while b.get(k) == Some(&b' ') {
        k += 1;
    }
    let c = *b.get(k)?;
    let end = if c == d.param {
        End::Parameter
    } else if c == d.record {
        End::Record
    } else {
        return None;
    };
    Some((value, k + 1, end))
}

/// Why the parameter at `i` is not a real: [`parameter`]'s error, or a `BadParameter`.
#[inline(never)]
#[cold]
fn not_a_real(d: Delimiters, i: &[u8]) -> Rule<'_, (f64, End)> {
    let (rest, (p, end)) = parameter(d)(i)?;
    if let Parameter::Value(v) = p
        && let Some(x) = std::str::from_utf8(v)
            .ok()
            .and_then(|t| parse_iges_real(t).ok())
    {
        return Ok((rest, (x, end)));
    }
    Err(nom::Err::Failure(bad_parameter(i, "a real", p)))
}

/// A `BadParameter` error at `at` (index and name are filled in by the record reader).
pub fn bad_parameter<'a>(at: &'a [u8], expected: &'static str, p: Parameter<'_>) -> Error<'a> {
    let at = &at[at.iter().take_while(|&&c| c == b' ').count()..];
    Error::format(
        at,
        ErrorKind::BadParameter {
            index: 0,
            name: "",
            expected,
            found: p.shown(),
        },
    )
}

/// An integer parameter and what ends it (section 2.2.2.2); `None` for a default.
pub fn integer_parameter(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, (Option<i64>, End)> {
    move |i: &[u8]| {
        let (rest, (p, end)) = parameter(d)(i)?;
        match p {
            Parameter::Default => Ok((rest, (None, end))),
            Parameter::Value(v) => match integer(v) {
                Some(n) => Ok((rest, (Some(n), end))),
                None => Err(nom::Err::Failure(bad_parameter(i, "an integer", p))),
            },
            Parameter::String(_) => Err(nom::Err::Failure(bad_parameter(i, "an integer", p))),
        }
    }
}

/// A string parameter and what ends it (section 2.2.2.4); `None` for a default.
pub fn string_parameter(d: Delimiters) -> impl Fn(&[u8]) -> Rule<'_, (Option<&str>, End)> {
    move |i: &[u8]| {
        let (rest, (p, end)) = parameter(d)(i)?;
        match p {
            Parameter::Default => Ok((rest, (None, end))),
            Parameter::String(s) => Ok((rest, (Some(s), end))),
            Parameter::Value(_) => {
                Err(nom::Err::Failure(bad_parameter(i, "a Hollerith string", p)))
            }
        }
    }
}

/// Whether `i` starts with a delimiter after blanks (a `default` parameter).
#[inline]
pub fn at_default(d: Delimiters, i: &[u8]) -> bool {
    i.iter()
        .find(|&&c| c != b' ')
        .is_some_and(|&c| c == d.param || c == d.record)
}

/// Reads one entity's parameter record parameter by parameter (section 2.2.3), with the
/// typed leaves above; counts parameters (index 0 is the entity type) for the error
/// messages and the parameter limit, and knows when the record delimiter has been read.
#[derive(Debug, Clone)]
pub struct ParameterReader<'a> {
    rest: &'a [u8],
    d: Delimiters,
    /// Parameters read so far: the index of the next one.
    index: usize,
    /// The record delimiter has been read: no parameter follows.
    done: bool,
    /// Most parameters allowed in the record.
    max: usize,
    /// The parameter count the record's declared counts need, and what for (the entity
    /// type and the counts it was computed from), once known.
    expected: Option<Expected>,
    /// Repeated reals (knots, weights, coordinates) given as defaults, read as 0.0.
    defaulted: usize,
}

/// What a record must hold once its counts are read: the parameters after the entity
/// type, the entity type, and the counts they follow from (for [`ErrorKind::Truncated`]).
#[derive(Debug, Clone)]
struct Expected {
    needed: usize,
    entity: i64,
    counts: Vec<(&'static str, i64)>,
}

impl<'a> ParameterReader<'a> {
    /// A reader at the start of `data` (the joined data columns of an entity's records).
    pub fn new(data: &'a [u8], d: Delimiters, max: usize) -> Self {
        ParameterReader {
            rest: data,
            d,
            index: 0,
            done: false,
            max,
            expected: None,
            defaulted: 0,
        }
    }

    /// The input not read yet.
    pub fn rest(&self) -> &'a [u8] {
        self.rest
    }

    /// The index of the next parameter.
    pub fn index(&self) -> usize {
        self.index
    }

    /// How many required values were defaults ([`ParameterReader::reals`],
    /// [`ParameterReader::points`], [`ParameterReader::required_real`],
    /// [`ParameterReader::required_flag`]), read as 0: the tables of chapter 4 give knots,
    /// weights, coordinates and PROP flags no default, so each is a parameter the writer
    /// left out.
    pub fn defaulted(&self) -> usize {
        self.defaulted
    }

    /// A required real (the entity's table gives it no default), counting a default.
    pub fn required_real(&mut self, name: &'static str) -> Result<f64, Error<'a>> {
        if !self.done && at_default(self.d, self.rest) {
            self.defaulted += 1;
        }
        self.real(name)
    }

    /// A flag (0 when defaulted), counting a default.
    pub fn required_flag(&mut self, name: &'static str) -> Result<i64, Error<'a>> {
        if !self.done && at_default(self.d, self.rest) {
            self.defaulted += 1;
        }
        self.integer(name, Some(0))
    }

    /// Whether the record delimiter has been read.
    pub fn done(&self) -> bool {
        self.done
    }

    /// Declares that the record of entity type `entity` needs `needed` parameters after
    /// the entity type, by the counts `counts`: reading past the record's end before that is
    /// a [`ErrorKind::Truncated`] error naming them.
    pub fn expect(&mut self, needed: usize, entity: i64, counts: Vec<(&'static str, i64)>) {
        self.expected = Some(Expected {
            needed,
            entity,
            counts,
        });
    }

    /// Room for `count` values of `width` parameters each, bounded by what the remaining
    /// data can hold (every parameter takes at least its delimiter byte), so a hostile
    /// count allocates nothing large.
    pub fn capacity(&self, count: usize, width: usize) -> usize {
        count.min(self.rest.len() / width.max(1))
    }

    /// Fails when no parameter can be read: the record is over, or the limit is reached.
    #[inline(always)]
    fn open(&self, name: &'static str, expected: &'static str) -> Result<(), Error<'a>> {
        if self.done {
            return Err(self.missing(name, expected));
        }
        if self.index >= self.max {
            return Err(Error::format(
                self.rest,
                ErrorKind::Limit(format!("more than {} parameters", self.max)),
            ));
        }
        Ok(())
    }

    #[cold]
    fn missing(&self, name: &'static str, expected: &'static str) -> Error<'a> {
        let kind = match &self.expected {
            Some(Expected {
                needed,
                entity,
                counts,
            }) if self.index <= *needed => ErrorKind::Truncated {
                what: counts
                    .iter()
                    .enumerate()
                    .fold(entity.to_string(), |w, (k, (n, v))| {
                        format!("{w}{} {n} = {v}", if k == 0 { " with" } else { "," })
                    }),
                needed: *needed,
                present: self.index.saturating_sub(1),
            },
            _ => ErrorKind::BadParameter {
                index: self.index,
                name,
                expected,
                found: "<missing>".to_owned(),
            },
        };
        Error::format(self.rest, kind)
    }

    #[inline(always)]
    fn step(&mut self, rest: &'a [u8], end: End) {
        self.rest = rest;
        self.index += 1;
        self.done = end == End::Record;
    }

    /// A rule's failure, with the parameter's index and name filled in.
    #[cold]
    fn fail(&self, e: nom::Err<Error<'a>>, name: &'static str) -> Error<'a> {
        let mut e = match e {
            nom::Err::Error(e) | nom::Err::Failure(e) => e,
            nom::Err::Incomplete(_) => Error::format(
                self.rest,
                ErrorKind::Unterminated(char::from(self.d.record)),
            ),
        };
        name_parameter(&mut e, self.index, name);
        e
    }

    /// The next parameter as the grammar cuts it, and where it starts; `None` after the
    /// record's end.
    pub fn parameter(&mut self) -> Result<Option<(&'a [u8], Parameter<'a>)>, Error<'a>> {
        if self.done {
            return Ok(None);
        }
        self.open("", "")?;
        let at = self.rest;
        match parameter(self.d)(at) {
            Ok((rest, (p, end))) => {
                self.step(rest, end);
                Ok(Some((at, p)))
            }
            Err(e) => Err(self.fail(e, "")),
        }
    }

    /// A required real; a default reads 0.0 (the IGES default).
    #[inline(always)]
    pub fn real(&mut self, name: &'static str) -> Result<f64, Error<'a>> {
        self.open(name, "a real")?;
        match real_parameter(self.d)(self.rest) {
            Ok((rest, (v, end))) => {
                self.step(rest, end);
                Ok(v)
            }
            Err(e) => Err(self.fail(e, name)),
        }
    }

    /// A real that may be absent (the record ended) or a default: `None` then.
    pub fn optional_real(&mut self, name: &'static str) -> Result<Option<f64>, Error<'a>> {
        if self.done {
            return Ok(None);
        }
        if at_default(self.d, self.rest) {
            self.real(name)?;
            return Ok(None);
        }
        self.real(name).map(Some)
    }

    /// `count` required reals.
    pub fn reals(&mut self, count: usize, name: &'static str) -> Result<Vec<f64>, Error<'a>> {
        let mut v = Vec::with_capacity(self.capacity(count, 1));
        // The usual case in one tight loop over the leaf's success path; the first
        // parameter it does not take (and everything after) goes through `real`.
        let rest = self.rest;
        let mut at = 0;
        let fast = count.min(self.max.saturating_sub(self.index));
        while !self.done && v.len() < fast {
            let Some((x, next, end, default)) = real_value(self.d, rest, at) else {
                break;
            };
            // A default reads 0.0 (counted, see `defaulted`).
            self.defaulted += usize::from(default);
            v.push(x);
            at = next;
            self.done = end == End::Record;
        }
        self.index += v.len();
        self.rest = rest.get(at..).unwrap_or_default();
        for _ in v.len()..count {
            v.push(self.required_real(name)?);
        }
        Ok(v)
    }

    /// `count` required points (three reals each).
    pub fn points(
        &mut self,
        count: usize,
        name: [&'static str; 3],
    ) -> Result<Vec<[f64; 3]>, Error<'a>> {
        let mut v = Vec::with_capacity(self.capacity(count, 3));
        // As in `reals`: whole points in the tight loop, the rest through `real`.
        let rest = self.rest;
        let mut at = 0;
        let fast = count.min(self.max.saturating_sub(self.index) / 3);
        while !self.done && v.len() < fast {
            let Some((x, a, End::Parameter, dx)) = real_value(self.d, rest, at) else {
                break;
            };
            let Some((y, b, End::Parameter, dy)) = real_value(self.d, rest, a) else {
                break;
            };
            let Some((z, c, end, dz)) = real_value(self.d, rest, b) else {
                break;
            };
            self.defaulted += usize::from(dx) + usize::from(dy) + usize::from(dz);
            v.push([x, y, z]);
            at = c;
            self.done = end == End::Record;
        }
        self.index += 3 * v.len();
        self.rest = rest.get(at..).unwrap_or_default();
        for _ in v.len()..count {
            v.push([
                self.required_real(name[0])?,
                self.required_real(name[1])?,
                self.required_real(name[2])?,
            ]);
        }
        Ok(v)
    }

    /// An integer; `default` when the parameter is a default (`None`: required).
    pub fn integer(&mut self, name: &'static str, default: Option<i64>) -> Result<i64, Error<'a>> {
        self.open(name, "an integer")?;
        let at = self.rest;
        // The usual shape without the rule's machinery; anything else through the rule.
        if let Some((Some(v), n, end)) =
            integer_value(self.d, at).map(|(v, n, end)| (v.or(default), n, end))
        {
            self.step(&at[n..], end);
            return Ok(v);
        }
        match integer_parameter(self.d)(at) {
            Ok((rest, (v, end))) => match v.or(default) {
                Some(v) => {
                    self.step(rest, end);
                    Ok(v)
                }
                None => Err(self.fail(
                    nom::Err::Failure(bad_parameter(at, "an integer", Parameter::Default)),
                    name,
                )),
            },
            Err(e) => Err(self.fail(e, name)),
        }
    }

    /// A string; `None` for a default.
    pub fn string(&mut self, name: &'static str) -> Result<Option<&'a str>, Error<'a>> {
        self.open(name, "a Hollerith string")?;
        match string_parameter(self.d)(self.rest) {
            Ok((rest, (v, end))) => {
                self.step(rest, end);
                Ok(v)
            }
            Err(e) => Err(self.fail(e, name)),
        }
    }

    /// Reads the parameters left up to the record delimiter; returns how many.
    pub fn skip_rest(&mut self) -> Result<usize, Error<'a>> {
        let mut n = 0;
        while self.parameter()?.is_some() {
            n += 1;
        }
        Ok(n)
    }

    /// Interprets a parameter already cut by [`ParameterReader::parameter`] as an optional
    /// real (a default is `None`); `index` and `name` name it in an error.
    pub fn as_optional_real(
        &self,
        (at, p): (&'a [u8], Parameter<'a>),
        index: usize,
        name: &'static str,
    ) -> Result<Option<f64>, Error<'a>> {
        let value = match p {
            Parameter::Default => return Ok(None),
            Parameter::Value(v) => std::str::from_utf8(v)
                .ok()
                .and_then(|t| parse_iges_real(t).ok()),
            Parameter::String(_) => None,
        };
        value.map(Some).ok_or_else(|| {
            let mut e = bad_parameter(at, "a real", p);
            name_parameter(&mut e, index, name);
            e
        })
    }
}

/// Fills in the index and name of a [`bad_parameter`] error.
fn name_parameter(e: &mut Error<'_>, index: usize, name: &'static str) {
    if let crate::grammar::Cause::Format(ErrorKind::BadParameter {
        index: i, name: n, ..
    }) = &mut e.cause
    {
        *i = index;
        *n = name;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const D: Delimiters = Delimiters {
        param: b',',
        record: b';',
    };

    /// The plain definition of a parameter list (section 2.2.3), written without nom:
    /// split at delimiters outside Hollerith strings, trim blanks.
    fn plain_split(s: &str, d: Delimiters) -> Option<Vec<(u8, String)>> {
        let b = s.as_bytes();
        let mut out = Vec::new();
        let mut i = 0;
        loop {
            while b.get(i) == Some(&b' ') {
                i += 1;
            }
            let start = i;
            let mut j = i;
            while b.get(j).is_some_and(u8::is_ascii_digit) {
                j += 1;
            }
            let (kind, text, mut after) = if j > i && matches!(b.get(j), Some(b'H' | b'h')) {
                let n: usize = s.get(i..j)?.parse().ok()?;
                let t = s.get(j + 1..j + 1 + n)?;
                (b'H', t.to_owned(), j + 1 + n)
            } else {
                let k = (i..b.len()).find(|&k| b[k] == d.param || b[k] == d.record)?;
                let t = s.get(start..k)?.trim_end_matches(' ');
                (if t.is_empty() { b'E' } else { b'V' }, t.to_owned(), k)
            };
            while b.get(after) == Some(&b' ') {
                after += 1;
            }
            out.push((kind, text));
            match b.get(after) {
                Some(&c) if c == d.record => return Some(out),
                Some(&c) if c == d.param => i = after + 1,
                _ => return None,
            }
        }
    }

    fn grammar_split(s: &str, d: Delimiters) -> Option<Vec<(u8, String)>> {
        let mut i = s.as_bytes();
        let mut out = Vec::new();
        loop {
            let (rest, (p, end)) = parameter(d)(i).ok()?;
            out.push(match p {
                Parameter::Default => (b'E', String::new()),
                Parameter::String(t) => (b'H', t.to_owned()),
                Parameter::Value(v) => (b'V', String::from_utf8(v.to_vec()).ok()?),
            });
            i = rest;
            if end == End::Record {
                return Some(out);
            }
        }
    }

    #[test]
    fn defaults_strings_values_and_comment() {
        let v = grammar_split("126, 3 ,,4Ha,;b,1.5D0; comment, 2;", D).unwrap();
        assert_eq!(
            v,
            vec![
                (b'V', "126".into()),
                (b'V', "3".into()),
                (b'E', String::new()),
                (b'H', "a,;b".into()),
                (b'V', "1.5D0".into()),
            ]
        );
    }

    #[test]
    fn errors_are_located() {
        let d = Delimiters {
            param: b'/',
            record: b'#',
        };
        assert_eq!(grammar_split("1/2.5/#", d).map(|v| v.len()), Some(3));
        let whole = b"5Hab";
        let Err(nom::Err::Failure(e)) = parameter(d)(whole) else {
            panic!()
        };
        assert!(matches!(
            e.cause,
            crate::grammar::Cause::Format(ErrorKind::HollerithTooLong { declared: 5, .. })
        ));
        let whole = b"1/2";
        let Err(nom::Err::Failure(e)) = parameter(d)(&whole[2..]) else {
            panic!()
        };
        assert_eq!(e.offset(whole), 3);
        let whole = b"2Habx/#";
        let Err(nom::Err::Failure(e)) = parameter(d)(whole) else {
            panic!()
        };
        assert_eq!(e.offset(whole), 4);
        assert_eq!(integer(b"-12"), Some(-12));
        assert_eq!(integer(b"1.0"), None);
        assert_eq!(integer(b"9999999999999999999"), None);
    }

    fn token() -> impl Strategy<Value = String> {
        prop_oneof![
            "[0-9]{1,4}",
            "-?[0-9]{0,3}\\.[0-9]{0,4}([EeDd][+-]?[0-9]{1,3})?",
            "[ ]{0,2}[0-9.]{1,3}[ ]{0,2}",
            Just(String::new()),
            "[a-z ]{1,4}",
            "[a-z,;]{0,6}".prop_map(|s| format!("{}H{s}", s.len())),
            "[0-9]H",
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        /// The nom rules cut a record as the plain definition does.
        #[test]
        fn parameter_matches_the_plain_definition(
            toks in proptest::collection::vec(token(), 1..8),
            tail in "[;, x]{0,2}",
        ) {
            let s = format!("{}{tail}", toks.join(","));
            prop_assert_eq!(grammar_split(&s, D), plain_split(&s, D), "{:?}", s);
        }

        /// Where the integer fast leaf answers, it answers as the `integer_parameter` rule
        /// (value or default, the same end and the same rest).
        #[test]
        fn integer_leaf_matches_the_rule(t in token(), tail in "[;, x]{0,2}") {
            let s = format!("{t}{tail}");
            let b = s.as_bytes();
            if let Some((v, n, end)) = integer_value(D, b) {
                let rule = integer_parameter(D)(b).ok().map(|(rest, (v, end))| (v, rest.len(), end));
                prop_assert_eq!(rule, Some((v, b.len() - n, end)), "{:?}", s);
            }
        }

        /// The fast real leaf answers as `parameter` followed by `parse_iges_real`
        /// (a default reads 0.0), and fails exactly where that fails.
        #[test]
        fn real_leaf_matches_parameter_then_parse(t in token(), tail in "[;, x]{0,2}") {
            let s = format!("{t}{tail}");
            let fast = real_parameter(D)(s.as_bytes());
            let plain = parameter(D)(s.as_bytes()).ok().and_then(|(rest, (p, end))| {
                let v = match p {
                    Parameter::Default => Some(0.0),
                    Parameter::Value(v) => std::str::from_utf8(v).ok().and_then(|t| parse_iges_real(t).ok()),
                    Parameter::String(_) => None,
                }?;
                Some((rest.len(), v.to_bits(), end))
            });
            prop_assert_eq!(fast.ok().map(|(rest, (v, end))| (rest.len(), v.to_bits(), end)), plain, "{:?}", s);
        }
    }

    proptest! {
        /// The word-at-a-time blank skip against the byte loop, at every start offset.
        #[test]
        fn skip_blanks_agrees_with_a_byte_loop(text in "[ ]{0,20}[0-9,; ]{0,20}", start in 0usize..45) {
            let b = text.as_bytes();
            let mut k = start;
            while b.get(k) == Some(&b' ') {
                k += 1;
            }
            prop_assert_eq!(skip_blanks(b, start), k);
        }

        /// `real_value` says "default" exactly where `at_default` does.
        #[test]
        fn real_value_default_flag_is_at_default(text in "[ ]{0,12}(1\\.5|[,;])[ ]{0,3}[,;]?") {
            let b = text.as_bytes();
            if let Some((v, _, _, default)) = real_value(D, b, 0) {
                prop_assert_eq!(default, at_default(D, b));
                if default {
                    prop_assert_eq!(v, 0.0);
                }
            }
        }
    }
}
