//! The HTML report in a real browser: Chromium, headless, loads the page
//! of `mms identify --format html` and `mms diagnose --format html` on
//! real recordings with `#selftest`, whose script then zooms one panel,
//! reads the readout and toggles a legend entry by itself and writes what
//! happened into the page; the test reads the page back (`--dump-dom`)
//! and checks that no script error occurred, that the plot is drawn
//! (inked pixels on the canvas), that the zoom narrowed the frequency
//! range, that the readout names the traces, and that the legend hid its
//! trace. A screenshot is taken as well and must not be blank. Where no
//! Chromium is installed (`.ci/run` installs Debian's package) the test
//! says so on stderr and passes.

mod common;

use common::{mms, real_data};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn chromium() -> Option<&'static str> {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|b| {
            Command::new(b)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

/// The self-test's report of the page, and the screenshot's size.
fn run_page(browser: &str, page: &Path, shot: &Path) -> (Value, u64) {
    let url = format!("file://{}#selftest", page.display());
    let headless = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--hide-scrollbars",
    ];
    let out = Command::new(browser)
        .args(headless)
        .args(["--virtual-time-budget=5000", "--dump-dom", &url])
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&out.stdout);
    let start = dom.find("<pre id=\"mms-selftest\">").unwrap_or_else(|| {
        panic!(
            "no self-test in the page: {}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let body = &dom[start + "<pre id=\"mms-selftest\">".len()..];
    let json = &body[..body.find("</pre>").unwrap()];
    let json = json
        .replace("&amp;", "&")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"");
    let report: Value = serde_json::from_str(&json).unwrap();
    let status = Command::new(browser)
        .args(headless)
        .args(["--window-size=1000,1200", "--virtual-time-budget=3000"])
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(status.status.success() || shot.exists());
    let size = std::fs::metadata(shot).map(|m| m.len()).unwrap_or(0);
    (report, size)
}

/// Each figure of the page drawn, zoomed, read out and toggled, and its
/// readout naming the curves of `traces` (one list per figure).
fn check(report: &Value, traces: &[&[&str]]) {
    assert_eq!(
        report["errors"],
        Value::Array(vec![]),
        "script errors: {report}"
    );
    let figures = report["figures"].as_array().unwrap();
    assert_eq!(figures.len(), traces.len(), "{report}");
    for (fig, traces) in figures.iter().zip(traces) {
        let (inked, pixels) = (
            fig["inked"].as_f64().unwrap(),
            fig["pixels"].as_f64().unwrap(),
        );
        // Frames, grid, curves and text ink a few percent of the canvas;
        // a blank or unfinished plot inks nothing.
        assert!(inked > 0.01 * pixels && inked < 0.6 * pixels, "{fig}");
        let (b, a) = (&fig["before"], &fig["after"]);
        let span = |v: &Value| (v[1].as_f64().unwrap() / v[0].as_f64().unwrap()).log10();
        // The drag covered 30 % of the panel's width: 30 % of the decades.
        assert!((span(a) / span(b) - 0.3).abs() < 0.01, "zoom {b} -> {a}");
        assert!(a[0].as_f64() > b[0].as_f64() && a[1].as_f64() < b[1].as_f64());
        let readout = fig["readout"].as_str().unwrap();
        assert!(
            readout.starts_with("f = ") && readout.contains(" dB, "),
            "{readout}"
        );
        for t in *traces {
            assert!(readout.contains(t), "{t} not in {readout}");
        }
        assert_eq!(fig["toggled"], true);
    }
}

#[test]
fn html_reports_draw_zoom_read_out_and_toggle_in_a_browser() {
    let Some(browser) = chromium() else {
        eprintln!("SKIPPED: no Chromium on this machine; the browser test did not run");
        return;
    };
    let dir = common::temp_dir("browser", "reports");
    let rec = real_data("sperte/setup18_motor_side_v0.3.mat");
    let sperte = ["--u", "result:1", "--y", "result:2", "--fs", "4000"];
    let id_dir = dir.join("identify");
    let mut args = vec!["identify", &rec];
    args.extend(sperte);
    let id = id_dir.to_str().unwrap();
    args.extend(["--format", "html", "--out", id]);
    let (code, _, err) = mms(&args);
    assert_eq!(code, 0, "{err}");
    let (report, shot) = run_page(
        browser,
        &id_dir.join("report.html"),
        &dir.join("identify.png"),
    );
    check(&report, &[&["measured", "N2-g0-a1.0-s1.0"]]);
    // A page of this size compresses to far more than a blank one's.
    assert!(shot > 20_000, "screenshot of {shot} bytes");

    // The diagnosis of the same record with the model just identified.
    let model = id_dir.join("model.toml");
    let dg_dir = dir.join("diagnose");
    let mut args = vec!["diagnose", &rec];
    args.extend(sperte);
    let (m, dg) = (model.to_str().unwrap(), dg_dir.to_str().unwrap());
    args.extend(["--model", m, "--format", "html", "--out", dg]);
    let (code, _, err) = mms(&args);
    assert_eq!(code, 0, "{err}");
    let (report, shot) = run_page(
        browser,
        &dg_dir.join("report.html"),
        &dir.join("diagnose.png"),
    );
    check(&report, &[&["recording", "model after diagnosis"]]);
    assert!(shot > 20_000, "screenshot of {shot} bytes");

    // Both joined on one page, each figure working by itself.
    let rp_dir = dir.join("report");
    let mut args = vec!["report", &rec];
    args.extend(sperte);
    let rp = rp_dir.to_str().unwrap();
    args.extend(["--format", "html", "--out", rp]);
    let (code, _, err) = mms(&args);
    assert_eq!(code, 0, "{err}");
    let (report, shot) = run_page(
        browser,
        &rp_dir.join("report.html"),
        &dir.join("report.png"),
    );
    check(
        &report,
        &[
            &["measured", "N2-g0-a1.0-s1.0"],
            &["recording", "model after diagnosis"],
        ],
    );
    assert!(shot > 20_000, "screenshot of {shot} bytes");
    let _ = std::fs::remove_dir_all(&dir);
}
