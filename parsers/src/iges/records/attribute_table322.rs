//! Entity 322, Attribute Table Definition (IGES 5.3 section 4.79): the table name, the
//! attribute list type, `NA`, then per attribute its type, value data type and value
//! count, with (forms 1 and 2) its values.
//!
//! | form | parameters |
//! | --- | --- |
//! | 0 | `NAME`, `ATYP`, `NA`, `NA` × (`AT`, `AVT`, `AVC`) |
//! | 1 | as form 0, each attribute followed by its `AVC` values |
//! | 2 | as form 1, each value followed by a pointer to a 312 Text Display Template |
//!
//! The values have the type the attribute's `AVT` names (0 none, 1 integer, 2 real, 3
//! string, 4 pointer, 5 not used, 6 logical; another code is an error), so their
//! parameters' types come from the data: no [`super::Schema`] declares them, and
//! [`definition`] checks them instead ([`super::Dependent::AttributeDefinition`]). A
//! defaulted `AVC` reads 0. The 422 Attribute Table Instance (section 4.141) repeats the
//! layout this returns.

use super::{AttributeLayout, count, count_parameter, too_big, typed_value, value_type};
use crate::iges::grammar::parameters::{Error, ParameterReader};

/// Checks a 322 in form `form` after the entity type: `3 + 3 NA` parameters, plus
/// `AVC` values (form 1) or `AVC` × (value, 312 pointer) (form 2) per attribute. The
/// pointer values go to `pointers`, the 312 pointers to `templates`. Returns the
/// attributes that hold values, `(AVT, AVC)` with `AVC` > 0, for a 422.
pub(super) fn definition<'a>(
    r: &mut ParameterReader<'a>,
    form: i64,
    pointers: &mut Vec<i64>,
    templates: &mut Vec<i64>,
) -> Result<AttributeLayout, Error<'a>> {
    let first = r.rest();
    r.string("NAME")?;
    r.integer("ATYP", Some(0))?;
    let na = count_parameter(r, "NA", None)?;
    let mut needed = na
        .checked_mul(3)
        .and_then(|n| n.checked_add(3))
        .ok_or_else(|| too_big(first, "3 + 3 NA"))?;
    r.expect(needed, 322, vec![("NA", count(na))]);
    // Each value of form 2 is followed by its 312 pointer.
    let width = if form == 2 { 2 } else { 1 };
    let mut layout = Vec::with_capacity(r.capacity(na, 3));
    for _ in 0..na {
        r.integer("AT", Some(0))?;
        let avt = value_type(r, "AVT")?;
        let avc_at = r.rest();
        let avc = count_parameter(r, "AVC", Some(0))?;
        if form > 0 {
            needed = avc
                .checked_mul(width)
                .and_then(|n| n.checked_add(needed))
                .ok_or_else(|| too_big(avc_at, "the value count"))?;
            r.expect(needed, 322, vec![("NA", count(na)), ("AVC", count(avc))]);
            for _ in 0..avc {
                typed_value(r, avt, "AVALUE", pointers)?;
                if form == 2 {
                    let p = r.integer("TEXT DISPLAY TEMPLATE", Some(0))?;
                    if p != 0 {
                        templates.push(p);
                    }
                }
            }
        }
        if avc > 0 {
            layout.push((avt, avc));
        }
    }
    Ok(layout)
}
