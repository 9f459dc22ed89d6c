//! REAL literals: one strict lexer per format and one exact writer shared by both.
//!
//! # Writing
//! [`write_real`] prints the *shortest* decimal digits that read back as the same `f64`
//! (Rust's `Display`/`LowerExp` implement the Ryu/Grisu shortest round-trip algorithm) and
//! then makes the token valid in both formats:
//!
//! - a decimal point is always present (`1.` not `1`; ISO 10303-21 clause 6.3.3 requires a
//!   digit, a point, optional digits; IGES 5.3 section 2.2.2.3 requires the point for REAL);
//! - magnitudes in `[1e-5, 1e16)` are written positionally (`0.5`, `250.`, `6.28318530717958`),
//!   all others with an upper-case exponent (`1.E16`, `5.E-324`, `-2.5E-7`);
//! - `-0.0` keeps its sign (`-0.`), so read -> write -> read is bit-identical.
//!
//! Non-finite values cannot be written in either format and are refused.
//!
//! # Reading
//! [`parse_step_real`] accepts exactly the Part 21 production
//! `REAL = [ SIGN ] DIGIT { DIGIT } "." { DIGIT } [ "E" [ SIGN ] DIGIT { DIGIT } ]`
//! and [`parse_iges_real`] the IGES form (leading digit optional, `E`, `e`, `D` or `d`
//! exponent, an integer token accepted where a real is expected, as Open CASCADE does).
//! The whole token must be consumed (`1.52.3` is an error, not `1.52`), and a value that
//! overflows to infinity (`1.E400`) is an error, not a silent `inf`.

/// Why a token is not an acceptable REAL.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum RealError {
    /// The token does not match the format's REAL grammar.
    #[error("not a valid real number")]
    Syntax,
    /// The token is well formed but its value is outside the finite `f64` range.
    #[error("real number overflows to infinity")]
    NonFinite,
}

/// A NaN or infinite value was given to the writer; neither format can represent it.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("cannot write non-finite real {0}")]
pub struct NonFiniteReal(pub f64);

// Lexing: the STEP and IGES REAL grammars, read and converted in one pass.
mod lex;
pub(crate) use lex::digit_word;
pub use lex::{iges_real_at, parse_iges_real, parse_step_real, step_real_at};

// Writing: the shortest round-trip digits, for both formats.
mod format;
pub use format::{format_real, write_real};
