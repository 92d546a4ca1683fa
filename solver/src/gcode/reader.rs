//! Reading G-code programs into typed moves with their line numbers. Not built yet.
