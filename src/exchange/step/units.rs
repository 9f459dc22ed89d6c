//! The length unit of a representation context (ISO 10303-41 units, spec.md c.5):
//! `SI_UNIT(prefix, .METRE.)`, or a `CONVERSION_BASED_UNIT('INCH', #m)` whose
//! `LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4), #mm)` defines it from another unit.

use nurbsx_parsers::step::schema::{At, MeasureWithUnit, RepresentationContext, Unit};
use nurbsx_parsers::step::{RawInstance, Scanned};

use crate::exchange::LengthUnit;

/// A length unit found in a file: its size in millimetres, and the [`LengthUnit`] it is
/// when nurbsx has one of that size.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FileUnit {
    /// Millimetres per unit.
    pub mm: f64,
    /// The matching named unit, if any.
    pub unit: Option<LengthUnit>,
    /// How the file names it (`MILLI METRE`, `INCH`).
    pub label: String,
    /// A note when the name and the factor disagree.
    pub note: Option<String>,
}

/// Millimetres per unit for an SI prefix on METRE (ISO 10303-41 `si_prefix`).
fn si_prefix_mm(prefix: Option<&str>) -> Option<f64> {
    Some(match prefix {
        None => 1e3,
        Some("EXA") => 1e21,
        Some("PETA") => 1e18,
        Some("TERA") => 1e15,
        Some("GIGA") => 1e12,
        Some("MEGA") => 1e9,
        Some("KILO") => 1e6,
        Some("HECTO") => 1e5,
        Some("DECA") => 1e4,
        Some("DECI") => 1e2,
        Some("CENTI") => 1e1,
        Some("MILLI") => 1.0,
        Some("MICRO") => 1e-3,
        Some("NANO") => 1e-6,
        Some("PICO") => 1e-9,
        Some("FEMTO") => 1e-12,
        Some("ATTO") => 1e-15,
        _ => return None,
    })
}

/// The named unit whose size is `mm` (relative tolerance 1e-9).
fn unit_of_size(mm: f64) -> Option<LengthUnit> {
    use LengthUnit::*;
    [Mm, Cm, M, Km, Um, In, Ft, Mi, Mil, Uin]
        .into_iter()
        .find(|u| (u.to_mm() - mm).abs() <= 1e-9 * mm.abs())
}

/// Resolves unit `#id`: `Ok(None)` when it is not a length unit; `Err` with a message when
/// it cannot be understood (bad record, unknown prefix, cyclic or too deep definition).
pub(super) fn resolve_length(
    s: &Scanned<'_>,
    id: u64,
    referrer: &RawInstance<'_>,
) -> Result<Option<FileUnit>, String> {
    let mut factor = 1.0;
    let mut names: Vec<String> = Vec::new();
    let mut current = id;
    let mut seen = Vec::new();
    loop {
        if seen.contains(&current) || seen.len() > 8 {
            return Err(format!(
                "unit definition #{id} is cyclic or nested too deep ({})",
                seen.iter()
                    .map(|&i| super::instance_label(i))
                    .collect::<Vec<_>>()
                    .join(" -> ")
            ));
        }
        seen.push(current);
        let raw = s
            .get(current)
            .ok_or_else(|| format!("unit #{current} (from #{}) is not defined", referrer.id))?;
        let inst = s.decode(raw).map_err(|e| e.to_string())?;
        let (line, column) = s.locate(raw.offset());
        let at = At {
            id: current,
            line,
            column,
        };
        match Unit::from_instance(&inst, at).map_err(|e| e.to_string())? {
            Unit::Si {
                prefix,
                name,
                length,
            } => {
                if name != "METRE" && !length {
                    return Ok(None);
                }
                let mm = si_prefix_mm(prefix).ok_or_else(|| {
                    format!("unknown SI prefix .{}. on #{current}", prefix.unwrap_or(""))
                })?;
                let base_label = format!(
                    "{}METRE",
                    prefix.map(|p| format!("{p} ")).unwrap_or_default()
                );
                let total = factor * mm;
                let label = names.first().cloned().unwrap_or(base_label);
                let unit = unit_of_size(total);
                let mut note = None;
                if let Some(n) = names.first() {
                    if let Some(named) = LengthUnit::parse_name(n) {
                        if Some(named) != unit {
                            note = Some(format!(
                                "unit '{n}' is defined as {total} mm, not the {} mm its name means; the definition is used",
                                named.to_mm()
                            ));
                        }
                    }
                }
                return Ok(Some(FileUnit {
                    mm: total,
                    unit,
                    label,
                    note,
                }));
            }
            Unit::ConversionBased {
                name,
                conversion_factor,
                ..
            } => {
                names.push(name.decode_lossy().into_owned());
                let (value, unit) = conversion(s, conversion_factor, current)?;
                factor *= value;
                current = unit;
            }
            Unit::Other {
                length,
                entity_type,
            } => {
                if length {
                    return Err(format!(
                        "length unit #{current} is an unsupported {entity_type}"
                    ));
                }
                return Ok(None);
            }
        }
    }
}

