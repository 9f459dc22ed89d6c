//! The IGES REAL lexer as a one-pass reader over a larger buffer: [`iges_real_at`] reads the
//! real that starts at an offset of a record's data and reports where it ends, so a caller
//! can convert the P-section parameters of a 126/128 entity straight from the bytes instead
//! of first cutting them into tokens and then parsing each token (IGES 5.3 section 2.2.2.3).

use super::{RealError, convert, lex_iges};

/// Reads the longest IGES real that starts at `b[start]` (optional sign, digits with an
/// optional decimal point and at least one digit, an optional `E`/`e`/`D`/`d` exponent with at
/// least one digit) and returns its value and the offset just past it.
///
/// Contract (checked by property tests): whenever this returns `Ok((v, end))`,
/// [`parse_iges_real`](super::parse_iges_real) of the text `b[start..end]` returns `Ok(v)`,
/// bit for bit; and whenever `parse_iges_real(t)` accepts a token `t` that `b` continues
/// with a byte that cannot extend a real (a blank, a delimiter), this reads exactly `t`. What
/// follows the real is the caller's business (`1.5H` reads as `1.5` ending before `H`).
///
/// ```
/// # use nurbsx_parsers::real::iges_real_at;
/// assert_eq!(iges_real_at(b"1.5D1,-.25;", 0), Ok((15.0, 5)));
/// assert_eq!(iges_real_at(b"1.5D1,-.25;", 6), Ok((-0.25, 10)));
/// assert!(iges_real_at(b"1.5D,", 0).is_err()); // an exponent letter needs digits
/// ```
#[inline]
pub fn iges_real_at(b: &[u8], start: usize) -> Result<(f64, usize), RealError> {
    match plain_decimal_at(b, start) {
        Some(r) => Ok(r),
        None => general_at(b, start),
    }
}

/// The common shape of a coordinate, `[SIGN] {DIGIT} "." {DIGIT}` with 1 to 19 digits and
/// no exponent letter after it (IGES allows an empty integer part, `.5`), read a word at a
/// time by the quick path both formats share; `None` for anything else, which
/// [`general_at`] then reads. Where it answers, it answers as `general_at` (tested below).
#[inline(always)]
fn plain_decimal_at(b: &[u8], start: usize) -> Option<(f64, usize)> {
    super::coordinate::plain_decimal_at(b, start, 0)
}

/// Every form of the IGES grammar ([`lex_iges`], the lexer of
/// [`parse_iges_real`](super::parse_iges_real) without its whole-token check).
#[inline(never)]
fn general_at(b: &[u8], start: usize) -> Result<(f64, usize), RealError> {
    let (d, exp_letter, end) = lex_iges(b, start)?;
    let token = b.get(start..end).ok_or(RealError::Syntax)?;
    Ok((convert(d, token, exp_letter)?, end))
}

#[cfg(test)]
mod tests {
    use super::super::parse_iges_real;
    use super::*;
    use proptest::prelude::*;

    /// Checks both halves of the contract on `text` followed by `rest`.
    fn check(text: &str, rest: &str) -> Result<(), TestCaseError> {
        let buf = format!("{text}{rest}");
        let b = buf.as_bytes();
        if let Ok((v, end)) = iges_real_at(b, 0) {
            let token = std::str::from_utf8(&b[..end]).unwrap();
            prop_assert_eq!(
                parse_iges_real(token).map(f64::to_bits),
                Ok(v.to_bits()),
                "{:?}",
                buf
            );
        }
        // A token the parser accepts, followed by a byte that cannot extend a real, is read
        // whole (so a lexer failure means the token fails too).
        if let Ok(v) = parse_iges_real(text)
            && !rest.starts_with(|c: char| c.is_ascii_alphanumeric() || ".+-".contains(c))
        {
            prop_assert_eq!(
                iges_real_at(b, 0).map(|(x, e)| (x.to_bits(), e)),
                Ok((v.to_bits(), text.len())),
                "{:?}",
                buf
            );
        }
        // The same at an offset inside a larger buffer.
        let shifted = format!(",{buf}");
        prop_assert_eq!(
            iges_real_at(shifted.as_bytes(), 1).map(|(x, e)| (x.to_bits(), e - 1)),
            iges_real_at(b, 0).map(|(x, e)| (x.to_bits(), e))
        );
        Ok(())
    }

    /// The quick shape and the general reader agree wherever the quick one answers.
    fn check_quick(text: &str) -> Result<(), TestCaseError> {
        let buf = format!("{text},");
        if let Some((v, end)) = plain_decimal_at(buf.as_bytes(), 0) {
            prop_assert_eq!(
                general_at(buf.as_bytes(), 0).map(|(x, e)| (x.to_bits(), e)),
                Ok((v.to_bits(), end)),
                "{:?}",
                text
            );
        }
        Ok(())
    }

    #[test]
    fn known_forms() {
        for (text, want) in [
            ("1.0D0", Ok(1.0)),
            ("2.1d-1", Ok(0.21)),
            (".5", Ok(0.5)),
            ("5.", Ok(5.0)),
            ("-5", Ok(-5.0)),
            ("+.5E+1", Ok(5.0)),
            ("1e400", Err(RealError::NonFinite)),
            ("1.E-400", Ok(0.0)),
            (".", Err(RealError::Syntax)),
            ("-", Err(RealError::Syntax)),
            ("E5", Err(RealError::Syntax)),
            ("1.0D", Err(RealError::Syntax)),
            ("1.0D+", Err(RealError::Syntax)),
        ] {
            assert_eq!(
                iges_real_at(text.as_bytes(), 0).map(|r| r.0),
                want,
                "{text}"
            );
            check(text, ",").unwrap();
            check(text, "").unwrap();
            check(text, "  ;").unwrap();
        }
        assert_eq!(iges_real_at(b"1.52.3", 0), Ok((1.52, 4)));
        assert_eq!(iges_real_at(b"12H", 0), Ok((12.0, 2)));
        assert!(parse_iges_real("1.52.3").is_err());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        /// Every syntactic form of the IGES grammar, with and without digits on either side
        /// of the point, all exponent letters, long significands and extreme exponents,
        /// followed by what may follow a parameter in a record.
        #[test]
        fn agrees_with_parse_iges_real(
            text in "[+-]?[0-9]{0,22}\\.?[0-9]{0,22}([EeDd][+-]?[0-9]{0,4})?",
            rest in prop_oneof![Just(""), Just(","), Just(";"), Just(" ,"), Just("   "), Just("/"), Just("#")],
        ) {
            check(&text, rest)?;
            check_quick(&text)?;
        }

        /// Arbitrary bytes around real-like text: whatever the lexer accepts, the token
        /// parser accepts with the same bits.
        #[test]
        fn agrees_on_noise(text in "[0-9.+\\-EeDdHh ,;x]{0,30}", rest in "[0-9.+\\-EeDd ,;]{0,4}") {
            check(&text, &rest)?;
            check_quick(&text)?;
        }

        /// Shortest round-trip text of any double, in several IGES spellings.
        #[test]
        fn every_double_reads_back(bits in any::<u64>(), letter in prop_oneof![Just('E'), Just('e'), Just('D'), Just('d')]) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let sci = format!("{x:E}").replace('E', &letter.to_string());
            for text in [format!("{x:?}"), sci] {
                let (v, end) = iges_real_at(format!("{text},").as_bytes(), 0).unwrap();
                prop_assert_eq!(v.to_bits(), bits, "{}", text);
                prop_assert_eq!(end, text.len());
                check(&text, ",")?;
                check_quick(&text)?;
            }
        }
    }
}
