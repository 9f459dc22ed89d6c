//! Entity 422, Attribute Table Instance (IGES 5.3 section 4.141): the values of the 322
//! Attribute Table Definition (section 4.79) that its DE structure field (field 3, a
//! negated pointer) names, in that 322's order and types.
//!
//! | form | parameters |
//! | --- | --- |
//! | 0 | one row: per attribute of the 322, its `AVC` values of type `AVT` |
//! | 1 | `NR`, then `NR` rows as form 0's |
//!
//! The parameters' types and count come from another entity, so no [`super::Schema`]
//! declares them; [`instance`] checks them against the 322's layout
//! ([`super::Dependent::AttributeInstance`]).

use super::{count, count_parameter, too_big, typed_value};
use crate::iges::grammar::parameters::{Error, ParameterReader};

/// Checks a 422 in form `form` after the entity type against `layout`, the `(AVT, AVC)`
/// of the 322's attributes that hold values ([`super::attribute_layout`]); the pointer
/// values go to `pointers`.
pub(super) fn instance<'a>(
    r: &mut ParameterReader<'a>,
    form: i64,
    layout: &[(i64, usize)],
    pointers: &mut Vec<i64>,
) -> Result<(), Error<'a>> {
    let first = r.rest();
    let row = layout
        .iter()
        .try_fold(0usize, |n, &(_, avc)| n.checked_add(avc))
        .ok_or_else(|| too_big(first, "the 322's value count"))?;
    let (rows, counts) = if form == 1 {
        let nr = count_parameter(r, "NR", None)?;
        (nr, vec![("NR", count(nr)), ("values a row", count(row))])
    } else {
        (1, vec![("values a row", count(row))])
    };
    let needed = rows
        .checked_mul(row)
        .and_then(|n| n.checked_add(usize::from(form == 1)))
        .ok_or_else(|| too_big(first, "NR × the 322's value count"))?;
    r.expect(needed, 422, counts);
    if row == 0 {
        return Ok(());
    }
    // Every turn of the inner loop reads a parameter (the layout holds no `AVC` of 0):
    // the data, not the counts, bounds the loops.
    for _ in 0..rows {
        for &(avt, avc) in layout {
            for _ in 0..avc {
                typed_value(r, avt, "VALUE", pointers)?;
            }
        }
    }
    Ok(())
}
