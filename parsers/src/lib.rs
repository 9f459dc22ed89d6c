//! # nurbsx-parsers: the format layer of nurbsx
//!
//! Pure syntax for the two neutral CAD formats nurbsx exchanges, and nothing else:
//!
//! - [`step`]: ISO 10303-21 (STEP Part 21) exchange structures: lexer, parser, a borrowed
//!   AST with an `#id` index, typed records for the ISO 10303-42 B-spline entities, and a
//!   writer.
//! - [`iges`]: IGES 5.3 fixed-column files: a nom grammar ([`iges::grammar`]: records and
//!   the S, G, D, P, T sections, the Global section with its delimiters and Hollerith
//!   strings, Directory Entries, free-format parameter data) whose fast leaves are the SWAR
//!   sequence-number reader and the one-pass real reader of the P section; one declaration
//!   per entity read ([`iges::records`]: 124, 126, 128, 102, 142, 144, 504, 508, 510) with
//!   one decoder for all; a writer from typed records.
//! - [`real`]: the one place where REAL literals are lexed and written (shortest digits
//!   that round-trip an `f64`, always with a decimal point), shared by both formats.
//! - [`limits`]: explicit resource limits applied while parsing untrusted input.
//!
//! This crate has no geometry in it: records follow the standards' attribute lists one to
//! one and check only what the syntax requires. Turning records into NURBS (knot
//! multiplicities, weights, units, transforms) belongs to the consumer of this crate (in nurbsx, its exchange layer); this crate depends on no geometry code.
//!
//! The STEP grammar is written with nom 8 ([`step`]'s private `grammar` module): every rule
//! of ISO 10303-21 (space and comments, keywords, simple and complex records, typed and
//! untyped parameters, lists, STRING, BINARY, ENUMERATION, entity instance names, INTEGER
//! and REAL, the structure keywords and the instance head) is a nom parser named after its
//! production, returning [`grammar::GrammarError`] (byte offset, innermost rule, cause).
//! The fast primitives are leaves of that one grammar, not a second parser: the SIMD
//! statement-end search (`step/specials.rs`) splits the file into statements for the rules,
//! the SWAR keyword run and the one-pass REAL reader ([`real`]) sit inside the `keyword`
//! and number rules, and a list steps through blank-free runs of references and reals in a
//! tight loop. Nested lists recurse with their depth checked against
//! [`Limits::max_nesting_depth`] before each nested rule, so the input cannot deepen the
//! recursion past the configured limit. Each record type has one public decoder of raw
//! instances ([`step::Scanned::bspline`], [`step::Scanned::cartesian_point`]) with its
//! one-pass text reader private inside it, and one writer from records
//! ([`step::writer`]).
//!
//! The IGES reader (sections, Global, directory entries, free-format parameters) is still a
//! hand-written byte scanner; its move onto the nom grammar framework is in progress.
//!
//! Every error carries a location: STEP errors a line, column and `#id`; IGES errors a
//! section letter, sequence number, column and DE pointer.

mod decimal;
pub mod grammar;
pub mod iges;
pub mod limits;
pub mod real;
pub mod signature;
pub mod step;
pub mod stop;

pub use limits::Limits;
pub use stop::Stop;

/// The exchange formats this crate reads and writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// ISO 10303-21 clear-text encoding (STEP Part 21).
    Step,
    /// IGES 5.3 fixed-column ASCII form.
    Iges,
}

impl Format {
    /// Guesses the format from the first bytes of a file.
    ///
    /// STEP files start (after optional whitespace and comments) with `ISO-10303-21;`.
    /// IGES files have an `S` (or, for a file without a Start section, `G`) in column 73
    /// of the first record followed by a sequence number. Returns `None` when neither
    /// signature is present.
    pub fn sniff(bytes: &[u8]) -> Option<Format> {
        let head = &bytes[..bytes.len().min(4096)];
        let trimmed = trim_leading_noise(head);
        if trimmed.starts_with(b"ISO-10303-21") {
            return Some(Format::Step);
        }
        let first_line = head.split(|&b| b == b'\n').next().unwrap_or(&[]);
        let first_line = first_line.strip_suffix(b"\r").unwrap_or(first_line);
        if first_line.len() >= 74 {
            let letter = first_line[72];
            let seq = &first_line[73..];
            if matches!(letter, b'S' | b'G')
                && seq.iter().any(|b| b.is_ascii_digit())
                && seq.iter().all(|b| b.is_ascii_digit() || *b == b' ')
            {
                return Some(Format::Iges);
            }
        }
        None
    }
}

/// Skips a UTF-8 byte-order mark, whitespace and `/* ... */` comments at the start of a
/// STEP file, so that sniffing accepts files whose first token is preceded by them.
fn trim_leading_noise(mut s: &[u8]) -> &[u8] {
    if let Some(rest) = s.strip_prefix(b"\xEF\xBB\xBF") {
        s = rest;
    }
    loop {
        let before = s.len();
        while let Some((first, rest)) = s.split_first() {
            if first.is_ascii_whitespace() {
                s = rest;
            } else {
                break;
            }
        }
        if let Some(rest) = s.strip_prefix(b"/*") {
            match memchr::memmem::find(rest, b"*/") {
                Some(end) => s = &rest[end + 2..],
                None => return &[],
            }
        }
        if s.len() == before {
            return s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sniffs_step_after_comment_and_bom() {
        assert_eq!(
            Format::sniff(b"\xEF\xBB\xBF /* hi */\r\nISO-10303-21;\nHEADER;"),
            Some(Format::Step)
        );
    }

    #[test]
    fn sniffs_iges_start_record() {
        let line = format!("{:<72}S{:>7}\n", "hello", 1);
        assert_eq!(Format::sniff(line.as_bytes()), Some(Format::Iges));
        assert_eq!(Format::sniff(b"garbage"), None);
    }
}
