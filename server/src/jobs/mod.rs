//! Jobs (docs/spec/api.md, Jobs): job files naming one or more operations, their resolution into
//! self-contained jobs, the pure execution of a job, and the persistent queue with its workers.

pub mod execute;
pub mod file;
pub mod local;
pub mod parts;
pub mod program;
pub mod pruner;
pub mod queue;
