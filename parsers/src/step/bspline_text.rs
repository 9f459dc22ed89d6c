//! The B-spline curve and surface instances (ISO 10303-42
//! `b_spline_curve_with_knots` and `b_spline_surface_with_knots`, attribute order as in
//! spec.md c.2; their rational complex forms, c.4) from the instance body text, in one
//! pass, into the typed records [`BSplineCurve`] and [`BSplineSurface`].
//!
//! Private to [`Scanned::bspline`](super::Scanned::bspline), the one decoder of these
//! records: its general path (the grammar, then [`BSplineCurve::from_instance`]) builds a [`Parameter`](super::Parameter) tree, one
//! vector per list, and then walks it by attribute name; for the pole, knot and weight
//! lists that make up nearly all of a B-spline's text this touches every value twice and
//! allocates a tree node per value. The reader here follows the fixed attribute order of the
//! shapes Open CASCADE, FreeCAD and our writer emit (ISO 10303-21 clause 12.2 syntax):
//!
//! - the simple instances `B_SPLINE_CURVE_WITH_KNOTS('name',deg,(#..),.FORM.,.F.,.F.,
//!   (m..),(k..),.SPEC.)` and `B_SPLINE_SURFACE_WITH_KNOTS('name',du,dv,((#..),..),.FORM.,.F.,
//!   .F.,.F.,(mu..),(mv..),(ku..),(kv..),.SPEC.)`;
//! - the complex instances `( BOUNDED_CURVE() B_SPLINE_CURVE(..) B_SPLINE_CURVE_WITH_KNOTS
//!   (..) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE((w..))
//!   REPRESENTATION_ITEM('') )` and the surface analogue, partials in any order, each at
//!   most once;
//!
//! and stores each value straight into the record's vectors.
//!
//! Exactness: the reader only ever *succeeds* where it is sure to give what the general path
//! gives, field for field (including `entity_type`, built as `Attributes::of` does). Reals
//! go through [`step_real_at`], as in the general lexer's number fast path, so the bits are
//! the same; every token must be followed by whitespace, `,` or `)`, which also rejects
//! what the general lexer reads as one malformed number token (`1.5E3X`, `1.5.2`). Anything else (another partial, a repeated partial, `$`, `*`, typed
//! parameters, an INTEGER where a REAL is expected or the reverse, a comment, an
//! overflowing integer, a parameter count or nesting depth beyond [`Limits`](crate::Limits)) gives `None`,
//! and the caller takes the general path, which decodes it or reports the located error.
//! The tests below compare both paths on every sample file, on generated files and on
//! damaged copies.

use std::borrow::Cow;

use super::grammar::ParamLimits;
use super::instance_text::Reader;
use super::scan::RawInstance;
use super::schema::{
    BSpline, BSplineCurve, BSplineSurface, KnotSpec, Logical, PerDirection, bspline_entity_type,
    canonical_name,
};
use super::string::StepString;

/// Reads a B-spline curve or surface instance straight from its body text, if it has one of
/// the shapes listed in the module documentation. `None` means "not read here": the caller
/// then decodes the instance with [`Scanned::decode`](super::Scanned::decode) and
/// [`BSplineCurve::from_instance`] / [`BSplineSurface::from_instance`], which give the
/// record or the error.
///
/// `limits` must be the limits the instance was scanned with (the general decoder enforces
/// their parameter count and nesting depth; this reader declines what would exceed them).
///
/// Whenever this returns `Some(x)`, the general path succeeds with a record equal to `x`
/// and [`bspline_kind`](super::schema::bspline_kind) gives the same kind.
pub(crate) fn read<'a>(
    text: &'a str,
    raw: &RawInstance<'a>,
    limits: ParamLimits,
) -> Option<BSpline<'a>> {
    let mut r = Reader::new(text, raw, limits);
    let out = match raw.keyword(text) {
        Some(k) => {
            r.i = k.len();
            r.simple(canonical_name(k))?
        }
        None => r.complex()?,
    };
    r.ws();
    (r.i == r.b.len()).then_some(out)
}

