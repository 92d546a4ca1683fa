//! The solver's tests, one binary: per capability its reference cases (the fixtures beside this
//! file, copied from the spec's cases), bad input and property tests; across capabilities the
//! cycle time, progress reports and requests split into parts.

mod cancellation;
mod contour;
mod cycle_properties;
mod deburr;
mod engagement;
mod inline;
mod predict;
mod progress;
mod segment;
mod split_parts;
