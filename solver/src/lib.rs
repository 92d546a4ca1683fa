//! kerf's solvers: pure, deterministic tool-path computation.
//!
//! Every capability is a function from a validated request to an answer or a [`SolverError`]; no
//! I/O, no clocks, no global state, so the same request always gives the same bytes and a solver
//! call can run on any thread or worker. The server crate does HTTP, storage and jobs.
//!
//! Modules: [`geometry`] (vectors and small numeric helpers), [`tool`] (the cutter),
//! [`path`] (typed moves), [`gcode`] (posts for the supported dialects), [`capability`] (the seam
//! every way in dispatches through), [`material`] (work materials' Kienzle values), and one
//! module per capability: [`deburr`], [`segment`],
//! [`contour`], [`engagement`], [`predict`], and [`verify`], which cuts a program to check it.
#![deny(missing_docs)]

pub mod capability;
#[cfg(test)]
mod chamfer_cut;
pub mod contour;
pub mod control;
pub mod deburr;
pub mod dxf;
pub mod engagement;
pub mod error;
mod error_code;
pub mod gcode;
pub mod geometry;
pub mod machine;
pub mod material;
pub mod path;
pub mod planar;
pub mod predict;
pub mod segment;
pub mod stock;
pub mod tool;
pub mod units;
pub mod validate;
pub mod verify;
pub(crate) mod wire;
#[cfg(test)]
mod writer_as_before;

pub use error::{ErrorCode, SolverError, Warning};
