//! End-to-end tests of the `mms` binary: results against the paper's printed
//! numbers, and the behaviour on bad input.

mod common;
use common::mms;

fn json(args: &[&str]) -> serde_json::Value {
    let (code, out, err) = mms(args);
    assert_eq!(code, 0, "mms {args:?} failed: {err}");
    serde_json::from_str(&out).expect("valid JSON")
}

#[test]
fn enumerate_reproduces_tab1() {
    // Tab. 1 of the paper: basic, degradation-free, redundancy-free.
    let paper = [
        (1, 1, 1, 1),
        (2, 8, 5, 3),
        (3, 34, 17, 11),
        (4, 104, 50, 29),
        (5, 259, 129, 73),
    ];
    for (n, basic, free, rule3) in paper {
        let v = json(&["enumerate", "--masses", &n.to_string(), "--format", "json"]);
        assert_eq!(v["masses"], n);
        assert_eq!(v["basic"], basic, "N={n}");
        assert_eq!(v["degradation_free"], free, "N={n}");
        assert_eq!(v["paper_rule3"], rule3, "N={n}");
        assert_eq!(v["models"].as_array().unwrap().len(), free, "N={n}");
    }
}

#[test]
fn enumerate_three_masses_has_the_papers_eleven_ids() {
    let v = json(&["enumerate", "--masses", "3", "--format", "json"]);
    let mut ids: Vec<String> = v["models"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["paper_rule3"] == true)
        .map(|m| m["paper_id"].as_str().unwrap().to_string())
        .collect();
    ids.sort();
    // Tab. 2 of the paper, stars on the collocated models.
    assert_eq!(
        ids,
        ["A1*", "A2", "A3", "A4*", "A5", "B1*", "B2", "C1*", "C2", "C3*", "C4"]
    );
    assert_eq!(v["classes"], 11);
}

#[test]
fn derive_json_matches_paper_eq21() {
    let v = json(&["derive", "A2", "--format", "json"]);
    let m = &v["models"][0];
    assert_eq!(m["id"], "A2");
    assert_eq!(m["gap"], 0);
    assert_eq!(m["actuator"], serde_json::json!([1, 0]));
    assert_eq!(m["sensor"], serde_json::json!([2, 0]));
    let num: poly::Poly = m["numerator"].as_str().unwrap().parse().unwrap();
    // eq. (21): Num_A2 = -m3 c12 Omega + c12 c23
    let paper: poly::Poly = "-m3*c12*Omega + c12*c23".parse().unwrap();
    assert_eq!(num, paper);
    // eq. (10): Den_A
    let den: poly::Poly = m["denominator"].as_str().unwrap().parse().unwrap();
    let paper_den: poly::Poly = "m1*m2*m3*Omega^2 - (c12*(m1*m3 + m2*m3) + c23*m1*(m2 + m3))*Omega + c12*c23*(m1 + m2 + m3)"
        .parse()
        .unwrap();
    assert_eq!(den, paper_den);
}

