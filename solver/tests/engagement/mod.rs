//! Tool engagement and flute counts (docs/spec/engagement.md): reference cases, bad input, forces, heights, programs, the answer's JSON, properties.

mod cases;
mod errors;
mod features;
mod forces;
mod gcode;
mod heights;
mod limits;
mod properties;
mod wire;
