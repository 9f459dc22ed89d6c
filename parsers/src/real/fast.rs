//! A faster [`super::write_real`] for the writers: the same text, byte for byte, with the
//! common CAD values (integers, short binary fractions such as `0.25`) formatted directly
//! instead of through std's `Display`, which the reference path uses for every value whose
//! exact decimal expansion is short (those are the only possible Ryu/std tie cases).
//!
//! Why the direct forms are the shortest round-trip digits:
//! - an integer `|x| < 2^53`: its neighbours are at most 1 apart, so no other decimal with as
//!   few significant digits lies within half an ulp; the digits are the integer's own;
//! - a non-integer whose exact value `v / 10^k` has `v` odd with at most 15 digits: every
//!   decimal of at most 15 significant digits reads back to a distinct double (DBL_DIG = 15
//!   for all normal doubles), so no shorter or equal-length candidate other than `v` itself
//!   reads back to `x`; `v` odd means it has no trailing zero to strip.
//!
//! The tests compare every path with the std reference over random bits, ties, short
//! decimals and the layout thresholds.

use super::{NonFiniteReal, has_short_exact_decimal, write_real};

/// 2^53: below it every integer is exactly representable and has a unique shortest form.
const TWO_POW_53: f64 = 9_007_199_254_740_992.0;

/// Appends `x` exactly as [`write_real`] does (same bytes for every finite `f64`; the same
/// error for NaN and infinities), faster for integers and short binary fractions.
///
/// ```
/// # use nurbsx_parsers::real::write_real_fast;
/// let mut s = String::new();
/// for x in [1.0, 0.25, -0.0, 250.0, 1e-7, 0.1 + 0.2] {
///     write_real_fast(&mut s, x).unwrap();
///     s.push(' ');
/// }
/// assert_eq!(s, "1. 0.25 -0. 250. 1.E-7 0.30000000000000004 ");
/// ```
pub fn write_real_fast(out: &mut String, x: f64) -> Result<(), NonFiniteReal> {
    if !x.is_finite() {
        return Err(NonFiniteReal(x));
    }
    let ax = x.abs();
    if ax < TWO_POW_53 && x.trunc() == x {
        if x.is_sign_negative() {
            out.push('-');
        }
        // Exact: an integer below 2^53 converts to u64 without loss.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        push_digits(out, ax as u64);
        out.push('.');
        return Ok(());
    }
    if let Some((v, k)) = short_fraction(x) {
        write_short_fraction(out, x.is_sign_negative(), v, k);
        return Ok(());
    }
    if has_short_exact_decimal(x) {
        // Ties are possible: the reference path (rare: 16-18 digit exact decimals).
        return write_real(out, x);
    }
    let mut buf = ryu::Buffer::new();
    let t = buf.format_finite(x);
    let positional = (1e-5..1e16).contains(&ax);
    match t.find('e') {
        None if positional => {
            out.push_str(t.strip_suffix(".0").map_or(t, |m| &t[..m.len() + 1]));
            Ok(())
        }
        Some(e) if !positional => {
            let (mantissa, exponent) = (&t[..e], &t[e + 1..]);
            out.push_str(mantissa);
            if !mantissa.contains('.') {
                out.push('.');
            }
            out.push('E');
            out.push_str(exponent);
            Ok(())
        }
        _ => write_real(out, x),
    }
}

/// For a non-integer `x = v / 10^k` exactly, with `v` odd and below 10^15: `(v, k)`.
fn short_fraction(x: f64) -> Option<(u64, u32)> {
    let bits = x.to_bits();
    let biased = (bits >> 52) & 0x7ff;
    if biased == 0 {
        return None; // zero or subnormal: not a short fraction (and handled elsewhere)
    }
    let m = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
    let tz = m.trailing_zeros();
    let m = m >> tz;
    // x = m 2^e with m odd; e = biased - 1075 + tz. A non-integer has e < 0.
    let e = i64::try_from(biased).ok()? - 1075 + i64::from(tz);
    if e >= 0 {
        return None;
    }
    let k = u32::try_from(-e).ok()?;
    if k > 21 {
        return None; // 5^22 > 10^15: v would have more than 15 digits
    }
    // m 2^-k = m 5^k / 10^k; m 5^k is odd (both factors are).
    let v = 5u64.checked_pow(k)?.checked_mul(m)?;
    (v < 1_000_000_000_000_000).then_some((v, k))
}

