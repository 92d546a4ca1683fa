//! Machining-error prediction and correction (docs/spec/predict.md): reference cases, bad input, exclusion, merging, programs, properties.

mod cases;
mod errors;
mod exclusion;
mod invariance;
mod merge;
mod program;
mod properties;
