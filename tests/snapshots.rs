//! Snapshots (insta, stored in snapshots/) of every 3-mass model's Num/Den in
//! every format. CI runs with INSTA_UPDATE=no, so any drift fails; review
//! intended changes with `cargo insta review`.

use std::process::Command;

fn mms(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_mms"))
        .args(args)
        .output()
        .expect("run mms");
    assert!(
        out.status.success(),
        "mms {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

macro_rules! snap {
    ($name:expr, $value:expr) => {
        insta::with_settings!({snapshot_path => "../snapshots", prepend_module_to_snapshot => false}, {
            insta::assert_snapshot!($name, $value);
        });
    };
}

#[test]
fn derive_three_masses_every_format() {
    for format in ["text", "json", "md", "tex"] {
        snap!(
            format!("derive_n3_{format}"),
            mms(&["derive", "--masses", "3", "--format", format])
        );
    }
    snap!(
        "derive_n3_md_abbreviated",
        mms(&["derive", "--masses", "3", "--format", "md", "--abbreviate"])
    );
}

#[test]
fn derive_three_masses_damped() {
    snap!(
        "derive_n3_damped_position_text",
        mms(&["derive", "--masses", "3", "--damped", "--output", "position"])
    );
}

#[test]
fn enumerate_tables() {
    for n in ["3", "4"] {
        snap!(
            format!("enumerate_n{n}_table"),
            mms(&["enumerate", "--masses", n])
        );
    }
}
