//! Helpers shared by the integration tests of the `mms` binary.

use std::process::Command;

/// Runs the `mms` binary: exit code, stdout, stderr.
pub fn mms(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mms"))
        .args(args)
        .output()
        .expect("run mms");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).expect("utf-8 stdout"),
        String::from_utf8(out.stderr).expect("utf-8 stderr"),
    )
}
