//! The common shape of a coordinate, `[SIGN] DIGITS "." DIGITS` with at most 19 digits and
//! no exponent, read a 64-bit word at a time: the quick path in front of both formats'
//! general lexers ([`step_real_at`](super::step_real_at) and
//! [`iges_real_at`](super::iges_real_at)).
//!
//! The general lexers test digit by digit (with eight- and four-digit chunks where the text
//! allows), which for a typical 17-digit coordinate means several failed chunk tests and a
//! tail of single digits. Here one word of eight bytes gives, in a fixed number of
//! operations, how many digits it starts with (a SWAR "non-digit" mask and a trailing-zero
//! count) and their value (the digits shifted to the top of the word, leading zeros below,
//! then the multiply-shift combination of Lemire 2021, section 4). A coordinate takes two or
//! three words. Anything else (exponents, more than 19 digits, a value only std's parser can
//! round) returns `None` and the general lexer reads it; on the shape read here the two give
//! the same value and end, bit for bit (property tests below and in the format modules).

use crate::decimal::Decimal;

/// `10^k` for the digit count `k` of one word.
const POW10: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

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

/// A run of digits from `b[i..]` appended to `m` (`m * 10^count + run`, wrapping): returns
/// the new `m` and the offset after the run. Reads at most three words; a longer run stops
/// inside the digits, which the callers reject as more than 19 digits.
#[inline(always)]
fn digit_run(b: &[u8], mut i: usize, mut m: u64) -> (u64, usize) {
    for _ in 0..3 {
        let (v, n) = digit_word(b, i);
        // POW10 has 9 entries and n <= 8.
        m = m
            .wrapping_mul(POW10.get(n).copied().unwrap_or(0))
            .wrapping_add(v);
        i += n;
        if n < 8 {
            break;
        }
    }
    (m, i)
}

/// `[SIGN] {DIGIT} "." {DIGIT}` from `b[start..]` with at least `min_int_digits` integer
/// digits, 1 to 19 digits in all, and no `E`/`e`/`D`/`d` after it: the value and the
/// offset after the last digit. `None` for anything else, or when only std's parser can
/// round the value (never for 15 digits or fewer).
///
/// On this shape both general lexers accumulate the same digits (fewer than 20, exact in a
/// `u64`), set the exponent to minus the fraction digits, and convert with
/// [`Decimal::to_f64`], as this does; the value is below 10^19 and so finite.
#[inline(always)]
pub(super) fn plain_decimal_at(
    b: &[u8],
    start: usize,
    min_int_digits: usize,
) -> Option<(f64, usize)> {
    let mut i = start;
    let negative = match b.get(i) {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    let int_start = i;
    let (m, int_end) = digit_run(b, i, 0);
    if int_end - int_start < min_int_digits || b.get(int_end) != Some(&b'.') {
        return None;
    }
    let frac_start = int_end + 1;
    let (m, end) = digit_run(b, frac_start, m);
    let frac_digits = end - frac_start;
    let digits = int_end - int_start + frac_digits;
    if digits == 0 || digits > 19 || matches!(b.get(end), Some(b'E' | b'e' | b'D' | b'd')) {
        return None;
    }
    let d = Decimal {
        negative,
        mantissa: m,
        // frac_digits <= 19.
        exponent: -i32::try_from(frac_digits).ok()?,
        truncated: false,
    };
    Some((d.to_f64()?, end))
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
