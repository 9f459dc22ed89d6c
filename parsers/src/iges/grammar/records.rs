//! The fixed 80-column records and the five sections (IGES 5.3 section 2.2.4).
//!
//! ```text
//! file    = { record } ; sections in the order S G D P T
//! record  = data (columns 1-72) section-letter (column 73) sequence-number (columns 74-80)
//! ```
//!
//! Lines are split with `memchr`; CR before LF and lines shorter than 80 columns are
//! tolerated with a warning when the section letter and sequence number can still be found
//! at the end of the line (as Open CASCADE does). [`sequence_number`] is the fast leaf: a
//! SWAR read of the seven digits most writers zero-pad.

use nom::Parser;

use super::super::error::{ErrorKind, ParseError, ParseWarning};
use super::parameters::{Error, Rule};
use crate::{Limits, Stop};

/// One record: its data columns (1-72, possibly shorter for a short line) and its position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record<'a> {
    /// Columns 1-72 (fewer when the line was short; never longer).
    pub data: &'a str,
    /// The sequence number as written in columns 74-80.
    pub sequence: usize,
    /// 1-based line number in the file.
    pub line: usize,
}

/// The records of a file, grouped by section, in file order.
#[derive(Debug, Clone, Default)]
pub struct Sections<'a> {
    /// Start section records.
    pub start: Vec<Record<'a>>,
    /// Global section records.
    pub global: Vec<Record<'a>>,
    /// Directory Entry records (two per entity).
    pub directory: Vec<Record<'a>>,
    /// Parameter Data records.
    pub parameters: Vec<Record<'a>>,
    /// Terminate record(s).
    pub terminate: Vec<Record<'a>>,
}

/// Splits `text` into records and sections, checking order and sequence numbers; polls
/// `stop` every [`SCAN_POLL`](crate::stop::SCAN_POLL) lines ([`ErrorKind::Stopped`] once
/// it has fired).
pub fn split<'a>(
    text: &'a str,
    limits: &Limits,
    warnings: &mut Vec<ParseWarning>,
    stop: Stop<'_>,
) -> Result<Sections<'a>, ParseError> {
    if text.len() > limits.max_input_bytes {
        return Err(ParseError::new(
            ErrorKind::Limit(format!(
                "input is {} bytes, above {}",
                text.len(),
                limits.max_input_bytes
            )),
            ' ',
            0,
        ));
    }
    let mut sections = Sections::default();
    let mut current = 0u8; // index into ORDER of the last section seen
    const ORDER: [char; 5] = ['S', 'G', 'D', 'P', 'T'];
    let mut crlf_warned = false;
    let mut short_warned = false;
    let mut long_warned = false;
    let bytes = text.as_bytes();
    let mut pos = 0usize;
    let mut line_no = 0usize;
    // One iterator over all line ends (the per-call set-up of `memchr` on every 80-byte line
    // showed in profiles of large files).
    let mut newlines = memchr::memchr_iter(b'\n', bytes);
    while pos < bytes.len() {
        line_no += 1;
        if stop.at(line_no) {
            return Err(ParseError::new(ErrorKind::Stopped, ' ', 0).at_line(line_no));
        }
        let end = newlines.next().unwrap_or(bytes.len());
        let mut line = &text[pos..end];
        pos = end + 1;
        if let Some(l) = line.strip_suffix('\r') {
            line = l;
            if !crlf_warned {
                crlf_warned = true;
                warnings.push(warning("crlf", "lines end with CR LF", ' ', 0, line_no));
            }
        }
        if is_blank(line) {
            continue; // blank lines (a trailing newline, padding) carry nothing
        }
        if current == 4 && !sections.terminate.is_empty() {
            // Anything after the Terminate record is not part of the file.
            warnings.push(warning(
                "after_terminate",
                "text after the Terminate record ignored",
                'T',
                0,
                line_no,
            ));
            break;
        }
        let (data, letter, seq) = match record(line) {
            Some((data, letter, seq, shape)) => {
                match shape {
                    Shape::Short if !short_warned => {
                        short_warned = true;
                        warnings.push(warning(
                            "short_line",
                            "records shorter than 80 columns (tolerated)",
                            letter,
                            seq,
                            line_no,
                        ));
                    }
                    Shape::Long if !long_warned => {
                        long_warned = true;
                        warnings.push(warning(
                            "long_line",
                            "records longer than 80 columns (extra columns ignored)",
                            letter,
                            seq,
                            line_no,
                        ));
                    }
                    _ => {}
                }
                (data, letter, seq)
            }
            None => {
                return Err(
                    ParseError::new(ErrorKind::BadRecord, ORDER[current as usize], 0)
                        .at_line(line_no)
                        .at_column(73),
                );
            }
        };
        if letter == 'C' || letter == 'B' {
            return Err(ParseError::new(ErrorKind::Compressed, letter, seq).at_line(line_no));
        }
        let Some(idx) = ORDER.iter().position(|&c| c == letter) else {
            return Err(ParseError::new(ErrorKind::BadRecord, letter, seq)
                .at_line(line_no)
                .at_column(73));
        };
        // idx < ORDER.len() = 5.
        #[allow(clippy::cast_possible_truncation)]
        let idx = idx as u8;
        if idx < current {
            return Err(ParseError::new(
                ErrorKind::SectionOrder {
                    found: letter,
                    after: ORDER[current as usize],
                },
                letter,
                seq,
            )
            .at_line(line_no)
            .at_column(73));
        }
        current = idx;
        let list = match letter {
            'S' => &mut sections.start,
            'G' => &mut sections.global,
            'D' => &mut sections.directory,
            'P' => &mut sections.parameters,
            _ => &mut sections.terminate,
        };
        if list.len() >= limits.max_entities.saturating_mul(4).max(1024) {
            return Err(
                ParseError::new(ErrorKind::Limit("too many records".into()), letter, seq)
                    .at_line(line_no),
            );
        }
        let expected = list.len() + 1;
        if seq != expected {
            warnings.push(warning(
                "sequence",
                &format!("sequence number {seq} where {expected} was expected"),
                letter,
                seq,
                line_no,
            ));
        }
        list.push(Record {
            data,
            sequence: seq,
            line: line_no,
        });
    }
    if sections.start.is_empty() {
        warnings.push(warning(
            "missing_start",
            "the file has no Start (S) section",
            'S',
            0,
            1,
        ));
    }
    // A model without entities (what the writer produces for an empty document) has empty
    // D and P sections; with its Terminate record present that is a complete file, not a
    // truncated one. Found by the `roundtrip` fuzz target.
    let no_entities = sections.directory.is_empty()
        && sections.parameters.is_empty()
        && !sections.terminate.is_empty();
    for (letter, list) in [
        ('G', &sections.global),
        ('D', &sections.directory),
        ('P', &sections.parameters),
    ] {
        if list.is_empty() && !(no_entities && letter != 'G') {
            return Err(
                ParseError::new(ErrorKind::MissingSection(letter), letter, 0)
                    .at_line(line_no.max(1)),
            );
        }
    }
    if sections.terminate.is_empty() {
        return Err(ParseError::new(ErrorKind::MissingSection('T'), 'T', 0).at_line(line_no.max(1)));
    }
    Ok(sections)
}

