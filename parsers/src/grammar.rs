//! What the two nom grammars share: the error type every rule returns.
//!
//! Each rule of ISO 10303-21 (in [`crate::step`]) and of IGES 5.3 (in [`crate::iges`]) is a
//! nom parser `fn(&[u8]) -> IResult<&[u8], T, GrammarError<'_, K>>`, where `K` is the
//! format's own error kind. A failure keeps the input left where it happened (so the byte
//! offset is `whole.len() - at.len()`, which the format turns into a STEP line/column/`#id`
//! or an IGES section/sequence/column/DE) and the innermost rule that named itself with
//! [`nom::error::context`].

use nom::error::{ContextError, ErrorKind, FromExternalError, ParseError};

/// Why a rule failed: a nom combinator's own failure, or the format's error kind raised by
/// a leaf (a REAL that overflows, a nesting limit, an unterminated string ...).
#[derive(Debug, Clone, PartialEq)]
pub enum Cause<K> {
    /// A combinator failed (`tag`, `char`, `alt` ...): the rule's name says what was expected.
    Syntax(ErrorKind),
    /// A leaf parser found something precise to say, in the format's own terms.
    Format(K),
}

/// The error of every grammar rule: where, in which rule, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct GrammarError<'a, K> {
    /// The input left where the failure happened (a suffix of the whole input).
    pub at: &'a [u8],
    /// The innermost named rule (`""` until a [`nom::error::context`] names it).
    pub rule: &'static str,
    /// Why it failed.
    pub cause: Cause<K>,
}

impl<'a, K> GrammarError<'a, K> {
    /// A failure raised by a leaf parser in the format's own terms.
    pub fn format(at: &'a [u8], kind: K) -> Self {
        GrammarError {
            at,
            rule: "",
            cause: Cause::Format(kind),
        }
    }

    /// The byte offset of the failure within `whole`, the input the grammar started on.
    pub fn offset(&self, whole: &[u8]) -> usize {
        whole.len().saturating_sub(self.at.len())
    }
}

impl<'a, K> ParseError<&'a [u8]> for GrammarError<'a, K> {
    fn from_error_kind(input: &'a [u8], kind: ErrorKind) -> Self {
        GrammarError {
            at: input,
            rule: "",
            cause: Cause::Syntax(kind),
        }
    }

    /// The innermost failure is the informative one: keep it.
    fn append(_input: &'a [u8], _kind: ErrorKind, other: Self) -> Self {
        other
    }

    /// Of two failed alternatives, report the one that got further into the input.
    fn or(self, other: Self) -> Self {
        if other.at.len() <= self.at.len() {
            other
        } else {
            self
        }
    }
}

impl<'a, K> ContextError<&'a [u8]> for GrammarError<'a, K> {
    /// Names the failure after the innermost rule that wraps it in a `context`.
    fn add_context(_input: &'a [u8], rule: &'static str, mut other: Self) -> Self {
        if other.rule.is_empty() {
            other.rule = rule;
        }
        other
    }
}

impl<'a, K, E: Into<K>> FromExternalError<&'a [u8], E> for GrammarError<'a, K> {
    fn from_external_error(input: &'a [u8], _kind: ErrorKind, e: E) -> Self {
        GrammarError::format(input, e.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nom::IResult;
    use nom::Parser;
    use nom::branch::alt;
    use nom::bytes::complete::tag;
    use nom::error::context;

    type E<'a> = GrammarError<'a, &'static str>;

    fn ab(i: &[u8]) -> IResult<&[u8], &[u8], E<'_>> {
        context("ab", (tag(&b"a"[..]), tag(&b"b"[..])).map(|(a, _)| a)).parse(i)
    }

    #[test]
    fn keeps_the_offset_and_innermost_rule() {
        let whole = b"ax";
        let Err(nom::Err::Error(e)) = context("outer", ab).parse(whole) else {
            panic!("must fail")
        };
        assert_eq!(e.offset(whole), 1);
        assert_eq!(e.rule, "ab");
        assert_eq!(e.cause, Cause::Syntax(ErrorKind::Tag));
    }

    #[test]
    fn alternatives_report_the_furthest_failure() {
        let whole = b"ax";
        let mut p = alt((tag(&b"zz"[..]), ab));
        let Err(nom::Err::Error(e)) = p.parse(whole) else {
            panic!("must fail")
        };
        assert_eq!(e.offset(whole), 1);
        let mut q = alt((ab, tag(&b"zz"[..])));
        let Err(nom::Err::Error(e)) = q.parse(whole) else {
            panic!("must fail")
        };
        assert_eq!(e.offset(whole), 1);
    }
}