/// The attributes of the `B_SPLINE_CURVE` partial.
struct CurveAttrs<'a> {
    degree: i64,
    control_points: Vec<u64>,
    form: &'a str,
    closed: Logical,
    self_intersect: Logical,
}

/// The attributes of the `B_SPLINE_SURFACE` partial.
struct SurfaceAttrs<'a> {
    u_degree: i64,
    v_degree: i64,
    control_points: Vec<Vec<u64>>,
    form: &'a str,
    u_closed: Logical,
    v_closed: Logical,
    self_intersect: Logical,
}

/// Which family a complex instance's partials belong to.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Family {
    Open,
    Curve,
    Surface,
}

/// Bits of the partials seen in a complex instance (each may appear once).
const P_REPRESENTATION_ITEM: u16 = 1 << 0;
const P_GEOMETRIC_REPRESENTATION_ITEM: u16 = 1 << 1;
const P_CURVE: u16 = 1 << 2;
const P_BOUNDED_CURVE: u16 = 1 << 3;
const P_B_SPLINE_CURVE: u16 = 1 << 4;
const P_CURVE_WITH_KNOTS: u16 = 1 << 5;
const P_RATIONAL_CURVE: u16 = 1 << 6;
const P_SURFACE: u16 = 1 << 7;
const P_BOUNDED_SURFACE: u16 = 1 << 8;
const P_B_SPLINE_SURFACE: u16 = 1 << 9;
const P_SURFACE_WITH_KNOTS: u16 = 1 << 10;
const P_RATIONAL_SURFACE: u16 = 1 << 11;

