//! The common shape of a coordinate, `[SIGN] DIGITS "." DIGITS` with at most 19 digits and
//! no exponent: the quick path in front of both formats' general lexers
//! ([`step_real_at`](super::step_real_at) and [`iges_real_at`](super::iges_real_at)), and
//! a word-at-a-time digit run ([`digit_word`]) for short integers such as instance ids.
//!
//! [`plain_decimal_at`] reads that shape with fewer branches and tests than the general
//! lexers (no exponent, no digit counting beyond 19, no token slice). Anything else
//! (exponents, more than 19 digits, a value only std's parser can round) returns `None` and
//! the general lexer reads it; on the shape read here the two give the same value and end,
//! bit for bit (property tests below and in the format modules).

use crate::decimal::Decimal;

/// Eight bytes from `b[i..]` as a little-endian word; past the end of `b` the word is padded
/// with zero bytes (which are not digits, so a run never extends past the input).
#[inline(always)]
fn load(b: &[u8], i: usize) -> u64 {
    match b.get(i..i + 8) {
        Some(chunk) => {
            let mut word = [0u8; 8];
            word.copy_from_slice(chunk);
            u64::from_le_bytes(word)
        }
        // Byte by byte: a variable-length copy would be a `memcpy` call.
        None => b
            .get(i..)
            .unwrap_or_default()
            .iter()
            .take(8)
            .enumerate()
            .fold(0, |w, (k, &c)| w | u64::from(c) << (8 * k)),
    }
}

/// The ASCII digits that `b[i..]` starts with, up to eight: `(value, count)`.
///
/// The non-digit mask flags byte `j` when `b[i + j] - '0'` borrows (below `'0'`) or
/// `b[i + j] + 0x46` carries into bit 7 (above `'9'`), or when either has bit 7 set already
/// (bytes >= 0x80). Borrows and carries only travel upwards, so every byte below the lowest
/// flag is a digit and the lowest flag is exact; bytes above it are ignored.
#[inline(always)]
pub(crate) fn digit_word(b: &[u8], i: usize) -> (u64, usize) {
    let v = load(b, i);
    let digits = v.wrapping_sub(0x3030_3030_3030_3030);
    let non_digit = (v.wrapping_add(0x4646_4646_4646_4646) | digits) & 0x8080_8080_8080_8080;
    // At most 64 / 8 = 8.
    let n = (non_digit.trailing_zeros() / 8) as usize;
    if n == 0 {
        return (0, 0);
    }
    // The n digit values to the top bytes (the first digit is the lowest byte), zeros below:
    // the eight-digit number 0...0d1..dn, whose value is that of the run.
    (super::eight_digit_values(digits << (8 * (8 - n))), n)
}

