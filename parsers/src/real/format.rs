//! The one REAL formatter of both writers ([`write_real`]): std's shortest round-trip digits
//! (its `Display`/`LowerExp`, the definition, [`write_real_std`]) in the layout of the
//! module documentation, reached by three routes that give the same bytes: the common CAD
//! values (integers, short binary fractions such as `0.25`) formatted directly, the shortest
//! digits of Żmij (Schubfach with yy's digit generation, the `zmij` crate) for values that
//! cannot be a tie between two shortest candidates, and std itself for the few whose exact
//! decimal expansion is short (the only cases where two shortest-digit algorithms may pick
//! different candidates).
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

use std::fmt::Write as _;

use super::NonFiniteReal;

/// Appends `x` to `out` in the shortest form that reads back bit-identical, always with a
/// decimal point (layout in the module documentation of [`crate::real`]); NaN and infinities
/// are refused.
///
/// ```
/// # use nurbsx_parsers::real::write_real;
/// let mut s = String::new();
/// for x in [1.0, 0.1 + 0.2, 1e16, -0.0, 5e-324, 250.0, 0.25, 1e-7] {
///     write_real(&mut s, x).unwrap();
///     s.push(' ');
/// }
/// assert_eq!(s, "1. 0.30000000000000004 1.E16 -0. 5.E-324 250. 0.25 1.E-7 ");
/// ```
pub fn write_real(out: &mut String, x: f64) -> Result<(), NonFiniteReal> {
    if !x.is_finite() {
        return Err(NonFiniteReal(x));
    }
    match classify(x) {
        Kind::Integer(v) => {
            if x.is_sign_negative() {
                out.push('-');
            }
            push_digits(out, v);
            out.push('.');
            Ok(())
        }
        Kind::ShortFraction(v, k) => {
            write_short_fraction(out, x.is_sign_negative(), v, k);
            Ok(())
        }
        // Ties between two shortest candidates are possible: the reference path.
        Kind::MayTie => write_real_std(out, x),
        Kind::Other => write_shortest(out, x),
    }
}

/// How [`write_real`] formats a finite value.
enum Kind {
    /// `|x| = v < 2^53`, an integer (zero included).
    Integer(u64),
    /// `|x| = v / 10^k` exactly, not an integer, `v` odd with at most 15 digits.
    ShortFraction(u64, u32),
    /// The exact decimal value is short enough for a tie between two shortest candidates
    /// (the reference's `has_short_exact_decimal` rule), and in neither case above.
    MayTie,
    /// Everything else: Żmij's shortest digits are the reference digits.
    Other,
}

/// Sorts a finite `x` into a [`Kind`] from its bits: `|x| = m 2^e` with `m` odd.
fn classify(x: f64) -> Kind {
    let bits = x.to_bits();
    let biased = (bits >> 52) & 0x7ff;
    let frac = bits & ((1u64 << 52) - 1);
    let (m, e) = if biased == 0 {
        (frac, -1074i64)
    } else {
        // biased <= 2047 always fits.
        #[allow(clippy::cast_possible_wrap)]
        let e = biased as i64 - 1075;
        (frac | (1u64 << 52), e)
    };
    if m == 0 {
        return Kind::Integer(0);
    }
    let tz = m.trailing_zeros();
    let m = m >> tz;
    let e = e + i64::from(tz);
    if e >= 0 {
        // An integer m 2^e; below 2^53 it is written directly.
        if e < 53 && m < (1u64 << (53 - e)) {
            return Kind::Integer(m << e);
        }
        // The reference's integer rule: 5^e divides m.
        let divisible = u32::try_from(e)
            .ok()
            .and_then(|k| 5u64.checked_pow(k))
            .is_some_and(|p| m % p == 0);
        return if divisible { Kind::MayTie } else { Kind::Other };
    }
    // A fraction m / 2^k = m 5^k / 10^k with k = -e; m 5^k is odd.
    let k = e.unsigned_abs();
    if k > 25 {
        // m >= 1 and 5^26 > 10^18: more than 18 digits, no tie possible.
        return Kind::Other;
    }
    // k <= 25: 5^k < 2^59 and m < 2^53, so the product fits a u128.
    let k = u32::try_from(k).unwrap_or(25);
    let v = u128::from(m) * u128::from(5u64.pow(k));
    if v < 1_000_000_000_000_000 {
        // Below 10^15: fits a u64.
        #[allow(clippy::cast_possible_truncation)]
        return Kind::ShortFraction(v as u64, k);
    }
    if v < 1_000_000_000_000_000_000 {
        Kind::MayTie
    } else {
        Kind::Other
    }
}

