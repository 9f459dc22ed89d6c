//! Reading REALs: the STEP (ISO 10303-21 6.3.3) and IGES (5.3 section 2.2.2.3) grammars,
//! lexed and converted in one pass ([`crate::decimal`]), with the common coordinate shape
//! read first by a shorter path ([`coordinate`]).

use super::RealError;
use crate::decimal::Decimal;

/// Parses a STEP Part 21 REAL token (ISO 10303-21:2016, 6.3.3) strictly.
///
/// ```
/// # use nurbsx_parsers::real::{parse_step_real, RealError};
/// assert_eq!(parse_step_real("-2.5E-7"), Ok(-2.5e-7));
/// assert_eq!(parse_step_real("1."), Ok(1.0));
/// assert_eq!(parse_step_real(".5"), Err(RealError::Syntax));
/// assert_eq!(parse_step_real("1.E400"), Err(RealError::NonFinite));
/// ```
pub fn parse_step_real(token: &str) -> Result<f64, RealError> {
    let b = token.as_bytes();
    let (d, end) = lex_step(b, 0)?;
    if end != b.len() {
        return Err(RealError::Syntax);
    }
    convert(d, b, None)
}

/// Reads the STEP REAL that starts at `b[start]` and returns it with the offset just past
/// it, in one pass over the bytes (the lexer of [`parse_step_real`] without the "whole
/// token" check; the caller decides what may follow). Same values as [`parse_step_real`],
/// bit for bit.
///
/// ```
/// # use nurbsx_parsers::real::step_real_at;
/// assert_eq!(step_real_at(b"(1.5,-2.E3)", 1), Ok((1.5, 4)));
/// assert_eq!(step_real_at(b"(1.5,-2.E3)", 5), Ok((-2000.0, 10)));
/// ```
#[inline]
pub fn step_real_at(b: &[u8], start: usize) -> Result<(f64, usize), RealError> {
    // A STEP REAL needs a digit before the point (ISO 10303-21 6.3.3).
    if let Some(r) = coordinate::plain_decimal_at(b, start, 1) {
        return Ok(r);
    }
    step_real_general_at(b, start)
}

/// [`step_real_at`] by the general lexer alone (every form; the quick path's reference).
#[inline(never)]
fn step_real_general_at(b: &[u8], start: usize) -> Result<(f64, usize), RealError> {
    let (d, end) = lex_step(b, start)?;
    let token = b.get(start..end).ok_or(RealError::Syntax)?;
    Ok((convert(d, token, None)?, end))
}

/// The STEP REAL grammar, read once: `[SIGN] DIGIT {DIGIT} "." {DIGIT} ["E" [SIGN] DIGIT
/// {DIGIT}]` starting at `start`. Returns the digits and the offset after the token.
#[inline]
fn lex_step(b: &[u8], start: usize) -> Result<(Decimal, usize), RealError> {
    let (negative, mut i) = sign(b, start);
    let mut d = Decimal {
        negative,
        ..Decimal::default()
    };
    let mut acc = Digits::default();
    let int_start = i;
    i = acc.run(b, i);
    if i == int_start || b.get(i) != Some(&b'.') {
        return Err(RealError::Syntax);
    }
    let frac_start = i + 1;
    i = acc.run(b, frac_start);
    let frac_digits = i - frac_start;
    let mut exp: i64 = 0;
    if b.get(i) == Some(&b'E') {
        (exp, i) = lex_exponent(b, i + 1)?;
    }
    acc.finish(&mut d, b, frac_digits, exp);
    Ok((d, i))
}

/// Parses an IGES 5.3 real (section 2.2.2.3): optional sign, digits with a decimal point
/// (a leading or trailing digit may be missing, `.5`, `5.`), an optional `E`/`D` exponent in
/// either case. A plain integer token is accepted too, as Open CASCADE accepts it.
///
/// ```
/// # use nurbsx_parsers::real::parse_iges_real;
/// assert_eq!(parse_iges_real("-3.905D2"), Ok(-390.5));
/// assert_eq!(parse_iges_real(".5"), Ok(0.5));
/// assert_eq!(parse_iges_real("5"), Ok(5.0));
/// assert!(parse_iges_real("1.52.3").is_err());
/// ```
pub fn parse_iges_real(token: &str) -> Result<f64, RealError> {
    let b = token.as_bytes();
    let (d, exp_letter, end) = lex_iges(b, 0)?;
    if end != b.len() {
        return Err(RealError::Syntax);
    }
    convert(d, b, exp_letter)
}

