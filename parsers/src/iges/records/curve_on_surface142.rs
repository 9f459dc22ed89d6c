//! Entity 142, Curve on a Parametric Surface (IGES 5.3 section 4.32).

use super::{CURVES, DirectoryEntry, Entity, Field, SURFACES, Schema, Type, Values};
use crate::iges::writer::{ParamWriter, WriteParams};
use crate::real::NonFiniteReal;

/// The declaration: CRTN, SPTR, BPTR, CPTR, PREF.
pub(super) const SCHEMA: Schema = Schema {
    entity: 142,
    name: "Curve on a Parametric Surface",
    fields: &[
        Field::one("CRTN", Type::Flag),
        Field::one("SPTR", Type::Pointer(SURFACES)),
        Field::one("BPTR", Type::Pointer(CURVES)),
        Field::one("CPTR", Type::Pointer(CURVES)),
        Field::one("PREF", Type::Flag),
    ],
};

/// Entity 142, Curve on a Parametric Surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveOnSurface142 {
    /// CRTN: how the curve was created (0 unspecified, 1 projection, 2 intersection,
    /// 3 isoparametric).
    pub creation: i64,
    /// SPTR: the surface.
    pub surface: i64,
    /// BPTR: the curve B(t) in the surface's parameter space (0 when absent).
    pub parameter_curve: i64,
    /// CPTR: the curve C(t) in model space (0 when absent).
    pub model_curve: i64,
    /// PREF: the preferred representation (0 unspecified, 1 S o B, 2 C, 3 equal).
    pub preferred: i64,
}

impl Entity for CurveOnSurface142 {
    const SCHEMA: Schema = SCHEMA;

    fn from_values(mut v: Values<'_>, _: &DirectoryEntry) -> Self {
        CurveOnSurface142 {
            creation: v.int("CRTN"),
            surface: v.int("SPTR"),
            parameter_curve: v.int("BPTR"),
            model_curve: v.int("CPTR"),
            preferred: v.int("PREF"),
        }
    }
}

impl WriteParams for CurveOnSurface142 {
    fn write_params(&self, w: &mut ParamWriter<'_>) -> Result<(), NonFiniteReal> {
        for x in [
            142,
            self.creation,
            self.surface,
            self.parameter_curve,
            self.model_curve,
            self.preferred,
        ] {
            w.int(x);
        }
        Ok(())
    }
}
