//! HTTP routes, one module per resource, each with a `router()`.

pub mod contour;
pub mod deburr;
pub mod engagement;
pub mod health;
pub mod jobs;
pub mod machines;
pub mod materials;
pub mod output;
pub mod predict;
pub mod segment;
pub mod solve;
pub mod tools;
