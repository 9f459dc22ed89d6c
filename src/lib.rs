//! # nurbsx: exact NURBS exchange between IGES 5.3 and STEP
//!
//! nurbsx reads and writes B-spline and NURBS curves and surfaces in IGES 5.3 (entities 126
//! and 128, with the Global section and 124 transforms honoured) and STEP (ISO 10303-21
//! files carrying ISO 10303-42 B-spline entities), through one exact NURBS model.
//!
//! ## Layering
//! Dependencies point one way, and the folders show it:
//!
//! ```text
//! cli ─┐
//!      ├─> pipeline ─> exchange ─> topology ─> nurbs
//! service ┘                 └──> nurbsx_parsers (format syntax, separate crate)
//! ```
//!
//! - [`nurbs`]: the model and the algorithms (no formats, no I/O).
//! - [`topology`]: vertices, edges, loops, faces, shells, solids and assemblies over the
//!   NURBS geometry, built through checked constructors (no formats, no I/O).
//! - [`exchange`]: format records <-> model, units, diagnostics, import/export policies.
//! - [`pipeline`]: the one conversion pipeline that both front ends call.
//! - [`cli`] and [`service`]: argument parsing and printing; HTTP routing. No logic of their own.

pub mod cli;
pub mod exchange;
pub mod nurbs;
pub mod pipeline;
pub mod service;
pub mod topology;