/// The Żmij path of [`write_real`], for values without possible ties.
fn write_shortest(out: &mut String, x: f64) -> Result<(), NonFiniteReal> {
    let mut buf = zmij::Buffer::new();
    let t = buf.format_finite(x);
    let positional = (1e-5..1e16).contains(&x.abs());
    if (1e-4..9e15).contains(&x.abs()) {
        // Żmij writes decimal exponents -5 <= kk < 16 positionally; the shortest digits of a
        // value in this range (with margins for their rounding) have such an exponent, so
        // there is no 'e' to look for, only an integer's ".0" to drop.
        match t.strip_suffix(".0") {
            Some(head) => {
                out.push_str(head);
                out.push('.');
            }
            None => out.push_str(t),
        }
        return Ok(());
    }
    // Byte scans: the token is short, a memchr call costs more than it saves.
    match t.bytes().position(|b| b == b'e') {
        None if positional => {
            out.push_str(t.strip_suffix(".0").map_or(t, |m| &t[..m.len() + 1]));
            Ok(())
        }
        Some(e) if !positional => {
            let (mantissa, exponent) = (&t[..e], &t[e + 1..]);
            out.push_str(mantissa);
            if !mantissa.bytes().any(|b| b == b'.') {
                out.push('.');
            }
            out.push('E');
            // Żmij signs positive exponents (`1e+16`); the layout does not.
            out.push_str(exponent.strip_prefix('+').unwrap_or(exponent));
            Ok(())
        }
        _ => write_real_std(out, x),
    }
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

/// Appends the decimal digits of `v` (as `{v}`), one by one: cheaper than validating and
/// copying a few bytes.
fn push_digits(out: &mut String, v: u64) {
    let mut buf = [0u8; 20];
    for c in digits_of(&mut buf, v).chars() {
        out.push(c);
    }
}

/// [`write_real`] through std's `Display`/`LowerExp`: the definition of the digits, and the
/// route for possible ties and for any value whose Żmij layout does not match ours.
pub(super) fn write_real_std(out: &mut String, x: f64) -> Result<(), NonFiniteReal> {
    if !x.is_finite() {
        return Err(NonFiniteReal(x));
    }
    let ax = x.abs();
    if ax == 0.0 || (1e-5..1e16).contains(&ax) {
        let start = out.len();
        // Display never uses an exponent and prints the shortest round-trip digits.
        let _ = write!(out, "{x}");
        if !out[start..].contains('.') {
            out.push('.');
        }
    } else {
        let start = out.len();
        let _ = write!(out, "{x:e}");
        // `{:e}` gives e.g. "1e16", "1.5e-7": insert the point and upper-case the exponent.
        let Some(e_pos) = out[start..].find('e').map(|p| p + start) else {
            return Ok(()); // unreachable for finite non-zero values; keep the digits as is
        };
        let exponent = out[e_pos + 1..].to_owned();
        out.truncate(e_pos);
        if !out[start..].contains('.') {
            out.push('.');
        }
        out.push('E');
        out.push_str(&exponent);
    }
    Ok(())
}

/// Formats `x` as [`write_real`] does, into a new string.
pub fn format_real(x: f64) -> Result<String, NonFiniteReal> {
    let mut s = String::with_capacity(24);
    write_real(&mut s, x)?;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Whether the exact decimal value of `x` has at most 18 significant digits.
    ///
    /// A tie (the exact value halfway between the two nearest shortest-digit decimals) needs the
    /// exact value to be that midpoint, an (n+1)-digit decimal with n <= 17 (shortest
    /// round-trip digits never exceed 17). Writing `x = m 2^e` with `m` odd: for `e < 0` the exact
    /// value is `m 5^-e / 10^-e`, whose significant digits are those of `m 5^-e`; for `e >= 0`
    /// it is an integer whose last non-zero digit can only be 5 if `5^e` divides `m`; all such
    /// integers are treated as short (conservative: the reference path is always correct).
    fn has_short_exact_decimal(x: f64) -> bool {
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let frac = bits & ((1u64 << 52) - 1);
        let (mut m, mut e) = if biased == 0 {
            (frac, -1074)
        } else {
            (frac | (1u64 << 52), biased - 1075)
        };
        if m == 0 {
            return true;
        }
        let tz = m.trailing_zeros();
        m >>= tz;
        // trailing_zeros of a non-zero u64 is at most 63.
        #[allow(clippy::cast_possible_wrap)]
        let tz = tz as i32;
        e += tz;
        if e < 0 {
            let Ok(k) = u32::try_from(-e) else {
                return false;
            };
            if k > 60 {
                return false;
            }
            5u128
                .checked_pow(k)
                .and_then(|p| p.checked_mul(u128::from(m)))
                .is_some_and(|v| v < 1_000_000_000_000_000_000)
        } else {
            // Conservative: any integer whose odd part is divisible by 5^e (including e = 0,
            // all odd integers) takes the reference path.
            u32::try_from(e)
                .ok()
                .and_then(|k| 5u64.checked_pow(k))
                .is_some_and(|p| m % p == 0)
        }
    }

    /// 2^53.
    const TWO_POW_53: f64 = 9_007_199_254_740_992.0;

    /// `classify` agrees with the reference's tie test on which values may tie.
    fn check_kind(x: f64) {
        let may_tie = matches!(
            classify(x),
            Kind::MayTie | Kind::Integer(_) | Kind::ShortFraction(..)
        );
        let reference = has_short_exact_decimal(x);
        // Integers below 2^53 and short fractions are direct paths; every other value the
        // reference calls short must take the reference path.
        if reference {
            assert!(may_tie, "{x:e}");
        } else {
            assert!(!matches!(classify(x), Kind::MayTie), "{x:e}");
        }
    }

    fn check(x: f64) {
        if x.is_finite() {
            check_kind(x);
        }
        let (mut fast, mut reference) = (String::new(), String::new());
        let a = write_real(&mut fast, x);
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
            assert!(write_real(&mut s, x).is_err());
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
