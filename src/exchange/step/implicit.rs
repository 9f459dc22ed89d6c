//! Knots implied by the Part 42 subtypes without explicit knots, and the knot
//! classification written as `knot_spec`.

/// A Part 42 knot subtype with implied knots (spec.md c.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnotForm {
    /// `bezier_curve`/`bezier_surface`: piecewise Bezier, knots `0, 1, ..., m+1` with
    /// multiplicities `d+1, d, ..., d, d+1` where `m = (k - d) / d` (k + 1 poles).
    Bezier,
    /// `uniform_curve`/`uniform_surface`: all multiplicities 1, spacing 1, starting at `-d`
    /// (ISO 10303-42 4.3.x; the domain is then `[0, n - d]` for n poles).
    Uniform,
    /// `quasi_uniform_curve`/`quasi_uniform_surface`: spacing 1 from 0, end multiplicities
    /// `d+1`, interior 1.
    QuasiUniform,
}

/// The flat knot vector a subtype implies for `poles` control points of degree `degree`;
/// `Err` names why none exists (too few poles, or a piecewise Bezier pole count that is
/// not `d*m + 1`).
///
/// ```
/// # use nurbsx::exchange::step::{implicit_knots, KnotForm};
/// assert_eq!(implicit_knots(KnotForm::Bezier, 2, 5).unwrap(), vec![0., 0., 0., 1., 1., 2., 2., 2.]);
/// assert_eq!(implicit_knots(KnotForm::Uniform, 2, 3).unwrap(), vec![-2., -1., 0., 1., 2., 3.]);
/// assert_eq!(implicit_knots(KnotForm::QuasiUniform, 2, 4).unwrap(), vec![0., 0., 0., 1., 2., 2., 2.]);
/// ```
pub fn implicit_knots(form: KnotForm, degree: usize, poles: usize) -> Result<Vec<f64>, String> {
    if degree == 0 || poles < degree + 1 {
        return Err(format!(
            "{poles} control points are too few for degree {degree}"
        ));
    }
    let total = poles
        .checked_add(degree)
        .and_then(|t| t.checked_add(1))
        .ok_or_else(|| "knot count overflows".to_owned())?;
    let mut out = Vec::with_capacity(total);
    match form {
        KnotForm::Bezier => {
            // poles = k + 1; segments = (k - d) / d + 1 = (poles - 1) / d.
            let k = poles - 1;
            if k % degree != 0 {
                return Err(format!(
                    "a piecewise Bezier of degree {degree} needs d*m + 1 control points; {poles} given"
                ));
            }
            let segments = k / degree;
            out.extend(std::iter::repeat_n(0.0, degree + 1));
            for s in 1..segments {
                out.extend(std::iter::repeat_n(s as f64, degree));
            }
            out.extend(std::iter::repeat_n(segments as f64, degree + 1));
        }
        KnotForm::Uniform => {
            let start = -(degree as f64);
            out.extend((0..total).map(|i| start + i as f64));
        }
        KnotForm::QuasiUniform => {
            let last = (poles - degree) as f64;
            out.extend(std::iter::repeat_n(0.0, degree + 1));
            out.extend((1..poles - degree).map(|i| i as f64));
            out.extend(std::iter::repeat_n(last, degree + 1));
        }
    }
    Ok(out)
}

/// The STEP `knot_type` of a flat knot vector, as Open CASCADE classifies it
/// (Geom_BSplineCurve::UpdateKnots: equally spaced distinct knots, then the multiplicity
/// pattern): `UNIFORM_KNOTS` (all multiplicities 1), `QUASI_UNIFORM_KNOTS` (ends d+1,
/// interior 1), `PIECEWISE_BEZIER_KNOTS` (ends d+1, interior d, or only two distinct knots),
/// otherwise `UNSPECIFIED`.
pub fn knot_form(degree: usize, knots: &[f64]) -> &'static str {
    let (values, mults) = crate::nurbs::knots::to_distinct(knots);
    let n = values.len();
    if n < 2 {
        return "UNSPECIFIED";
    }
    let d0 = values[1] - values[0];
    let spaced = values
        .windows(2)
        .all(|w| ((w[1] - w[0]) - d0).abs() <= 1e-12 * d0.abs().max(1.0));
    if !spaced {
        return "UNSPECIFIED";
    }
    let first = mults[0];
    let last = mults[n - 1];
    let interior = &mults[1..n - 1];
    if n == 2 {
        return if first == degree + 1 && last == degree + 1 {
            "PIECEWISE_BEZIER_KNOTS"
        } else if first == 1 && last == 1 {
            "UNIFORM_KNOTS"
        } else {
            "UNSPECIFIED"
        };
    }
    if mults.iter().all(|&m| m == 1) {
        return "UNIFORM_KNOTS";
    }
    if first == degree + 1 && last == degree + 1 {
        if interior.iter().all(|&m| m == 1) {
            return "QUASI_UNIFORM_KNOTS";
        }
        if interior.iter().all(|&m| m == degree) {
            return "PIECEWISE_BEZIER_KNOTS";
        }
    }
    "UNSPECIFIED"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn implied_counts_match_poles_plus_degree_plus_one() {
        for d in 1..6 {
            for n in d + 1..d + 12 {
                for f in [KnotForm::Uniform, KnotForm::QuasiUniform, KnotForm::Bezier] {
                    if let Ok(k) = implicit_knots(f, d, n) {
                        assert_eq!(k.len(), n + d + 1, "{f:?} d={d} n={n}");
                        crate::nurbs::knots::validate(d, n, &k).unwrap();
                    }
                }
            }
        }
        assert!(implicit_knots(KnotForm::Bezier, 3, 6).is_err());
    }

    #[test]
    fn classification() {
        assert_eq!(
            knot_form(2, &[0., 0., 0., 1., 1., 1.]),
            "PIECEWISE_BEZIER_KNOTS"
        );
        assert_eq!(
            knot_form(2, &[0., 0., 0., 1., 2., 2., 2.]),
            "QUASI_UNIFORM_KNOTS"
        );
        assert_eq!(
            knot_form(2, &[0., 0., 0., 1., 1., 2., 2., 2.]),
            "PIECEWISE_BEZIER_KNOTS"
        );
        assert_eq!(knot_form(2, &[-2., -1., 0., 1., 2., 3.]), "UNIFORM_KNOTS");
        assert_eq!(knot_form(2, &[0., 0., 0., 0.3, 1., 1., 1.]), "UNSPECIFIED");
    }
}
