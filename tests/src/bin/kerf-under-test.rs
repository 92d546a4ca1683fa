//! The `kerf` program, built inside the test crate so tests can start it as a process
//! (`CARGO_BIN_EXE_kerf-under-test`), kill it with SIGKILL and run `kerf run`.

fn main() -> anyhow::Result<()> {
    kerf_server::cli::main()
}
