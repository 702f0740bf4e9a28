//! Helpers shared by the integration tests of the `mms` binary.

use std::path::{Path, PathBuf};
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

/// A fresh, empty directory `mms-{group}-{name}-{pid}` under the system's
/// temporary directory.
#[allow(dead_code)] // not every test binary writes files
pub fn temp_dir(group: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("mms-{group}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A file of the shared real recordings (see ../shared/data/real/README.md).
#[allow(dead_code)] // not every test binary reads them
pub fn real_data(rel: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/real")
        .join(rel);
    assert!(p.exists(), "real recording {} missing", p.display());
    p.to_string_lossy().into_owned()
}

/// The EMPS model the diagnosis starts from: one rigid body of 100 kg
/// behind the drive's 35.15 N/V, viscous friction only (no Coulomb
/// friction, no offset).
#[allow(dead_code)] // not every test binary diagnoses EMPS
pub const EMPS_MODEL: &str = "masses = 1\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
    output = \"position\"\ngain = 35.15\n[parameters]\nm1 = 100\n[effects]\n\
    friction = { viscous_ns_per_m = 200 }\n";
