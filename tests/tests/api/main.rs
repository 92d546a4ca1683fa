//! Loopback tests: the real service on 127.0.0.1:0 with a temporary SQLite file, over HTTP.

mod bad_requests;
mod browser;
mod deburr;
mod gcode;
mod jobs;
mod openapi;
mod tools;
