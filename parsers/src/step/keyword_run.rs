//! Byte-class tests on eight bytes at once ("SIMD within a register"): where does an
//! upper-case keyword end. Every statement head has one (`#12 = CARTESIAN_POINT(`), and a
//! table lookup per byte cost about 15 instructions per character; this costs about three.
//! (The crate forbids `unsafe`, so these are plain integer tricks, not intrinsics. The same
//! trick for the statement's `;`/`'`/`/` search measured slower than `memchr3`; that
//! search now uses 16-byte SIMD compares through the `wide` crate, `specials.rs`.)
//!
//! The per-byte flags below are exact (no false positives from carries between bytes),
//! tested for every byte value in every lane, and the run is property-tested against the
//! byte-at-a-time definition.

/// `0x01` in every byte.
const ONES: u64 = 0x0101_0101_0101_0101;
/// `0x80` in every byte.
const HIGH: u64 = 0x8080_8080_8080_8080;
/// `0x7F` in every byte.
const LOW7: u64 = 0x7F7F_7F7F_7F7F_7F7F;

/// Eight bytes from `b[i..]` as a little-endian word (first byte lowest), if there are eight.
#[inline(always)]
fn word(b: &[u8], i: usize) -> Option<u64> {
    let chunk = b.get(i..i.checked_add(8)?)?;
    let mut w = [0u8; 8];
    w.copy_from_slice(chunk);
    Some(u64::from_le_bytes(w))
}

/// `0x80` in each byte of `v` that is strictly between `lo` and `hi` (`lo < byte < hi`,
/// `hi <= 128`), 0 elsewhere; bytes >= 0x80 are never flagged.
///
/// Exact per byte ("hasbetween", Anderson's bit hacks): with `x = byte & 0x7F`,
/// `127 + hi - x` has its top bit set iff `x < hi` and never borrows (it is >= `hi` >= 0);
/// `x + 127 - lo` has its top bit set iff `x > lo` and never carries (it is <= 254).
#[inline(always)]
const fn between(v: u64, lo: u8, hi: u8) -> u64 {
    let x = v & LOW7;
    (ONES * (127 + hi as u64)).wrapping_sub(x) & !v & (x + ONES * (127 - lo as u64)) & HIGH
}

/// `0x80` in each byte of `v` that is a keyword character of ISO 10303-21 6.4 in upper
/// case: `A`-`Z`, `0`-`9` or `_`.
#[inline(always)]
const fn keyword_bytes(v: u64) -> u64 {
    between(v, b'A' - 1, b'Z' + 1) | between(v, b'0' - 1, b'9' + 1) | between(v, b'_' - 1, b'_' + 1)
}

/// Index of the lowest flagged byte of a non-zero flag word.
#[inline(always)]
fn first(flags: u64) -> usize {
    (flags.trailing_zeros() / 8) as usize
}

/// The end of the run of upper-case keyword characters (`A-Z0-9_`) starting at `from`,
/// not going past `end`: the first offset in `from..end` holding another byte, else `end`.
#[inline]
pub(crate) fn keyword_run(b: &[u8], from: usize, end: usize) -> usize {
    let end = end.min(b.len());
    let mut i = from;
    while i + 8 <= end {
        let Some(v) = word(b, i) else { break };
        let other = !keyword_bytes(v) & HIGH;
        if other != 0 {
            return i + first(other);
        }
        i += 8;
    }
    while i < end {
        match b.get(i) {
            Some(c) if c.is_ascii_uppercase() || c.is_ascii_digit() || *c == b'_' => i += 1,
            _ => break,
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn is_kw(c: u8) -> bool {
        c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_'
    }

    #[test]
    fn byte_classes_are_exact_for_every_byte_in_every_lane() {
        for c in 0..=255u8 {
            for lane in 0..8 {
                // The byte under test among neighbours that are and are not in the class,
                // so a carry or borrow from a neighbour would show.
                for fill in [0x00u8, b'A', b'Z', b'0', b'_', b'a', 0x7F, 0x80, 0xFF, b';'] {
                    let mut bytes = [fill; 8];
                    bytes[lane] = c;
                    let v = u64::from_le_bytes(bytes);
                    let flag = |f: u64| (f >> (lane * 8)) & 0x80 != 0;
                    assert_eq!(flag(keyword_bytes(v)), is_kw(c), "byte {c:#x} lane {lane}");
                }
            }
        }
    }

    proptest! {
        #[test]
        fn keyword_run_matches_byte_at_a_time(
            b in proptest::collection::vec(prop_oneof![
                Just(b'A'), Just(b'Z'), Just(b'_'), Just(b'7'), Just(b'('), Just(b'a'),
                Just(b' '), any::<u8>()
            ], 0..40),
            from in 0usize..40,
            end in 0usize..48,
        ) {
            let from = from.min(b.len());
            let end = end.max(from);
            let mut expected = from;
            while expected < end.min(b.len()) && is_kw(b[expected]) {
                expected += 1;
            }
            prop_assert_eq!(keyword_run(&b, from, end), expected);
        }
    }
}