/// Writes `±v / 10^k` (v odd, at most 15 digits, not an integer) in [`write_real`]'s layout.
fn write_short_fraction(out: &mut String, negative: bool, v: u64, k: u32) {
    let mut buf = [0u8; 20];
    let digits = digits_of(&mut buf, v);
    let n = digits.len();
    let k = k as usize;
    if negative {
        out.push('-');
    }
    // |x| lies in [10^lead_exp, 10^(lead_exp + 1)), so |x| >= 1e-5 <=> lead_exp >= -5;
    // non-integers are below 2^53 < 1e16, so only the small side takes the exponent form.
    let lead_exp = i64::try_from(n).unwrap_or(0) - i64::try_from(k).unwrap_or(0) - 1;
    if lead_exp >= -5 {
        if n > k {
            out.push_str(digits.get(..n - k).unwrap_or_default());
            out.push('.');
            out.push_str(digits.get(n - k..).unwrap_or_default());
        } else {
            out.push_str("0.");
            for _ in 0..k - n {
                out.push('0');
            }
            out.push_str(digits);
        }
    } else {
        out.push_str(digits.get(..1).unwrap_or_default());
        out.push('.');
        out.push_str(digits.get(1..).unwrap_or_default());
        out.push_str("E-");
        push_digits(out, lead_exp.unsigned_abs());
    }
}

/// The decimal digits of `v`, in the end of `buf`.
fn digits_of(buf: &mut [u8; 20], mut v: u64) -> &str {
    let mut i = buf.len();
    loop {
        i -= 1;
        // v % 10 < 10 fits in u8.
        #[allow(clippy::cast_possible_truncation)]
        let d = (v % 10) as u8;
        if let Some(slot) = buf.get_mut(i) {
            *slot = b'0' + d;
        }
        v /= 10;
        if v == 0 || i == 0 {
            break;
        }
    }
    // Only ASCII digits were written.
    std::str::from_utf8(buf.get(i..).unwrap_or_default()).unwrap_or_default()
}

/// Appends the decimal digits of `v` (as `{v}`).
fn push_digits(out: &mut String, v: u64) {
    let mut buf = [0u8; 20];
    out.push_str(digits_of(&mut buf, v));
}

#[cfg(test)]
mod tests {
    use super::super::write_real_std;
    use super::*;
    use proptest::prelude::*;

    fn check(x: f64) {
        let (mut fast, mut reference) = (String::new(), String::new());
        let a = write_real_fast(&mut fast, x);
        let b = write_real_std(&mut reference, x);
        assert_eq!(a.is_ok(), b.is_ok(), "{x:e}");
        assert_eq!(fast, reference, "{x:e} bits {:#x}", x.to_bits());
    }

    #[test]
    fn known_values_and_thresholds() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.25,
            0.125,
            1e-5,
            9.5367431640625e-7, // 2^-20: exponent layout, short fraction
            3.814697265625e-6,  // 2^-18
            1.52587890625e-5,   // 2^-16: positional
            TWO_POW_53,
            TWO_POW_53 - 1.0,
            -(TWO_POW_53 - 1.0),
            TWO_POW_53 + 2.0,
            1e15,
            1e16,
            1e300,
            1e-300,
            5e-324,
            f64::MIN_POSITIVE,
            f64::MAX,
            0.1,
            0.1 + 0.2,
            123.456,
            4503599627370495.5,
        ] {
            check(x);
            check(-x);
        }
        for e in -1074..=1023 {
            let p = 2f64.powi(e);
            for x in [p, 3.0 * p, 5.0 * p, 7.0 * p, 1.5 * p, 1.25 * p] {
                if x.is_finite() {
                    check(x);
                    check(-x);
                }
            }
        }
        for e in -324..=308 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            for x in [
                p,
                f64::from_bits(p.to_bits() + 1),
                f64::from_bits(p.to_bits().saturating_sub(1)),
            ] {
                if x.is_finite() {
                    check(x);
                    check(-x);
                }
            }
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut s = String::new();
            assert!(write_real_fast(&mut s, x).is_err());
            assert!(s.is_empty());
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        #[test]
        fn agrees_on_any_bits(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            check(x);
        }

        #[test]
        fn agrees_on_short_binary_fractions(k in 0u64..(1u64 << 53), shift in 0u32..53, q in -60i32..60) {
            let x = (k >> shift) as f64 * 2f64.powi(q);
            prop_assume!(x.is_finite());
            check(x);
            check(-x);
        }

        #[test]
        fn agrees_on_short_decimals(m in -99_999_999i64..99_999_999, e in -30i32..30) {
            check(m as f64 * 10f64.powi(e));
        }

        #[test]
        fn agrees_on_integers(i in -(1i64 << 54)..(1i64 << 54)) {
            check(i as f64);
        }
    }
}
