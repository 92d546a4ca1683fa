//! HTTP routes, one module per resource, each with a `router()`; the solver endpoints are generated
//! from the capability registry in `endpoints`; `stream` holds the response bodies they hand out
//! a piece at a time.

pub mod contour;
pub mod dxf;
pub mod endpoints;
pub mod health;
pub mod jobs;
pub mod machines;
pub mod materials;
pub mod output;
pub mod predict;
pub mod solve;
pub mod stream;
pub mod tools;
