//! Deburring the ridge of a cross hole (docs/spec/deburr.md): reference cases, block-time rule, the swept chamfer, properties.

mod block_time;
mod cases;
mod properties;
mod swept;