/// The IGES REAL grammar (section 2.2.2.3), read once from `start`: optional sign, digits
/// with an optional decimal point and at least one digit, an optional `E`/`e`/`D`/`d`
/// exponent with at least one digit. Returns the digits, the offset of the exponent letter
/// relative to `start` (for [`convert`]'s `D` handling) and the offset after the literal;
/// what follows is the caller's business. Shared by [`parse_iges_real`] (whole token) and
/// [`iges_real_at`] (inside a record).
#[inline]
fn lex_iges(b: &[u8], start: usize) -> Result<(Decimal, Option<usize>, usize), RealError> {
    let (negative, mut i) = sign(b, start);
    let mut d = Decimal {
        negative,
        ..Decimal::default()
    };
    let mut acc = Digits::default();
    let int_start = i;
    i = acc.run(b, i);
    let mut n_digits = i - int_start;
    let mut frac_digits = 0;
    if b.get(i) == Some(&b'.') {
        let frac_start = i + 1;
        i = acc.run(b, frac_start);
        frac_digits = i - frac_start;
        n_digits += frac_digits;
    }
    if n_digits == 0 {
        return Err(RealError::Syntax);
    }
    let mut exp: i64 = 0;
    let mut exp_letter = None;
    if let Some(&c) = b.get(i)
        && matches!(c, b'E' | b'e' | b'D' | b'd')
    {
        exp_letter = Some(i - start);
        (exp, i) = lex_exponent(b, i + 1)?;
    }
    // Only the literal's own bytes: a long literal's significant digits are recounted
    // from the text.
    acc.finish(&mut d, b.get(..i).unwrap_or_default(), frac_digits, exp);
    Ok((d, exp_letter, i))
}

/// Digits accumulated over the integer and fraction parts of a literal.
#[derive(Default)]
struct Digits {
    /// The value of the digits read, modulo 2^64 (exact while at most 19 of them are
    /// significant).
    mantissa: u64,
    /// Digits read, leading zeros included.
    count: usize,
    /// Where the first run started (to recount without leading zeros when `count > 19`).
    first: Option<usize>,
}

impl Digits {
    /// Reads a run of decimal digits from `i`; returns the offset after it. Eight digits
    /// at a time where the input allows (the multiply-shift "SWAR" conversion of Lemire
    /// 2021, section 4, also used by std): an 8-digit chunk costs three multiplications
    /// instead of a dependent multiply-add per digit.
    #[inline(always)]
    fn run(&mut self, b: &[u8], mut i: usize) -> usize {
        if self.first.is_none() {
            self.first = Some(i);
        }
        let start = i;
        while let Some(chunk) = b.get(i..i + 8) {
            let mut word = [0u8; 8];
            word.copy_from_slice(chunk);
            let v = u64::from_le_bytes(word);
            if !all_eight_digits(v) {
                break;
            }
            self.mantissa = self
                .mantissa
                .wrapping_mul(100_000_000)
                .wrapping_add(eight_digits(v));
            i += 8;
        }
        // Then four at a time (the typical 13-17 digit coordinate leaves 5-7 after the
        // eights), then singles.
        if let Some(chunk) = b.get(i..i + 4) {
            let mut word = [0u8; 4];
            word.copy_from_slice(chunk);
            let v = u32::from_le_bytes(word);
            if all_four_digits(v) {
                self.mantissa = self
                    .mantissa
                    .wrapping_mul(10_000)
                    .wrapping_add(u64::from(four_digits(v)));
                i += 4;
            }
        }
        while let Some(&c) = b.get(i) {
            let digit = c.wrapping_sub(b'0');
            if digit > 9 {
                break;
            }
            self.mantissa = self
                .mantissa
                .wrapping_mul(10)
                .wrapping_add(u64::from(digit));
            i += 1;
        }
        self.count += i - start;
        i
    }

