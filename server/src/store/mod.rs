//! Repositories: the only place with SQL. Handlers call these functions.

pub mod jobs;
pub mod machines;
pub mod tools;
