//! Decimal -> binary conversion of a REAL already split into digits and exponent: the one
//! place where `f64` values are made from text, correctly rounded (round half to even),
//! bit-identical to Rust's `str::parse::<f64>`.
//!
//! The lexers in [`crate::real`] read a literal once, byte by byte, accumulating up to 19
//! significant digits into a `u64` and the decimal exponent into an `i32`
//! ([`Decimal`]). [`Decimal::to_f64`] then tries, in order:
//!
//! 1. Clinger's fast path (W. D. Clinger, "How to read floating point numbers accurately",
//!    PLDI 1990): `m <= 2^53` and `|e| <= 22` make `m` and `10^|e|` exact `f64`s, so one
//!    IEEE multiplication or division is correctly rounded;
//! 2. the Eisel-Lemire algorithm (D. Lemire, "Number Parsing at a Gigabyte per Second",
//!    Software: Practice and Experience 51(8), 2021, sections 5-8; N. Mushtak and D. Lemire,
//!    "Fast Number Parsing Without Fallback", 2023): one or two 64x64 -> 128-bit products with
//!    a truncated power of five (table in `pow5.rs`) give the correctly rounded result or
//!    report that they cannot decide;
//! 3. otherwise (more than 19 significant digits, or an undecided Eisel-Lemire case) `None`,
//!    and the caller hands the token text to std's parser.
//!
//! Both fast steps are the ones std itself uses (`core::num::dec2flt`), so results agree bit
//! for bit; property tests in [`crate::real`] check that against std over random bit
//! patterns, shortest representations, long mantissas and extreme exponents.

mod pow5;

use pow5::{LARGEST_POW5, POW5, SMALLEST_POW5};

/// A decimal literal read by a lexer: `(-1)^negative * mantissa * 10^exponent`, exact
/// unless `truncated`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Decimal {
    /// A leading `-`.
    pub negative: bool,
    /// The first (at most 19) significant digits.
    pub mantissa: u64,
    /// The decimal exponent that applies to `mantissa` (saturated far outside the `f64`
    /// range, where only the std fallback decides).
    pub exponent: i32,
    /// More than 19 significant digits: `mantissa` is a truncation and only std decides.
    pub truncated: bool,
}

/// Exact powers of ten representable in an `f64` (10^0 ..= 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Bits of the `f64` significand without the hidden bit.
const MANTISSA_BITS: i32 = 52;
/// The biased exponent of infinity.
const INFINITE_POWER: i32 = 0x7FF;
/// The smallest exponent; values below round to zero.
const MINIMUM_EXPONENT: i32 = -1023;
/// Decimal exponents outside which `m * 10^q` is 0 or infinite for every 19-digit `m`.
const SMALLEST_POWER_OF_TEN: i32 = -342;
const LARGEST_POWER_OF_TEN: i32 = 308;
/// Range of `q` in which an exact halfway case (round to even) can occur (Lemire 2021,
/// section 7).
const MIN_EXPONENT_ROUND_TO_EVEN: i32 = -4;
const MAX_EXPONENT_ROUND_TO_EVEN: i32 = 23;

impl Decimal {
    /// The correctly rounded `f64`, or `None` when only the slow path can decide (the
    /// caller then parses the text with std). Infinity is returned for overflow; callers
    /// reject it.
    ///
    /// Inlined into the number readers (the Clinger branch is a few instructions; a call
    /// passing the `Decimal` through memory cost more); Eisel-Lemire stays a call.
    #[inline(always)]
    pub fn to_f64(self) -> Option<f64> {
        if self.truncated {
            return None;
        }
        let magnitude = if self.mantissa == 0 {
            0.0
        } else if self.mantissa <= 1 << 53 && (-22..=22).contains(&self.exponent) {
            // Clinger: both operands exact, one correctly rounded operation. Casts are exact:
            // mantissa <= 2^53, exponent within +-22.
            #[allow(clippy::cast_precision_loss, clippy::cast_sign_loss)]
            let (m, k) = (self.mantissa as f64, self.exponent.unsigned_abs() as usize);
            let p = *POW10.get(k)?;
            if self.exponent >= 0 { m * p } else { m / p }
        } else {
            eisel_lemire(self.exponent, self.mantissa)?
        };
        Some(if self.negative { -magnitude } else { magnitude })
    }
}

