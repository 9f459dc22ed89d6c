//! Entity 416, External Reference (IGES 5.3 section 4.138), declared for the arity check:
//! its parameters are strings naming a file, a library and a definition in them, so it
//! holds no DE pointer. nurbsx does not follow external references.
//!
//! | form | use | parameters |
//! | --- | --- | --- |
//! | 0 | one definition of the referenced file | file identifier `EXTFID`, symbolic name `EXTNAM` |
//! | 1 | the whole referenced file as one definition | file identifier `EXTFID` |
//! | 2 | a logical reference to an entity of another file | file identifier `EXTFID`, symbolic name `EXTNAM` |
//! | 3 | a subfigure held natively by the receiving system | symbolic name `EXTNAM` |
//! | 4 | a subfigure in a library of the receiving system | library name `LIBNAM`, symbolic name `EXTNAM` |

use super::{Field, Schema, Type};

/// Forms 0 and 2: the file identifier (Global parameter 4 of the referenced file) and the
/// entity's symbolic name.
pub(super) const FILE_AND_NAME: Schema = Schema {
    entity: 416,
    name: "External Reference",
    fields: &[
        Field::one("EXTFID", Type::String),
        Field::one("EXTNAM", Type::String),
    ],
};

/// Form 1: the file identifier only.
pub(super) const FILE: Schema = Schema {
    entity: 416,
    name: "External Reference (form 1)",
    fields: &[Field::one("EXTFID", Type::String)],
};

/// Form 3: the symbolic name only.
pub(super) const NAME: Schema = Schema {
    entity: 416,
    name: "External Reference (form 3)",
    fields: &[Field::one("EXTNAM", Type::String)],
};

/// Form 4: the library name and the symbolic name.
pub(super) const LIBRARY_AND_NAME: Schema = Schema {
    entity: 416,
    name: "External Reference (form 4)",
    fields: &[
        Field::one("LIBNAM", Type::String),
        Field::one("EXTNAM", Type::String),
    ],
};