    /// Stores mantissa and exponent (`exp - frac_digits`, saturated) in `d`. `b` is the
    /// literal's text, for counting significant digits when there are many.
    #[inline(always)]
    fn finish(self, d: &mut Decimal, b: &[u8], frac_digits: usize, exp: i64) {
        d.mantissa = self.mantissa;
        // More than 19 digits: exact only if leading zeros bring it down to 19.
        d.truncated = self.count > 19 && self.significant(b) > 19;
        let frac = i64::try_from(frac_digits).unwrap_or(i64::MAX);
        // Far outside +-400 the value is 0 or infinite whatever the digits; the
        // saturation keeps the arithmetic in range without changing that outcome.
        let e = exp.saturating_sub(frac).clamp(-100_000, 100_000);
        d.exponent = i32::try_from(e).unwrap_or(0);
    }

    /// Digits from the first non-zero one (the point skipped), for the rare long literal.
    #[cold]
    fn significant(&self, b: &[u8]) -> usize {
        let from = self.first.unwrap_or(0);
        let digits = b
            .get(from..)
            .unwrap_or_default()
            .iter()
            .take_while(|c| c.is_ascii_digit() || **c == b'.')
            .filter(|c| c.is_ascii_digit());
        let mut n = 0;
        let mut seen = false;
        for &c in digits {
            seen |= c != b'0';
            n += usize::from(seen);
        }
        n
    }
}

/// Whether the eight bytes of `v` (little-endian) are all ASCII digits.
#[inline(always)]
fn all_eight_digits(v: u64) -> bool {
    let a = v.wrapping_add(0x4646_4646_4646_4646);
    let b = v.wrapping_sub(0x3030_3030_3030_3030);
    (a | b) & 0x8080_8080_8080_8080 == 0
}

/// Whether the four bytes of `v` (little-endian) are all ASCII digits.
#[inline(always)]
fn all_four_digits(v: u32) -> bool {
    let a = v.wrapping_add(0x4646_4646);
    let b = v.wrapping_sub(0x3030_3030);
    (a | b) & 0x8080_8080 == 0
}

/// The value of four ASCII digits (first digit in the lowest byte): pairs, then the two
/// pairs combined as `100 * first + second` in bits 16..32.
#[inline(always)]
fn four_digits(v: u32) -> u32 {
    let v = v.wrapping_sub(0x3030_3030);
    let v = v.wrapping_mul(10).wrapping_add(v >> 8);
    ((v & 0x00FF_00FF).wrapping_mul(0x0064_0001) >> 16) & 0xFFFF
}

/// The value of eight ASCII digits (first digit in the lowest byte), by three
/// multiply-shift steps that combine pairs, then quads.
#[inline(always)]
fn eight_digits(v: u64) -> u64 {
    eight_digit_values(v.wrapping_sub(0x3030_3030_3030_3030))
}

/// [`eight_digits`] of bytes that already hold digit values 0..=9 (not ASCII).
#[inline(always)]
fn eight_digit_values(v: u64) -> u64 {
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    const MUL1: u64 = 0x000F_4240_0000_0064; // 100 + (1000000 << 32)
    const MUL2: u64 = 0x0000_2710_0000_0001; // 1 + (10000 << 32)
    let v = v.wrapping_mul(10).wrapping_add(v >> 8);
    let hi = (v & MASK).wrapping_mul(MUL1);
    let lo = ((v >> 16) & MASK).wrapping_mul(MUL2);
    hi.wrapping_add(lo) >> 32
}

/// An optional sign at `b[i]` (both formats: `+` or `-`): whether it is `-`, and the offset
/// after it.
#[inline(always)]
fn sign(b: &[u8], i: usize) -> (bool, usize) {
    match b.get(i) {
        Some(b'-') => (true, i + 1),
        Some(b'+') => (false, i + 1),
        _ => (false, i),
    }
}

/// `[SIGN] DIGIT {DIGIT}` after an exponent letter; the value saturates (a huge exponent is
/// still huge) and the offset after the digits is returned.
#[inline(always)]
fn lex_exponent(b: &[u8], i: usize) -> Result<(i64, usize), RealError> {
    let (negative, mut i) = sign(b, i);
    let start = i;
    let mut exp: i64 = 0;
    while let Some(&c) = b.get(i) {
        let digit = c.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        exp = (exp * 10 + i64::from(digit)).min(1 << 40);
        i += 1;
    }
    if i == start {
        return Err(RealError::Syntax);
    }
    Ok((if negative { -exp } else { exp }, i))
}

