//! Shared by the command-line tests: running the `texmap` binary Cargo built for them.

use std::process::{Command, Output};

/// Run `texmap` with `args` and collect its exit status, stdout and stderr.
pub fn texmap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texmap"))
        .args(args)
        .output()
        .expect("the texmap binary runs")
}