fn warning(
    code: &'static str,
    message: &str,
    section: char,
    sequence: usize,
    line: usize,
) -> ParseWarning {
    ParseWarning {
        code,
        message: message.to_owned(),
        section,
        sequence,
        de: None,
        line: Some(line),
    }
}

/// How a line matched the 80-column shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    Exact,
    Short,
    Long,
}

/// `record`: the data, section letter and sequence number of a line (section 2.2.4).
///
/// The 80-column form is `take(72) letter sequence-number` and blanks; a shorter line is
/// read back from its end (`... S0000001`, `... S1`), as Open CASCADE reads it.
fn record(line: &str) -> Option<(&str, char, usize, Shape)> {
    let b = line.as_bytes();
    if b.len() >= 80 {
        let (data, columns_73_on) = b.split_at(72);
        let (rest, (letter, seq)) = (section_letter, sequence_number)
            .parse(columns_73_on)
            .ok()?;
        let shape = if rest.iter().all(|c| *c == b' ') {
            Shape::Exact
        } else {
            Shape::Long
        };
        let data = line.get(..data.len())?;
        return Some((data, char::from(letter), seq, shape));
    }
    // Short line: scan back over the sequence digits to the section letter.
    let trimmed = line.trim_end();
    let tb = trimmed.as_bytes();
    let mut i = tb.len();
    while i > 0 && tb[i - 1].is_ascii_digit() {
        i -= 1;
    }
    let digits = &tb[i..];
    // Zero-padded "S0000001" or a plain "S1": blanks between letter and digits allowed.
    let mut j = i;
    while j > 0 && tb[j - 1] == b' ' {
        j -= 1;
    }
    if digits.is_empty() || digits.len() > 7 || j == 0 {
        return None;
    }
    let letter = tb[j - 1];
    if !matches!(letter, b'S' | b'G' | b'D' | b'P' | b'T' | b'C' | b'B') {
        return None;
    }
    let (_, seq) = sequence_number(digits).ok()?;
    let data_end = (j - 1).min(72);
    let data = trimmed.get(..data_end)?;
    Some((data, letter as char, seq, Shape::Short))
}