/// Eisel-Lemire: the correctly rounded `w * 10^q` for `w != 0`, `None` when the truncated
/// 128-bit product cannot decide the rounding (rare; the slow path decides). Follows
/// Lemire (2021), algorithm 1, with the ties-to-even rule of section 7 and the subnormal
/// handling of section 8 (as in `core::num::dec2flt::lemire`).
#[inline(never)]
fn eisel_lemire(q: i32, w: u64) -> Option<f64> {
    if q < SMALLEST_POWER_OF_TEN {
        return Some(0.0);
    }
    if q > LARGEST_POWER_OF_TEN {
        return Some(f64::INFINITY);
    }
    // Normalise so the most significant bit of w is set.
    let lz = w.leading_zeros();
    let w = w << lz;
    let (lo, hi) = product_approx(q, w, MANTISSA_BITS + 3)?;
    if lo == u64::MAX && !(-27..=55).contains(&q) {
        // The truncated table value may be one unit too small here and the +1 could carry
        // across the halfway point: undecided.
        return None;
    }
    let upperbit = i32::try_from(hi >> 63).ok()?;
    let shift = u32::try_from(upperbit + 64 - MANTISSA_BITS - 3).ok()?;
    let mut mantissa = hi >> shift;
    let mut power2 = power(q) + upperbit - i32::try_from(lz).ok()? - MINIMUM_EXPONENT;
    if power2 <= 0 {
        // Subnormal or zero.
        if -power2 + 1 >= 64 {
            return Some(0.0);
        }
        mantissa >>= u32::try_from(-power2 + 1).ok()?;
        mantissa += mantissa & 1;
        mantissa >>= 1;
        let biased = u64::from(mantissa >= (1 << MANTISSA_BITS));
        return Some(f64::from_bits((biased << MANTISSA_BITS) | mantissa));
    }
    // An exact halfway case rounds to even: only possible when the product was exact (lo
    // <= 1), q is small, the kept bits end in 01 and nothing below was dropped.
    if lo <= 1
        && (MIN_EXPONENT_ROUND_TO_EVEN..=MAX_EXPONENT_ROUND_TO_EVEN).contains(&q)
        && mantissa & 3 == 1
        && (mantissa << shift) == hi
    {
        mantissa &= !1;
    }
    mantissa += mantissa & 1;
    mantissa >>= 1;
    if mantissa >= (2 << MANTISSA_BITS) {
        // Rounding carried into a new bit: 1.0 * 2^(power2 + 1).
        mantissa = 1 << MANTISSA_BITS;
        power2 += 1;
    }
    mantissa &= !(1 << MANTISSA_BITS);
    if power2 >= INFINITE_POWER {
        return Some(f64::INFINITY);
    }
    let biased = u64::try_from(power2).ok()?;
    Some(f64::from_bits((biased << MANTISSA_BITS) | mantissa))
}

/// `floor(q * log2(10)) + 63`, exact for |q| < 1233 (Lemire 2021, section 5).
#[inline]
fn power(q: i32) -> i32 {
    (q.wrapping_mul(152_170 + 65_536) >> 16) + 63
}

/// The high 128 bits of `w * 5^q` (as `(low, high)` words) to the precision needed: one
/// multiplication by the table's high word, a second by its low word only when the bits
/// that decide rounding are all ones.
#[inline]
fn product_approx(q: i32, w: u64, precision: i32) -> Option<(u64, u64)> {
    let index = usize::try_from(q.checked_sub(SMALLEST_POW5)?).ok()?;
    if q > LARGEST_POW5 {
        return None;
    }
    let &(hi5, lo5) = POW5.get(index)?;
    let mask = u64::MAX >> u32::try_from(precision).ok()?;
    let (mut first_lo, mut first_hi) = full_multiplication(w, hi5);
    if first_hi & mask == mask {
        let (_, second_hi) = full_multiplication(w, lo5);
        first_lo = first_lo.wrapping_add(second_hi);
        if second_hi > first_lo {
            first_hi += 1;
        }
    }
    Some((first_lo, first_hi))
}

/// `a * b` as `(low, high)` 64-bit words.
#[inline]
fn full_multiplication(a: u64, b: u64) -> (u64, u64) {
    let r = u128::from(a) * u128::from(b);
    // Truncations intended: the two halves of the 128-bit product.
    #[allow(clippy::cast_possible_truncation)]
    (r as u64, (r >> 64) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dec(mantissa: u64, exponent: i32) -> Decimal {
        Decimal {
            negative: false,
            mantissa,
            exponent,
            truncated: false,
        }
    }

    #[test]
    fn agrees_with_std_on_hard_cases() {
        // Halfway cases, the largest/smallest normals and subnormals, and 19-digit mantissas.
        let cases: &[(u64, i32)] = &[
            (9007199254740993, 0), // 2^53 + 1: a tie, rounds to even
            (9007199254740995, 0),
            (18446744073709551615, 0),
            (17976931348623157, 292),  // f64::MAX
            (17976931348623159, 292),  // overflows
            (22250738585072014, -324), // smallest normal
            (22250738585072011, -324), // largest subnormal region
            (49406564584124654, -340), // smallest subnormal
            (24703282292062327, -340), // below half the smallest subnormal
            (24703282292062328, -340),
            (7450580596923828125, -27),
            (1, -342),
            (1, 308),
            (9999999999999999999, 308),
            (123456789012345678, -5),
        ];
        for &(m, e) in cases {
            let text = format!("{m}E{e}");
            let want: f64 = text.parse().unwrap();
            if let Some(got) = dec(m, e).to_f64() {
                assert_eq!(got.to_bits(), want.to_bits(), "{text}");
            }
        }
    }

    #[test]
    fn power_matches_log2_of_ten() {
        for q in -342..=308 {
            #[allow(clippy::cast_possible_truncation)]
            let exact = (f64::from(q) * std::f64::consts::LOG2_10).floor() as i32 + 63;
            assert_eq!(power(q), exact, "q = {q}");
        }
    }
}
