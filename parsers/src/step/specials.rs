//! The bytes that end or suspend a statement, `;`, `'` (a string) and `/` (perhaps a
//! comment), found 64 bytes at a time: the statement search of the scanner
//! ([`statement_end_in`], ISO 10303-21 clause 5.4/5.5).
//!
//! The scanner used to call `memchr3` from each statement start; a point statement
//! (`#21 = CARTESIAN_POINT('',(...));`) then costs three searches of a few dozen bytes each,
//! and each search pays `memchr3`'s set-up again (~90 instructions per call). Here one
//! 64-bit mask per 64-byte block (four 16-byte SIMD compares through the `wide` crate, which
//! is safe code over SSE2 on x86_64, NEON on aarch64, scalar elsewhere) is computed once and
//! shared by every statement and string in the block: the next special byte is a
//! trailing-zero count.

use wide::u8x16;

use super::grammar::LResult;
use crate::step::ParseErrorKind;

/// Bytes per mask.
const BLOCK: usize = 64;

/// A cursor over the special bytes of `b`, block by block.
pub(crate) struct Specials<'b> {
    b: &'b [u8],
    /// Offset of the block described by `mask`.
    block: usize,
    /// Bit `k` set: `b[block + k]` is `;`, `'` or `/`.
    mask: u64,
}

impl<'b> Specials<'b> {
    /// A cursor over `b`.
    pub(crate) fn new(b: &'b [u8]) -> Self {
        Specials {
            b,
            block: 0,
            mask: block_mask(b, 0),
        }
    }

    /// The offset of the first special byte at or after `pos`, `None` if there is none.
    #[inline]
    pub(crate) fn next(&mut self, mut pos: usize) -> Option<usize> {
        loop {
            let rel = pos.wrapping_sub(self.block);
            if rel < BLOCK {
                let m = self.mask & (u64::MAX << rel);
                if m != 0 {
                    return Some(self.block + m.trailing_zeros() as usize);
                }
                pos = self.block + BLOCK;
            }
            if pos >= self.b.len() {
                return None;
            }
            self.block = pos;
            self.mask = block_mask(self.b, pos);
        }
    }
}

/// The special-byte mask of `b[at..at + 64]` (bytes past the end are not special).
#[inline]
fn block_mask(b: &[u8], at: usize) -> u64 {
    match b.get(at..at + BLOCK) {
        Some(full) => mask_of(full),
        None => tail_mask(b, at),
    }
}

/// [`block_mask`] of the last, short block: copied into a zero-padded block first (kept
/// out of line so that the usual path has no buffer to clear).
#[cold]
#[inline(never)]
fn tail_mask(b: &[u8], at: usize) -> u64 {
    let mut padded = [0u8; BLOCK];
    let tail = b.get(at..).unwrap_or_default();
    if let Some(dst) = padded.get_mut(..tail.len()) {
        dst.copy_from_slice(tail);
    }
    mask_of(&padded)
}

/// Bit `k` set for each `;`, `'` or `/` at `block[k]` (`block` holds 64 bytes).
#[inline(always)]
fn mask_of(block: &[u8]) -> u64 {
    let mut mask = 0u64;
    for (k, chunk) in block.chunks_exact(16).enumerate() {
        let mut lanes = [0u8; 16];
        lanes.copy_from_slice(chunk);
        let v = u8x16::new(lanes);
        let hit = v.cmp_eq(u8x16::splat(b';'))
            | v.cmp_eq(u8x16::splat(b'\''))
            | v.cmp_eq(u8x16::splat(b'/'));
        // `move_mask` gives one bit per lane in the low 16 bits (0..=0xFFFF, never
        // negative), so the narrowing is exact.
        #[allow(clippy::cast_sign_loss, clippy::cast_possible_truncation)]
        let bits = u64::from(hit.move_mask() as u16);
        mask |= bits << (16 * k);
    }
    mask
}

/// The index of the `;` that ends the statement starting at `from`, skipping strings and
/// comments (so `';'` inside a string or a comment does not end it), for a one-off search
/// (the header, skipped sections); the scan loop keeps one cursor for all its statements
/// and calls [`statement_end_in`].
pub(crate) fn statement_end(b: &[u8], from: usize) -> LResult<usize> {
    statement_end_in(&mut Specials::new(b), from)
}

