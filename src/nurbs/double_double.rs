//! Double-double numbers: an unevaluated sum `hi + lo` of two `f64` with `|lo| <= ulp(hi)/2`,
//! about 106 significant bits, built from error-free transformations (Knuth's TwoSum,
//! Dekker's splitting product; Dekker 1971, Shewchuk 1997). Used where a long chain of
//! affine combinations and divisions must not accumulate `f64` rounding (degree elevation,
//! A5.9): each operation is accurate to a few units in 2^-104 relative.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// `hi + lo`, normalised so that `hi` is the sum rounded to `f64`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoubleDouble {
    hi: f64,
    lo: f64,
}

/// `a + b = s + e` exactly (Knuth's TwoSum; no ordering precondition).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a + b = s + e` exactly when `|a| >= |b|` (Dekker's FastTwoSum).
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// Dekker's split of `a` into two 26-bit halves with `a = hi + lo`. Magnitudes near the
/// top of the `f64` range are scaled down first so that the splitting product cannot
/// overflow.
fn split(a: f64) -> (f64, f64) {
    const FACTOR: f64 = 134_217_729.0; // 2^27 + 1
    const BIG: f64 = 1e300;
    if a.abs() > BIG {
        let (h, l) = split(a * 2f64.powi(-28));
        return (h * 2f64.powi(28), l * 2f64.powi(28));
    }
    let c = FACTOR * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

/// `a * b = p + e` exactly (Dekker's TwoProduct, without fused multiply-add).
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// The arithmetic an algorithm can run in: `f64`, or [`DoubleDouble`] where rounding
/// would be amplified (degree elevation of high degrees, A5.9).
pub(super) trait Scalar:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    /// The exact value of `x`.
    fn of(x: f64) -> Self;
}

impl Scalar for f64 {
    fn of(x: f64) -> Self {
        x
    }
}

impl Scalar for DoubleDouble {
    fn of(x: f64) -> Self {
        DoubleDouble::of(x)
    }
}

impl DoubleDouble {
    /// The exact value of `x`.
    pub fn of(x: f64) -> Self {
        DoubleDouble { hi: x, lo: 0.0 }
    }

    /// The value rounded to the nearest `f64` (the normalised high part).
    pub fn value(self) -> f64 {
        self.hi + self.lo
    }

    fn normalised(hi: f64, lo: f64) -> Self {
        let (hi, lo) = fast_two_sum(hi, lo);
        DoubleDouble { hi, lo }
    }
}

impl Add for DoubleDouble {
    type Output = Self;
    fn add(self, b: Self) -> Self {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = fast_two_sum(s, e + t);
        Self::normalised(s, e + f)
    }
}

impl Neg for DoubleDouble {
    type Output = Self;
    fn neg(self) -> Self {
        DoubleDouble {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for DoubleDouble {
    type Output = Self;
    fn sub(self, b: Self) -> Self {
        self + (-b)
    }
}

impl Mul for DoubleDouble {
    type Output = Self;
    fn mul(self, b: Self) -> Self {
        let (p, e) = two_product(self.hi, b.hi);
        Self::normalised(p, e + (self.hi * b.lo + self.lo * b.hi))
    }
}

impl Div for DoubleDouble {
    type Output = Self;
    /// Long division with three `f64` quotient digits.
    fn div(self, b: Self) -> Self {
        let q1 = self.hi / b.hi;
        let r = self - b * DoubleDouble::of(q1);
        let q2 = r.hi / b.hi;
        let r = r - b * DoubleDouble::of(q2);
        let q3 = r.hi / b.hi;
        let (q1, q2) = fast_two_sum(q1, q2);
        DoubleDouble { hi: q1, lo: q2 } + DoubleDouble::of(q3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_third_times_three_is_one_to_double_double_precision() {
        let third = DoubleDouble::of(1.0) / DoubleDouble::of(3.0);
        // 1/3 = 0x1.5555555555555p-2 + 0x1.5555555555555p-56 (plus a smaller remainder).
        assert_eq!(third.hi, 1.0 / 3.0);
        assert!((third.lo - (1.0 / 3.0) * 2f64.powi(-54)).abs() <= 2f64.powi(-106));
        let one = third * DoubleDouble::of(3.0);
        assert!((one.hi - 1.0).abs() + one.lo.abs() <= 2f64.powi(-104));
    }

    #[test]
    fn sums_keep_what_f64_loses() {
        let big = DoubleDouble::of(1e16);
        let s = (big + DoubleDouble::of(1.0)) - big;
        assert_eq!(s.value(), 1.0);
        assert_eq!((1e16 + 1.0) - 1e16, 0.0);
        let (h, l) = split(1.7e308);
        assert_eq!(h + l, 1.7e308);
    }
}
