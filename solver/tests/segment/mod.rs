//! Segmentation by the block-time rule (docs/spec/segment.md): reference cases, bad input, properties.

mod cases;
mod errors;
mod properties;