/// `[SIGN] {DIGIT} "." {DIGIT}` from `b[start..]` with at least `min_int_digits` integer
/// digits (1 for STEP, ISO 10303-21 6.3.3; 0 for IGES, which allows `.5`), 1 to 19 digits in
/// all, and no `E`/`e`/`D`/`d` after it: the value and the offset after the last digit.
/// `None` for anything else, or when only std's parser can round the value (never for 15
/// digits or fewer).
///
/// On this shape both general lexers accumulate the same digits (fewer than 20, exact in a
/// `u64`), set the exponent to minus the fraction digits and convert with
/// [`Decimal::to_f64`], as this does; the value is below 10^19 and so finite.
///
/// The integer part is read a digit at a time (coordinates have few integer digits) and the
/// fraction eight, then four digits at a time, then singly. A version reading every part a
/// word at a time ([`digit_word`]) took 5 % more instructions on STEP and 4 % more on IGES
/// (callgrind, 10 MB files), so only the instance ids use that.
#[inline(always)]
pub(super) fn plain_decimal_at(
    b: &[u8],
    start: usize,
    min_int_digits: usize,
) -> Option<(f64, usize)> {
    let (negative, mut i) = super::sign(b, start);
    let int_start = i;
    let mut m: u64 = 0;
    // Integer digits: few in coordinates, one at a time (bounded: more than 19 is not this
    // shape).
    while let Some(&c) = b.get(i) {
        let digit = c.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        m = m.wrapping_mul(10).wrapping_add(u64::from(digit));
        i += 1;
        if i - int_start > 19 {
            return None;
        }
    }
    let int_digits = i - int_start;
    if int_digits < min_int_digits || b.get(i) != Some(&b'.') {
        return None;
    }
    i += 1;
    let frac_start = i;
    // Fraction digits: eight at a time (twice covers a 16-digit fraction), then four, then
    // singles; more than 19 digits in all is left to the general reader.
    for _ in 0..2 {
        let Some(chunk) = b.get(i..i + 8) else { break };
        let mut word = [0u8; 8];
        word.copy_from_slice(chunk);
        let v = u64::from_le_bytes(word);
        if !super::all_eight_digits(v) {
            break;
        }
        m = m
            .wrapping_mul(100_000_000)
            .wrapping_add(super::eight_digits(v));
        i += 8;
    }
    if let Some(chunk) = b.get(i..i + 4) {
        let mut word = [0u8; 4];
        word.copy_from_slice(chunk);
        let v = u32::from_le_bytes(word);
        if super::all_four_digits(v) {
            m = m
                .wrapping_mul(10_000)
                .wrapping_add(u64::from(super::four_digits(v)));
            i += 4;
        }
    }
    while let Some(&c) = b.get(i) {
        let digit = c.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        m = m.wrapping_mul(10).wrapping_add(u64::from(digit));
        i += 1;
        if i - frac_start > 19 {
            return None;
        }
    }
    let frac_digits = i - frac_start;
    let digits = int_digits + frac_digits;
    if digits == 0 || digits > 19 || matches!(b.get(i), Some(b'E' | b'e' | b'D' | b'd')) {
        return None;
    }
    let d = Decimal {
        negative,
        mantissa: m,
        // frac_digits <= 19.
        exponent: -i32::try_from(frac_digits).ok()?,
        truncated: false,
    };
    Some((d.to_f64()?, i))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The digit-run value and count by the definition, one byte at a time.
    fn reference(b: &[u8], i: usize) -> (u64, usize) {
        let run = b[i.min(b.len())..]
            .iter()
            .take(8)
            .take_while(|c| c.is_ascii_digit())
            .count();
        let v = b[i..i + run]
            .iter()
            .fold(0u64, |m, c| m * 10 + u64::from(c - b'0'));
        (v, run)
    }

    #[test]
    fn words_at_the_end_of_the_input() {
        assert_eq!(digit_word(b"12", 0), (12, 2));
        assert_eq!(digit_word(b"12", 2), (0, 0));
        assert_eq!(digit_word(b"x123456789", 1), (12_345_678, 8));
        assert_eq!(digit_word(b"", 0), (0, 0));
        assert_eq!(plain_decimal_at(b"-12.5", 0, 1), Some((-12.5, 5)));
        assert_eq!(plain_decimal_at(b"(0.,", 1, 1), Some((0.0, 3)));
        assert!(plain_decimal_at(b"-0.", 0, 1).unwrap().0.is_sign_negative());
        assert_eq!(plain_decimal_at(b".5", 0, 1), None);
        assert_eq!(plain_decimal_at(b".5", 0, 0), Some((0.5, 2)));
        assert_eq!(plain_decimal_at(b"1.5E3", 0, 1), None);
        assert_eq!(plain_decimal_at(b"12345678901234567890.", 0, 1), None);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        /// Any bytes at any offset: the word reader's count and value are those of the
        /// digits, however the non-digit that ends them looks (every byte value, in every
        /// lane, with anything above it).
        #[test]
        fn digit_word_is_the_digit_run(bytes in proptest::collection::vec(prop_oneof![any::<u8>(), (b'0'..=b'9')], 0..20), at in 0usize..20) {
            let at = at.min(bytes.len());
            prop_assert_eq!(digit_word(&bytes, at), reference(&bytes, at));
        }

        /// The quick shape against std's parser wherever it answers, in the shapes where it
        /// must answer (at most 15 digits: always exactly convertible).
        #[test]
        fn agrees_with_std(text in "[+-]?[0-9]{0,21}\\.[0-9]{0,21}", rest in "[,); E]?") {
            let buf = format!("{text}{rest}");
            let int_digits = text.trim_start_matches(['+', '-']).find('.').unwrap_or(0);
            let digits = text.bytes().filter(u8::is_ascii_digit).count();
            for min_int in [0, 1] {
                let got = plain_decimal_at(buf.as_bytes(), 0, min_int);
                let shaped = int_digits >= min_int && (1..=19).contains(&digits) && rest != "E";
                if let Some((v, end)) = got {
                    prop_assert!(shaped, "{:?} read as {}", buf, v);
                    prop_assert_eq!(end, text.len());
                    prop_assert_eq!(v.to_bits(), text.parse::<f64>().unwrap().to_bits(), "{:?}", buf);
                } else {
                    prop_assert!(!shaped || digits > 15, "{:?} not read", buf);
                }
            }
        }
    }
}