/// The value of a lexed literal: the fast paths of [`Decimal::to_f64`], else std's parser
/// on the token text (`D` exponent rewritten to `E`, the only letter std knows). Refuses
/// overflow to infinity.
#[inline]
fn convert(d: Decimal, token: &[u8], d_exponent_at: Option<usize>) -> Result<f64, RealError> {
    let v = match d.to_f64() {
        Some(v) => v,
        None => slow_parse(token, d_exponent_at)?,
    };
    if v.is_finite() {
        Ok(v)
    } else {
        Err(RealError::NonFinite)
    }
}

/// std's correctly rounded parser, for the cases the fast paths leave (more than 19
/// significant digits, undecided Eisel-Lemire rounding). `token` already matched a grammar.
#[cold]
fn slow_parse(token: &[u8], exp_letter: Option<usize>) -> Result<f64, RealError> {
    let mut owned;
    let mut text = token;
    if let Some(pos) = exp_letter.filter(|&p| matches!(token.get(p), Some(b'D' | b'd'))) {
        owned = token.to_vec();
        if let Some(c) = owned.get_mut(pos) {
            *c = b'E';
        }
        text = &owned;
    }
    let s = std::str::from_utf8(text).map_err(|_| RealError::Syntax)?;
    s.parse().map_err(|_| RealError::Syntax)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::real::format::write_real_std;
    use crate::real::{format_real, write_real};
    use proptest::prelude::*;

    #[test]
    fn shortest_digits_agree_with_std_at_every_power_of_ten() {
        // Layout thresholds (1e-5, 1e16) and integer/".0" cases across the whole range,
        // each power of ten and its two neighbouring doubles.
        for e in -324..=308 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            for x in [
                p,
                f64::from_bits(p.to_bits() + 1),
                f64::from_bits(p.to_bits().saturating_sub(1)),
            ] {
                for x in [x, -x, x * 3.0, x * 7.25] {
                    if !x.is_finite() {
                        continue;
                    }
                    let (mut fast, mut slow) = (String::new(), String::new());
                    write_real(&mut fast, x).unwrap();
                    write_real_std(&mut slow, x).unwrap();
                    assert_eq!(fast, slow, "{x:e}");
                }
            }
        }
    }

    #[test]
    fn known_shapes() {
        let cases: &[(f64, &str)] = &[
            (0.0, "0."),
            (-0.0, "-0."),
            (1.0, "1."),
            (-1.5, "-1.5"),
            (1e16, "1.E16"),
            (1.5e-7, "1.5E-7"),
            (1e-5, "0.00001"),
            (f64::MAX, "1.7976931348623157E308"),
            (f64::MIN_POSITIVE, "2.2250738585072014E-308"),
            (5e-324, "5.E-324"),
            (1e300, "1.E300"),
            (123456789012345.0, "123456789012345."),
        ];
        for &(x, want) in cases {
            assert_eq!(format_real(x).unwrap(), want, "formatting {x:e}");
        }
        assert!(format_real(f64::NAN).is_err());
        assert!(format_real(f64::INFINITY).is_err());
    }

    #[test]
    fn step_grammar_is_strict() {
        for bad in [
            "", "1", ".5", "1.e5", "1.E", "1.E+", "1.52.3", "1.0E5x", "+", "1,5",
        ] {
            assert_eq!(parse_step_real(bad), Err(RealError::Syntax), "{bad:?}");
        }
        assert_eq!(parse_step_real("-0."), Ok(-0.0));
        assert!(parse_step_real("-0.").unwrap().is_sign_negative());
        assert_eq!(parse_step_real("1.E-400"), Ok(0.0));
        assert_eq!(parse_step_real("-1.E400"), Err(RealError::NonFinite));
    }

    #[test]
    fn iges_grammar() {
        assert_eq!(parse_iges_real("1.0D0"), Ok(1.0));
        assert_eq!(parse_iges_real("2.1d-1"), Ok(0.21));
        assert_eq!(parse_iges_real("1.E5"), Ok(1e5));
        assert_eq!(parse_iges_real("5."), Ok(5.0));
        assert_eq!(parse_iges_real("0.E+000"), Ok(0.0));
        assert_eq!(parse_iges_real("1e400"), Err(RealError::NonFinite));
        for bad in ["", ".", "-", "E5", "1.0D", "1.0 ", "1,5", "0x10"] {
            assert_eq!(parse_iges_real(bad), Err(RealError::Syntax), "{bad:?}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        /// Any finite f64, from its raw bits (subnormals, -0.0 and 1e300 included), reads back
        /// bit-identical through both grammars.
        #[test]
        fn shortest_digits_agree_with_std(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let (mut fast, mut slow) = (String::new(), String::new());
            write_real(&mut fast, x).unwrap();
            write_real_std(&mut slow, x).unwrap();
            prop_assert_eq!(fast, slow);
        }

        #[test]
        fn shortest_digits_agree_with_std_near_ties(k in 1u64..(1u64 << 53), shift in 0u32..12, q in -70i32..70) {
            // Doubles with a few fraction bits at magnitudes where ulp is a "round" decimal:
            // where ties between shortest candidates occur.
            let x = (k >> shift) as f64 * 2f64.powi(q);
            prop_assume!(x.is_finite());
            let (mut fast, mut slow) = (String::new(), String::new());
            write_real(&mut fast, x).unwrap();
            write_real_std(&mut slow, x).unwrap();
            prop_assert_eq!(fast, slow);
        }

        #[test]
        fn shortest_digits_agree_with_std_on_short_decimals(m in -99_999_999i64..99_999_999, e in -30i32..30) {
            // CAD-like values (few digits, any scale), where integer and boundary layouts
            // (".0" suffix, 1e-5 and 1e16 thresholds) are most likely.
            let x = m as f64 * 10f64.powi(e);
            let (mut fast, mut slow) = (String::new(), String::new());
            write_real(&mut fast, x).unwrap();
            write_real_std(&mut slow, x).unwrap();
            prop_assert_eq!(fast, slow);
        }

        #[test]
        fn round_trip_is_bit_exact(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let s = format_real(x).unwrap();
            prop_assert!(s.contains('.'));
            prop_assert_eq!(parse_step_real(&s).unwrap().to_bits(), bits, "{}", s);
            prop_assert_eq!(parse_iges_real(&s).unwrap().to_bits(), bits, "{}", s);
        }

        /// Differential test against std: whatever the strict lexer accepts, std reads the same.
        #[test]
        fn fast_path_agrees_with_std(s in "[+-]?[0-9]{1,9}\\.[0-9]{0,9}(E[+-]?[0-9]{1,2})?") {
            // Short significands and small exponents: the Clinger fast path's domain.
            let std: f64 = s.parse().unwrap();
            prop_assert_eq!(parse_step_real(&s).map(f64::to_bits), Ok(std.to_bits()));
        }

        #[test]
        fn iges_agrees_with_std(s in "[+-]?[0-9]{0,20}\\.[0-9]{1,20}([EeDd][+-]?[0-9]{1,3})?") {
            let std_form = s.replace(['D', 'd'], "E");
            match std_form.parse::<f64>() {
                Ok(v) if v.is_finite() => prop_assert_eq!(parse_iges_real(&s).map(f64::to_bits), Ok(v.to_bits())),
                _ => prop_assert!(parse_iges_real(&s).is_err()),
            }
        }

        /// The Eisel-Lemire domain: 15 to 19 significant digits at every decimal exponent
        /// where a 64-bit significand gives a finite non-zero double, and a little beyond.
        #[test]
        fn long_significands_agree_with_std(m in 100_000_000_000_000u64..=u64::MAX, e in -360i32..330, neg in any::<bool>()) {
            let digits = m.to_string();
            let (int, frac) = digits.split_at(1);
            let s = format!("{}{int}.{frac}E{e}", if neg { "-" } else { "" });
            let std: f64 = s.parse().unwrap();
            let iges = s.replace('E', "D");
            if std.is_finite() {
                prop_assert_eq!(parse_step_real(&s).map(f64::to_bits), Ok(std.to_bits()), "{}", s);
                prop_assert_eq!(parse_iges_real(&iges).map(f64::to_bits), Ok(std.to_bits()), "{}", iges);
            } else {
                prop_assert_eq!(parse_step_real(&s), Err(RealError::NonFinite));
            }
        }

        /// The SWAR digit kernels against the digits' plain value.
        #[test]
        fn swar_digit_kernels(n in 0u64..100_000_000) {
            let eight = format!("{n:08}");
            let v = u64::from_le_bytes(eight.as_bytes().try_into().unwrap());
            prop_assert!(all_eight_digits(v));
            prop_assert_eq!(eight_digits(v), n);
            let four = format!("{:04}", n % 10_000);
            let w = u32::from_le_bytes(four.as_bytes().try_into().unwrap());
            prop_assert!(all_four_digits(w));
            prop_assert_eq!(u64::from(four_digits(w)), n % 10_000);
        }

        /// One non-digit byte anywhere, of any value, is seen.
        #[test]
        fn swar_digit_checks_see_every_non_digit(n in 0u64..100_000_000, at in 0usize..8, c in any::<u8>()) {
            prop_assume!(!c.is_ascii_digit());
            let mut eight = format!("{n:08}").into_bytes();
            eight[at] = c;
            prop_assert!(!all_eight_digits(u64::from_le_bytes(eight[..].try_into().unwrap())));
            prop_assert!(!all_four_digits(u32::from_le_bytes(eight[at / 4 * 4..at / 4 * 4 + 4].try_into().unwrap())));
        }

        /// Every double's shortest text (positional and scientific) with leading and
        /// trailing zeros added reads back as that double.
        #[test]
        fn padded_shortest_forms_read_back(bits in any::<u64>(), lead in 0usize..25, trail in 0usize..25) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let sci = format!("{:E}", x.abs());
            let (mant, exp) = sci.split_once('E').unwrap();
            let mant = if mant.contains('.') { mant.to_owned() } else { format!("{mant}.") };
            let sign = if x.is_sign_negative() { "-" } else { "" };
            let s = format!("{sign}{}{mant}{}E{exp}", "0".repeat(lead), "0".repeat(trail));
            prop_assert_eq!(parse_step_real(&s).map(f64::to_bits), Ok(bits), "{}", s);
            let (_, end) = step_real_at(format!("({s},").as_bytes(), 1).unwrap();
            prop_assert_eq!(end, s.len() + 1);
        }

        /// The word-at-a-time quick path and the general lexer give the same value and end
        /// wherever the quick path answers, whatever follows the literal.
        #[test]
        fn step_quick_path_equals_general(
            text in "[+-]?[0-9]{0,21}\\.?[0-9]{0,21}(E[+-]?[0-9]{1,3})?",
            rest in "[0-9.,)Ee +-]{0,3}",
        ) {
            let buf = format!("({text}{rest}");
            if let Some((v, end)) = coordinate::plain_decimal_at(buf.as_bytes(), 1, 1) {
                prop_assert_eq!(
                    step_real_general_at(buf.as_bytes(), 1).map(|(x, e)| (x.to_bits(), e)),
                    Ok((v.to_bits(), end)),
                    "{:?}", buf
                );
            }
            prop_assert_eq!(
                step_real_at(buf.as_bytes(), 1).map(|(x, e)| (x.to_bits(), e)),
                step_real_general_at(buf.as_bytes(), 1).map(|(x, e)| (x.to_bits(), e)),
                "{:?}", buf
            );
        }

        #[test]
        fn agrees_with_std(s in "[+-]?[0-9]{1,20}\\.[0-9]{0,20}(E[+-]?[0-9]{1,3})?") {
            let ours = parse_step_real(&s);
            let std: f64 = s.parse().unwrap();
            if std.is_finite() {
                prop_assert_eq!(ours.unwrap().to_bits(), std.to_bits());
            } else {
                prop_assert_eq!(ours, Err(RealError::NonFinite));
            }
        }
    }
}

// The coordinate shape read a word at a time, in front of both general lexers.
mod coordinate;
pub(crate) use coordinate::digit_word;

// The IGES real read in place from a record's bytes (one pass, no token slice).
mod iges;
pub use iges::iges_real_at;