#[test]
fn derive_position_output_is_receptance() {
    // Receptance = -Num/(Omega Den): the denominator gains the factor Omega.
    let v = json(&["derive", "A3", "--format", "json", "--output", "position"]);
    let den: poly::Poly = v["models"][0]["denominator"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(den.min_degree("Omega"), 1);
    let num: poly::Poly = v["models"][0]["numerator"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(num, "-c12*c23".parse().unwrap());
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    for args in [
        vec!["enumerate", "--masses", "0"],
        vec!["enumerate", "--masses", "1000000"],
        vec!["derive", "--masses", "0"],
        vec!["derive", "Z9"],
        vec!["derive", "N3-g5-a1.0-s1.0"],
        vec!["enumerate", "--masses", "3", "--format", "xml"],
        vec!["enumerate", "--masses", "-3"],
        vec!["algebra", "--masses", "99"],
        vec!["benchmark", "--cases", "0"],
        vec!["benchmark", "--cases", "2000000"],
        vec!["frobnicate"],
    ] {
        let (code, out, err) = mms(&args);
        assert_eq!(code, 2, "{args:?}: stdout {out:?} stderr {err:?}");
        assert!(out.is_empty(), "{args:?} wrote to stdout");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        if !args.contains(&"xml") && !args.contains(&"frobnicate") && !args.contains(&"-3") {
            // Our own errors are one line; clap's usage errors add a usage hint.
            assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        }
    }
}

#[test]
fn study_writes_the_report_atomically() {
    let dir = std::env::temp_dir().join(format!("mms-study-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("study.md");
    let (code, out, err) = mms(&["study", "--out", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.is_empty());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("Tab. 1"));
    assert!(text.contains("| 3 | 34 | 17 | 11 | 11 |"), "{text}");
    // no temporary file left behind
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(Result::ok)
        .collect();
    assert_eq!(leftovers.len(), 1);
    // an unwritable target fails with exit 2 and no partial file
    let bad = dir.join("no-such-dir").join("x.md");
    let (code, _, err) = mms(&["study", "--out", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(!bad.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_accepts_analyze_output_and_rejects_tampering() {
    let dir = std::env::temp_dir().join(format!("mms-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut v = json(&["analyze", "--masses", "3", "--format", "json"]);
    let good = dir.join("n3.json");
    std::fs::write(&good, v.to_string()).unwrap();
    let (code, out, err) = mms(&["check", good.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
    assert!(
        out.starts_with("checked 25 witnesses and ") && out.ends_with(" certificates: all valid\n"),
        "{out}"
    );
    // Models checked in parallel: the same line.
    for jobs in ["0", "2"] {
        let (code, same, err) = mms(&["check", "--jobs", jobs, good.to_str().unwrap()]);
        assert_eq!(
            (code, same.as_str()),
            (0, out.as_str()),
            "--jobs {jobs}: {err}"
        );
    }

    // Flip the sign of the first definite factor of the first certificate
    // that has factors (A1 is collocated: most of its certificates are the
    // factor-free collocation theorem).
    let verdict = v["models"][0]["types"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|t| {
            t["status"] == "impossible"
                && t["certificate"]["factors"]
                    .as_array()
                    .is_some_and(|f| !f.is_empty())
        })
        .unwrap();
    let factor = &mut verdict["certificate"]["factors"][0];
    assert_eq!(factor["kind"], "definite");
    factor["sign"] = serde_json::json!(-factor["sign"].as_i64().unwrap());
    let bad = dir.join("tampered.json");
    std::fs::write(&bad, v.to_string()).unwrap();
    let (code, out, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}");
    assert!(out.is_empty(), "{out}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    let prefix = format!("mms: error: {}: model A1, type ", bad.display());
    assert!(err.starts_with(&prefix), "{err}");
    assert!(err.contains("definite: no_subtraction"), "{err}");

    // A polynomial whose expansion would not fit in memory (a power of a
    // sum of six variables to 10000): refused at once, not expanded.
    let factor = v["models"][0]["types"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find_map(|t| {
            // `get_mut`: indexing would add a certificate to possible types.
            let f = t.get_mut("certificate")?["factors"].get_mut(0)?;
            (f["kind"] == "definite").then_some(f)
        })
        .unwrap();
    factor["factor"] = serde_json::json!("(m1+m2+m3+c12+c23+Omega)^10000");
    std::fs::write(&bad, v.to_string()).unwrap();
    let start = std::time::Instant::now();
    let (code, out, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("above the limit"), "{err}");
    assert!(start.elapsed().as_secs() < 30);

    // A pruned table (one verdict, or one model, cut out of the analysis
    // of every class of 3 masses) is not "all valid".
    let full = json(&["analyze", "--masses", "3", "--format", "json"]);
    assert_eq!(full["covers"], serde_json::json!({ "masses": 3 }));
    // It also states by which version and search it was made.
    assert!(full["engine_version"].as_u64().is_some());
    assert_eq!(full["mms_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(full["search_limits"]["max_depth"], 4);
    let mut pruned = full.clone();
    pruned["models"][0]["types"].as_array_mut().unwrap().pop();
    std::fs::write(&bad, pruned.to_string()).unwrap();
    let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("has no verdict"), "{err}");
    let mut pruned = full.clone();
    pruned["models"].as_array_mut().unwrap().pop();
    std::fs::write(&bad, pruned.to_string()).unwrap();
    let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is missing"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    // The similar systems `mms analyze` lists (its own lookup) agree with
    // the checker's, recomputed from the verdicts; one edited out does not.
    let mut edited = full.clone();
    let entry = edited["models"][1]["similar"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|e| !e["models"].as_array().unwrap().is_empty())
        .unwrap();
    entry["models"].as_array_mut().unwrap().pop();
    std::fs::write(&bad, edited.to_string()).unwrap();
    let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("its verdicts give"), "{err}");
    // So do the moment invariants it counts (by `mms::identifiability`)
    // and the checker's own count on the reduced TF.
    let mut edited = full.clone();
    let count = edited["models"][3]["moment_invariants"].as_u64().unwrap();
    edited["models"][3]["moment_invariants"] = (count + 1).into();
    std::fs::write(&bad, edited.to_string()).unwrap();
    let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("moment_invariants: the file says"), "{err}");
    // The determinable parameters: the checker's own rank of its own
    // Jacobian at a point (lower bound) against the listed unidentifiable
    // directions, each multiplied out (upper bound). B2 (N3-g1-a2.1-s3.1)
    // has five invariants and five parameters but rank 4 (Tab. 5 of the
    // paper), so its bound needs the one direction.
    let b2 = full["models"]
        .as_array()
        .unwrap()
        .iter()
        .position(|m| m["id"] == "B2")
        .unwrap();
    assert_eq!(full["models"][b2]["determinable_parameters"], 4);
    assert_eq!(full["models"][b2]["moment_invariants"], 5);
    let refused = |edit: &dyn Fn(&mut serde_json::Value), why: &str| {
        let mut edited = full.clone();
        edit(&mut edited["models"][b2]);
        std::fs::write(&bad, edited.to_string()).unwrap();
        let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
        assert_eq!(code, 2, "{why}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("model B2") && err.contains(why), "{err}");
    };
    refused(
        &|m| m["determinable_parameters"] = 5.into(),
        "the file says 5, more than 4",
    );
    refused(
        &|m| m["determinable_parameters"] = 3.into(),
        "proves no bound below 4",
    );
    refused(
        &|m| m["unidentifiable_directions"] = serde_json::json!([]),
        "the file says 4 and proves no bound below 5",
    );
    refused(
        &|m| m["unidentifiable_directions"][0]["m2"] = "m2*m3 + m1".into(),
        "changes along it",
    );
    // Where the rank is only sampled (six masses), the file claims a
    // range: the sampled rank as a lower bound, and an upper bound the
    // checker reaches on its own (here by counting, without the
    // direction). A range whose top it cannot reach, or one that is no
    // range, is refused.
    let mut ranged = full.clone();
    ranged["models"][b2]["unidentifiable_directions"] = serde_json::json!([]);
    ranged["models"][b2]["determinable_parameters_at_most"] = 5.into();
    std::fs::write(&bad, ranged.to_string()).unwrap();
    let (code, out, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("all valid"), "{out}");
    refused(
        &|m| {
            m["unidentifiable_directions"] = serde_json::json!([]);
            m["determinable_parameters_at_most"] = 4.into();
        },
        "the file says 4, not above determinable_parameters (4)",
    );
    refused(
        &|m| {
            m["unidentifiable_directions"] = serde_json::json!([]);
            m["determinable_parameters"] = 3.into();
            m["determinable_parameters_at_most"] = 4.into();
        },
        "determinable_parameters_at_most: the file says 4 and proves no bound below 5",
    );
    // The critical factors' statuses carry their proofs: a definite sign
    // flipped, an undetermined factor called definite, a wall without its
    // substitution.
    let statuses = |m: &serde_json::Value| -> Vec<String> {
        m["critical"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["status"].as_str().unwrap().to_string())
            .collect()
    };
    let with = |status: &str| {
        full["models"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .find_map(|(i, m)| Some((i, statuses(m).iter().position(|s| s == status)?)))
            .unwrap()
    };
    for (status, edit, why) in [
        (
            "definite",
            (|f: &mut serde_json::Value| f["sign"] = (-f["sign"].as_i64().unwrap()).into())
                as fn(&mut serde_json::Value),
            "is not shown definite",
        ),
        (
            "wall",
            |f: &mut serde_json::Value| {
                f["status"] = "definite".into();
                f["sign"] = 1.into();
                f["definiteness"] = serde_json::json!({"method": "no_subtraction"});
            },
            "is not shown definite",
        ),
        (
            "wall",
            |f: &mut serde_json::Value| {
                let alpha = f["substitution"]["alpha"].as_str().unwrap().to_string();
                f["substitution"]["alpha"] = format!("2*({alpha})").into();
            },
            "is not a constant multiple of the wall",
        ),
        (
            "definite",
            |f: &mut serde_json::Value| f["status"] = "wall".into(),
            "missing key \"substitution\"",
        ),
    ] {
        let (i, j) = with(status);
        let mut edited = full.clone();
        edit(&mut edited["models"][i]["critical"][j]);
        std::fs::write(&bad, edited.to_string()).unwrap();
        let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
        assert_eq!(code, 2, "{status}: {err}");
        assert!(
            err.contains(&format!("critical[{j}]")) && err.contains(why),
            "{err}"
        );
    }

    // A table that claims nothing is not "all valid".
    let mut empty = full.clone();
    empty["models"] = serde_json::json!([]);
    std::fs::write(&bad, empty.to_string()).unwrap();
    let (code, out, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}");
    assert!(err.contains("claims no model"), "{err}");

    // Unreadable and malformed files: exit 2 naming the file.
    let missing = dir.join("missing.json");
    let (code, _, err) = mms(&["check", missing.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains(missing.to_str().unwrap()), "{err}");
    std::fs::write(&bad, "{\"models\": [").unwrap();
    let (code, _, err) = mms(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("not an analysis table"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn analyze_output_does_not_depend_on_jobs() {
    // The models finish in a different order with more jobs; the output
    // keeps the order of the model list.
    for format in ["json", "table"] {
        let run = |jobs: &str| {
            let (code, out, err) = mms(&[
                "analyze", "--masses", "3", "--format", format, "--jobs", jobs,
            ]);
            assert_eq!(code, 0, "{err}");
            // The closing timing line is on stderr, never on stdout.
            assert!(
                err.starts_with("mms: analyzed 11 models (0 from cache) in "),
                "{err}"
            );
            out
        };
        let one = run("1");
        assert_eq!(run("2"), one, "--format {format} --jobs 2");
        assert_eq!(run("0"), one, "--format {format} --jobs 0");
    }
}

#[test]
fn analyze_timings_are_opt_in_and_json_only() {
    let plain = json(&["analyze", "--masses", "3", "--format", "json"]);
    assert!(plain.get("timing").is_none());
    assert!(plain["models"][0].get("timing").is_none());
    let mut timed = json(&["analyze", "--masses", "3", "--format", "json", "--timings"]);
    assert_eq!(timed["timing"]["models_analysed"], 11);
    assert_eq!(timed["timing"]["threads"], 1);
    assert!(timed["timing"]["wall_seconds"].as_f64().unwrap() > 0.0);
    // Without the timing fields, the output is the plain one.
    timed.as_object_mut().unwrap().remove("timing");
    for m in timed["models"].as_array_mut().unwrap() {
        let t = m.as_object_mut().unwrap().remove("timing").unwrap();
        assert!(t["seconds"].as_f64().unwrap() > 0.0);
        assert_eq!(t["cached"], false);
    }
    assert_eq!(timed, plain);
    let (code, out, err) = mms(&["analyze", "A2", "--format", "md", "--timings"]);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert_eq!(
        err,
        "mms: error: --timings adds timing fields to --format json only\n"
    );
}

#[test]
fn analyze_cache_resumes_and_recomputes_bad_files() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("mms-analyze-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let cache = dir.join("cache");
    let cache_arg = cache.to_str().unwrap();
    let run = |format: &str, extra: &[&str]| {
        let mut args = vec!["analyze", "--masses", "3", "--format", format];
        args.extend_from_slice(extra);
        let (code, out, err) = mms(&args);
        assert_eq!(code, 0, "{err}");
        (out, err)
    };
    let formats = ["json", "table", "md", "tex"];
    let fresh: Vec<String> = formats.iter().map(|f| run(f, &[]).0).collect();

    // A first run fills the cache, one file per model; a second run takes
    // everything from it; every format renders the same from the cache.
    let (out, err) = run("json", &["--cache", cache_arg, "--jobs", "2"]);
    assert_eq!(out, fresh[0]);
    assert!(err.contains("(0 from cache)"), "{err}");
    let mut files: Vec<_> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 11, "{files:?}");
    let a2 = cache.join("N3-g0-a1.0-s2.0.json");
    let entry: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&a2).unwrap()).unwrap();
    assert_eq!(entry["format"], "mms-analyze-cache");
    assert_eq!(entry["model"], "N3-g0-a1.0-s2.0");
    assert_eq!(entry["summary"]["id"], "A2");
    for (f, want) in formats.iter().zip(&fresh) {
        let (out, err) = run(f, &["--cache", cache_arg]);
        assert_eq!(&out, want, "--format {f} from the cache");
        assert!(err.contains("(11 from cache)"), "{err}");
    }

    // An interrupted run: a model without its file is recomputed alone.
    std::fs::remove_file(&a2).unwrap();
    let (out, err) = run("json", &["--cache", cache_arg]);
    assert_eq!(out, fresh[0]);
    assert!(err.contains("(10 from cache)"), "{err}");
    assert!(!err.contains("warning"), "{err}");
    assert!(a2.exists());

    // Damaged, edited, stale or misplaced files: a warning naming the
    // file, a recomputation, and a good file again; never a crash, never
    // the bad content.
    let good = std::fs::read_to_string(&a2).unwrap();
    let mut edited: serde_json::Value = serde_json::from_str(&good).unwrap();
    edited["summary"]["possible"] = serde_json::json!(["C"]);
    let mut stale: serde_json::Value = serde_json::from_str(&good).unwrap();
    stale["fingerprint"] = serde_json::json!("cache layout 0");
    let other = std::fs::read_to_string(cache.join("N3-g0-a1.0-s1.0.json")).unwrap();
    let bad = [
        ("truncated", good[..good.len() / 2].to_string()),
        ("garbage", "\u{0}not json".to_string()),
        ("edited", edited.to_string()),
        ("stale", stale.to_string()),
        ("another model's", other),
    ];
    for (what, text) in bad {
        std::fs::write(&a2, text).unwrap();
        let (out, err) = run("table", &["--cache", cache_arg]);
        assert_eq!(out, fresh[1], "{what} cache file");
        let warning = format!("mms: warning: {}: ", a2.display());
        assert!(err.starts_with(&warning), "{what}: {err}");
        assert!(err.contains("; recomputing\n"), "{what}: {err}");
        assert!(err.contains("(10 from cache)"), "{what}: {err}");
        // Rewritten: the same entry but for the recorded time.
        let entry = |text: &str| {
            let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
            v.as_object_mut().unwrap().remove("seconds");
            v
        };
        let now = std::fs::read_to_string(&a2).unwrap();
        assert!(entry(&now) == entry(&good), "{what}: not rewritten");
    }
    // No temporary files are left behind.
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 11);

    // A cache path that cannot be a directory is a one-line error.
    let file = dir.join("a-file");
    std::fs::write(&file, "").unwrap();
    let (code, out, err) = mms(&["analyze", "A2", "--cache", file.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!(
            "mms: error: {}: cannot create cache directory: ",
            file.display()
        )),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 4, item 4: the report's identification summary for three masses
/// against the paper's Tab. 3 (mms::paper::TAB3, typed in from the paper):
/// a type identifies the structure exactly when one model of Tab. 3 lists
/// it, and the groups of several classes are the paper's.
#[test]
fn analyze_report_summary_matches_the_papers_tab3() {
    use std::collections::BTreeMap;
    let (code, out, err) = mms(&["analyze", "--masses", "3", "--format", "report"]);
    assert_eq!(code, 0, "{err}");
    let mut paper: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (id, types) in mms::paper::TAB3.iter() {
        for t in types.iter() {
            paper.entry(t.to_string()).or_default().push(id.to_string());
        }
    }
    let section = |title: &str| -> BTreeMap<String, Vec<String>> {
        let start = out.find(title).unwrap_or_else(|| panic!("no {title}"));
        out[start..]
            .lines()
            .skip_while(|l| !l.starts_with("|---"))
            .skip(1)
            .take_while(|l| l.starts_with('|'))
            .map(|l| {
                let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                let models = cells[2].split(", ").map(String::from).collect();
                (cells[1].trim_matches('`').to_string(), models)
            })
            .collect()
    };
    let unique = section("### Types that identify the structure");
    let shared = section("### Types several classes can show");
    for (t, models) in &paper {
        let mut models = models.clone();
        models.sort();
        let got = if models.len() == 1 {
            unique.get(t)
        } else {
            shared.get(t)
        };
        assert_eq!(got, Some(&models), "type {t}");
    }
    assert_eq!(unique.len() + shared.len(), paper.len());
    assert!(out.contains("None: the table is complete."), "{out}");
}

/// `mms analyze ID --format json` is a table of that one model, which
/// `mms check` accepts, whether the model is named by the paper's ID or
/// the generic one (the table's `covers` lists the generic ID, its model
/// the paper's).
#[test]
fn a_table_of_one_model_checks() {
    let dir = common::temp_dir("cli", "one-model-table");
    for id in ["A2", "N4-g1-a2.1-s4.0"] {
        let (code, out, err) = mms(&["analyze", id, "--format", "json"]);
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["format"], "mms-analysis-table");
        assert_eq!(v["covers"]["models"].as_array().unwrap().len(), 1);
        let file = dir.join(format!("{id}.json"));
        std::fs::write(&file, &out).unwrap();
        let (code, out, err) = mms(&["check", file.to_str().unwrap()]);
        assert_eq!(code, 0, "{id}: {err}");
        assert!(out.ends_with(": all valid\n"), "{out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A table analysed in slices (`--shard K/N`, as separate machines would)
/// and joined by `mms merge` is the table one run writes, byte for byte,
/// for every split; each slice checks on its own; a missing or doubled
/// slice, a slice of other settings and a malformed shard spec are refused
/// in one line, naming the classes or the file.
#[test]
fn sliced_tables_merge_into_the_whole_table() {
    let dir = common::temp_dir("cli", "shards");
    let (code, whole, err) = mms(&["analyze", "--masses", "3", "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let slice = |k: usize, n: usize| write_slice(&dir, k, n);
    for n in [1, 2, 3, 11] {
        // Given in reverse order: the merge puts the classes in order.
        let files: Vec<String> = (1..=n).rev().map(|k| slice(k, n)).collect();
        let mut args = vec!["merge"];
        args.extend(files.iter().map(String::as_str));
        let (code, merged, err) = mms(&args);
        assert_eq!(code, 0, "{n} slices: {err}");
        assert_eq!(merged, whole, "{n} slices");
    }
    let parts: Vec<String> = (1..=3).map(|k| slice(k, 3)).collect();
    let (code, out, err) = mms(&["check", &parts[1]]);
    assert_eq!(code, 0, "{err}");
    assert!(out.ends_with("all valid\n"), "{out}");
    let one_line = |args: &[&str], want: &str| {
        let (code, _, err) = mms(args);
        assert_eq!(code, 2, "{args:?}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(want), "{args:?}: {err}");
    };
    one_line(&["merge", &parts[0], &parts[2]], "gap: the classes of");
    one_line(
        &["merge", &parts[0], &parts[1], &parts[2], &parts[1]],
        "overlap",
    );
    let mut other: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&parts[2]).unwrap()).unwrap();
    other["engine_version"] = (other["engine_version"].as_u64().unwrap() + 1).into();
    let edited = dir.join("other-engine.json");
    std::fs::write(&edited, other.to_string()).unwrap();
    one_line(
        &["merge", &parts[0], &parts[1], edited.to_str().unwrap()],
        "the engine version differs",
    );
    one_line(
        &["merge", &parts[0], &whole_file(&dir, &whole)],
        "not a slice",
    );
    for spec in ["0/3", "4/3", "a/b", "-1/3"] {
        one_line(
            &[
                "analyze", "--masses", "3", "--format", "json", "--shard", spec,
            ],
            "expected K/N",
        );
    }
    one_line(
        &["analyze", "A2", "--format", "json", "--shard", "1/2"],
        "--masses",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `mms check --cache DIR` keeps a record of each verified model: slices
/// checked one by one, then the merged table, whose models are all taken
/// from the records with the line of a plain check; a record is never
/// taken for an entry that differs from it (a tampered table is rejected
/// as without records), and a damaged or stale record is reported and
/// the model checked again.
#[test]
fn a_check_resumes_from_its_records_and_never_takes_one_for_another_entry() {
    let dir = common::temp_dir("cli", "check-records");
    let records = dir.join("records");
    let records_arg = records.to_str().unwrap();
    let parts: Vec<String> = (1..=3).map(|k| write_slice(&dir, k, 3)).collect();
    for part in &parts {
        let (code, out, err) = mms(&["check", "--cache", records_arg, part]);
        assert_eq!(code, 0, "{part}: {err}");
        assert!(out.ends_with(": all valid\n"), "{out}");
    }
    let (code, merged, err) = mms(&["merge", &parts[0], &parts[1], &parts[2]]);
    assert_eq!(code, 0, "{err}");
    let whole = whole_file(&dir, &merged);
    let models = serde_json::from_str::<serde_json::Value>(&merged).unwrap()["models"]
        .as_array()
        .unwrap()
        .len();
    let (code, plain, err) = mms(&["check", &whole]);
    assert_eq!(code, 0, "{err}");
    let (code, recalled, err) = mms(&["check", "--jobs", "2", "--cache", records_arg, &whole]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        recalled,
        format!(
            "{}; {models} of {models} models by their records in {records_arg}\n",
            plain.trim_end()
        )
    );

    // A certificate's definite factor with its sign flipped: the entry is
    // no longer the recorded one, so it is checked, and rejected.
    let mut v: serde_json::Value = serde_json::from_str(&merged).unwrap();
    let model = v["models"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|m| {
            m["types"].as_array().unwrap().iter().any(|t| {
                t.get("certificate")
                    .and_then(|c| c["factors"].get(0))
                    .is_some_and(|f| f["kind"] == "definite")
            })
        })
        .unwrap();
    let factor = model["types"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find_map(|t| {
            let f = t.get_mut("certificate")?["factors"].get_mut(0)?;
            (f["kind"] == "definite").then_some(f)
        })
        .unwrap();
    factor["sign"] = serde_json::json!(-factor["sign"].as_i64().unwrap());
    let tampered = dir.join("tampered.json");
    std::fs::write(&tampered, v.to_string()).unwrap();
    let tampered = tampered.to_str().unwrap();
    let (code, _, without) = mms(&["check", tampered]);
    assert_eq!(code, 2);
    let (code, out, with) = mms(&["check", "--cache", records_arg, tampered]);
    assert_eq!((code, out.as_str()), (2, ""));
    assert_eq!(with, without);

    // A damaged record and a record of another checker version: each
    // named in a warning, its model checked again; the check still passes.
    let mut files: Vec<_> = std::fs::read_dir(&records)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), models);
    std::fs::write(&files[0], "{").unwrap();
    let mut stale: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&files[1]).unwrap()).unwrap();
    stale["fingerprint"] = "check record layout 0".into();
    std::fs::write(&files[1], stale.to_string()).unwrap();
    let (code, out, err) = mms(&["check", "--cache", records_arg, &whole]);
    assert_eq!(code, 0, "{err}");
    let left = models - 2;
    assert!(
        out.ends_with(&format!(
            "; {left} of {models} models by their records in {records_arg}\n"
        )),
        "{out}"
    );
    assert!(
        err.contains("not a check record") && err.contains("stale"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 2, "{err}");
    // Both were written again: the next check takes every model from them.
    let (code, out, err) = mms(&["check", "--cache", records_arg, &whole]);
    assert_eq!((code, err.as_str()), (0, ""));
    assert_eq!(out, recalled);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Slice `k` of `n` of the 3-mass table written into `dir`; its path.
fn write_slice(dir: &std::path::Path, k: usize, n: usize) -> String {
    let spec = format!("{k}/{n}");
    let (code, out, err) = mms(&[
        "analyze", "--masses", "3", "--format", "json", "--shard", &spec,
    ]);
    assert_eq!(code, 0, "{spec}: {err}");
    let file = dir.join(format!("slice-{k}-of-{n}.json"));
    std::fs::write(&file, out).unwrap();
    file.to_string_lossy().into_owned()
}

/// `text` written into `dir` as a file; its path.
fn whole_file(dir: &std::path::Path, text: &str) -> String {
    let file = dir.join("whole.json");
    std::fs::write(&file, text).unwrap();
    file.to_string_lossy().into_owned()
}

#[test]
fn sample_poses_two_cancelled_poles_as_a_pair_where_the_blocks_share_them() {
    // `AR` of N4-g2-a3.1-s3.2 (two of three poles cancelled) has an exact
    // witness in the 4-mass table. Left open, it is sampled on its single
    // cancellations, whose points all lie where the Jacobian drops rank
    // (none read), and with the pair posed, which reads it; the type is
    // counted once.
    let dir = std::env::temp_dir().join(format!("mms-sample-pairs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut v = json(&["analyze", "N4-g2-a3.1-s3.2", "--format", "json"]);
    let t = v["models"][0]["types"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|t| t["type"] == "AR")
        .unwrap();
    assert_eq!(t["status"], "possible");
    let o = t.as_object_mut().unwrap();
    o.remove("witness");
    o.insert("status".into(), "unknown".into());
    let file = dir.join("open.json");
    std::fs::write(&file, v.to_string()).unwrap();
    let (code, out, err) = mms(&["sample", file.to_str().unwrap(), "--starts", "2000"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("1 of the 1 unknown types were read at least once; 0 never."),
        "{out}"
    );
    let cells = out.split("## Limits").next().unwrap();
    let rows: Vec<&str> = cells.lines().filter(|l| l.starts_with("| N4-")).collect();
    assert_eq!(rows.len(), 2, "{out}");
    assert!(
        rows[0].contains("| 2 | 0 | - |") && rows[0].ends_with("| 0 | `AR` 0 |"),
        "{out}"
    );
    assert!(
        rows[1].contains("| 2 | 1 | - |") && !rows[1].ends_with("`AR` 0 |"),
        "{out}"
    );
    // AR has a witness, a limit of generic points: some possible generic
    // type gathers into it.
    let limit = out
        .lines()
        .find(|l| l.starts_with("| N4-g2-a3.1-s3.2 | `AR` |"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(!limit.ends_with("| - |"), "{limit}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sample_reads_a_type_left_open_and_resumes_from_its_cache() {
    // The 3-mass table with A2's R (a cancelled pole, possible by the
    // paper's Tab. 3) left unknown: points on the variety of one
    // cancellation read R, and no point reads a type the table certifies
    // impossible.
    let dir = std::env::temp_dir().join(format!("mms-sample-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut v = json(&["analyze", "--masses", "3", "--format", "json"]);
    let a2 = v["models"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|m| m["id"] == "A2")
        .unwrap();
    let r = a2["types"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|t| t["type"] == "R")
        .unwrap();
    let o = r.as_object_mut().unwrap();
    o.remove("witness");
    o.insert("status".into(), "unknown".into());
    let file = dir.join("open.json");
    std::fs::write(&file, v.to_string()).unwrap();
    let cache = dir.join("cache");
    let args = |jobs: &str| {
        vec![
            "sample".to_string(),
            file.to_str().unwrap().to_string(),
            "--starts".into(),
            "3000".into(),
            "--format".into(),
            "json".into(),
            "--jobs".into(),
            jobs.into(),
            "--cache".into(),
            cache.to_str().unwrap().to_string(),
        ]
    };
    let run = |jobs: &str| {
        let a = args(jobs);
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        let (code, out, err) = mms(&refs);
        assert_eq!(code, 0, "{err}");
        out
    };
    let first = run("1");
    let s: serde_json::Value = serde_json::from_str(&first).unwrap();
    assert_eq!(s.as_array().unwrap().len(), 1, "{first}");
    assert_eq!(s[0]["id"], "A2");
    let cell = &s[0]["cells"][0];
    assert_eq!(
        (cell["cell"]["cancelled"].as_u64(), cell["starts"].as_u64()),
        (Some(1), Some(3000))
    );
    assert!(cell["seen"]["R"].as_u64().unwrap() > 100, "{cell}");
    assert_eq!(s[0]["impossible_read"], serde_json::json!({}));
    // From the cache, and with two jobs: the same bytes.
    assert!(std::fs::read_dir(&cache).unwrap().count() == 1);
    assert_eq!(run("2"), first);
    // Bad input: no starts, a file that is no table.
    for bad in [
        vec!["sample", file.to_str().unwrap(), "--starts", "0"],
        vec!["sample", "/nonexistent/table.json"],
    ] {
        let (code, out, err) = mms(&bad);
        assert_eq!(code, 2, "{bad:?}: {err}");
        assert!(
            out.is_empty() && err.trim_end().lines().count() == 1,
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
