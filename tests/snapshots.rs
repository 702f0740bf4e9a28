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

/// Tab. 3: the possible types, similar systems and the number of certified
/// impossible candidates per model.
#[test]
fn analyze_three_masses_tab3() {
    for format in ["table", "md", "tex"] {
        snap!(
            format!("analyze_n3_{format}"),
            mms(&["analyze", "--masses", "3", "--format", format])
        );
    }
}

/// Two verdicts written out: a sign-condition proof the paper gives by hand
/// (B2 cannot show RAAR, Sec. 4.3.7) and a witness.
#[test]
fn prove_derivations() {
    snap!("prove_b2_raar_md", mms(&["prove", "B2", "RAAR"]));
    snap!("prove_b2_a2rr_md", mms(&["prove", "B2", "A^2RR"]));
}

/// The generated reports in docs/ are what the README's main command
/// produces today (regenerate with `mms study --out docs/study-3-masses.md`
/// and `--format tex --out docs/study-3-masses.tex`).
#[test]
fn committed_study_reports_are_current() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/");
    let md = std::fs::read_to_string(format!("{root}study-3-masses.md"))
        .expect("docs/study-3-masses.md");
    assert!(
        md == mms(&["study"]),
        "docs/study-3-masses.md is stale: regenerate it"
    );
    let tex = std::fs::read_to_string(format!("{root}study-3-masses.tex"))
        .expect("docs/study-3-masses.tex");
    assert!(
        tex == mms(&["study", "--format", "tex"]),
        "docs/study-3-masses.tex is stale: regenerate it"
    );
}

/// Issue 4: the 4-mass table as it stands (possible types with witnesses,
/// impossible ones with certificates, and the unknown verdicts, counted),
/// and the independent checker run over every witness and certificate of
/// it. Both come from one analysis, through the resumable cache.
#[test]
fn analyze_n4_table_and_every_certificate_checked() {
    let dir = std::env::temp_dir().join(format!("mms-n4-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cache = dir.join("cache");
    let json = mms(&[
        "analyze",
        "--masses",
        "4",
        "--format",
        "json",
        "--jobs",
        "0",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    let file = dir.join("n4.json");
    std::fs::write(&file, &json).unwrap();
    let report = mms(&["check", file.to_str().unwrap()]);
    assert!(!report.is_empty());
    let table = mms(&[
        "analyze",
        "--masses",
        "4",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    snap!("analyze_n4_table", table);
    snap!("check_n4", report);
    // Issue 4, item 4: the committed document is the current one.
    let doc = mms(&[
        "analyze",
        "--masses",
        "4",
        "--format",
        "report",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    let committed = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/tables/n4.md"
    ))
    .expect("docs/tables/n4.md");
    assert!(
        committed == doc,
        "docs/tables/n4.md is stale: regenerate it with `mms analyze --masses 4 --format report`"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
