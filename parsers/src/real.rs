//! REAL literals: one strict lexer per format and one exact writer shared by both.
//!
//! # Writing
//! [`write_real`] prints the *shortest* decimal digits that read back as the same `f64`
//! (Rust's `Display`/`LowerExp` implement the Ryu/Grisu shortest round-trip algorithm) and
//! then makes the token valid in both formats:
//!
//! - a decimal point is always present (`1.` not `1`; ISO 10303-21 clause 6.3.3 requires a
//!   digit, a point, optional digits; IGES 5.3 section 2.2.2.3 requires the point for REAL);
//! - magnitudes in `[1e-5, 1e16)` are written positionally (`0.5`, `250.`, `6.28318530717958`),
//!   all others with an upper-case exponent (`1.E16`, `5.E-324`, `-2.5E-7`);
//! - `-0.0` keeps its sign (`-0.`), so read -> write -> read is bit-identical.
//!
//! Non-finite values cannot be written in either format and are refused.
//!
//! # Reading
//! [`parse_step_real`] accepts exactly the Part 21 production
//! `REAL = [ SIGN ] DIGIT { DIGIT } "." { DIGIT } [ "E" [ SIGN ] DIGIT { DIGIT } ]`
//! and [`parse_iges_real`] the IGES form (leading digit optional, `E`, `e`, `D` or `d`
//! exponent, an integer token accepted where a real is expected, as Open CASCADE does).
//! The whole token must be consumed (`1.52.3` is an error, not `1.52`), and a value that
//! overflows to infinity (`1.E400`) is an error, not a silent `inf`.

use std::fmt::Write as _;

/// Why a token is not an acceptable REAL.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum RealError {
    /// The token does not match the format's REAL grammar.
    #[error("not a valid real number")]
    Syntax,
    /// The token is well formed but its value is outside the finite `f64` range.
    #[error("real number overflows to infinity")]
    NonFinite,
}

/// A NaN or infinite value was given to the writer; neither format can represent it.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("cannot write non-finite real {0}")]
pub struct NonFiniteReal(pub f64);