/// The factor and the base unit of a conversion-based unit's `conversion_factor` (a
/// MEASURE_WITH_UNIT, ISO 10303-41); the factor must be > 0.
fn conversion(s: &Scanned<'_>, id: u64, of: u64) -> Result<(f64, u64), String> {
    let mraw = s
        .get(id)
        .ok_or_else(|| format!("conversion factor #{id} of #{of} is not defined"))?;
    let minst = s.decode(mraw).map_err(|e| e.to_string())?;
    let m = MeasureWithUnit::from_instance(&minst, s.at(mraw)).map_err(|e| e.to_string())?;
    if !(m.value.is_finite() && m.value > 0.0) {
        return Err(format!(
            "conversion factor #{id} is {} (must be > 0)",
            m.value
        ));
    }
    Ok((m.value, m.unit))
}

/// A unit problem: the context's id, its byte offset, and the message.
pub(super) type UnitProblem = (u64, usize, String);

/// Keeps the instances of `complex` that may be contexts assigning units: the file's
/// complex instances in file order (a context assigning units is one, ISO 10303-41
/// `global_unit_assigned_context` being a partial of it; simple instances cannot be),
/// searched once for that partial's name. A SIMD substring search: rational B-splines
/// are complex instances too, their long bodies searched in full, and a B-rep written by
/// Open CASCADE has a complex parameter-space context for every pcurve.
pub(super) fn unit_contexts<'a, 'r>(
    s: &Scanned<'a>,
    mut complex: Vec<&'r RawInstance<'a>>,
) -> Vec<&'r RawInstance<'a>> {
    let finder = memchr::memmem::Finder::new("GLOBAL_UNIT_ASSIGNED_CONTEXT");
    complex.retain(|raw| finder.find(raw.body(s.text).as_bytes()).is_some());
    complex.shrink_to_fit();
    complex
}

/// The length units of the contexts that assign units, in file order:
/// `(context id, unit)`, plus messages for units that could not be understood. `contexts`
/// are the instances [`unit_contexts`] kept.
///
/// The third list holds the contexts' length uncertainties in millimetres
/// (`GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT` naming `UNCERTAINTY_MEASURE_WITH_UNIT`s whose unit
/// is a length, ISO 10303-43 `global_uncertainty_assigned_context`).
pub(super) fn context_units(
    s: &Scanned<'_>,
    contexts: &[&RawInstance<'_>],
) -> (Vec<(u64, FileUnit)>, Vec<UnitProblem>, Vec<f64>) {
    let mut found = Vec::new();
    let mut problems = Vec::new();
    let mut uncertainties = Vec::new();
    for &raw in contexts {
        let Ok(inst) = s.decode(raw) else { continue };
        let (line, column) = s.locate(raw.offset());
        let at = At {
            id: raw.id,
            line,
            column,
        };
        let ctx = match RepresentationContext::from_instance(&inst, at) {
            Ok(Some(c)) => c,
            Ok(None) => continue,
            Err(e) => {
                problems.push((raw.id, raw.offset(), e.to_string()));
                continue;
            }
        };
        for &u in &ctx.uncertainty {
            match length_uncertainty(s, u, raw) {
                Ok(Some(mm)) => uncertainties.push(mm),
                Ok(None) => {}
                Err(m) => problems.push((raw.id, raw.offset(), m)),
            }
        }
        let mut lengths = Vec::new();
        for u in ctx.units {
            match resolve_length(s, u, raw) {
                Ok(Some(fu)) => lengths.push(fu),
                Ok(None) => {}
                Err(m) => problems.push((raw.id, raw.offset(), m)),
            }
        }
        match lengths.len() {
            0 => problems.push((
                raw.id,
                raw.offset(),
                format!("context #{} assigns no length unit", raw.id),
            )),
            1 => found.extend(lengths.into_iter().map(|l| (raw.id, l))),
            n => problems.push((
                raw.id,
                raw.offset(),
                format!("context #{} assigns {n} length units", raw.id),
            )),
        }
    }
    (found, problems, uncertainties)
}

/// The uncertainty measure `#id` in millimetres when its unit is a length (`None` for an
/// angle or other unit); it must be a finite value > 0.
fn length_uncertainty(
    s: &Scanned<'_>,
    id: u64,
    referrer: &RawInstance<'_>,
) -> Result<Option<f64>, String> {
    let raw = s
        .get(id)
        .ok_or_else(|| format!("uncertainty #{id} (from #{}) is not defined", referrer.id))?;
    let inst = s.decode(raw).map_err(|e| e.to_string())?;
    let m = MeasureWithUnit::from_instance(&inst, s.at(raw)).map_err(|e| e.to_string())?;
    let Some(unit) = resolve_length(s, m.unit, raw)? else {
        return Ok(None);
    };
    let mm = m.value * unit.mm;
    if !(mm.is_finite() && mm > 0.0) {
        return Err(format!("uncertainty #{id} is {} (must be > 0)", m.value));
    }
    Ok(Some(mm))
}

/// A plane-angle unit found in a file: radians per unit and how the file names it.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct AngleUnit {
    /// Radians per unit (1 for `SI_UNIT($,.RADIAN.)`).
    pub radians: f64,
    /// How the file names it (`RADIAN`, `DEGREE`).
    pub label: String,
}

