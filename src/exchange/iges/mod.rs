//! IGES 5.3 curves and surfaces <-> the NURBS model (spec.md b, d; pitfalls.md A4, B9, B11,
//! D18-22).
//!
//! - [`read()`]: every 126 Rational B-Spline Curve and 128 Rational B-Spline Surface of a file
//!   becomes an [`Entity`](super::Entity) with id `D<n>` (its DE pointer), and so does every
//!   analytic curve and surface with an exact rational form (`curves`: 100, 102, 104, 106,
//!   110, 112; `surfaces`: 108, 114, 118, 120, 122, 190-198; parameter maps in README,
//!   "IGES entities and their parameterisation"). Flags are kept in [`Meta`](super::Meta) and
//!   *checked* against the data, never used to rewrite it (PROP3 vs weights:
//!   `prop3_inconsistent`; PROP2/PROP4 vs knots and end points: `flag_mismatch`). 124
//!   transformation chains are applied to the Euclidean poles of every entity; Global units
//!   (flag wins over name, `unit_conflict`) are reported and, on request, converted; on
//!   request ([`ImportOptions::trim_to_parameter_range`](super::ImportOptions)) 126/128 are
//!   trimmed exactly to their declared ranges. The faces, shells and solids (144 trimmed
//!   surfaces with their 142 boundaries; 186 B-rep solids with 514/510/508/504/502) are read
//!   into [`Document::topology`](super::Document) by the `topology` module over the same converted
//!   geometry (not with `geometry_only`, which says what it left out). One bad entity gives
//!   a located error diagnostic; the others still load.
//! - [`write()`]: the topology as 144 trimmed surfaces with 142 boundaries (or, with
//!   `ExportOptions::iges_brep`, 186 solids with 514/510/508/504/502), then every curve and
//!   surface no face or edge names as 126/128 with PROP flags computed
//!   from the data, `V(0)`, `V(1)`, the plane normal and the form number of its kind when
//!   the geometry passes that kind's check ([`form_warnings`] lists those that do not), and a
//!   Global section declaring the unit the numbers are in.

mod analysis;
mod chain;
mod curves;
mod forms;
mod read;
mod subfigure;
mod surfaces;
mod topology;
mod vector;
mod write;
mod write_topology;

pub(crate) use analysis::written_point_rounding;
pub(crate) use forms::checked_label;
pub use forms::{form, form_warnings};
pub use read::read;
pub use write::{range_warnings, write};
pub(crate) use write_topology::write_warnings;

/// The source entity type of IGES entity type number `n` (IGES 5.3 section 4): the
/// numbers nurbsx reads spelt without an allocation per entity, any other one formatted.
fn entity_type_name(n: i64) -> std::borrow::Cow<'static, str> {
    let known = match n {
        100 => "100",
        102 => "102",
        104 => "104",
        106 => "106",
        108 => "108",
        110 => "110",
        112 => "112",
        114 => "114",
        118 => "118",
        120 => "120",
        122 => "122",
        126 => "126",
        128 => "128",
        141 => "141",
        142 => "142",
        143 => "143",
        144 => "144",
        186 => "186",
        190 => "190",
        192 => "192",
        194 => "194",
        196 => "196",
        198 => "198",
        502 => "502",
        504 => "504",
        508 => "508",
        510 => "510",
        514 => "514",
        _ => return n.to_string().into(),
    };
    known.into()
}

/// An entity's form number (IGES 5.3 section 2.2.4.4.15) as the model keeps it
/// (`Meta::form`): the forms of the curve and surface entities (0 to 12) spelt without an
/// allocation per entity, any other one formatted.
fn form_text(form: i64) -> std::borrow::Cow<'static, str> {
    const FORMS: [&str; 13] = [
        "0", "1", "2", "3", "4", "5", "6", "7", "8", "9", "10", "11", "12",
    ];
    match usize::try_from(form).ok().and_then(|k| FORMS.get(k)) {
        Some(f) => (*f).into(),
        None => form.to_string().into(),
    }
}
