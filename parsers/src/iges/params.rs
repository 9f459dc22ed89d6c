//! The free-format parameter tokenizer of the Global and Parameter Data sections
//! (IGES 5.3 sections 2.2.2 and 2.2.4; spec.md a.3, a.5).
//!
//! A [`Tokenizer`] is built from the file's two delimiters (Global parameters 1 and 2). It
//! splits the joined data columns of one record into [`Token`]s without allocating per
//! token: each token is a byte range into the data. Rules:
//! - two adjacent delimiters give an empty parameter (= default value);
//! - `nH` followed by exactly `n` characters is a Hollerith string; the characters may be
//!   delimiters and may continue on the next record;
//! - blanks around a parameter are ignored;
//! - the record delimiter ends the record; text after it is a comment and is ignored.

use super::error::ErrorKind;

/// What kind of parameter a token is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TokenKind {
    /// Nothing between two delimiters: the default value.
    Empty,
    /// A Hollerith string; the range is its characters (without the `nH` prefix).
    Hollerith,
    /// Anything else (integer, real, pointer, logical): the range is the trimmed text.
    Plain,
}

/// One parameter: its kind and byte range in the data it was cut from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Token {
    /// Kind of parameter.
    pub kind: TokenKind,
    /// Start byte in the data (for Hollerith, the first character after `H`).
    pub start: u32,
    /// End byte (exclusive).
    pub end: u32,
}

impl Token {
    /// The token's text in `data`.
    #[inline]
    pub fn text<'d>(&self, data: &'d str) -> &'d str {
        data.get(self.start as usize..self.end as usize)
            .unwrap_or("")
    }
}

/// A tokenizer error: what and at which byte offset of the data.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TokenError {
    /// What went wrong.
    pub kind: ErrorKind,
    /// Byte offset in the data.
    pub offset: usize,
}

/// Splits parameter data using the file's delimiters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tokenizer {
    /// Parameter delimiter (Global parameter 1; default `,`).
    pub param: u8,
    /// Record delimiter (Global parameter 2; default `;`).
    pub record: u8,
}

impl Default for Tokenizer {
    fn default() -> Self {
        Tokenizer {
            param: b',',
            record: b';',
        }
    }
}

impl Tokenizer {
    /// Tokenizes `data` from byte `from` up to the record delimiter, appending to `out`.
    /// Returns the offset just after the record delimiter. `max_tokens` bounds the work.
    pub fn tokenize(
        &self,
        data: &str,
        from: usize,
        out: &mut Vec<Token>,
        max_tokens: usize,
    ) -> Result<usize, TokenError> {
        let b = data.as_bytes();
        let mut i = from;
        if u32::try_from(b.len()).is_err() {
            return Err(TokenError {
                kind: ErrorKind::Limit("parameter record longer than 4 GiB".into()),
                offset: 0,
            });
        }
        loop {
            if out.len() >= max_tokens {
                return Err(TokenError {
                    kind: ErrorKind::Limit(format!("more than {max_tokens} parameters")),
                    offset: i,
                });
            }
            // Skip leading blanks.
            while i < b.len() && b[i] == b' ' {
                i += 1;
            }
            if i >= b.len() {
                return Err(TokenError {
                    kind: ErrorKind::Unterminated(self.record as char),
                    offset: i,
                });
            }
            let c = b[i];
            if c == self.param || c == self.record {
                out.push(Token {
                    kind: TokenKind::Empty,
                    start: off(i),
                    end: off(i),
                });
                i += 1;
                if c == self.record {
                    return Ok(i);
                }
                continue;
            }
            let start = i;
            // Hollerith: digits immediately followed by H.
            let mut j = i;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            let (tok, after) = if j > i && j < b.len() && (b[j] == b'H' || b[j] == b'h') {
                let mut n: usize = 0;
                for &d in &b[i..j] {
                    n = n
                        .checked_mul(10)
                        .and_then(|v| v.checked_add(usize::from(d - b'0')))
                        .ok_or(TokenError {
                            kind: ErrorKind::HollerithTooLong {
                                declared: usize::MAX,
                                available: b.len() - j - 1,
                            },
                            offset: start,
                        })?;
                }
                let content = j + 1;
                let available = b.len() - content;
                if n > available {
                    return Err(TokenError {
                        kind: ErrorKind::HollerithTooLong {
                            declared: n,
                            available,
                        },
                        offset: start,
                    });
                }
                // A character boundary check keeps `text()` exact on non-ASCII data.
                if !data.is_char_boundary(content + n) {
                    return Err(TokenError {
                        kind: ErrorKind::Garbage("non-ASCII text in Hollerith string".into()),
                        offset: content + n,
                    });
                }
                (
                    Token {
                        kind: TokenKind::Hollerith,
                        start: off(content),
                        end: off(content + n),
                    },
                    content + n,
                )
            } else {
                // SIMD search for the next delimiter (tokens are short, lines are long).
                let k =
                    memchr::memchr2(self.param, self.record, &b[j..]).map_or(b.len(), |e| j + e);
                let mut e = k;
                while e > start && b[e - 1] == b' ' {
                    e -= 1;
                }
                (
                    Token {
                        kind: TokenKind::Plain,
                        start: off(start),
                        end: off(e),
                    },
                    k,
                )
            };
            out.push(tok);
            i = after;
            while i < b.len() && b[i] == b' ' {
                i += 1;
            }
            if i >= b.len() {
                return Err(TokenError {
                    kind: ErrorKind::Unterminated(self.record as char),
                    offset: i,
                });
            }
            if b[i] == self.record {
                return Ok(i + 1);
            }
            if b[i] != self.param {
                let mut e = i + 1;
                while e < b.len() && !data.is_char_boundary(e) {
                    e += 1;
                }
                return Err(TokenError {
                    kind: ErrorKind::Garbage(data.get(i..e).unwrap_or("?").to_owned()),
                    offset: i,
                });
            }
            i += 1;
        }
    }
}