/// [`statement_end`] over a shared [`Specials`] cursor.
#[inline]
pub(crate) fn statement_end_in(sp: &mut Specials<'_>, from: usize) -> LResult<usize> {
    let b = sp.b;
    let mut i = from;
    loop {
        let Some(q) = sp.next(i) else {
            return Err((
                ParseErrorKind::Expected {
                    expected: "`;`",
                    found: "end of input".to_owned(),
                },
                from,
            ));
        };
        match b.get(q) {
            Some(b';') => return Ok(q),
            // The empty string `''` (most names in real files) needs no search.
            Some(b'\'') if b.get(q + 1) == Some(&b'\'') && b.get(q + 2) != Some(&b'\'') => {
                i = q + 2;
            }
            Some(b'\'') => i = string_end_in(sp, q)? + 1,
            _ => {
                if b.get(q + 1) == Some(&b'*') {
                    // Comments are rare: one substring search, then the cursor moves on.
                    let hay = b.get(q + 2..).unwrap_or_default();
                    match memchr::memmem::find(hay, b"*/") {
                        Some(e) => i = q + 2 + e + 2,
                        None => return Err((ParseErrorKind::UnterminatedComment, q)),
                    }
                } else {
                    i = q + 1;
                }
            }
        }
    }
}

/// The index of the apostrophe closing the string that opens at `start` (doubled
/// apostrophes belong to the string), as [`string_end`](super::grammar) to the
/// end of the input.
fn string_end_in(sp: &mut Specials<'_>, start: usize) -> LResult<usize> {
    let b = sp.b;
    let mut i = start + 1;
    loop {
        let Some(q) = sp.next(i) else {
            return Err((ParseErrorKind::UnterminatedString, start));
        };
        if b.get(q) != Some(&b'\'') {
            i = q + 1;
        } else if b.get(q + 1) == Some(&b'\'') {
            i = q + 2;
        } else {
            return Ok(q);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The definition, one byte at a time: the first `;` outside strings (`''` inside one
    /// is an apostrophe) and comments `/* */`, with the errors the reader gives.
    fn reference(b: &[u8], from: usize) -> LResult<usize> {
        let mut i = from;
        while let Some(&c) = b.get(i) {
            match c {
                b';' => return Ok(i),
                b'\'' => {
                    let start = i;
                    i += 1;
                    loop {
                        match b.get(i) {
                            None => return Err((ParseErrorKind::UnterminatedString, start)),
                            Some(b'\'') if b.get(i + 1) == Some(&b'\'') => i += 2,
                            Some(b'\'') => break,
                            Some(_) => i += 1,
                        }
                    }
                    i += 1;
                }
                b'/' if b.get(i + 1) == Some(&b'*') => {
                    let start = i;
                    i += 2;
                    loop {
                        match (b.get(i), b.get(i + 1)) {
                            (Some(b'*'), Some(b'/')) => break,
                            (Some(_), Some(_)) => i += 1,
                            _ => return Err((ParseErrorKind::UnterminatedComment, start)),
                        }
                    }
                    i += 2;
                }
                _ => i += 1,
            }
        }
        Err((
            ParseErrorKind::Expected {
                expected: "`;`",
                found: "end of input".to_owned(),
            },
            from,
        ))
    }

    #[test]
    fn finds_ends_across_blocks() {
        let text = format!(
            "#1=A('{}');#2=B('it''s;/',/* ; */1.);{};",
            "x".repeat(100),
            " ".repeat(70)
        );
        let b = text.as_bytes();
        let mut sp = Specials::new(b);
        let first = statement_end_in(&mut sp, 0).unwrap();
        assert_eq!(first, text.find(");#2").unwrap() + 1);
        let second = statement_end_in(&mut sp, first + 1).unwrap();
        assert_eq!(second, text.find("1.);").unwrap() + 3);
        assert_eq!(statement_end_in(&mut sp, second + 1), Ok(text.len() - 1));
        assert!(statement_end_in(&mut sp, text.len()).is_err());
        let mut sp = Specials::new(b"'abc");
        assert_eq!(
            statement_end_in(&mut sp, 0),
            Err((ParseErrorKind::UnterminatedString, 0))
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(5_000))]
        /// Statement after statement through one cursor, as the scanner goes (and from
        /// arbitrary restart points): the same ends and errors as the byte-at-a-time
        /// definition; and the one-off search agrees too.
        #[test]
        fn agrees_with_the_definition(
            text in "([a-z;'/* ]{0,6}|x{60,70}){0,40}",
            restarts in proptest::collection::vec(0usize..400, 0..4),
        ) {
            let b = text.as_bytes();
            let mut sp = Specials::new(b);
            let mut from = 0;
            let mut starts = vec![];
            while from <= b.len() && starts.len() < 200 {
                starts.push(from);
                match reference(b, from) {
                    Ok(e) => from = e + 1,
                    Err(_) => break,
                }
            }
            starts.extend(restarts.iter().map(|&r| r.min(b.len())));
            for from in starts {
                prop_assert_eq!(statement_end_in(&mut sp, from), reference(b, from), "from {}", from);
                prop_assert_eq!(statement_end(b, from), reference(b, from), "from {}", from);
            }
        }
    }
}
