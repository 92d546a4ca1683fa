//! The `kerf` binary; everything it does lives in `kerf_server::cli`, so the tests can build
//! the same program.

fn main() -> anyhow::Result<()> {
    kerf_server::cli::main()
}