/// Resolves unit `#id` as a plane-angle unit (ISO 10303-41 `plane_angle_unit`):
/// `SI_UNIT($,.RADIAN.)`, or a `CONVERSION_BASED_UNIT('DEGREE', #m)` with `#m =
/// PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925), #rad)`. `Ok(None)` when
/// it is another kind of unit.
///
/// A conversion-based unit named `DEGREE` whose factor is pi/180 to 1e-6 is taken as exactly
/// pi/180 radians (files print the factor to 10-12 digits; ISO 10303-41 defines the degree
/// as pi/180 rad); any other factor is used as written.
pub(super) fn resolve_plane_angle(
    s: &Scanned<'_>,
    id: u64,
    referrer: &RawInstance<'_>,
) -> Result<Option<AngleUnit>, String> {
    let mut factor = 1.0;
    let mut first_name: Option<String> = None;
    let mut current = id;
    for _ in 0..8 {
        let raw = s
            .get(current)
            .ok_or_else(|| format!("unit #{current} (from #{}) is not defined", referrer.id))?;
        let inst = s.decode(raw).map_err(|e| e.to_string())?;
        match Unit::from_instance(&inst, s.at(raw)).map_err(|e| e.to_string())? {
            Unit::Si { prefix, name, .. } => {
                if name != "RADIAN" {
                    return Ok(None);
                }
                if let Some(p) = prefix {
                    return Err(format!("plane-angle unit #{current} has a prefix .{p}."));
                }
                let label = first_name.clone().unwrap_or_else(|| "RADIAN".to_owned());
                let degree = std::f64::consts::PI / 180.0;
                let radians = if label.eq_ignore_ascii_case("DEGREE")
                    && (factor - degree).abs() <= 1e-6 * degree
                {
                    degree
                } else {
                    factor
                };
                return Ok(Some(AngleUnit { radians, label }));
            }
            Unit::ConversionBased {
                name,
                conversion_factor,
                plane_angle,
                ..
            } => {
                if !plane_angle && first_name.is_none() {
                    return Ok(None);
                }
                first_name.get_or_insert_with(|| name.decode_lossy().into_owned());
                let (value, unit) = conversion(s, conversion_factor, current)?;
                factor *= value;
                current = unit;
            }
            Unit::Other { .. } => return Ok(None),
        }
    }
    Err(format!("plane-angle unit #{id} is nested too deep"))
}

/// The plane-angle unit of the first context that assigns one (with its context id), and
/// messages for plane-angle units that could not be understood. `contexts` are the
/// instances [`unit_contexts`] kept.
pub(super) fn context_plane_angle(
    s: &Scanned<'_>,
    contexts: &[&RawInstance<'_>],
) -> (Option<(u64, AngleUnit)>, Vec<UnitProblem>) {
    let mut problems = Vec::new();
    for &raw in contexts {
        let Ok(inst) = s.decode(raw) else { continue };
        let Ok(Some(ctx)) = RepresentationContext::from_instance(&inst, s.at(raw)) else {
            continue;
        };
        for u in ctx.units {
            match resolve_plane_angle(s, u, raw) {
                Ok(Some(a)) => return (Some((raw.id, a)), problems),
                Ok(None) => {}
                Err(m) => problems.push((raw.id, raw.offset(), m)),
            }
        }
    }
    (None, problems)
}
