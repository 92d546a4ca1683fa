//! Contour milling with corner loops (docs/spec/contour.md): reference cases, bad input, block-time rule, reliefs, programs, properties.

mod blocks;
mod cases;
mod detect;
mod errors;
mod program;
mod properties;
mod relief;
