//! Loopback tests: the real service on 127.0.0.1:0 with a temporary SQLite file, over HTTP.

mod arcs;
mod auth;
mod bad_requests;
mod browser;
mod cli;
mod contour;
mod deburr;
mod deburr_machine;
mod engagement;
mod entries;
mod gcode;
mod job_fuzz;
mod jobs;
mod limits;
mod load;
mod machines;
mod materials;
mod metrics;
mod openapi;
mod predict;
mod request_fuzz;
mod schemathesis;
mod segment;
mod tools;
mod web;
