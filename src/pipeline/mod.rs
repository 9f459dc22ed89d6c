//! # The conversion pipeline
//!
//! The one place where a request becomes work: load (sniff -> parse -> import), operate
//! (evaluate, elevate, clamp, ...), export (write -> optionally verify). The CLI and the
//! HTTP service call these functions and only parse arguments and print; they hold no
//! logic of their own, so the two front ends cannot drift apart.
//!
//! Everything here is synchronous and CPU-bound; the service runs it off the async threads.

mod cancel;
pub mod construct;
mod error;
mod export;
mod input;
pub mod measure;
pub mod mesh;
mod ops;
pub mod picture;
mod reports;

pub use cancel::{Cancel, cancelled};
pub use error::{ErrorKind, PipelineError};
pub use export::{KnotForm, write_as, write_model_json};
pub use input::{InputKind, Loaded, Settings, load};
pub use ops::{
    ClampPolicy, ConvertOutput, ConvertRequest, Direction, EvalRequest, MeshFile, MeshFormat,
    OpNote, Operation, Tessellated, affine, apply, check_evaluation, check_file_reply, convert,
    drop_unwritable, evaluate, evaluate_each, file_report, info, select, tessellate,
    tessellate_file, validate, write,
};
pub use reports::{
    ConvertReport, EntityDeviation, EntityInfo, EvalReport, EvalResult, FaceInfo, InfoReport,
    PartDeviation, ShellInfo, SolidInfo, StructureInfo, UnitsInfo, ValidationReport,
};