/// Parses an IGES integer token: optional sign and digits (blanks already trimmed).
pub fn parse_int(s: &str) -> Option<i64> {
    let b = s.as_bytes();
    let (neg, digits) = match b.first() {
        Some(b'-') => (true, &b[1..]),
        Some(b'+') => (false, &b[1..]),
        _ => (false, b),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v * 10 + i64::from(d - b'0');
    }
    Some(if neg { -v } else { v })
}

/// A byte offset as stored in a [`Token`]. The tokenizer refuses records of 4 GiB or more
/// before it starts (`u32::try_from(b.len())` above), so every offset fits in `u32`.
#[inline]
#[allow(clippy::cast_possible_truncation)]
fn off(i: usize) -> u32 {
    i as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str, t: Tokenizer) -> Vec<(TokenKind, String)> {
        let mut out = Vec::new();
        t.tokenize(s, 0, &mut out, 1000).unwrap();
        out.iter().map(|k| (k.kind, k.text(s).to_owned())).collect()
    }

    #[test]
    fn empty_hollerith_plain_and_comment() {
        let t = Tokenizer::default();
        let v = toks("126, 3 ,,4Ha,;b,1.5D0; comment, 2;", t);
        assert_eq!(
            v,
            vec![
                (TokenKind::Plain, "126".into()),
                (TokenKind::Plain, "3".into()),
                (TokenKind::Empty, String::new()),
                (TokenKind::Hollerith, "a,;b".into()),
                (TokenKind::Plain, "1.5D0".into()),
            ]
        );
    }

    #[test]
    fn custom_delimiters_and_errors() {
        let t = Tokenizer {
            param: b'/',
            record: b'#',
        };
        assert_eq!(toks("1/2.5/#", t).len(), 3);
        let mut out = Vec::new();
        let e = t.tokenize("5Hab", 0, &mut out, 10).unwrap_err();
        assert!(matches!(
            e.kind,
            ErrorKind::HollerithTooLong { declared: 5, .. }
        ));
        let e = t.tokenize("1/2", 0, &mut out, 10).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Unterminated('#')));
        let e = t.tokenize("2Habx/#", 0, &mut out, 10).unwrap_err();
        assert_eq!(e.offset, 4);
        assert_eq!(parse_int("-12"), Some(-12));
        assert_eq!(parse_int("1.0"), None);
        assert_eq!(parse_int("9999999999999999999"), None);
    }
}
