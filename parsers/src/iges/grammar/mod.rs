//! The IGES 5.3 grammar as nom rules, by part of the file:
//!
//! - [`records`]: 80-column records and the S, G, D, P, T sections (section 2.2.4), with
//!   the SWAR sequence-number leaf;
//! - [`global`]: the Global section, its delimiter bootstrap and Hollerith strings (section
//!   2.2.4.3);
//! - [`directory`]: the Directory Entry's twenty fields (section 2.2.4.4);
//! - [`parameters`]: free-format parameter data with both delimiters (section 2.2.3), the
//!   data types of section 2.2.2 (integers, reals with `E` or `D` exponents, Hollerith
//!   strings), the one-pass real leaf of the P section and the reader that walks one
//!   entity's record with them.
//!
//! Every rule returns [`crate::grammar::GrammarError`] with the IGES [`ErrorKind`] as its
//! format cause; [`super::IgesFile`] turns the byte offset into a section, sequence
//! number, column and DE pointer.
//!
//! [`ErrorKind`]: super::ErrorKind

pub mod directory;
pub mod global;
pub mod parameters;
pub mod records;
