//! HTTP routes, one module per resource, each with a `router()`.

pub mod deburr;
pub mod health;
pub mod jobs;
pub mod output;
pub mod predict;
pub mod tools;