impl<'a> Reader<'a> {
    /// `B_SPLINE_CURVE`'s own attributes, the first without a leading comma.
    fn curve_attrs(&mut self) -> Option<CurveAttrs<'a>> {
        let degree = self.integer()?;
        self.byte(b',')?;
        let control_points = self.list(1, Self::reference_token, None)?;
        self.byte(b',')?;
        let form = self.enumeration()?;
        self.byte(b',')?;
        let closed = self.logical()?;
        self.byte(b',')?;
        let self_intersect = self.logical()?;
        Some(CurveAttrs {
            degree,
            control_points,
            form,
            closed,
            self_intersect,
        })
    }

    /// `B_SPLINE_SURFACE`'s own attributes.
    fn surface_attrs(&mut self) -> Option<SurfaceAttrs<'a>> {
        let u_degree = self.integer()?;
        self.byte(b',')?;
        let v_degree = self.integer()?;
        self.byte(b',')?;
        let control_points = self.grid(Self::reference_token, None)?;
        self.byte(b',')?;
        let form = self.enumeration()?;
        self.byte(b',')?;
        let u_closed = self.logical()?;
        self.byte(b',')?;
        let v_closed = self.logical()?;
        self.byte(b',')?;
        let self_intersect = self.logical()?;
        Some(SurfaceAttrs {
            u_degree,
            v_degree,
            control_points,
            form,
            u_closed,
            v_closed,
            self_intersect,
        })
    }

    /// `B_SPLINE_CURVE_WITH_KNOTS`'s own attributes.
    fn curve_knots(&mut self) -> Option<KnotSpec<'a>> {
        let m = self.list(1, Self::integer_token, None)?;
        self.byte(b',')?;
        let k = self.list(1, Self::real_token, Some(m.len()))?;
        self.byte(b',')?;
        let knot_spec = self.enumeration()?;
        Some(KnotSpec::Explicit {
            multiplicities: PerDirection::curve(m),
            knots: PerDirection::curve(k),
            knot_spec,
        })
    }

    /// `B_SPLINE_SURFACE_WITH_KNOTS`'s own attributes.
    fn surface_knots(&mut self) -> Option<KnotSpec<'a>> {
        let mu = self.list(1, Self::integer_token, None)?;
        self.byte(b',')?;
        let mv = self.list(1, Self::integer_token, None)?;
        self.byte(b',')?;
        let ku = self.list(1, Self::real_token, Some(mu.len()))?;
        self.byte(b',')?;
        let kv = self.list(1, Self::real_token, Some(mv.len()))?;
        self.byte(b',')?;
        let knot_spec = self.enumeration()?;
        Some(KnotSpec::Explicit {
            multiplicities: PerDirection::surface(mu, mv),
            knots: PerDirection::surface(ku, kv),
            knot_spec,
        })
    }

    /// A simple instance (the keyword already read): the whole supertype chain's attributes
    /// in order (`SUPERTYPE_CHAINS` in the schema module).
    fn simple(&mut self, keyword: &str) -> Option<BSpline<'a>> {
        match keyword {
            "B_SPLINE_CURVE_WITH_KNOTS" => {
                if self.max_depth < 2 {
                    return None;
                }
                self.byte(b'(')?;
                let name = self.string()?;
                self.byte(b',')?;
                let c = self.curve_attrs()?;
                self.byte(b',')?;
                let knots = self.curve_knots()?;
                self.byte(b')')?;
                Some(BSpline::Curve(curve_record(
                    Some(name),
                    c,
                    knots,
                    None,
                    bspline_entity_type(keyword),
                )))
            }
            "B_SPLINE_SURFACE_WITH_KNOTS" => {
                if self.max_depth < 3 {
                    return None;
                }
                self.byte(b'(')?;
                let name = self.string()?;
                self.byte(b',')?;
                let s = self.surface_attrs()?;
                self.byte(b',')?;
                let knots = self.surface_knots()?;
                self.byte(b')')?;
                Some(BSpline::Surface(surface_record(
                    Some(name),
                    s,
                    knots,
                    None,
                    bspline_entity_type(keyword),
                )))
            }
            _ => None,
        }
    }

    /// A complex instance `( partial partial ... )`.
    fn complex(&mut self) -> Option<BSpline<'a>> {
        // Every shape read here has a list at depth 1.
        if self.max_depth < 2 {
            return None;
        }
        self.byte(b'(')?;
        let mut seen: u16 = 0;
        let mut family = Family::Open;
        let mut entity_type = String::with_capacity(160);
        entity_type.push('(');
        let mut name = None;
        let mut curve = None;
        let mut surface = None;
        let mut knots = None;
        let mut curve_weights = None;
        let mut surface_weights = None;
        loop {
            self.ws();
            if self.b.get(self.i) == Some(&b')') {
                self.i += 1;
                break;
            }
            let keyword = canonical_name(self.keyword()?);
            let (bit, fam) = match keyword {
                "REPRESENTATION_ITEM" => (P_REPRESENTATION_ITEM, Family::Open),
                "GEOMETRIC_REPRESENTATION_ITEM" => (P_GEOMETRIC_REPRESENTATION_ITEM, Family::Open),
                "CURVE" => (P_CURVE, Family::Curve),
                "BOUNDED_CURVE" => (P_BOUNDED_CURVE, Family::Curve),
                "B_SPLINE_CURVE" => (P_B_SPLINE_CURVE, Family::Curve),
                "B_SPLINE_CURVE_WITH_KNOTS" => (P_CURVE_WITH_KNOTS, Family::Curve),
                "RATIONAL_B_SPLINE_CURVE" => (P_RATIONAL_CURVE, Family::Curve),
                "SURFACE" => (P_SURFACE, Family::Surface),
                "BOUNDED_SURFACE" => (P_BOUNDED_SURFACE, Family::Surface),
                "B_SPLINE_SURFACE" => (P_B_SPLINE_SURFACE, Family::Surface),
                "B_SPLINE_SURFACE_WITH_KNOTS" => (P_SURFACE_WITH_KNOTS, Family::Surface),
                "RATIONAL_B_SPLINE_SURFACE" => (P_RATIONAL_SURFACE, Family::Surface),
                _ => return None,
            };
            if seen & bit != 0 {
                return None;
            }
            seen |= bit;
            if fam != Family::Open {
                if family != Family::Open && family != fam {
                    return None;
                }
                family = fam;
            }
            if entity_type.len() > 1 {
                entity_type.push(',');
            }
            entity_type.push_str(keyword);
            self.byte(b'(')?;
            match bit {
                P_REPRESENTATION_ITEM => name = Some(self.string()?),
                P_B_SPLINE_CURVE => curve = Some(self.curve_attrs()?),
                P_CURVE_WITH_KNOTS => knots = Some(self.curve_knots()?),
                P_RATIONAL_CURVE => {
                    // One weight per pole (when B_SPLINE_CURVE came first, as usual).
                    let hint = curve
                        .as_ref()
                        .map(|c: &CurveAttrs<'a>| c.control_points.len());
                    curve_weights = Some(self.list(1, Self::real_token, hint)?);
                }
                P_B_SPLINE_SURFACE => {
                    if self.max_depth < 3 {
                        return None;
                    }
                    surface = Some(self.surface_attrs()?);
                }
                P_SURFACE_WITH_KNOTS => knots = Some(self.surface_knots()?),
                P_RATIONAL_SURFACE => {
                    if self.max_depth < 3 {
                        return None;
                    }
                    let shape = surface.as_ref().map(|s: &SurfaceAttrs<'a>| {
                        let rows = &s.control_points;
                        (rows.len(), rows.first().map_or(0, Vec::len))
                    });
                    surface_weights = Some(self.grid(Self::real_token, shape)?);
                }
                // The attribute-less partials.
                _ => {}
            }
            self.byte(b')')?;
        }
        entity_type.push(')');
        let entity_type = bspline_entity_type(&entity_type);
        match family {
            Family::Curve => Some(BSpline::Curve(curve_record(
                name,
                curve?,
                knots?,
                curve_weights,
                entity_type,
            ))),
            Family::Surface => Some(BSpline::Surface(surface_record(
                name,
                surface?,
                knots?,
                surface_weights,
                entity_type,
            ))),
            Family::Open => None,
        }
    }
}

