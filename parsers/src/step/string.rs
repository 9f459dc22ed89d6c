//! STEP strings: decoding the ISO 10303-21 (clause 6.4.3) escapes, and encoding for the
//! writer.
//!
//! A string keeps its *raw* text (between the apostrophes, escapes untouched) so that a
//! re-export can be verbatim; [`StepString::decode`] turns it into Unicode:
//!
//! | escape | meaning |
//! |---|---|
//! | `''` | one apostrophe |
//! | `\\` | one backslash |
//! | `\X\hh` | the ISO 8859-1 character `hh` |
//! | `\X2\hhhh...\X0\` | UTF-16 code units (surrogate pairs allowed) |
//! | `\X4\hhhhhhhh...\X0\` | UCS-4 code points |
//! | `\S\c` | the character `c + 128` of the current alphabet (decoded as ISO 8859-1) |
//! | `\PA\` ... `\PI\` | select the ISO 8859 part used by `\S\` (accepted; decoded as part 1) |
//! | `\N\`, `\T\`, `\F\` | newline, tab, form feed (print control directives; Open CASCADE writes `\N\`/`\T\`) |
//!
//! Hex digits are accepted in either case. Physical line breaks inside a string are not part
//! of its value (the exchange structure is a character stream; writers wrap long strings).

use std::borrow::Cow;

/// A Part 21 string parameter, stored as the raw text between its apostrophes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct StepString<'a> {
    /// The text between the apostrophes, escapes as written (`O''Brien`): borrowed from the
    /// input when parsed, owned when built ([`StepString::from_text`]).
    pub raw: Cow<'a, str>,
}

/// Why a string's escapes cannot be decoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid string escape at byte {offset} of the string: {reason}")]
pub struct StringError {
    /// Byte offset of the offending backslash within [`StepString::raw`].
    pub offset: usize,
    /// What is wrong.
    pub reason: &'static str,
}

impl<'a> StepString<'a> {
    /// Wraps raw string text (between apostrophes, escapes as written).
    pub fn new(raw: &'a str) -> Self {
        StepString {
            raw: Cow::Borrowed(raw),
        }
    }

    /// Encodes Unicode text as a string parameter ([`encode_string`]).
    pub fn from_text(text: &str) -> StepString<'static> {
        let mut raw = String::with_capacity(text.len());
        encode_string(&mut raw, text);
        StepString {
            raw: Cow::Owned(raw),
        }
    }

    /// Decodes the escapes (table in the module documentation). Borrows when the raw text
    /// has nothing to decode.
    ///
    /// ```
    /// # use nurbsx_parsers::step::StepString;
    /// assert_eq!(StepString::new("O''Brien").decode().unwrap(), "O'Brien");
    /// assert_eq!(StepString::new("\\X2\\041F0440\\X0\\").decode().unwrap(), "Пр");
    /// assert!(StepString::new("\\X2\\00").decode().is_err());
    /// ```
    pub fn decode(&self) -> Result<Cow<'_, str>, StringError> {
        let raw: &str = &self.raw;
        if !raw
            .bytes()
            .any(|b| matches!(b, b'\'' | b'\\' | b'\n' | b'\r'))
        {
            return Ok(Cow::Borrowed(raw));
        }
        let b = raw.as_bytes();
        let mut out = String::with_capacity(raw.len());
        let mut i = 0;
        while let Some(&c) = b.get(i) {
            match c {
                b'\'' => {
                    // The lexer only lets doubled apostrophes through.
                    out.push('\'');
                    i += 2;
                }
                b'\n' | b'\r' => i += 1,
                b'\\' => i = decode_escape(b, i, &mut out)?,
                _ => {
                    // Copy a run of ordinary characters (keeps multi-byte UTF-8 intact).
                    let start = i;
                    while let Some(&d) = b.get(i) {
                        if matches!(d, b'\'' | b'\\' | b'\n' | b'\r') {
                            break;
                        }
                        i += 1;
                    }
                    out.push_str(raw.get(start..i).unwrap_or_default());
                }
            }
        }
        Ok(Cow::Owned(out))
    }

    /// Decodes, falling back to the raw text when an escape is invalid.
    pub fn decode_lossy(&self) -> Cow<'_, str> {
        self.decode().unwrap_or(Cow::Borrowed(&self.raw))
    }
}