/// `section-letter` (column 73): an upper-case letter.
#[inline(always)]
fn section_letter(i: &[u8]) -> Rule<'_, u8> {
    match i.first() {
        Some(&c) if c.is_ascii_uppercase() => Ok((&i[1..], c)),
        _ => Err(nom::Err::Error(Error::format(i, ErrorKind::BadRecord))),
    }
}

/// `sequence-number` (columns 74-80): right-justified digits, blanks or zeros before them.
/// The fast leaf: seven digits (the zero-padded form most writers use) in one
/// multiply-shift pass, anything else one byte at a time.
#[inline(always)]
pub fn sequence_number(i: &[u8]) -> Rule<'_, usize> {
    let n = i.len().min(7);
    let (field, rest) = i.split_at(n);
    match parse_seq(field) {
        Some(v) => Ok((rest, v)),
        None => Err(nom::Err::Error(Error::format(i, ErrorKind::BadRecord))),
    }
}

/// `line.trim().is_empty()`, answered from the bytes for ASCII lines (the per-line cost of
/// the Unicode-aware trim showed in profiles of large files).
fn is_blank(line: &str) -> bool {
    match line
        .bytes()
        .find(|c| !matches!(c, b' ' | b'\t' | b'\n' | b'\x0b' | b'\x0c' | b'\r'))
    {
        None => true,
        Some(c) if c >= 0x80 => line.trim().is_empty(),
        Some(_) => false,
    }
}

/// Parses a right-justified sequence number (blanks and leading zeros allowed).
#[inline(always)]
fn parse_seq(b: &[u8]) -> Option<usize> {
    // Seven digits (the zero-padded form many writers use) in one multiply-shift pass;
    // anything else, one byte at a time below.
    if let Ok(&[a, b1, c, d, e, f, g]) = <&[u8; 7]>::try_from(b) {
        let v = u64::from_le_bytes([b'0', a, b1, c, d, e, f, g]);
        if all_eight_digits(v) {
            return usize::try_from(eight_digits(v)).ok();
        }
    }
    parse_seq_bytes(b)
}

/// [`parse_seq`] one byte at a time.
fn parse_seq_bytes(b: &[u8]) -> Option<usize> {
    let mut v: usize = 0;
    let mut any = false;
    for &c in b {
        match c {
            b' ' if !any => {}
            b'0'..=b'9' => {
                any = true;
                v = v * 10 + usize::from(c - b'0');
            }
            _ => return None,
        }
    }
    any.then_some(v)
}

/// Whether the eight bytes of `v` (little-endian) are all ASCII digits.
fn all_eight_digits(v: u64) -> bool {
    let a = v.wrapping_add(0x4646_4646_4646_4646);
    let b = v.wrapping_sub(0x3030_3030_3030_3030);
    (a | b) & 0x8080_8080_8080_8080 == 0
}

/// The value of eight ASCII digits (first digit in the lowest byte): pairs, then quads,
/// then the two quads (Lemire 2021, section 4).
fn eight_digits(v: u64) -> u64 {
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    const MUL1: u64 = 0x000F_4240_0000_0064; // 100 + (1000000 << 32)
    const MUL2: u64 = 0x0000_2710_0000_0001; // 1 + (10000 << 32)
    let v = v.wrapping_sub(0x3030_3030_3030_3030);
    let v = v.wrapping_mul(10).wrapping_add(v >> 8);
    let hi = (v & MASK).wrapping_mul(MUL1);
    let lo = ((v >> 16) & MASK).wrapping_mul(MUL2);
    hi.wrapping_add(lo) >> 32
}

/// The character at 1-based `column` of a record's data, for error columns.
pub(crate) fn field(data: &str, from: usize, to: usize) -> &str {
    let len = data.len();
    let a = from.min(len);
    let b = to.min(len);
    data.get(a..b).unwrap_or("")
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    proptest! {
        /// The seven-digit shortcut against the byte loop, on digits, blanks and noise.
        #[test]
        fn parse_seq_agrees_with_bytes(s in "[0-9 ]{7}|[0-9 a+\\-]{0,9}", n in 0usize..10_000_000) {
            prop_assert_eq!(super::parse_seq(s.as_bytes()), super::parse_seq_bytes(s.as_bytes()));
            let padded = format!("{n:07}");
            prop_assert_eq!(super::parse_seq(padded.as_bytes()), Some(n));
            let blanks = format!("{n:>7}");
            prop_assert_eq!(super::parse_seq(blanks.as_bytes()), Some(n));
        }
    }

    #[test]
    fn is_blank_is_trim_is_empty() {
        for line in [
            "",
            " ",
            "\t \x0b\x0c\r",
            "\u{a0}",
            " \u{85} ",
            "\u{2003}x",
            "x",
            "  1H,",
            "\u{a0}\u{a0}a",
            "\u{feff}",
        ] {
            assert_eq!(super::is_blank(line), line.trim().is_empty(), "{line:?}");
        }
    }
}
