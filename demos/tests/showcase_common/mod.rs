//! Runs the showcase binary, as the showcase tests all do.

use std::process::Command;

/// Runs the showcase with `args`; its standard output (it must succeed, else the test
/// fails with both its outputs).
pub fn run_showcase(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_showcase"))
        .args(args)
        .output()
        .expect("showcase runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}
