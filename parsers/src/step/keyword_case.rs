//! Keywords written in lower case (ISO 10303-21 clause 6.4: `standard_keyword = UPPER
//! { UPPER | DIGIT }`, `user_defined_keyword = "!" standard_keyword`; the structure
//! keywords of clauses 8-10 are upper case too).
//!
//! The grammar refuses such a keyword ([`ParseErrorKind::LowercaseKeyword`]). Its meaning is
//! still unambiguous (keywords name EXPRESS entities, whose names are case-insensitive), so
//! a reader that met one can upper-case every keyword of the file with
//! [`upper_case_keywords`] and read the copy, reporting each keyword it changed. Upper-casing
//! ASCII letters keeps every byte offset, so lines, columns and `#id`s of the copy are
//! those of the original.

use super::error::{LineIndex, ParseError, ParseErrorKind};
use crate::Stop;

/// Upper-cases, in place, every keyword of `text` that has lower-case letters: every run of
/// letters, digits and `_` that starts with a letter or `_` and does not continue a number,
/// an enumeration value (`.F.`) or another token, outside strings (`'...'`, clause 6.3.3),
/// binaries (`"..."`, clause 6.3.6) and comments (`/* */`, clause 6.5). Returns how many it
/// changed and, for the first `listed` of them, a located error (line, column, and the
/// `#id` of the instance holding it; none in the header).
///
/// Polls `stop` every [`crate::stop::SCAN_POLL`] tokens (a token is a keyword, a string, a
/// comment or one other byte) and ends with a [`ParseErrorKind::Stopped`] error once it has
/// fired; `text` is then partly upper-cased.
pub fn upper_case_keywords(
    text: &mut String,
    listed: usize,
    stop: Stop<'_>,
) -> Result<(usize, Vec<ParseError>), ParseError> {
    let lines = LineIndex::default();
    let mut changed = 0;
    let mut found = Vec::new();
    // The instance whose statement is being read (`#id =` right after a `;`).
    let mut instance: Option<u64> = None;
    let mut statement_start = true;
    let mut i = 0;
    let mut tokens = 0usize;
    while let Some(&c) = text.as_bytes().get(i) {
        tokens += 1;
        if stop.at(tokens) {
            return Err(ParseError::stopped(i));
        }
        let b = text.as_bytes();
        match c {
            b'\'' => {
                // A string; `''` inside is one apostrophe.
                i += 1;
                loop {
                    match memchr::memchr(b'\'', b.get(i..).unwrap_or_default()) {
                        Some(p) if b.get(i + p + 1) == Some(&b'\'') => i += p + 2,
                        Some(p) => {
                            i += p + 1;
                            break;
                        }
                        None => {
                            i = b.len();
                            break;
                        }
                    }
                }
                statement_start = false;
            }
            b'"' => {
                i = memchr::memchr(b'"', b.get(i + 1..).unwrap_or_default())
                    .map_or(b.len(), |p| i + 1 + p + 1);
                statement_start = false;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i = memchr::memmem::find(b.get(i + 2..).unwrap_or_default(), b"*/")
                    .map_or(b.len(), |p| i + 2 + p + 2);
            }
            b';' => {
                instance = None;
                statement_start = true;
                i += 1;
            }
            b'#' if statement_start => {
                let digits = b
                    .get(i + 1..)
                    .unwrap_or_default()
                    .iter()
                    .take_while(|c| c.is_ascii_digit())
                    .count();
                instance =
                    super::grammar::decimal_u64(b.get(i + 1..i + 1 + digits).unwrap_or_default());
                statement_start = false;
                i += 1 + digits;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let start = i;
                let after_token = i
                    .checked_sub(1)
                    .and_then(|p| b.get(p))
                    .is_some_and(|p| p.is_ascii_alphanumeric() || *p == b'_' || *p == b'.');
                while b
                    .get(i)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                {
                    i += 1;
                }
                let lower = b
                    .get(start..i)
                    .is_some_and(|w| w.iter().any(u8::is_ascii_lowercase));
                if lower && !after_token {
                    changed += 1;
                    if found.len() < listed {
                        let word = text.get(start..i).unwrap_or_default().to_owned();
                        found.push(lines.error(
                            text,
                            ParseErrorKind::LowercaseKeyword(word),
                            start,
                            instance,
                        ));
                    }
                    if let Some(w) = text.get_mut(start..i) {
                        w.make_ascii_uppercase();
                    }
                }
                statement_start = false;
            }
            c => {
                if !c.is_ascii_whitespace() {
                    statement_start = false;
                }
                i += 1;
            }
        }
    }
    Ok((changed, found))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Line, column, `#id` and the keyword as written.
    type Found = (usize, usize, Option<u64>, String);

    fn upper(text: &str) -> (String, Vec<Found>) {
        let mut t = text.to_owned();
        let (n, found) = upper_case_keywords(&mut t, usize::MAX, Stop::NEVER).unwrap();
        assert_eq!(n, found.len());
        let found = found
            .into_iter()
            .map(|e| match e.kind {
                ParseErrorKind::LowercaseKeyword(w) => (e.line, e.column, e.entity, w),
                other => panic!("{other:?}"),
            })
            .collect();
        (t, found)
    }

    #[test]
    fn keywords_only_are_upper_cased() {
        let text = "header;\nfile_name('a b',\"0f\");\nDATA;\n#12 = cartesian_Point('x',(1.e5,2.E0),.unspecified.,/* a comment */ length_measure(1.));\n#3=!my_kw(#12,'it''s');\nENDSEC;";
        let (t, found) = upper(text);
        let line4 = text.lines().nth(3).unwrap_or_default();
        let column = |w: &str| line4.find(w).map(|c| c + 1).unwrap_or_default();
        assert_eq!(
            t,
            "HEADER;\nFILE_NAME('a b',\"0f\");\nDATA;\n#12 = CARTESIAN_POINT('x',(1.e5,2.E0),.unspecified.,/* a comment */ LENGTH_MEASURE(1.));\n#3=!MY_KW(#12,'it''s');\nENDSEC;"
        );
        assert_eq!(
            found,
            vec![
                (1, 1, None, "header".to_owned()),
                (2, 1, None, "file_name".to_owned()),
                (
                    4,
                    column("cartesian"),
                    Some(12),
                    "cartesian_Point".to_owned()
                ),
                (4, column("length"), Some(12), "length_measure".to_owned()),
                (5, 5, Some(3), "my_kw".to_owned()),
            ]
        );
    }

    #[test]
    fn upper_case_text_is_unchanged() {
        let text =
            "#1=B_SPLINE_CURVE_WITH_KNOTS('',2,(#2),.UNSPECIFIED.,.F.,.F.,(3),(0.),.UNSPECIFIED.);";
        let (t, found) = upper(text);
        assert_eq!(t, text);
        assert!(found.is_empty());
    }

    #[test]
    fn a_fired_stop_signal_ends_the_pass() {
        let text = "#1=a();\n".repeat(10_000);
        let fired = || true;
        let err =
            upper_case_keywords(&mut text.clone(), usize::MAX, Stop::new(&fired)).unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::Stopped);
        // A poll comes every 4096 tokens (here at most 8 bytes each): the pass stopped at
        // the first of the 80,000 bytes' polls.
        assert!(err.offset <= 8 * 4096, "{}", err.offset);
        let never = || false;
        let (n, _) = upper_case_keywords(&mut text.clone(), 0, Stop::new(&never)).unwrap();
        assert_eq!(n, 10_000);
    }

    #[test]
    fn unterminated_tokens_end_the_pass() {
        for text in ["#1=a('x", "#1=a(\"0", "#1=a(/* b"] {
            let (_, found) = upper(text);
            assert_eq!(found.len(), 1, "{text}");
        }
    }
}