/// Appends `x` to `out` in the shortest form that reads back bit-identical, always with a
/// decimal point. See the module documentation for the exact shape.
///
/// ```
/// # use nurbsx_parsers::real::write_real;
/// let mut s = String::new();
/// for x in [1.0, 0.1 + 0.2, 1e16, -0.0, 5e-324, 250.0] {
///     write_real(&mut s, x).unwrap();
///     s.push(' ');
/// }
/// assert_eq!(s, "1. 0.30000000000000004 1.E16 -0. 5.E-324 250. ");
/// ```
pub fn write_real(out: &mut String, x: f64) -> Result<(), NonFiniteReal> {
    if !x.is_finite() {
        return Err(NonFiniteReal(x));
    }
    // Fast path: Ryu (`ryu` crate) prints the same shortest round-trip digits as std's
    // Grisu/Dragon (both give the shortest digit string that reads back, the closest to the
    // exact value); about 3x faster and allocation free. Its layout is `1.0`, `250.0`,
    // `0.5`, `1e16`, `1.5e-7`, `-0.0`; we only reshape it, and fall back to the std path
    // whenever Ryu's positional/exponent choice differs from ours (the test
    // `ryu_agrees_with_std` checks the two paths give identical text).
    if has_short_exact_decimal(x) {
        // Only such values can be a tie between two shortest candidates, which Ryu rounds
        // half to even and std half up; take the reference path for them.
        return write_real_std(out, x);
    }
    let mut buf = ryu::Buffer::new();
    let t = buf.format_finite(x);
    let ax = x.abs();
    let positional = ax == 0.0 || (1e-5..1e16).contains(&ax);
    match t.find('e') {
        None if positional => {
            // "250.0" -> "250.", "0.5" stays; shortest digits never end in 0 after the point
            // except the ".0" Ryu adds to integers.
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
        _ => write_real_std(out, x),
    }
}

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

/// [`write_real`] through std's `Display`/`LowerExp` (the reference implementation; used
/// where Ryu's layout does not match ours).
fn write_real_std(out: &mut String, x: f64) -> Result<(), NonFiniteReal> {
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
    let mut i = 0;
    if matches!(b.first(), Some(b'+' | b'-')) {
        i += 1;
    }
    let digits_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if i == digits_start || b.get(i) != Some(&b'.') {
        return Err(RealError::Syntax);
    }
    i += 1;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if i < b.len() {
        if b[i] != b'E' {
            return Err(RealError::Syntax);
        }
        i += 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        let exp_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i == exp_start || i != b.len() {
            return Err(RealError::Syntax);
        }
    }
    if let Some(v) = clinger_fast_path(b) {
        return Ok(v);
    }
    finish(token)
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
    let mut i = 0;
    if matches!(b.first(), Some(b'+' | b'-')) {
        i += 1;
    }
    let int_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut n_digits = i - int_start;
    if b.get(i) == Some(&b'.') {
        i += 1;
        let frac_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        n_digits += i - frac_start;
    }
    if n_digits == 0 {
        return Err(RealError::Syntax);
    }
    let mut exp_letter = None;
    if i < b.len() {
        if !matches!(b[i], b'E' | b'e' | b'D' | b'd') {
            return Err(RealError::Syntax);
        }
        exp_letter = Some(i);
        i += 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        let exp_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i == exp_start || i != b.len() {
            return Err(RealError::Syntax);
        }
    }
    if let Some(v) = clinger_fast_path(b) {
        return Ok(v);
    }
    match exp_letter {
        Some(pos) if matches!(b[pos], b'D' | b'd') => {
            // Rust's float parser knows only `e`/`E`: rewrite the Fortran exponent letter.
            let mut buf = [0u8; 64];
            if b.len() <= buf.len() {
                buf[..b.len()].copy_from_slice(b);
                buf[pos] = b'E';
                let s = std::str::from_utf8(&buf[..b.len()]).map_err(|_| RealError::Syntax)?;
                finish(s)
            } else {
                let mut owned = token.to_owned().into_bytes();
                owned[pos] = b'E';
                let s = String::from_utf8(owned).map_err(|_| RealError::Syntax)?;
                finish(&s)
            }
        }
        _ => finish(token),
    }
}

/// Exact powers of ten representable in an `f64` (10^0 ..= 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Clinger's fast path (W. D. Clinger, "How to read floating point numbers accurately",
/// PLDI 1990): when the decimal significand `m` is at most 2^53 and the decimal exponent
/// `e` is within +-22, both `m` and `10^|e|` are exact `f64`s, so one IEEE multiplication
/// or division gives the correctly rounded result, bit-identical to std's parser. Returns
/// `None` otherwise (the caller uses std). `b` must already match the REAL grammar
/// (`[sign] digits [. digits] [E|e|D|d [sign] digits]`).
fn clinger_fast_path(b: &[u8]) -> Option<f64> {
    let mut i = 0;
    let negative = b.first() == Some(&b'-');
    if matches!(b.first(), Some(b'+' | b'-')) {
        i += 1;
    }
    let mut m: u64 = 0;
    let mut frac_digits: i32 = 0;
    let mut in_frac = false;
    while let Some(&c) = b.get(i) {
        match c {
            b'0'..=b'9' => {
                // More than 2^53 (or 19 digits) leaves the fast path.
                m = m.checked_mul(10)?.checked_add(u64::from(c - b'0'))?;
                if m > 1 << 53 {
                    return None;
                }
                if in_frac {
                    frac_digits += 1;
                }
            }
            b'.' => in_frac = true,
            _ => break,
        }
        i += 1;
    }
    let mut exp: i32 = 0;
    if i < b.len() {
        i += 1; // the exponent letter
        let exp_negative = b.get(i) == Some(&b'-');
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        for &c in b.get(i..)? {
            exp = exp
                .checked_mul(10)?
                .checked_add(i32::from(c.wrapping_sub(b'0')))?;
            if exp > 1000 {
                return None;
            }
        }
        if exp_negative {
            exp = -exp;
        }
    }
    let e = exp - frac_digits;
    let mf = m as f64; // exact: m <= 2^53
    let v = if e >= 0 {
        mf * *POW10.get(usize::try_from(e).ok()?)?
    } else {
        mf / *POW10.get(usize::try_from(-e).ok()?)?
    };
    Some(if negative { -v } else { v })
}

/// Converts a token already checked against a grammar with the correctly rounded std
/// parser, and refuses overflow to infinity.
fn finish(token: &str) -> Result<f64, RealError> {
    let v: f64 = token.parse().map_err(|_| RealError::Syntax)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(RealError::NonFinite)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn ryu_agrees_with_std_at_every_power_of_ten() {
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
        fn ryu_agrees_with_std(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let (mut fast, mut slow) = (String::new(), String::new());
            write_real(&mut fast, x).unwrap();
            write_real_std(&mut slow, x).unwrap();
            prop_assert_eq!(fast, slow);
        }

        #[test]
        fn ryu_agrees_with_std_near_ties(k in 1u64..(1u64 << 53), shift in 0u32..12, q in -70i32..70) {
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
        fn ryu_agrees_with_std_on_short_decimals(m in -99_999_999i64..99_999_999, e in -30i32..30) {
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

// The writers' fast formatter (same output as `write_real`), kept in its own file.
mod fast;
pub use fast::write_real_fast;