/// Decodes the escape starting at the backslash `b[i]`; returns the index after it.
fn decode_escape(b: &[u8], i: usize, out: &mut String) -> Result<usize, StringError> {
    let err = |reason| StringError { offset: i, reason };
    let rest = b.get(i..).unwrap_or_default();
    if rest.starts_with(b"\\\\") {
        out.push('\\');
        return Ok(i + 2);
    }
    for (seq, ch) in [(&b"\\N\\"[..], '\n'), (b"\\T\\", '\t'), (b"\\F\\", '\x0c')] {
        if rest.starts_with(seq) {
            out.push(ch);
            return Ok(i + 3);
        }
    }
    if rest.starts_with(b"\\X\\") {
        let v = hex_value(rest.get(3..5)).ok_or_else(|| err("\\X\\ needs two hex digits"))?;
        out.push(char::from(u8::try_from(v).map_err(|_| err("\\X\\ value"))?));
        return Ok(i + 5);
    }
    if rest.starts_with(b"\\X2\\") || rest.starts_with(b"\\X4\\") {
        let width = if rest.get(2) == Some(&b'2') { 4 } else { 8 };
        let mut j = 4;
        let mut units: Vec<u32> = Vec::new();
        loop {
            if rest.get(j..).is_some_and(|r| r.starts_with(b"\\X0\\")) {
                j += 4;
                break;
            }
            let v = hex_value(rest.get(j..j + width))
                .ok_or_else(|| err("\\X2\\/\\X4\\ needs hex groups closed by \\X0\\"))?;
            units.push(v);
            j += width;
        }
        if width == 4 {
            let u16s: Vec<u16> = units
                .iter()
                .map(|&u| u16::try_from(u).unwrap_or(0xFFFD))
                .collect();
            for c in char::decode_utf16(u16s) {
                out.push(c.map_err(|_| err("unpaired UTF-16 surrogate in \\X2\\"))?);
            }
        } else {
            for u in units {
                out.push(char::from_u32(u).ok_or_else(|| err("\\X4\\ value is not a character"))?);
            }
        }
        return Ok(i + j);
    }
    if rest.starts_with(b"\\S\\") {
        let c = *rest.get(3).ok_or_else(|| err("\\S\\ needs a character"))?;
        if !(0x20..0x7f).contains(&c) {
            return Err(err("\\S\\ needs a printable ASCII character"));
        }
        out.push(char::from(c + 128));
        return Ok(i + 4);
    }
    if rest.len() >= 4 && rest.get(1) == Some(&b'P') && rest.get(3) == Some(&b'\\') {
        if rest.get(2).is_some_and(|c| (b'A'..=b'I').contains(c)) {
            return Ok(i + 4);
        }
        return Err(err("\\P?\\ needs an alphabet letter A-I"));
    }
    Err(err("unknown escape (a backslash must be written \\\\)"))
}

/// The value of a run of hex digits (either case); `None` if absent, short or not hex.
fn hex_value(digits: Option<&[u8]>) -> Option<u32> {
    let digits = digits?;
    let mut v: u32 = 0;
    for &d in digits {
        v = v.checked_mul(16)? + char::from(d).to_digit(16)?;
    }
    Some(v)
}

/// Appends `text` as the inside of a Part 21 string (no surrounding apostrophes): `'` as
/// `''`, `\` as `\\`, printable ASCII as itself, everything else as `\X2\hhhh...\X0\`
/// (upper-case hex, UTF-16) so the output is pure ASCII.
///
/// ```
/// # use nurbsx_parsers::step::encode_string;
/// let mut s = String::new();
/// encode_string(&mut s, "O'Brien \\ Пр");
/// assert_eq!(s, "O''Brien \\\\ \\X2\\041F0440\\X0\\");
/// ```
pub fn encode_string(out: &mut String, text: &str) {
    let mut in_x2 = false;
    for c in text.chars() {
        let plain = (' '..='~').contains(&c);
        if plain && in_x2 {
            out.push_str("\\X0\\");
            in_x2 = false;
        }
        match c {
            '\'' => out.push_str("''"),
            '\\' => out.push_str("\\\\"),
            _ if plain => out.push(c),
            _ => {
                if !in_x2 {
                    out.push_str("\\X2\\");
                    in_x2 = true;
                }
                let mut buf = [0u16; 2];
                for unit in c.encode_utf16(&mut buf) {
                    out.push_str(&format!("{unit:04X}"));
                }
            }
        }
    }
    if in_x2 {
        out.push_str("\\X0\\");
    }
}