fn curve_record<'a>(
    name: Option<StepString<'a>>,
    c: CurveAttrs<'a>,
    knots: KnotSpec<'a>,
    weights: Option<Vec<f64>>,
    entity_type: Cow<'static, str>,
) -> BSplineCurve<'a> {
    BSplineCurve {
        name,
        degree: c.degree,
        control_points: c.control_points,
        curve_form: c.form,
        closed_curve: c.closed,
        self_intersect: c.self_intersect,
        knots,
        weights,
        entity_type,
    }
}

fn surface_record<'a>(
    name: Option<StepString<'a>>,
    s: SurfaceAttrs<'a>,
    knots: KnotSpec<'a>,
    weights: Option<Vec<Vec<f64>>>,
    entity_type: Cow<'static, str>,
) -> BSplineSurface<'a> {
    BSplineSurface {
        name,
        u_degree: s.u_degree,
        v_degree: s.v_degree,
        control_points: s.control_points,
        surface_form: s.form,
        u_closed: s.u_closed,
        v_closed: s.v_closed,
        self_intersect: s.self_intersect,
        knots,
        weights,
        entity_type,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Limits;
    use crate::step::schema::{At, BSplineKind, bspline_kind};
    use crate::step::test_files::{check_damaged, edit, file, repo_files};
    use crate::step::{Scanned, scan};
    use proptest::prelude::*;

    /// The text reader under the parameter limits the scanner derives from `limits`.
    fn bspline_direct<'a>(
        text: &'a str,
        raw: &RawInstance<'a>,
        limits: &Limits,
    ) -> Option<BSpline<'a>> {
        read(text, raw, ParamLimits::from(limits))
    }

    /// The contract: when the direct reader answers, the general path gives the same kind
    /// and an equal record (reals compared bit for bit through `Debug`, which keeps `-0.0`).
    /// Returns whether the direct reader answered.
    fn check(s: &Scanned<'_>, raw: &RawInstance<'_>, limits: &Limits) -> bool {
        let Some(direct) = bspline_direct(s.text, raw, limits) else {
            return false;
        };
        let inst = match s.decode(raw) {
            Ok(i) => i,
            Err(e) => panic!("direct read #{} but general decode fails: {e}", raw.id),
        };
        let at = At::default();
        let general = match bspline_kind(&inst.body) {
            Some(BSplineKind::Curve) => BSplineCurve::from_instance(&inst, at).map(BSpline::Curve),
            Some(BSplineKind::Surface) => {
                BSplineSurface::from_instance(&inst, at).map(BSpline::Surface)
            }
            None => panic!("direct read #{} but it is not a B-spline", raw.id),
        };
        match general {
            Ok(g) => {
                assert_eq!(direct, g, "#{}: {}", raw.id, raw.body(s.text));
                assert_eq!(format!("{direct:?}"), format!("{g:?}"), "#{}", raw.id);
            }
            Err(e) => panic!("direct read #{} but the general path fails: {e}", raw.id),
        }
        true
    }

    /// Checks every instance of a file; returns (answered, general B-spline successes).
    fn check_text(text: &str, limits: &Limits) -> (usize, usize) {
        let Ok(s) = scan(text, limits) else {
            return (0, 0);
        };
        let mut answered = 0;
        let mut bsplines = 0;
        for raw in &s.instances {
            if check(&s, raw, limits) {
                answered += 1;
            }
            let ok = s
                .decode(raw)
                .is_ok_and(|inst| match bspline_kind(&inst.body) {
                    Some(BSplineKind::Curve) => {
                        BSplineCurve::from_instance(&inst, At::default()).is_ok()
                    }
                    Some(BSplineKind::Surface) => {
                        BSplineSurface::from_instance(&inst, At::default()).is_ok()
                    }
                    None => false,
                });
            if ok {
                bsplines += 1;
            }
        }
        (answered, bsplines)
    }

    fn one(data: &str, limits: &Limits) -> Option<BSpline<'static>> {
        let text: &'static str = Box::leak(file(data).into_boxed_str());
        let s = scan(text, limits).unwrap();
        let raw = s.instances.last().unwrap();
        check(&s, raw, limits);
        bspline_direct(text, raw, limits)
    }

    fn answers(data: &str) -> bool {
        one(data, &Limits::default()).is_some()
    }

    const CURVE: &str = "#5=B_SPLINE_CURVE_WITH_KNOTS('c1',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.PIECEWISE_BEZIER_KNOTS.);";
    const SURFACE: &str = "#9=B_SPLINE_SURFACE_WITH_KNOTS('s',1,1,((#1,#2),(#3,#4)),.PLANE_SURF.,.F.,.T.,.U.,(2),(2),(0.,1.),(-2.5,3.E-2),.UNSPECIFIED.);";
    const RCURVE: &str = "#7=( BOUNDED_CURVE() B_SPLINE_CURVE(2,(#1,#2,#3),\n.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,\n1.),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM(\n) RATIONAL_B_SPLINE_CURVE((1.,0.5,1.)) REPRESENTATION_ITEM('') );";
    const RSURFACE: &str = "#8=( BOUNDED_SURFACE() B_SPLINE_SURFACE(1,1,((#1,#2),(#3,#4)),.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS((2),(2),(0.,1.),(0.,1.),.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(((1.,2.),(3.,4.))) REPRESENTATION_ITEM('') SURFACE() );";

    #[test]
    fn simple_curve_values() {
        let Some(BSpline::Curve(c)) = one(CURVE, &Limits::default()) else {
            panic!("not read");
        };
        // Hand-read from the text above.
        assert_eq!(c.name.as_ref().map(|n| n.raw.as_ref()), Some("c1"));
        assert_eq!(c.degree, 2);
        assert_eq!(c.control_points, vec![1, 2, 3]);
        assert_eq!(c.curve_form, "UNSPECIFIED");
        assert_eq!(c.closed_curve, Logical::False);
        assert_eq!(
            c.knots,
            KnotSpec::Explicit {
                multiplicities: PerDirection::curve(vec![3, 3]),
                knots: PerDirection::curve(vec![0.0, 1.0]),
                knot_spec: "PIECEWISE_BEZIER_KNOTS"
            }
        );
        assert_eq!(c.weights, None);
        assert_eq!(c.entity_type, "B_SPLINE_CURVE_WITH_KNOTS");
    }

    #[test]
    fn simple_surface_values() {
        let Some(BSpline::Surface(s)) = one(SURFACE, &Limits::default()) else {
            panic!("not read");
        };
        assert_eq!(s.control_points, vec![vec![1, 2], vec![3, 4]]);
        assert_eq!((s.u_degree, s.v_degree), (1, 1));
        assert_eq!(s.surface_form, "PLANE_SURF");
        assert_eq!(
            (s.u_closed, s.v_closed, s.self_intersect),
            (Logical::False, Logical::True, Logical::Unknown)
        );
        let KnotSpec::Explicit { knots, .. } = &s.knots else {
            panic!("explicit")
        };
        assert_eq!(&knots[..], &[vec![0.0, 1.0], vec![-2.5, 0.03]]);
    }

    #[test]
    fn complex_curve_and_surface_values() {
        let Some(BSpline::Curve(c)) = one(RCURVE, &Limits::default()) else {
            panic!("not read");
        };
        assert_eq!(c.weights, Some(vec![1.0, 0.5, 1.0]));
        assert_eq!(
            c.entity_type,
            "(BOUNDED_CURVE,B_SPLINE_CURVE,B_SPLINE_CURVE_WITH_KNOTS,CURVE,\
             GEOMETRIC_REPRESENTATION_ITEM,RATIONAL_B_SPLINE_CURVE,REPRESENTATION_ITEM)"
        );
        let Some(BSpline::Surface(s)) = one(RSURFACE, &Limits::default()) else {
            panic!("not read");
        };
        assert_eq!(s.weights, Some(vec![vec![1.0, 2.0], vec![3.0, 4.0]]));
        assert_eq!(s.name.as_ref().map(|n| n.raw.as_ref()), Some(""));
    }

    #[test]
    fn accepted_variants() {
        // Whitespace everywhere the lexer allows it, partials in another order, short
        // names, no REPRESENTATION_ITEM (name None), '' escapes, negative and signed reals.
        for data in [
            "#5 = B_SPLINE_CURVE_WITH_KNOTS ( 'a''b' , 2 ,\r\n( #1 ,\t#2 , #3 ) , .UNSPECIFIED. , .F. , .F. , ( 3 , 3 ) , ( -0. , +1.5E1 ) , .UNSPECIFIED. ) ;",
            "#5=BSCWK('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=(RATIONAL_B_SPLINE_CURVE((1.,1.,1.))B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.)BSPCR(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.));",
            "#5=( B_SPLINE_SURFACE_WITH_KNOTS((2),(2),(0.,1.),(0.,1.),.UNSPECIFIED.) B_SPLINE_SURFACE(1,1,((#1,#2),(#3,#4)),.UNSPECIFIED.,.F.,.F.,.F.) REPRESENTATION_ITEM('x\\X\\E9') );",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(),.UNSPECIFIED.,.F.,.F.,(),(),.UNSPECIFIED.);",
            "#5=B_SPLINE_SURFACE_WITH_KNOTS('',1,1,((),()),.UNSPECIFIED.,.F.,.F.,.F.,(2),(2),(0.,1.),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#18446744073709551615),.UNSPECIFIED.,.F.,.F.,(3,9223372036854775807),(0.,1.),.UNSPECIFIED.);",
        ] {
            assert!(answers(data), "{data}");
        }
    }

    #[test]
    fn declined_shapes() {
        for data in [
            // `$` or a typed name, a comment, an integer knot, a real degree.
            "#5=B_SPLINE_CURVE_WITH_KNOTS($,2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,/* x */#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2.,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',-2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            // Malformed tokens the general lexer rejects.
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.5E3X),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.5.2),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2A,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#18446744073709551616),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,9223372036854775808),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.X.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3,),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.,1.);",
            "#5=B_SPLINE_CURVE_WITH_KNOTS('',2,(#1,#2,#3),.unspecified.,.F.,.F.,(3,3),(0.,1.),.UNSPECIFIED.);",
            // Other entities and subtypes.
            "#5=B_SPLINE_CURVE('',2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.);",
            "#5=(BEZIER_CURVE()B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.));",
            "#5=(B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.)B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.)FOO());",
            "#5=(B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.)B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.)CURVE()CURVE());",
            "#5=(B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.)B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.)SURFACE());",
            "#5=(B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.));",
            "#5=(B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.)B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.)RATIONAL_B_SPLINE_CURVE(W((1.,1.,1.))));",
            "#5=(B_SPLINE_CURVE(2,(#1,#2,#3),.UNSPECIFIED.,.F.,.F.)B_SPLINE_CURVE_WITH_KNOTS((3,3),(0.,1.),.UNSPECIFIED.)REPRESENTATION_ITEM(*));",
        ] {
            assert!(!answers(data), "{data}");
        }
    }

    #[test]
    fn limits_are_declined_not_exceeded() {
        // 1 (name) + 1 + 1+3 + 3 (form, logicals) + 1+2 + 1+2 + 1 = 16 parameters.
        let at = |max_params, max_depth| Limits {
            max_params_per_entity: max_params,
            max_nesting_depth: max_depth,
            ..Limits::default()
        };
        assert!(one(CURVE, &at(16, 2)).is_some());
        assert!(one(CURVE, &at(15, 2)).is_none());
        assert!(one(CURVE, &at(16, 1)).is_none());
        // The surface's rows are at depth 2.
        assert!(one(SURFACE, &at(1000, 3)).is_some());
        assert!(one(SURFACE, &at(1000, 2)).is_none());
        assert!(one(RSURFACE, &at(1000, 2)).is_none());
        assert!(one(RCURVE, &at(1000, 2)).is_some());
    }

    #[test]
    fn every_repository_file_agrees_and_freecad_splines_are_read_directly() {
        let files = repo_files();
        assert!(files.len() > 50, "sample files not found");
        let mut total = 0;
        for (path, text) in &files {
            let (answered, bsplines) = check_text(text, &Limits::default());
            total += answered;
            // Open CASCADE writes only the shapes read directly.
            if path.to_string_lossy().contains("samples/freecad") {
                assert_eq!(answered, bsplines, "{}", path.display());
            }
        }
        assert!(total > 100, "only {total} direct reads");
    }

    /// The B-spline instances of the FreeCAD samples, as separate statements.
    fn sample_statements() -> &'static [String] {
        static CACHE: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
        CACHE.get_or_init(collect_statements)
    }

    fn collect_statements() -> Vec<String> {
        let mut out = Vec::new();
        for (path, text) in repo_files() {
            if !path.to_string_lossy().contains("samples/freecad") {
                continue;
            }
            let Ok(s) = scan(&text, &Limits::default()) else {
                continue;
            };
            for raw in &s.instances {
                if bspline_direct(&text, raw, &Limits::default()).is_some() && raw.body_len() < 4000
                {
                    out.push(format!("#{}={};", raw.id, raw.body(&text)));
                }
            }
        }
        out.extend([CURVE, SURFACE, RCURVE, RSURFACE].map(str::to_owned));
        out
    }

    #[test]
    fn whitespace_between_all_tokens_is_still_read_directly() {
        // Every blank the general lexer skips, after every `(`, `,` and `)` and before every
        // `,` and `)` of every sample B-spline: still read here, still equal.
        let blanks = [" ", "\t", "\r\n", "\n", "\x0c", "  \t "];
        for (k, stmt) in sample_statements().iter().enumerate() {
            let Some(eq) = stmt.find('=') else { continue };
            let (head, body) = stmt.split_at(eq + 1);
            let body = body.strip_suffix(';').unwrap_or(body);
            let blank = blanks[k % blanks.len()];
            let mut spaced = String::new();
            for c in body.chars() {
                if matches!(c, ',' | ')') {
                    spaced.push_str(blank);
                }
                spaced.push(c);
                if matches!(c, '(' | ',' | ')') {
                    spaced.push_str(blank);
                }
            }
            let data = format!("{head}{blank}{spaced}{blank};");
            assert!(answers(&data), "{data}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        /// Damaged copies of real instances: whenever the direct reader answers, the general
        /// path agrees (checked inside `check_text`), under default and tight limits.
        #[test]
        fn damaged_instances_agree(
            pick in any::<prop::sample::Index>(),
            edits in prop::collection::vec(edit(), 0..4),
            max_params in 5usize..200,
            max_depth in 1usize..4,
        ) {
            let stmt: &String = pick.get(sample_statements());
            check_damaged(stmt, &edits, max_params, max_depth, check_text);
        }
    }
}
