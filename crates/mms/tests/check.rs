//! The independent checker ([`mms::check`]) against the analysis of the
//! paper's eleven models: it accepts the prover's output, and rejects
//! tampered witnesses and certificates, naming the failing step.

use mms::analysis::{analyze, SearchLimits};
use mms::check::{check_analysis, check_file, check_file_on, CheckError, CheckReport};
use mms::table::{AnalysisTable, Covers, TableError, TableModel, TABLE_FORMAT_VERSION};
use mms::{Model, PAPER_IDS};
use serde_json::{json, Value};
use std::sync::OnceLock;

/// The table of the eleven paper models as `mms analyze --format json`
/// writes it (without the derived fields), as a JSON value to tamper with.
fn paper_file() -> &'static Value {
    static FILE: OnceLock<Value> = OnceLock::new();
    FILE.get_or_init(|| {
        let limits = SearchLimits::default();
        let models: Vec<TableModel> = PAPER_IDS
            .iter()
            .map(|(id, ..)| TableModel::new(analyze(&Model::from_id(id).unwrap(), &limits)))
            .collect();
        // The paper's eleven models are the eleven classes of three masses.
        AnalysisTable::new(Covers::Masses(3), models).to_value()
    })
}

fn check(v: &Value) -> Result<CheckReport, CheckError> {
    check_file(&v.to_string())
}

/// The JSON pointer of model `id`.
fn model_ptr(id: &str) -> String {
    let i = paper_file()["models"]
        .as_array()
        .unwrap()
        .iter()
        .position(|m| m["id"] == id)
        .unwrap_or_else(|| panic!("no model {id}"));
    format!("/models/{i}")
}

/// The JSON pointer of the verdict on type `t` of model `id`.
fn verdict_ptr(id: &str, t: &str) -> String {
    let m = model_ptr(id);
    let j = paper_file().pointer(&m).unwrap()["types"]
        .as_array()
        .unwrap()
        .iter()
        .position(|v| v["type"] == t)
        .unwrap_or_else(|| panic!("model {id} has no type {t}"));
    format!("{m}/types/{j}")
}

/// Pointers of every proof node (certificates and nested wall proofs).
fn proof_ptrs() -> Vec<String> {
    fn walk(p: &Value, ptr: String, out: &mut Vec<String>) {
        for (i, f) in p["factors"].as_array().unwrap().iter().enumerate() {
            if f["kind"] == "wall" {
                walk(&f["proof"], format!("{ptr}/factors/{i}/proof"), out);
            }
        }
        out.push(ptr);
    }
    let mut out = Vec::new();
    for (i, m) in paper_file()["models"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        for (j, v) in m["types"].as_array().unwrap().iter().enumerate() {
            if v["status"] == "impossible" {
                walk(
                    &v["certificate"],
                    format!("/models/{i}/types/{j}/certificate"),
                    &mut out,
                );
            }
        }
    }
    out
}

/// The first proof node whose open part has the given kind.
fn first_open(kind: &str) -> String {
    proof_ptrs()
        .into_iter()
        .find(|p| paper_file().pointer(p).unwrap()["open"]["kind"] == kind)
        .unwrap_or_else(|| panic!("no {kind} proof"))
}

/// Applies `f` to a copy of the paper file at `ptr` and checks it.
fn tampered(ptr: &str, f: impl FnOnce(&mut Value)) -> CheckError {
    let mut v = paper_file().clone();
    f(v.pointer_mut(ptr).unwrap_or_else(|| panic!("no {ptr}")));
    match check(&v) {
        Ok(r) => panic!("tampering at {ptr} was accepted: {r}"),
        Err(e) => e,
    }
}

fn status_count(status: &str) -> usize {
    paper_file()["models"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| m["types"].as_array().unwrap())
        .filter(|v| v["status"] == status)
        .count()
}

fn type_step(e: &CheckError) -> (&str, &str, &str) {
    match e {
        CheckError::Type {
            model,
            frf_type,
            step,
        } => (model, frf_type, step),
        other => panic!("expected a type-level error, got {other:?}"),
    }
}

#[test]
fn accepts_all_paper_models() {
    let r = check(paper_file()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.models, 11);
    assert_eq!(r.witnesses, status_count("possible"));
    assert_eq!(r.certificates, status_count("impossible"));
    assert_eq!(r.unknown, 0);
    assert_eq!(r.witnesses, 25);
    assert!(r.proofs >= r.certificates);
    assert_eq!(
        r.to_string(),
        format!(
            "checked 25 witnesses and {} certificates: all valid",
            r.certificates
        )
    );
}

#[test]
fn threads_change_neither_the_report_nor_the_error() {
    let text = paper_file().to_string();
    let one = check_file(&text).unwrap_or_else(|e| panic!("{e}"));
    for threads in [2, 3, 11, 16] {
        assert_eq!(
            check_file_on(&text, threads),
            Ok(one.clone()),
            "{threads} threads"
        );
    }
    // Two bad witnesses, in an early and a late model: every number of
    // threads names the first in the file's order, as one thread does.
    let mut v = paper_file().clone();
    v.pointer_mut(&verdict_ptr("A2", "R")).unwrap()["witness"]["m1"] = "17/3".into();
    let last = PAPER_IDS.last().unwrap().0;
    let t = v.pointer(&model_ptr(last)).unwrap()["types"]
        .as_array()
        .unwrap()
        .iter()
        .position(|t| t["status"] == "possible" && t.get("witness").is_some())
        .expect("a witness in the last model");
    v.pointer_mut(&format!("{}/types/{t}/witness", model_ptr(last)))
        .unwrap()
        .as_object_mut()
        .unwrap()
        .remove("m1");
    let text = v.to_string();
    let first = check_file(&text).unwrap_err();
    assert_eq!(type_step(&first).0, "A2", "{first}");
    for threads in [2, 3, 11] {
        assert_eq!(
            check_file_on(&text, threads),
            Err(first.clone()),
            "{threads} threads"
        );
    }
}

#[test]
fn check_analysis_takes_one_model() {
    let b2 = paper_file().pointer(&model_ptr("B2")).unwrap();
    let r = check_analysis(b2).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.models, 1);
    assert_eq!(r.witnesses, 9);
}

#[test]
fn wrong_witness_is_rejected() {
    // A2's R lives on the cancellation wall c12*m3 = c23*m1; moving m1
    // off it brings the antiresonance back.
    let e = tampered(&verdict_ptr("A2", "R"), |v| {
        v["witness"]["m1"] = "17/3".into();
    });
    let (model, t, step) = type_step(&e);
    assert_eq!((model, t), ("A2", "R"));
    assert!(step.starts_with("witness: the type there is"), "{e}");
    // A witness must give every undamped parameter, and only those.
    let e = tampered(&verdict_ptr("A2", "ARR"), |v| {
        v["witness"].as_object_mut().unwrap().remove("c23");
    });
    assert!(e.to_string().contains("no value for c23"), "{e}");
    let e = tampered(&verdict_ptr("A2", "ARR"), |v| {
        v["witness"]["d12"] = "1".into();
    });
    assert!(
        e.to_string().contains("d12 is not an undamped parameter"),
        "{e}"
    );
    let e = tampered(&verdict_ptr("A2", "ARR"), |v| {
        v["witness"]["m2"] = "-1".into();
    });
    assert!(e.to_string().contains("is not positive"), "{e}");
}

/// A2's type R at a point over Q(sqrt 2): c12 = m1 = sqrt 2, the rest 1,
/// where the zero c23/m3 = 1 is a pole too (the wall c12*m3 = c23*m1).
fn a2_algebraic_r() -> Value {
    json!({
        "minimal": "theta^2 - 2",
        "interval": ["1", "2"],
        "parameters": {"c12": "theta", "m1": "theta", "m2": "1", "c23": "1", "m3": "1"},
        "cancelled": ["1"],
    })
}

/// The paper file with A2's verdict on `t` replaced by an algebraic
/// witness `w`, checked.
fn with_algebraic(t: &str, w: Value) -> Result<CheckReport, CheckError> {
    let mut v = paper_file().clone();
    let verdict = v.pointer_mut(&verdict_ptr("A2", t)).unwrap();
    let o = verdict.as_object_mut().unwrap();
    o.remove("witness");
    o.insert("algebraic".into(), w);
    check(&v)
}

#[test]
fn algebraic_witnesses_are_checked_over_their_field() {
    // Accepted: the cancellation at 1 with the rest's poles read by exact
    // signs over Q(sqrt 2).
    with_algebraic("R", a2_algebraic_r()).unwrap_or_else(|e| panic!("{e}"));
    // Also with nothing posed: RAR at m3 = sqrt 2 (the zero 72/sqrt 2,
    // between the poles; the rational witness has m3 = 9/8).
    let rar = json!({
        "minimal": "theta^2 - 2", "interval": ["1", "2"],
        "parameters": {"c12": "88", "c23": "72", "m1": "2", "m2": "32", "m3": "theta"},
    });
    with_algebraic("RAR", rar.clone()).unwrap_or_else(|e| panic!("{e}"));
    let refused = |t: &str, w: Value, what: &str| {
        let e = with_algebraic(t, w).expect_err(what);
        let (model, ty, step) = type_step(&e);
        assert_eq!((model, ty), ("A2", t));
        assert!(step.starts_with("algebraic"), "{what}: {e}");
        step.to_string()
    };
    // The same point claimed for another type.
    let step = refused("ARR", rar.clone(), "another type");
    assert!(step.contains("the type there is RAR"), "{step}");
    // m1 off the wall: the posed pole no longer cancels.
    let mut off = a2_algebraic_r();
    off["parameters"]["m1"] = "theta + 1/10".into();
    let step = refused("R", off, "off the wall");
    assert!(step.contains("no root of the denominator"), "{step}");
    // A cancellation claimed where there is none.
    let mut elsewhere = a2_algebraic_r();
    elsewhere["cancelled"] = json!(["2"]);
    refused("R", elsewhere, "a cancellation elsewhere");
    // A multiplicity that is not there.
    let mut double = rar.clone();
    double["multiple"] = json!([["72/100", 2]]);
    refused("RAR", double, "a double zero that is not there");
    // An interval without the root, a reducible polynomial, a parameter
    // not positive at theta.
    let mut no_root = a2_algebraic_r();
    no_root["interval"] = json!(["2", "3"]);
    let step = refused("R", no_root, "no root in the interval");
    assert!(step.contains("does not isolate"), "{step}");
    let mut reducible = a2_algebraic_r();
    reducible["minimal"] = "theta^2 - 4".into();
    reducible["interval"] = json!(["1", "3"]);
    let step = refused("R", reducible, "reducible");
    assert!(step.contains("not irreducible"), "{step}");
    let mut negative = rar;
    negative["parameters"]["m2"] = "1 - theta".into();
    let step = refused("RAR", negative, "a negative mass");
    assert!(step.contains("not positive"), "{step}");
}

/// A2's type R isolated in a box: with c12 = c23 = m2 = 1 fixed and the
/// pole at 1 cancelled, the conditions `c23 - m3 = 0` and `1 - m1 m3 = 0`
/// have the one solution m1 = m3 = 1, where the denominator is
/// `(Omega - 1)(Omega - 3)` (by hand, from the paper's Den of A2).
fn a2_isolated_r() -> Value {
    json!({
        "fixed": {"c12": "1", "c23": "1", "m2": "1"},
        "free": {"m1": ["1023/1024", "1025/1024"], "m3": ["1023/1024", "1025/1024"]},
        "cancelled": ["1"],
        "partition": ["2", "4"],
    })
}

/// The paper file with A2's verdict on `t` replaced by an isolated
/// witness `w`, checked.
fn with_isolated(t: &str, w: Value) -> Result<CheckReport, CheckError> {
    with_isolated_on("A2", t, w)
}

/// The paper file with model `id`'s verdict on `t` replaced by an
/// isolated witness `w`, checked.
fn with_isolated_on(id: &str, t: &str, w: Value) -> Result<CheckReport, CheckError> {
    let mut v = paper_file().clone();
    let verdict = v.pointer_mut(&verdict_ptr(id, t)).unwrap();
    let o = verdict.as_object_mut().unwrap();
    o.remove("witness");
    o.insert("isolated".into(), w);
    check(&v)
}

#[test]
fn isolated_witnesses_are_checked_in_their_box() {
    with_isolated("R", a2_isolated_r()).unwrap_or_else(|e| panic!("{e}"));
    // With no partition point at all: the one pole is alone in (0, inf).
    let mut bare = a2_isolated_r();
    bare["partition"] = json!([]);
    with_isolated("R", bare).unwrap_or_else(|e| panic!("{e}"));
    // Posed by the numerator and the denominator themselves as factors,
    // with the trivial cofactors: accepted.
    let a2 = paper_file().pointer(&model_ptr("A2")).unwrap();
    let (num, den) = (a2["numerator"].clone(), a2["denominator"].clone());
    let mut posed = a2_isolated_r();
    posed["poses"] = json!([{
        "pole": 0, "factors": [num, den], "numerator": ["1", "0"], "denominator": ["0", "1"],
    }]);
    with_isolated("R", posed.clone()).unwrap_or_else(|e| panic!("{e}"));
    let refused = |t: &str, w: Value, what: &str| {
        let e = with_isolated(t, w).expect_err(what);
        let (model, ty, step) = type_step(&e);
        assert_eq!((model, ty), ("A2", t));
        assert!(step.starts_with("isolated"), "{what}: {e}");
        step.to_string()
    };
    let step = refused("ARR", a2_isolated_r(), "another type");
    assert!(step.contains("the type there is R"), "{step}");
    // A box beside the solution: Krawczyk's operator leaves it.
    let mut beside = a2_isolated_r();
    beside["free"]["m1"] = json!(["9/8", "5/4"]);
    let step = refused("R", beside, "a box without the solution");
    assert!(step.contains("Krawczyk"), "{step}");
    // A partition point on the other pole, 3.
    let mut on_pole = a2_isolated_r();
    on_pole["partition"] = json!(["3"]);
    let step = refused("R", on_pole, "a point on a root");
    assert!(step.contains("no one sign"), "{step}");
    // Cofactors that do not multiply out to the numerator.
    let mut forged = posed;
    forged["poses"][0]["numerator"] = json!(["2", "0"]);
    let step = refused("R", forged, "forged cofactors");
    assert!(step.contains("numerator is not"), "{step}");
    // A double zero claimed as well: more conditions than free parameters.
    let mut double = a2_isolated_r();
    double["multiple"] = json!([["2", 2]]);
    let step = refused("R", double, "a double zero that is not posed right");
    assert!(step.contains("conditions posed"), "{step}");
    // A parameter both fixed and free, one with neither, a box not positive.
    let mut both = a2_isolated_r();
    both["fixed"]["m1"] = "1".into();
    let step = refused("R", both, "fixed and free");
    assert!(step.contains("both fixed and free"), "{step}");
    let mut neither = a2_isolated_r();
    neither["fixed"].as_object_mut().unwrap().remove("m2");
    let step = refused("R", neither, "no value");
    assert!(step.contains("no value or range for m2"), "{step}");
    let mut negative = a2_isolated_r();
    negative["free"]["m3"] = json!(["-1", "2"]);
    let step = refused("R", negative, "a box not positive");
    assert!(step.contains("not positive"), "{step}");
}

/// B2's type C with its one pair of poles cancelled together, posed by
/// the blocks: `den = det(A) q_B` with `det(A) = m1 Omega - c1`, `q_B =
/// m2 m3 Omega - c23 (m2 + m3)`, and `num = -c23 det(A) + Omega q_B` (by
/// hand from the paper's Num and Den). With c23 = m2 = 1 fixed and the
/// pole at 2, `det(A)`, `q_B` and `num'` vanish there only at m1 = 2,
/// m3 = 1, c1 = 4, where num = (Omega - 2)^2 and den = 2 (Omega - 2)^2.
fn b2_double_c() -> Value {
    json!({
        "fixed": {"c23": "1", "m2": "1"},
        "free": {
            "c1": ["4095/1024", "4097/1024"],
            "m1": ["2047/1024", "2049/1024"],
            "m3": ["1023/1024", "1025/1024"],
        },
        "cancelled": ["2"],
        "poses": [{
            "pole": 0, "double": true,
            "factors": ["m1*Omega - c1", "m2*m3*Omega - c23*m2 - c23*m3"],
            "numerator": ["-c23", "Omega"],
            "denominator": ["m2*m3*Omega - c23*m2 - c23*m3", "0"],
        }],
        "partition": [],
    })
}

#[test]
fn a_pole_cancelled_twice_is_checked() {
    with_isolated_on("B2", "C", b2_double_c()).unwrap_or_else(|e| panic!("{e}"));
    let refused = |w: Value, what: &str| {
        let e = with_isolated_on("B2", "C", w).expect_err(what);
        let (model, ty, step) = type_step(&e);
        assert_eq!((model, ty), ("B2", "C"));
        assert!(step.starts_with("isolated"), "{what}: {e}");
        step.to_string()
    };
    // Claimed once only: two conditions for three free parameters.
    let mut once = b2_double_c();
    once["poses"][0]["double"] = false.into();
    let step = refused(once, "cancelled once");
    assert!(step.contains("conditions posed"), "{step}");
    // Posed by the numerator and the denominator themselves, with the
    // trivial cofactors: both vanish at the pole, but the denominator is
    // no constant times their product, so no double root follows.
    let b2 = paper_file().pointer(&model_ptr("B2")).unwrap();
    let mut loose = b2_double_c();
    loose["poses"][0]["factors"] = json!([b2["numerator"], b2["denominator"]]);
    loose["poses"][0]["numerator"] = json!(["1", "0"]);
    loose["poses"][0]["denominator"] = json!(["0", "1"]);
    let step = refused(loose, "a denominator not the factors' product");
    assert!(step.contains("not a constant times f0 f1"), "{step}");
    // The pair claimed at another pole: the box holds no solution there.
    let mut elsewhere = b2_double_c();
    elsewhere["cancelled"] = json!(["3"]);
    let step = refused(elsewhere, "another pole");
    assert!(step.contains("Krawczyk"), "{step}");
}

#[test]
fn flipped_multiplier_is_rejected() {
    let ptr = first_open("sign_conditions");
    let e = tampered(&ptr, |p| {
        let case = &mut p["open"]["cases"][0];
        let i = case["multipliers"]
            .as_array()
            .unwrap()
            .iter()
            .position(|m| m != "0")
            .unwrap();
        let m: poly::Poly = case["multipliers"][i].as_str().unwrap().parse().unwrap();
        case["multipliers"][i] = (-m).to_string().into();
    });
    let (_, _, step) = type_step(&e);
    assert!(step.starts_with("sign_conditions case ["), "{e}");
    assert!(step.contains("has a negative coefficient"), "{e}");
}

#[test]
fn weakened_combination_is_rejected() {
    // Dropping one multiplier of a tight combination leaves a positive
    // coefficient (the bug once in the prover's rescaling of multipliers).
    let ptr = first_open("sign_conditions");
    let e = tampered(&ptr, |p| {
        let case = &mut p["open"]["cases"][0];
        let i = case["multipliers"]
            .as_array()
            .unwrap()
            .iter()
            .position(|m| m != "0")
            .unwrap();
        case["multipliers"][i] = "0".into();
    });
    let (_, _, step) = type_step(&e);
    assert!(
        step.contains("combination has a positive coefficient")
            || step.contains("no strict condition has a nonzero multiplier"),
        "{e}"
    );
}

#[test]
fn tampered_condition_is_rejected() {
    let ptr = first_open("sign_conditions");
    let e = tampered(&ptr, |p| {
        let c = &mut p["open"]["cases"][0]["conditions"][0];
        c["derived"] = "c1 + 1".into();
    });
    assert!(
        e.to_string().contains("derived is c1 + 1, the rule gives"),
        "{e}"
    );
    // An assignment left out.
    let e = tampered(&ptr, |p| {
        p["open"]["cases"].as_array_mut().unwrap().pop();
    });
    assert!(e.to_string().contains("has no case"), "{e}");
}

#[test]
fn altered_definiteness_sign_is_rejected() {
    let ptr = verdict_ptr("A2", "RRA");
    let e = tampered(&ptr, |v| {
        let f = &mut v["certificate"]["factors"][0];
        assert_eq!(f["kind"], "definite");
        f["sign"] = json!(-1);
    });
    let (model, t, step) = type_step(&e);
    assert_eq!((model, t), ("A2", "RRA"));
    assert!(
        step.starts_with("factor 0 (c12) definite: no_subtraction"),
        "{e}"
    );
    // A completed square whose inner argument does not hold.
    let e = tampered(&ptr, |v| {
        let factors = v["certificate"]["factors"].as_array_mut().unwrap();
        let f = factors
            .iter_mut()
            .find(|f| f["definiteness"]["method"] == "completed_square")
            .unwrap();
        f["definiteness"]["var"] = "m1".into();
    });
    assert!(
        e.to_string().contains("completed_square: ") && e.to_string().contains(" m1"),
        "{e}"
    );
}

#[test]
fn dropped_factor_is_rejected() {
    let e = tampered(&verdict_ptr("A2", "RRA"), |v| {
        v["certificate"]["factors"]
            .as_array_mut()
            .unwrap()
            .remove(0);
    });
    let (_, _, step) = type_step(&e);
    assert!(step.starts_with("critical polynomial: "), "{e}");
    assert!(step.contains("is not covered by the factors"), "{e}");
}

/// A proof may leave its `needs_cancellation` factors unlisted (six-mass
/// discriminant factors are too large to write) if it says so: the checker
/// then shows what the listed factors leave coprime to every resultant of
/// the parts and boundary polynomial. Leaving out a factor of another role
/// under that claim, or claiming it where the type has every pole, fails.
#[test]
fn unlisted_factors_must_need_a_cancellation() {
    let drop_kind = |p: &mut Value, kind: &str| {
        let list = p["factors"].as_array_mut().unwrap();
        let before = list.len();
        list.retain(|f| f["kind"] != kind);
        assert!(list.len() < before, "no {kind} factor");
        p["unlisted"] = json!("needs_cancellation");
    };
    let has = |p: &str, kind: &str| {
        paper_file().pointer(p).unwrap()["factors"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f["kind"] == kind)
    };
    let counting: Vec<String> = proof_ptrs()
        .into_iter()
        .filter(|p| has(p, "needs_cancellation"))
        .collect();
    assert!(!counting.is_empty());
    // Every such proof holds with those factors unlisted.
    let mut v = paper_file().clone();
    for p in &counting {
        drop_kind(v.pointer_mut(p).unwrap(), "needs_cancellation");
    }
    let full = check(paper_file()).unwrap();
    let r = check(&v).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.to_string(), full.to_string());

    // Without the claim, the factors left out leave a critical polynomial
    // uncovered.
    let e = tampered(&counting[0], |p| {
        drop_kind(p, "needs_cancellation");
        p.as_object_mut().unwrap().remove("unlisted");
    });
    assert!(
        type_step(&e).2.contains("is not covered by the factors"),
        "{e}"
    );

    // A definite boundary factor left out with them is not coprime to the
    // boundary polynomials.
    let e = tampered(&counting[0], |p| {
        drop_kind(p, "needs_cancellation");
        drop_kind(p, "definite");
    });
    let step = type_step(&e).2;
    assert!(
        step.contains("the unlisted factors (needs_cancellation)"),
        "{e}"
    );
    assert!(step.contains("is not shown coprime"), "{e}");

    // A factor that cancels a pole may not be left out as needing a
    // cancellation; nor can the claim stand when the type has every pole.
    let cancelling = proof_ptrs()
        .into_iter()
        .find(|p| has(p, "needs_no_cancellation"))
        .expect("a proof with a needs_no_cancellation factor");
    let e = tampered(&cancelling, |p| drop_kind(p, "needs_no_cancellation"));
    assert!(
        type_step(&e)
            .2
            .contains("not fewer than the stratum's denominator degree"),
        "{e}"
    );

    // A cancellation wall left out under the claim: it divides a resultant.
    let (ptr, wall) = counting
        .iter()
        .filter(|p| p.ends_with("/certificate"))
        .find_map(|p| {
            let m: usize = p.split('/').nth(2)?.parse().ok()?;
            let critical = paper_file()["models"][m]["critical"].as_array()?;
            let factors = paper_file().pointer(p)?["factors"].as_array()?;
            let i = factors.iter().position(|f| {
                f["kind"] == "wall"
                    && critical
                        .iter()
                        .any(|c| c["factor"] == f["factor"] && c["cancels"] == true)
            })?;
            Some((p.clone(), i))
        })
        .expect("a counting proof with a cancellation wall");
    let e = tampered(&ptr, |p| {
        p["factors"].as_array_mut().unwrap().remove(wall);
        drop_kind(p, "needs_cancellation");
    });
    assert!(type_step(&e).2.contains("is not shown coprime"), "{e}");

    let e = tampered(&counting[0], |p| p["unlisted"] = json!("definite"));
    // The typed reader refuses it before the check, naming the place.
    assert!(e.to_string().contains("unknown variant `definite`"), "{e}");
}

#[test]
fn certificate_for_a_possible_type_is_rejected() {
    // Every certificate of every model, relabelled as one of the model's
    // possible types, must fail: otherwise the checker would accept a
    // proof of something false.
    let file = paper_file();
    for m in file["models"].as_array().unwrap() {
        let types = m["types"].as_array().unwrap();
        let possible: Vec<&Value> = types.iter().filter(|v| v["status"] == "possible").collect();
        for v in types.iter().filter(|v| v["status"] == "impossible") {
            for p in &possible {
                let mut model = m.clone();
                let mut forged = v.clone();
                forged["type"] = p["type"].clone();
                model["types"] = json!([forged]);
                let r = check_analysis(&model);
                assert!(
                    r.is_err(),
                    "model {}: the certificate of {} was accepted for {}",
                    m["id"],
                    v["type"],
                    p["type"]
                );
            }
        }
    }
    // The brief's example: A2's certificates do not prove ARR impossible.
    let e = tampered(&verdict_ptr("A2", "RRA"), |v| v["type"] = "ARR".into());
    let (model, t, _) = type_step(&e);
    assert_eq!((model, t), ("A2", "ARR"));
}

#[test]
fn regions_samples_are_recomputed() {
    let ptr = first_open("regions");
    let e = tampered(&ptr, |p| p["open"]["samples"][0]["type"] = "RARA".into());
    assert!(
        e.to_string()
            .contains("regions: sample 0: the type there is"),
        "{e}"
    );
    // A sample moved across its wall.
    let ptr = proof_ptrs()
        .into_iter()
        .find(|p| paper_file().pointer(p).unwrap()["open"]["var"].is_string())
        .unwrap();
    let e = tampered(&ptr, |p| {
        let x = p["open"]["var"].as_str().unwrap().to_string();
        p["open"]["samples"][0]["point"][x] = "1000000".into();
    });
    assert!(e.to_string().contains("is not below wall 0"), "{e}");
}

#[test]
fn descartes_counts_are_recomputed() {
    let ptr = first_open("descartes");
    let e = tampered(&ptr, |p| {
        let v = p["open"]["sign_changes"].as_u64().unwrap();
        p["open"]["sign_changes"] = json!(v + 2);
    });
    assert!(e.to_string().contains("descartes: the file says"), "{e}");
}

#[test]
fn wall_substitution_must_match_its_factor() {
    let ptr = proof_ptrs()
        .into_iter()
        .find(|p| p.ends_with("/proof"))
        .expect("a nested wall proof");
    let parent = ptr.trim_end_matches("/proof").to_string();
    let e = tampered(&parent, |f| {
        let beta: poly::Poly = f["substitution"]["beta"].as_str().unwrap().parse().unwrap();
        f["substitution"]["beta"] = (&beta + &poly::Poly::int(1)).to_string().into();
    });
    assert!(
        e.to_string().contains("is not a constant multiple of"),
        "{e}"
    );
    // A wall proof for a different stratum.
    let e = tampered(&ptr, |p| p["stratum"] = json!([]));
    assert!(e.to_string().contains("the stratum is [], expected"), "{e}");
}

#[test]
fn transfer_function_is_rederived() {
    let e = tampered(&model_ptr("A2"), |m| {
        m["numerator"] = "-Omega*c12*m2 + c12*c23".into();
    });
    match &e {
        CheckError::Model { model, step } => {
            assert_eq!(model, "A2");
            assert!(step.starts_with("transfer function: the numerator"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    // A constant factor, a sign in particular, is fine.
    let mut v = paper_file().clone();
    let m = v.pointer_mut(&model_ptr("A2")).unwrap();
    let den: poly::Poly = m["denominator"].as_str().unwrap().parse().unwrap();
    m["denominator"] = den.scale(&poly::Rat::from(-3)).to_string().into();
    check(&v).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn malformed_input_names_the_key() {
    assert!(matches!(
        check_file("{"),
        Err(CheckError::Table(TableError::Json(_)))
    ));
    let e = check_file("{}").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("format \"\": not an analysis table"),
        "{e}"
    );
    let mut v = paper_file().clone();
    v.as_object_mut().unwrap().remove("models");
    let e = check(&v).unwrap_err();
    assert!(e.to_string().contains("missing field `models`"), "{e}");
    let e = tampered(&verdict_ptr("A1", "AARR"), |v| {
        v.as_object_mut().unwrap().remove("certificate");
    });
    assert!(e.to_string().contains("missing key \"certificate\""), "{e}");
    let e = tampered(&verdict_ptr("A1", "AARR"), |v| {
        v["certificate"]["open"]
            .as_object_mut()
            .unwrap()
            .remove("kind");
    });
    assert!(e.to_string().contains("missing field `kind`"), "{e}");
    let e = tampered(&model_ptr("A1"), |m| {
        m.as_object_mut().unwrap().remove("denominator");
    });
    assert!(e.to_string().contains("missing field `denominator`"), "{e}");
    let e = tampered(&verdict_ptr("A1", "AARR"), |v| v["type"] = "AXR".into());
    assert!(e.to_string().contains("not an FRF type"), "{e}");
}

/// A certificate of `kind` moved onto the verdict at `to` (marked
/// impossible there) must be rejected with a message containing `why`.
fn moved_certificate_is_rejected(kind: &str, to: &str, why: &str) {
    let from = proof_ptrs()
        .into_iter()
        .find(|p| paper_file().pointer(p).unwrap()["open"]["kind"] == kind)
        .unwrap_or_else(|| panic!("no {kind} certificate"));
    let cert = paper_file().pointer(&from).unwrap().clone();
    let e = tampered(to, |v| {
        v["status"] = "impossible".into();
        v["witness"] = Value::Null;
        v["certificate"] = cert;
    });
    let (_, _, step) = type_step(&e);
    assert!(step.contains(why), "{step}");
}

#[test]
fn simple_resonance_certificate_needs_a_multiple_resonance() {
    // B2 (gap 1, two blocks) excludes its R^2 types by the theorem; on a
    // type without a multiple resonance the premise does not apply.
    moved_certificate_is_rejected(
        "simple_resonances",
        &verdict_ptr("B2", "AARR"),
        "the type has no multiple resonance",
    );
}

#[test]
fn collocated_certificate_needs_collocation_and_a_non_modal_type() {
    // C3 is collocated and shows ARAR: (AR)^k is what the theorem allows.
    moved_certificate_is_rejected(
        "collocated_modes",
        &verdict_ptr("C3", "ARAR"),
        "of the form (AR)^k",
    );
    // A2 is not collocated: its ARR may not borrow the argument.
    moved_certificate_is_rejected(
        "collocated_modes",
        &verdict_ptr("A2", "ARR"),
        "not collocated",
    );
}

/// The pole-sign certificates of a 4-mass model whose denominator is one
/// block (N4-g3-a4.1-s4.2: m1-m2-m3 grounded, m4 alone behind the gap).
fn n4_block_model() -> &'static Value {
    static FILE: OnceLock<Value> = OnceLock::new();
    FILE.get_or_init(|| {
        let m = Model::from_id("N4-g3-a4.1-s4.2").unwrap();
        let a = analyze(&m, &SearchLimits::default());
        serde_json::to_value(a).unwrap()
    })
}

#[test]
fn pole_sign_certificates_are_checked_and_tampering_rejected() {
    let model = n4_block_model();
    let types = model["types"].as_array().unwrap();
    let pole_signs: Vec<&Value> = types
        .iter()
        .filter(|v| v["status"] == "impossible" && v["certificate"]["open"]["kind"] == "pole_signs")
        .collect();
    // The strata leave these undecided; the pole signs settle them.
    assert!(pole_signs.len() >= 50, "{}", pole_signs.len());
    let r = check_analysis(model).unwrap();
    assert_eq!(r.unknown, 0, "{r}");

    // On a possible type the parity argument must fail.
    let cert = pole_signs[0]["certificate"].clone();
    let possible = types.iter().find(|v| v["status"] == "possible").unwrap();
    let mut forged = possible.clone();
    forged["status"] = "impossible".into();
    forged["witness"] = Value::Null;
    forged["certificate"] = cert.clone();
    let mut m = model.clone();
    m["types"] = json!([forged]);
    let e = check_analysis(&m).unwrap_err();
    assert!(
        e.to_string()
            .contains("pole_signs: the type fits the placement"),
        "{e}"
    );

    // A remainder factor changed: the product no longer is the remainder.
    let mut bad = pole_signs[0].clone();
    let f = &mut bad["certificate"]["open"]["remainder_factors"][0]["exponent"];
    *f = json!(f.as_u64().unwrap() + 1);
    let mut m = model.clone();
    m["types"] = json!([bad]);
    let e = check_analysis(&m).unwrap_err();
    assert!(e.to_string().contains("pole_signs: "), "{e}");
}

/// A second route to the pole-sign verdicts: exact classification at
/// random rational points never shows a type they exclude (and does show
/// the model's possible types).
#[test]
fn pole_sign_verdicts_agree_with_random_points() {
    let model = n4_block_model();
    let excluded: Vec<String> = model["types"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "impossible" && v["certificate"]["open"]["kind"] == "pole_signs")
        .map(|v| v["type"].as_str().unwrap().to_string())
        .collect();
    let m = Model::from_id("N4-g3-a4.1-s4.2").unwrap();
    let seen = observed_types(&m, 41, 300);
    if let Some((t, point)) = seen.iter().find(|(t, _)| excluded.contains(t)) {
        panic!("{t} at {point:?}");
    }
    assert!(
        seen.contains_key("ARARRA") && seen.contains_key("ARRARA"),
        "{seen:?}"
    );
}

/// The analysis of a 4-mass model whose denominator spans two blocks
/// (N4-g2-a3.1-s3.2: m1-m2 grounded, m3-m4 free behind the gap; the
/// actuator between m3 and m1 and the sensor between m3 and m2 reach
/// across it).
fn n4_two_block_model() -> &'static Value {
    static FILE: OnceLock<Value> = OnceLock::new();
    FILE.get_or_init(|| {
        let m = Model::from_id("N4-g2-a3.1-s3.2").unwrap();
        serde_json::to_value(analyze(&m, &SearchLimits::default())).unwrap()
    })
}

fn with_kind<'a>(model: &'a Value, kind: &str) -> Vec<&'a Value> {
    model["types"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "impossible" && v["certificate"]["open"]["kind"] == kind)
        .collect()
}

#[test]
fn block_pole_sign_certificates_are_checked_and_tampering_rejected() {
    let model = n4_two_block_model();
    let certified = with_kind(model, "block_pole_signs");
    // The strata and the one-block pole signs leave these undecided.
    assert!(certified.len() >= 40, "{}", certified.len());
    check_analysis(model).unwrap();
    let cert = certified[0]["certificate"].clone();
    let blocks = cert["open"]["blocks"].as_array().unwrap();
    assert_eq!(blocks.len(), 2, "{cert}");
    let with_cert = |mut v: Value, cert: &Value| {
        v["status"] = "impossible".into();
        v["witness"] = Value::Null;
        v["certificate"] = cert.clone();
        let mut m = model.clone();
        m["types"] = json!([v]);
        check_analysis(&m).unwrap_err().to_string()
    };
    let types = model["types"].as_array().unwrap();

    // On a possible type with every resonance the parities must fit.
    let full = types
        .iter()
        .filter(|v| v["status"] == "possible")
        .find(|v| v["type"].as_str().unwrap().matches('R').count() == 3)
        .unwrap();
    let e = with_cert(full.clone(), &cert);
    assert!(
        e.contains("block_pole_signs: the type fits the configuration"),
        "{e}"
    );

    // A numerator n_B changed: it is not the block's term.
    let mut bad = cert.clone();
    bad["open"]["blocks"][0]["numerator"] = json!("2");
    let e = with_cert(certified[0].clone(), &bad);
    assert!(e.contains("not c_B^T adj(P_B) b_B"), "{e}");

    // Found by review: n_A + t d_A and n_B - t d_B keep the sum of the
    // terms (the identity) but not the terms, on which collocation and the
    // signs rest; the checker recomputes each term.
    let m = Model::from_id("N4-g2-a3.1-s3.2").unwrap();
    let (mass, stiff) = (m.mass_matrix(), m.stiffness_matrix());
    let block_det = |idx: &[usize]| -> poly::Poly {
        let om = poly::Poly::var(mms::OMEGA);
        let p: Vec<Vec<poly::Poly>> = idx
            .iter()
            .map(|&i| {
                idx.iter()
                    .map(|&j| &stiff[i][j] - &(&om * &mass[i][j]))
                    .collect()
            })
            .collect();
        poly::det(&p)
    };
    let masses = |k: usize| -> Vec<usize> {
        blocks[k]["masses"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize - 1)
            .collect()
    };
    let n = |k: usize| {
        blocks[k]["numerator"]
            .as_str()
            .unwrap()
            .parse::<poly::Poly>()
            .unwrap()
    };
    let mut bad = cert.clone();
    bad["open"]["blocks"][0]["numerator"] = json!((&n(0) + &block_det(&masses(0))).to_string());
    bad["open"]["blocks"][1]["numerator"] = json!((&n(1) - &block_det(&masses(1))).to_string());
    let e = with_cert(certified[0].clone(), &bad);
    assert!(e.contains("not c_B^T adj(P_B) b_B"), "{e}");

    // A factor's exponent changed: the product is not what it claims.
    let mut bad = cert.clone();
    let b = blocks
        .iter()
        .position(|b| !b["factors"].as_array().unwrap().is_empty())
        .unwrap();
    let f = &mut bad["open"]["blocks"][b]["factors"][0]["exponent"];
    *f = json!(f.as_u64().unwrap() + 1);
    let e = with_cert(certified[0].clone(), &bad);
    assert!(e.contains("the factors multiply to"), "{e}");

    // A block listed with no term: its poles would all cancel (found by
    // review: with a zero numerator the identity and the factors hold
    // trivially).
    let mut bad = cert.clone();
    bad["open"]["blocks"][0]["numerator"] = json!("0");
    bad["open"]["blocks"][0]["unit"] = json!("0");
    bad["open"]["blocks"][0]["factors"] = json!([]);
    let e = with_cert(certified[0].clone(), &bad);
    assert!(e.contains("numerator: zero"), "{e}");

    // Blocks that are not blocks of the chain.
    let mut bad = cert.clone();
    bad["open"]["blocks"][0]["masses"] = json!([1, 2, 3]);
    let e = with_cert(certified[0].clone(), &bad);
    assert!(e.contains("not a block of the chain"), "{e}");
}

/// A second route to the block pole-sign verdicts, and to the one-block
/// ones the minors' interlacing adds: exact classification at random
/// rational points never shows a type they exclude.
#[test]
fn block_pole_sign_verdicts_agree_with_random_points() {
    let free_chain = Model::from_id("N4-g0-a1.0-s2.0").unwrap();
    let free_chain = serde_json::to_value(analyze(&free_chain, &SearchLimits::default())).unwrap();
    for (id, model, seed) in [
        ("N4-g2-a3.1-s3.2", n4_two_block_model(), 43),
        ("N4-g0-a1.0-s2.0", &free_chain, 47),
    ] {
        let excluded: Vec<String> = with_kind(model, "block_pole_signs")
            .iter()
            .map(|v| v["type"].as_str().unwrap().to_string())
            .collect();
        assert!(!excluded.is_empty(), "{id}");
        let m = Model::from_id(id).unwrap();
        let seen = observed_types(&m, seed, 300);
        if let Some((t, point)) = seen.iter().find(|(t, _)| excluded.contains(t)) {
            panic!("{id}: {t} at {point:?}");
        }
        assert!(seen.len() >= 2, "{id}: {seen:?}");
        // And the checker's own enumeration: a certificate moved onto a
        // type that occurs must be rejected.
        let cert = with_kind(model, "block_pole_signs")[0]["certificate"].clone();
        for t in seen.keys() {
            let forged = json!({"type": t, "status": "impossible", "certificate": cert});
            let mut m = model.clone();
            m["types"] = json!([forged]);
            let e = check_analysis(&m).expect_err(t);
            assert!(
                e.to_string().contains("fits the configuration"),
                "{id} {t}: {e}"
            );
        }
    }
}

/// The free chain m1-m2-m3-m4 driven at m1 and seen at m2: the zeros are
/// the eigenvalues of m3-m4 with m2 held (`num = c12 * det(K_34 - Omega
/// M_34)`). Together with m1 held they are the eigenvalues of the chain
/// without m2, which interlace the chain's one per gap between poles
/// (Cauchy), so two zeros never share a gap: RAARR, AARRR, RRAAR and
/// RRRAA are out. Parities alone cannot show it: RAARR has an even count
/// in every gap, as a type with no zero at all.
#[test]
fn end_runs_take_distinct_gaps() {
    let (_, a) = analysis_of("N4-g0-a1.0-s2.0");
    assert_impossible(&a, &["RAARR", "AARRR", "RRAAR", "RRRAA"]);
    check_analysis(&a).unwrap();
}

/// Double antiresonances are measure-zero: the root-condition search
/// builds them exactly. The witness's numerator has a repeated positive
/// root (its gcd with its derivative, recomputed here), and the checker
/// classifies the witness as the type.
#[test]
fn double_antiresonances_get_exact_witnesses() {
    use poly::{gcd, Rat};
    let (m, a) = analysis_of("N4-g1-a2.1-s3.1");
    check_analysis(&a).unwrap();
    let doubles: Vec<&Value> = a["types"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "possible" && v["type"].as_str().unwrap().contains("A^2"))
        .collect();
    // Before the search only A^2RR and RRA^2 (on cancellation walls).
    assert!(doubles.len() >= 8, "{}", doubles.len());
    let tf = m.undamped_tf();
    for v in doubles {
        let mut num = tf.num.clone();
        for (p, x) in v["witness"].as_object().unwrap() {
            num = num.subs(p, &x.as_str().unwrap().parse::<Rat>().unwrap());
        }
        let g = gcd(&num, &num.derivative(mms::OMEGA));
        assert!(g.degree(mms::OMEGA) >= 1, "{}: {num}", v["type"]);
        // One double root, positive: g = a*Omega + b with a*b < 0.
        assert_eq!(g.degree(mms::OMEGA), 1, "{}: {g}", v["type"]);
        let at_zero = g.subs(mms::OMEGA, &Rat::ZERO).as_constant().unwrap();
        let lead = g
            .coeffs_in(mms::OMEGA)
            .last()
            .unwrap()
            .as_constant()
            .unwrap();
        assert!(at_zero.signum() * lead.signum() < 0, "{}: {g}", v["type"]);
    }
}

/// The exact type at `n` random rational points (log-uniform over about
/// `[1/64, 64]`, three decimals), with the first point showing each.
fn observed_types(
    m: &Model,
    seed: u64,
    n: usize,
) -> std::collections::BTreeMap<String, std::collections::BTreeMap<String, poly::Rat>> {
    let tf = m.undamped_tf();
    let mut rng = mms::xorshift::XorShift::new(seed);
    let mut seen = std::collections::BTreeMap::new();
    for _ in 0..n {
        let point: std::collections::BTreeMap<String, poly::Rat> = m
            .undamped_parameters()
            .into_iter()
            .map(|p| {
                let v = rng.log_uniform(1.0 / 64.0, 64.0);
                let r = poly::Rat::new(((v * 1000.0).round() as i64).into(), 1000.into());
                (p, r)
            })
            .collect();
        let t = mms::analysis::frf_type_at(&tf.num, &tf.den, mms::OMEGA, &point)
            .unwrap()
            .to_string();
        seen.entry(t).or_insert(point);
    }
    seen
}

/// A model and its analysis as JSON.
fn analysis_of(id: &str) -> (Model, Value) {
    let m = Model::from_id(id).unwrap();
    let a = serde_json::to_value(analyze(&m, &SearchLimits::default())).unwrap();
    (m, a)
}

/// The verdict on type `t` in an analysis.
fn verdict<'a>(a: &'a Value, t: &str) -> &'a Value {
    a["types"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["type"] == t)
        .unwrap()
}

/// Every type of `types` is certified impossible in the analysis `a`.
fn assert_impossible(a: &Value, types: &[&str]) {
    for t in types {
        assert_eq!(verdict(a, t)["status"], "impossible", "{t}");
    }
}

/// The generic types (simple, every resonance) a model's analysis finds
/// possible.
fn generic_possible(a: &Value) -> Vec<String> {
    let mut v: Vec<String> = a["types"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "possible")
        .map(|v| v["type"].as_str().unwrap().to_string())
        .filter(|t| !t.contains('^') && t.matches('R').count() == 3)
        .collect();
    v.sort();
    v
}

/// The free chain driven at m2 and seen at m3: `num = c23 (c12 - Omega
/// m1)(c34 - Omega m4)`, zeros `c12/m1` and `c34/m4`, the eigenvalues of
/// the runs m1 and m4 together. Cauchy for their union (two masses of
/// four): its larger eigenvalue is at least the chain's second (`lambda_2
/// <= max(c12/m1, c34/m4)`, Courant-Fischer on the vectors supported on
/// m1 and m4), its smaller at most the third. So both zeros never lie
/// below the first resonance or above the second; each run alone only
/// lies somewhere between the rigid-body 0 and the top resonance.
#[test]
fn separated_runs_interlace_together() {
    let (_, a) = analysis_of("N4-g0-a2.0-s3.0");
    for t in ["AARRR", "A^2RRR", "RRAAR", "RRA^2R"] {
        let v = verdict(&a, t);
        assert_eq!(v["status"], "impossible", "{t}");
        assert_eq!(v["certificate"]["open"]["kind"], "block_pole_signs", "{t}");
    }
    // The one zero per gap the union allows: found.
    assert_eq!(generic_possible(&a), ["ARARR", "ARRAR", "RAARR", "RARAR"]);
    check_analysis(&a).unwrap();
}

/// N4-g1-a2.1-s4.1: m1 grounded by c1 behind the gap, the free chain
/// m2-m3-m4 in front, the actuator between m2 and m1, the sensor between
/// m4 and m1. By hand: `c^T P^-1 b = 1/(c1 - Omega m1) - k/(Omega (Omega -
/// mu1)(Omega - mu2))` with `k > 0` and `mu1 < mu2` the chain's
/// eigenvalues, so the zeros are where the cubic `Omega (Omega - mu1)
/// (Omega - mu2)` meets the falling line `a (lambda - Omega)`, `lambda =
/// c1/m1`, `a = k m1`. The cubic is positive below `mu1`, negative up to
/// `mu2`, positive above; the line positive below `lambda`: wherever the
/// two have opposite signs (both block terms one sign) there is no zero,
/// and two zeros above `mu2` would make their sum, `mu1 + mu2`, too large.
/// Going through the three orders of `lambda` the generic types are
/// exactly these six; `AAARRR` (three zeros below `lambda < mu1`, which
/// needs `mu2 < 2 mu1`) is rare enough that only the violation search
/// finds it.
#[test]
fn two_block_generic_types_match_the_hand_derivation() {
    let (_, a) = analysis_of("N4-g1-a2.1-s4.1");
    assert_eq!(
        generic_possible(&a),
        [
            "AAARRR",
            "AARRAR",
            "ARRAAR",
            "ARRR (nm)",
            "RRAAAR",
            "RRAR (nm)"
        ]
    );
    // The rest of the generic types with three resonances are certified.
    assert_impossible(&a, &["ARAARR", "ARRRAA", "RAARAR", "RRARAA"]);
    check_analysis(&a).unwrap();
}

/// N4-g3-a4.1-s4.3: the grounded chain m1-m2-m3 and the lone free m4,
/// actuator between m4 and m1, sensor between m4 and m3. By hand: `c^T
/// P^-1 b = c12 c23 / det P_L - 1/(Omega m4)`. Below the first pole both
/// terms rise (`det P_L` is a product of positive falling factors there;
/// `-1/(Omega m4)` rises everywhere), so one simple zero at most, and the
/// parities make it exactly one; between the first and second pole and
/// above the third both terms are negative: no zero. Three zeros in all
/// leave `ARRAAR` and `ARRR (nm)`; `AAARRR` and the triple or double zero
/// below the first pole are certified impossible.
#[test]
fn monotone_terms_allow_one_zero_per_gap() {
    let (m, a) = analysis_of("N4-g3-a4.1-s4.3");
    assert_eq!(generic_possible(&a), ["ARRAAR", "ARRR (nm)"]);
    assert_impossible(
        &a,
        &["AAARRR", "A^3RRR", "AA^2RRR", "A^2ARRR", "ARAARR", "ARRRAA"],
    );
    check_analysis(&a).unwrap();
    // The checker's own gap rules: the certificate moved onto the types
    // random points show is rejected.
    let cert = with_kind(&a, "block_pole_signs")[0]["certificate"].clone();
    for t in observed_types(&m, 53, 300).keys() {
        let forged = json!({"type": t, "status": "impossible", "certificate": cert});
        let mut mm = a.clone();
        mm["types"] = json!([forged]);
        assert!(check_analysis(&mm).is_err(), "{t}");
    }
}

/// The last types of the 4-mass table: a double zero with a cancelled
/// pole and a triple zero (N4-g2-a3.2-s4.2: m1-m2 grounded, m3-m4 free,
/// actuator between m3 and m2, sensor between m4 and m2). No set of
/// parameters makes their root conditions linear; the elimination (the
/// cancelled root as the unknown) and the merge from the split type's
/// witness build them. Checked here by another route: the witness's
/// numerator and denominator share a root (gcd, recomputed), and the
/// reduced numerator has the multiple root (its gcd with its
/// derivatives).
#[test]
fn cancelled_double_and_triple_zeros_get_exact_witnesses() {
    use poly::{gcd, Poly, Rat};
    let (m, a) = analysis_of("N4-g2-a3.2-s4.2");
    check_analysis(&a).unwrap();
    assert_eq!(
        a["types"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|v| v["status"] == "unknown")
            .count(),
        0
    );
    let tf = m.undamped_tf();
    let at = |p: &Poly, w: &Value| {
        w.as_object().unwrap().iter().fold(p.clone(), |p, (k, x)| {
            p.subs(k, &x.as_str().unwrap().parse::<Rat>().unwrap())
        })
    };
    let witness = |t: &str| {
        let v = verdict(&a, t);
        assert_eq!(v["status"], "possible", "{t}");
        v["witness"].clone()
    };
    for (t, cancelled, mult) in [
        ("A^2RR", 1, 2),
        ("RA^2R", 1, 2),
        ("RRA^2", 1, 2),
        ("A^3RRR", 0, 3),
    ] {
        let w = witness(t);
        let (num, den) = (at(&tf.num, &w), at(&tf.den, &w));
        let common = gcd(&num, &den);
        assert_eq!(common.degree(mms::OMEGA), cancelled, "{t}: {common}");
        let reduced = num.div_exact(&common).unwrap();
        let mut g = reduced.clone();
        let mut d = reduced.clone();
        for _ in 1..mult {
            d = d.derivative(mms::OMEGA);
            g = gcd(&g, &d);
        }
        assert_eq!(g.degree(mms::OMEGA), 1, "{t}: {reduced}");
    }
}

/// The file is held to what it says it covers: a verdict cut out, a model
/// cut out or listed twice, and a file that does not say what it covers
/// are refused, each naming what is missing.
#[test]
fn a_pruned_table_is_refused() {
    let full = paper_file();
    check(full).unwrap_or_else(|e| panic!("{e}"));
    // One verdict removed (an impossible type of A1).
    let mut v = full.clone();
    let ptr = verdict_ptr("A1", "AARR");
    let (types, j) = ptr.rsplit_once('/').unwrap();
    v.pointer_mut(types)
        .unwrap()
        .as_array_mut()
        .unwrap()
        .remove(j.parse().unwrap());
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("type AARR has no verdict"), "{e}");
    // One model removed.
    let mut v = full.clone();
    v["models"].as_array_mut().unwrap().remove(4);
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("is missing") && e.contains("11 classes"), "{e}");
    // One model twice (in place of another).
    let mut v = full.clone();
    let first = v["models"][0].clone();
    v["models"][1] = first;
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("same class"), "{e}");
    // No statement of what it covers.
    let mut v = full.clone();
    v.as_object_mut().unwrap().remove("covers");
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("missing field `covers`"), "{e}");
    // A list of models: exactly those.
    let mut v = full.clone();
    v["covers"] = json!({ "models": ["A1", "A2"] });
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("is not among the models the file covers"), "{e}");
    let mut one = full.clone();
    one["models"] = json!([full["models"][1].clone()]);
    one["covers"] = json!({ "models": ["A2"] });
    assert_eq!(one["models"][0]["id"], "A2");
    check(&one).unwrap_or_else(|e| panic!("{e}"));
    // Named by the generic ID, as mms analyze names it.
    one["covers"] = json!({ "models": ["N3-g0-a1.0-s2.0"] });
    check(&one).unwrap_or_else(|e| panic!("{e}"));
}

/// The table's text, written a model at a time, is the whole table's
/// JSON value pretty-printed in one go (sorted keys), with and without the
/// run's timing and for a table of no model.
#[test]
fn the_table_text_is_the_pretty_printed_value() {
    let whole = |t: &AnalysisTable| serde_json::to_string_pretty(&t.to_value()).unwrap() + "\n";
    let mut table = AnalysisTable::from_json(&paper_file().to_string()).unwrap();
    assert_eq!(table.to_json(), whole(&table));
    table.timing = Some(mms::table::RunTiming {
        wall_seconds: 1.5,
        threads: 2,
        models_analysed: 11,
        models_from_cache: 3,
    });
    assert!(table.to_json().contains("\"timing\": {"));
    assert_eq!(table.to_json(), whole(&table));
    let empty = AnalysisTable::new(Covers::Models(Vec::new()), Vec::new());
    assert_eq!(empty.to_json(), whole(&empty));
}

/// The table file names its format and version: a file of another
/// version, of no version (as written before the format was versioned)
/// or of another format is refused as such, before anything else is read;
/// and a table read back is the table written.
#[test]
fn the_table_format_is_versioned_and_round_trips() {
    let full = paper_file();
    let table = AnalysisTable::from_json(&full.to_string()).unwrap();
    assert_eq!(table.to_value(), *full);
    assert_eq!(AnalysisTable::from_json(&table.to_json()).unwrap(), table);
    let mut v = full.clone();
    v["format_version"] = json!(TABLE_FORMAT_VERSION + 1);
    // Even with a structure this version cannot read.
    v["models"] = json!("rewritten");
    let e = check(&v).unwrap_err();
    assert_eq!(
        e,
        CheckError::Table(TableError::Version {
            found: u64::from(TABLE_FORMAT_VERSION) + 1
        })
    );
    assert!(
        e.to_string()
            .contains(&format!("reads version {TABLE_FORMAT_VERSION}")),
        "{e}"
    );
    let mut v = full.clone();
    v.as_object_mut().unwrap().remove("format_version");
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("format_version"), "{e}");
    let mut v = full.clone();
    v.as_object_mut().unwrap().remove("format");
    assert!(matches!(
        check(&v),
        Err(CheckError::Table(TableError::Format { .. }))
    ));
    v["format"] = json!("another-table");
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("\"another-table\""), "{e}");
}

/// The pole-zero cancellations a file lists are recomputed: A2's (its
/// antiresonance cancels the resonance of m2-m3 on the wall c12 m3 =
/// c23 m1, the paper's eq. for A2) is accepted as written, and refused
/// with its reduced denominator or its condition edited.
#[test]
fn pole_zero_cancellations_are_recomputed() {
    let full = paper_file();
    let ptr = format!("{}/pzc/0", model_ptr("A2"));
    assert_eq!(full.pointer(&ptr).unwrap()["condition"], "c12*m3 - c23*m1");
    let mut v = full.clone();
    v.pointer_mut(&ptr).unwrap()["den"] = "Omega*m2*m3 - c12*m3 - c23*m2".into();
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("is not the transfer function"), "{e}");
    let mut v = full.clone();
    v.pointer_mut(&ptr).unwrap()["condition"] = "c12*m3 - c23*m2".into();
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("is not the wall"), "{e}");
    // The TF on the wall left unreduced (substituted by hand, times c23):
    // right as a function, but it claims no cancellation.
    let mut v = full.clone();
    let entry = v.pointer_mut(&ptr).unwrap();
    entry["num"] = "-Omega*c12*m3 + c12*c23".into();
    entry["den"] = "Omega^2*c12*m2*m3^2 - Omega*c12^2*m3^2 - 2*Omega*c12*c23*m2*m3 \
                    - Omega*c12*c23*m3^2 + c12^2*c23*m3 + c12*c23^2*m2 + c12*c23^2*m3"
        .into();
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("no pole cancels"), "{e}");
}

/// The pointer of A2's critical factors, and the index of its
/// cancellation wall `c12*m3 - c23*m1` among them.
fn a2_cancellation_wall() -> (String, usize) {
    let ptr = format!("{}/critical", model_ptr("A2"));
    let wall = paper_file()
        .pointer(&ptr)
        .unwrap()
        .as_array()
        .unwrap()
        .iter()
        .position(|c| c["factor"] == "c12*m3 - c23*m1")
        .expect("A2's cancellation wall");
    (ptr, wall)
}

/// The critical factors a model lists are recomputed: A2's are accepted,
/// and refused with one dropped (a critical polynomial left uncovered),
/// with a factor that is not critical, and with `cancels` flipped.
#[test]
fn critical_factors_are_recomputed() {
    let full = paper_file();
    let (ptr, wall) = a2_cancellation_wall();
    assert_eq!(full.pointer(&ptr).unwrap()[wall]["cancels"], true);
    let mut v = full.clone();
    v.pointer_mut(&ptr)
        .unwrap()
        .as_array_mut()
        .unwrap()
        .remove(wall);
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("is not covered by the listed factors"), "{e}");
    let mut v = full.clone();
    v.pointer_mut(&ptr).unwrap()[wall]["factor"] = "c12*m3 - c23*m2".into();
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("divides no critical polynomial"), "{e}");
    let mut v = full.clone();
    v.pointer_mut(&ptr).unwrap()[wall]["cancels"] = false.into();
    let e = check(&v).unwrap_err().to_string();
    assert!(e.contains("cancels must be true"), "{e}");
}

/// An undetermined factor may be left out with its size (six masses have
/// factors of millions of terms): A2 with its wall so listed is accepted,
/// one more undetermined factor counted; a wall, which claims a zero set,
/// may not be left out.
#[test]
fn only_undetermined_factors_may_be_left_out() {
    let full = paper_file();
    let (ptr, wall) = a2_cancellation_wall();
    let before = check(full).unwrap().undetermined_factors;
    let mut v = full.clone();
    let entry = &mut v.pointer_mut(&ptr).unwrap()[wall];
    entry.as_object_mut().unwrap().remove("factor");
    let e = check(&v).unwrap_err().to_string();
    assert!(
        e.contains("only an undetermined factor may be left out"),
        "{e}"
    );
    let entry = &mut v.pointer_mut(&ptr).unwrap()[wall];
    *entry = json!({
        "cancels": true,
        "size": {"terms": 2, "total_degree": 2},
        "status": "undetermined"
    });
    assert_eq!(check(&v).unwrap().undetermined_factors, before + 1);
}

/// Model `id` as a table file holds it, with the one `verdict`.
fn one_verdict(id: &str, verdict: Value) -> Value {
    let m = Model::from_id(id).unwrap();
    let tf = m.undamped_tf();
    let port = |p: mms::Port| json!([p.plus, p.minus]);
    json!({"id": id, "generic_id": id, "masses": m.masses().len(), "gap": m.gap(),
           "actuator": port(m.actuator()), "sensor": port(m.sensor()),
           "numerator": tf.num.to_string(), "denominator": tf.den.to_string(),
           "types": [verdict]})
}

/// The block certificate of N5-g1-a2.1-s5.1: the grounded m1's term
/// (numerator 1) and the free chain m2-m5's end-to-end term (numerator
/// `c23 c34 c45`).
fn grounded_mass_beside_a_chain() -> Value {
    json!({
        "factors": [],
        "stratum": [],
        "open": {"kind": "block_pole_signs", "blocks": [
            {"factors": [], "masses": [1], "numerator": "1", "remainder": false, "unit": "1"},
            {"factors": [
                {"exponent": 1, "factor": "c23"},
                {"exponent": 1, "factor": "c34"},
                {"exponent": 1, "factor": "c45"}],
             "masses": [2, 3, 4, 5], "numerator": "c23*c34*c45", "remainder": false, "unit": "1"}]}
    })
}

/// Rolle's bound across resonances (docs/analysis.md): N5-g1-a2.1-s5.1, a
/// grounded mass beside a free chain of four seen end to end, has the
/// numerator `Omega p(Omega) + c23 c34 c45 (c1 - m1 Omega)` up to signs,
/// whose second derivative is that of the quartic with the roots `0 <
/// l1 < l2 < l3`: one root below `l2`, one above `l1`. So at most three
/// zeros lie below the first resonance, and at most two above the last,
/// although the parities allow four. The certificate is the blocks' terms
/// alone; a type at the bound has a witness, which the certificate must
/// not exclude.
#[test]
fn rolle_bound_spans_resonances() {
    let id = "N5-g1-a2.1-s5.1";
    let cert = grounded_mass_beside_a_chain();
    // Three zeros below the first resonance: an exact witness.
    let witness = json!({"c1": "27/5", "c23": "9/500", "c34": "13/5", "c45": "6/25",
        "m1": "12/5", "m2": "39/5000", "m3": "73/1000", "m4": "97/10", "m5": "1/10"});
    block_certificate_holds_up_to_a_witness(
        id,
        &cert,
        &["AAAARRRR", "A^2AARRRR", "RRRRAAAA", "ARRRRAAA", "RRAARRAA"],
        ("AAARRRRA", witness),
    );
}

/// Rolle on the numerator divided by a shared pole (docs/analysis.md):
/// in N5-g1-a2.1-s5.1 the grounded m1's pole `c1/m1` on the chain's `i`-th
/// eigenvalue `l_i` divides `E = -c23 c34 c45 m1 (c1/m1 - Omega) + Omega
/// p_R(Omega)` (up to signs) by `Omega - l_i`, leaving a constant plus
/// `Omega` times the chain's other two pole factors: its derivative's
/// roots lie one below the lower of those and one between them, and
/// between them it has one sign. So with one cancellation the only type
/// with two resonances below every zero has a single zero above the
/// last of them (`RRAR (nm)` with the pole on the third eigenvalue,
/// `RRRA (nm)` otherwise), and with the pole cancelled twice (the
/// residues adding up to zero) the quotient's zero on the cancelled pole
/// is not the type's: `RRAA` and `RRA^2` are out, `ARRA` stays. The
/// parities and Rolle on `E` itself allow all ten types below, which the
/// sampler never read in 10^6 starts.
#[test]
fn rolle_bound_less_a_shared_pole() {
    let id = "N5-g1-a2.1-s5.1";
    let cert = grounded_mass_beside_a_chain();
    let impossible = [
        "RRAAAR", "RRAARA", "RRARAA", "RRAA^2R", "RRARA^2", "RRA^2AR", "RRA^2RA", "RRA^3R", "RRAA",
        "RRA^2",
    ];
    // c1/m1 = 15, the chain's third eigenvalue (c34 solved for it).
    let once = json!({"c1": "9/4", "c23": "64", "c34": "1/4", "c45": "1", "m1": "3/20",
        "m2": "36", "m3": "1413775/291074", "m4": "3", "m5": "1"});
    block_certificate_holds_up_to_a_witness(id, &cert, &impossible, ("RRAR (nm)", once));
    // The pole cancelled twice, on the chain's first eigenvalue.
    let twice = json!({"c1": "213358129792913083/980314713147572224", "c23": "88",
        "c34": "11/64", "c45": "63232286051/239088999104512",
        "m1": "19396193617537553/3829354348232704", "m2": "3/8", "m3": "7", "m4": "11/4",
        "m5": "5748389641/934900963924"});
    block_certificate_holds_up_to_a_witness(id, &cert, &impossible, ("ARRA", twice));
}

/// A multiple zero is one point, in one gap between samples
/// (docs/analysis.md): N5-g4-a5.2-s5.3, the grounded chain m1-m4 driven at
/// m2 and seen at m3 beside the lone free m5, has the zeros where `Omega
/// T_32(Omega) = 1/m5`, `T_32 = c23 (c1 + c12 - Omega m1)(c34 - Omega m4)
/// / d`. Two zeros between the second and the third resonance need
/// `T_32` positive at both (the runs' eigenvalues `(c1 + c12)/m1` and
/// `c34/m4` on one side of both, which Cauchy for the two separated runs
/// forbids, or both between them): then the sign changes on either side of
/// the two eigenvalues, an odd number of zeros on each, so the two are
/// simple. The parities alone (a double zero counted as two zeros to
/// spread) allowed `ARRA^2RRA`; `ARRAARRA` has a witness, which the
/// certificate must not exclude.
#[test]
fn a_multiple_zero_lies_in_one_gap() {
    let cert = json!({
        "factors": [],
        "stratum": [],
        "open": {"kind": "block_pole_signs", "blocks": [
            {"factors": [
                {"exponent": 1, "factor": "c23"},
                {"exponent": 1, "factor": "Omega*m4 - c34"},
                {"exponent": 1, "factor": "Omega*m1 - c1 - c12"}],
             "masses": [1, 2, 3, 4],
             "numerator": "Omega^2*c23*m1*m4 - Omega*c1*c23*m4 - Omega*c12*c23*m4 - Omega*c23*c34*m1 + c1*c23*c34 + c12*c23*c34",
             "remainder": false, "unit": "1"},
            {"factors": [], "masses": [5], "numerator": "1", "remainder": false, "unit": "1"}]}
    });
    let witness = json!({"c1": "40", "c12": "5/32", "c23": "13", "c34": "80", "m1": "3/16",
        "m2": "7/4", "m3": "3/8", "m4": "7", "m5": "36"});
    block_certificate_holds_up_to_a_witness(
        "N5-g4-a5.2-s5.3",
        &cert,
        &["ARRA^2RRA"],
        ("ARRAARRA", witness),
    );
}

/// The block pole-sign certificate `cert` of model `id` is accepted for
/// each type of `impossible`, the `witnessed` type's witness is valid, and
/// the certificate moved onto that type is rejected because the type fits
/// one of its configurations.
fn block_certificate_holds_up_to_a_witness(
    id: &str,
    cert: &Value,
    impossible: &[&str],
    witnessed: (&str, Value),
) {
    let model = |verdict: Value| one_verdict(id, verdict);
    let certified = |t: &str| json!({"type": t, "status": "impossible", "certificate": cert});
    for t in impossible {
        check_analysis(&model(certified(t))).unwrap_or_else(|e| panic!("{t}: {e}"));
    }
    let (t, witness) = witnessed;
    let possible = json!({"type": t, "status": "possible", "witness": witness});
    check_analysis(&model(possible)).unwrap();
    let e = check_analysis(&model(certified(t))).unwrap_err();
    assert!(
        e.to_string().contains("the type fits the configuration"),
        "{e}"
    );
}

/// Rolle one order lower (docs/analysis.md): N5-g3-a4.1-s5.3, the grounded
/// chain m1-m2-m3 driven at m1 and seen at m3 beside the free m4-m5
/// driven at m4 and seen at m5; both terms' numerators are constants. The
/// numerator's zeros are those of `E = c12 c23 d_R + c45 d_L`, the
/// quadratic `d_R = -Omega m4 m5 (b - Omega)` (convex) plus the cubic
/// `c45 d_L` with the chain's eigenvalues as roots. `E''` is the cubic's
/// second derivative, whose root lies between the chain's first and third
/// eigenvalue, plus a positive constant: positive below the first
/// eigenvalue, so at most two zeros lie below the first resonance,
/// although the parities (and Rolle at the cubic's degree) allow three.
/// For the zeros above the last resonance the same holds for `u^3 E(1/u)`,
/// where the constants' roles are the roots at `0`: at most two. Types at
/// either bound have witnesses, which the certificate must not exclude.
#[test]
fn rolle_one_order_lower_bounds_both_ends() {
    let id = "N5-g3-a4.1-s5.3";
    let cert = json!({
        "factors": [],
        "stratum": [],
        "open": {"kind": "block_pole_signs", "blocks": [
            {"factors": [{"exponent": 1, "factor": "c12"}, {"exponent": 1, "factor": "c23"}],
             "masses": [1, 2, 3], "numerator": "c12*c23", "remainder": false, "unit": "1"},
            {"factors": [{"exponent": 1, "factor": "c45"}],
             "masses": [4, 5], "numerator": "c45", "remainder": false, "unit": "1"}]}
    });
    let below = json!({"c1": "11/16", "c12": "7/4", "c23": "88", "c45": "9/128", "m1": "26",
        "m2": "8", "m3": "5/128", "m4": "72", "m5": "15/4"});
    block_certificate_holds_up_to_a_witness(
        id,
        &cert,
        &["AAARRRR", "AA^2RRRR", "A^2ARRRR", "A^3RRRR"],
        ("AARRRRA", below),
    );
    let above = json!({"c1": "5/128", "c12": "7", "c23": "15/512", "c45": "64",
        "m1": "901/3072", "m2": "7/16", "m3": "5/4096", "m4": "3/2", "m5": "13/2"});
    block_certificate_holds_up_to_a_witness(
        id,
        &cert,
        &["RRRRAAA", "RRRRAA^2", "RRRRA^2A", "RRRRA^3"],
        ("ARRRRAA", above),
    );
}

/// A term's direction on a gap from its zeros and poles paired across it
/// (docs/analysis.md): N5-g4-a5.1-s5.3, the grounded chain m1-m4 driven at
/// m1 and seen at m3 beside the lone free m5. Below the first pole the
/// chain's term `c12 c23 (c34 - Omega m4) / d_1` has its zero `c34/m4`
/// above the chain's first eigenvalue (an end run's eigenvalue lies
/// strictly inside the block's), so that pole and that zero pair up and
/// the term rises; so does `-1/(Omega m5)`. One zero at most lies there,
/// although the parities allow three. A type with one zero there has a
/// witness, which the certificate must not exclude.
#[test]
fn paired_zeros_and_poles_make_a_term_monotone() {
    let id = "N5-g4-a5.1-s5.3";
    let cert = json!({
        "factors": [],
        "stratum": [],
        "open": {"kind": "block_pole_signs", "blocks": [
            {"factors": [
                {"exponent": 1, "factor": "c12"},
                {"exponent": 1, "factor": "c23"},
                {"exponent": 1, "factor": "Omega*m4 - c34"}],
             "masses": [1, 2, 3, 4], "numerator": "-Omega*c12*c23*m4 + c12*c23*c34",
             "remainder": false, "unit": "-1"},
            {"factors": [], "masses": [5], "numerator": "1", "remainder": false, "unit": "1"}]}
    });
    let witness = json!({"c1": "1/4", "c12": "7/128", "c23": "30", "c34": "15/64",
        "m1": "39/224", "m2": "14398481/4311684", "m3": "55575/3248", "m4": "5/192", "m5": "96"});
    block_certificate_holds_up_to_a_witness(
        id,
        &cert,
        &["AAARARRR", "AAARRARR", "AAARRRAR", "AA^2RARRR", "A^3RARRR"],
        ("ARRAAARR", witness),
    );
}

/// The block pole-sign certificate of N5-g2-a3.1-s3.2: the grounded m1-m2
/// with the term `c12 / det P_L`, the free chain m3-m4-m5 driven and seen
/// at m3, whose term's numerator is the determinant of m4-m5 held at m3.
fn gap_two_certificate() -> Value {
    json!({
        "factors": [],
        "stratum": [],
        "open": {"kind": "block_pole_signs", "blocks": [
            {"factors": [{"exponent": 1, "factor": "c12"}], "masses": [1, 2],
             "numerator": "c12", "remainder": false, "unit": "1"},
            {"factors": [{"exponent": 1,
               "factor": "Omega^2*m4*m5 - Omega*c34*m5 - Omega*c45*m4 - Omega*c45*m5 + c34*c45"}],
             "masses": [3, 4, 5],
             "numerator": "Omega^2*m4*m5 - Omega*c34*m5 - Omega*c45*m4 - Omega*c45*m5 + c34*c45",
             "remainder": false, "unit": "1"}]}
    })
}

/// A log-uniform rational in about `[1/16, 16]`, three decimals.
fn short_rational(rng: &mut mms::xorshift::XorShift) -> poly::Rat {
    let v = rng.log_uniform(1.0 / 16.0, 16.0);
    poly::Rat::new(((v * 1000.0).round() as i64).into(), 1000.into())
}

/// The exact type of N5-g2-a3.1-s3.2 (`tf`) at `[c1, c12, c34, c45, m1,
/// ..., m5]`, and the point.
fn gap_two_type(
    tf: &mms::UndampedTf,
    values: [poly::Rat; 9],
) -> (String, std::collections::BTreeMap<String, poly::Rat>) {
    let names = ["c1", "c12", "c34", "c45", "m1", "m2", "m3", "m4", "m5"];
    let point: std::collections::BTreeMap<String, poly::Rat> =
        names.into_iter().map(String::from).zip(values).collect();
    let t = mms::analysis::frf_type_at(&tf.num, &tf.den, mms::OMEGA, &point).unwrap();
    (t.to_string(), point)
}

/// Monotone terms across the points between samples (docs/analysis.md):
/// N5-g2-a3.1-s3.2, the grounded m1-m2 (c1, c12) behind the gap, the free
/// chain m3-m4-m5 in front, the actuator between m3 and m1, the sensor
/// between m3 and m2. By hand: `c^T P^-1 b = c12 / det P_L + T_R` with
/// `T_R` the driving-point receptance of the free chain at m3. Below the
/// lowest pole both terms rise (`det P_L` is a product of positive falling
/// factors there, `T_R` is collocated), zero of `T_R` (the eigenvalue of
/// m4-m5 with m3 held) or not: one zero at most lies there, also when the
/// lowest pole is one both blocks share, where the zero of `T_R` below it
/// gives no sign and the parities alone allow three. A type with one zero
/// there has a witness, which the certificate must not exclude; and on
/// exact points where the blocks share an eigenvalue (m1 and m3 solved
/// for it by hand), every type shown escapes the certificate.
#[test]
fn monotone_terms_span_the_points_between_samples() {
    use poly::Rat;
    let id = "N5-g2-a3.1-s3.2";
    let cert = gap_two_certificate();
    let witness = json!({"c1": "6", "c12": "3/2", "c34": "8", "c45": "9/16", "m1": "7/2",
        "m2": "1712/417", "m3": "3", "m4": "36", "m5": "9012/4277"});
    let excluded = ["AAARRR", "AA^2RRR", "A^2ARRR", "A^3RRR", "AARR", "A^2RR"];
    block_certificate_holds_up_to_a_witness(id, &cert, &excluded, ("ARAARR", witness));
    let m = Model::from_id(id).unwrap();
    let tf = m.undamped_tf();
    let mut rng = mms::xorshift::XorShift::new(11);
    let mut draw = || short_rational(&mut rng);
    let mut shown = std::collections::BTreeSet::new();
    for _ in 0..400 {
        let [l, c1, c12, c34, c45, m2, m4, m5] = [(); 8].map(|_| draw());
        // det P_L(l) = (c1 + c12 - l m1)(c12 - l m2) - c12^2 = 0.
        let m1 = &(&(&c1 + &c12) - &(&(&c12 * &c12) / &(&c12 - &(&l * &m2)))) / &l;
        // det P_R(l) = (c34 - l m3) D - c34^2 (c45 - l m5) = 0, with D the
        // determinant of m4-m5 held at m3.
        let d = &(&(&(&c34 + &c45) - &(&l * &m4)) * &(&c45 - &(&l * &m5))) - &(&c45 * &c45);
        if d.is_zero() {
            continue;
        }
        let m3 = &(&c34 - &(&(&(&c34 * &c34) * &(&c45 - &(&l * &m5))) / &d)) / &l;
        if m1 <= Rat::ZERO || m3 <= Rat::ZERO {
            continue;
        }
        let (t, _) = gap_two_type(&tf, [c1, c12, c34, c45, m1, m2, m3, m4, m5]);
        shown.insert(t);
    }
    // The shared eigenvalue cancels once: three resonances.
    assert!(shown.len() >= 5, "{shown:?}");
    for t in &shown {
        assert_eq!(t.matches('R').count(), 3, "{t}");
        assert!(!excluded.contains(&t.as_str()), "{t}");
        let forged = json!({"type": t, "status": "impossible", "certificate": cert});
        assert!(check_analysis(&one_verdict(id, forged)).is_err(), "{t}");
    }
}

/// A pole both blocks share, cancelled once, where their residues agree
/// (docs/analysis.md): N5-g2-a3.1-s3.2 with both eigenvalues of m1-m2
/// equal to the free chain's two. The numerator's derivative there is a
/// sum of two products, each with the sign of its block's residue (times
/// the same factor), so where the residues agree its sign is known: at
/// the lower shared pole both are positive (m1-m2's first mode moves
/// both masses one way, the chain's term is collocated). Below it the
/// TF runs from the rigid body's minus infinity to plus infinity, with
/// one zero (the terms rise together): a type that starts with a
/// resonance is out, which the parities with an unknown sign allowed.
/// The points are built by hand: the chain's pole polynomial `q` fixed,
/// `c12` and `m2` drawn, `c1` and `m1` solved so that `det P_L` is a
/// multiple of `q` (its two coefficient ratios are linear in `1/c1` once
/// `m1 = A c1 c12 / m2`). Every type they show escapes the certificate,
/// and each shown point is an exact witness of its type.
#[test]
fn a_shared_pole_with_agreeing_residues_has_a_sign() {
    use poly::Rat;
    let id = "N5-g2-a3.1-s3.2";
    let cert = gap_two_certificate();
    let m = Model::from_id(id).unwrap();
    let tf = m.undamped_tf();
    let mut rng = mms::xorshift::XorShift::new(5);
    let mut draw = || short_rational(&mut rng);
    let mut shown = std::collections::BTreeMap::new();
    for _ in 0..400 {
        let [c12, c34, c45, m2, m3, m4, m5] = [(); 7].map(|_| draw());
        // q = m3 m4 m5 W^2 - (c34 m5 (m3 + m4) + c45 m3 (m4 + m5)) W + c34
        // c45 (m3 + m4 + m5); det P_L / (c1 c12) = (m1 m2 / (c1 c12)) W^2 -
        // (m2 / c12 + (m1 + m2) / c1) W + 1 must be q / q(0).
        let q0 = &(&c34 * &c45) * &(&(&m3 + &m4) + &m5);
        let a = &(&(&m3 * &m4) * &m5) / &q0;
        let b = &(&(&(&c34 * &m5) * &(&m3 + &m4)) + &(&(&c45 * &m3) * &(&m4 + &m5))) / &q0;
        let inv_c1 = &(&(&b - &(&m2 / &c12)) - &(&(&a * &c12) / &m2)) / &m2;
        if inv_c1 <= Rat::ZERO {
            continue;
        }
        let c1 = &Rat::ONE / &inv_c1;
        let m1 = &(&(&a * &c1) * &c12) / &m2;
        let (t, point) = gap_two_type(&tf, [c1, c12, c34, c45, m1, m2, m3, m4, m5]);
        shown.entry(t).or_insert(point);
    }
    let excluded = ["RAAR", "RRAA", "RA^2R", "RRA^2", "RA", "RR (nm)"];
    for t in excluded {
        let certified = json!({"type": t, "status": "impossible", "certificate": cert});
        check_analysis(&one_verdict(id, certified)).unwrap_or_else(|e| panic!("{t}: {e}"));
    }
    // Both shared poles cancel once: two resonances, a zero below the first.
    assert!(shown.len() >= 2, "{shown:?}");
    for (t, point) in &shown {
        assert_eq!(t.matches('R').count(), 2, "{t}");
        assert!(t.starts_with('A'), "{t}");
        let w: serde_json::Map<String, Value> = point
            .iter()
            .map(|(k, v)| (k.clone(), json!(v.to_string())))
            .collect();
        let possible = json!({"type": t, "status": "possible", "witness": w});
        check_analysis(&one_verdict(id, possible)).unwrap_or_else(|e| panic!("{t}: {e}"));
        let forged = json!({"type": t, "status": "impossible", "certificate": cert});
        let e = check_analysis(&one_verdict(id, forged)).unwrap_err();
        assert!(
            e.to_string().contains("the type fits the configuration"),
            "{t}: {e}"
        );
    }
}

/// A double zero shown by continuity (docs/analysis.md): N5-g2-a3.1-s4.1,
/// with two cancelled poles, along a path on which only `c1` and `m1`
/// move (the others fixed, `m3` and `m1` keeping the cancellations). At
/// `s = 0` the two zeros below the first remaining pole are apart
/// (`AARR`); at `s = 1` they have left the real axis (`RR (nm)`).
fn continuity_path() -> Value {
    json!({"parameters": {
        "c1": ["139/320*s + 7297/320", "1"], "c12": ["287/100", "1"],
        "c34": ["29/40", "1"], "c45": ["207/100", "1"],
        "m1": ["-6812490395947/16000000000*s - 1155982370821973/80000000000",
               "-3073532673061/2000000000"],
        "m2": ["27/20", "1"], "m3": ["2059/2000", "207/100"], "m4": ["127/5", "1"],
        "m5": ["71/50", "1"]}})
}

/// The exact point of a path of [`continuity_path`]'s form at `s`.
fn path_point(path: &Value, s: &poly::Rat) -> std::collections::BTreeMap<String, poly::Rat> {
    let at = |v: &Value| {
        let p: poly::Poly = v.as_str().unwrap().parse().unwrap();
        p.subs("s", s).as_constant().unwrap()
    };
    path["parameters"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), &at(&v[0]) / &at(&v[1])))
        .collect()
}

#[test]
fn a_double_zero_by_continuity_is_checked_and_its_forgeries_rejected() {
    let id = "N5-g2-a3.1-s4.1";
    let model = |t: &str, path: &Value| {
        one_verdict(id, json!({"type": t, "status": "possible", "path": path}))
    };
    let path = continuity_path();
    check_analysis(&model("A^2RR", &path)).unwrap_or_else(|e| panic!("{e}"));

    meets_below_the_first_pole(id, &path);

    // Forgeries: the path run backwards; the claim moved to another type;
    // a parameter that turns negative; the path folded so that the pair
    // meets three times (s -> u(s) = s + 20 s (s - 1/2)(s - 1), whose
    // values run 0, above 1, below 0, 1).
    let reversed = map_path(&path, "1 - s");
    let e = check_analysis(&model("A^2RR", &reversed)).unwrap_err();
    assert!(
        e.to_string()
            .contains("from RR (nm) at s = 0 to AARR at s = 1 with 1 meeting(s)"),
        "{e}"
    );
    let e = check_analysis(&model("RA^2R", &path)).unwrap_err();
    assert!(
        e.to_string().contains("the event gives A^2RR, not RA^2R"),
        "{e}"
    );
    let mut negative = path.clone();
    negative["parameters"]["c12"] = json!(["1 - 2*s", "1"]);
    let e = check_analysis(&model("A^2RR", &negative)).unwrap_err();
    assert!(e.to_string().contains("c12 is not positive"), "{e}");
    let folded = map_path(&path, "s + 20*s*(s - 1/2)*(s - 1)");
    let e = check_analysis(&model("A^2RR", &folded)).unwrap_err();
    assert!(
        e.to_string().contains("with 3 meeting(s) of two zeros"),
        "{e}"
    );
}

/// A second route to the merge of a path whose pair lies below the first
/// pole: the zeros of the reduced numerator below its first pole, counted
/// by exact root isolation at points of the path. Two at s = 0, none at
/// s = 1; halving the interval where the count drops brings the two
/// together.
fn meets_below_the_first_pole(id: &str, path: &Value) {
    use poly::{positive_roots, Rat};
    let tf = Model::from_id(id).unwrap().undamped_tf();
    let below_first_pole = |s: &Rat| -> Vec<f64> {
        let (n, d) = reduced_on_path(&tf, path, s);
        let pole = refined(&d, &positive_roots(&d)[0]);
        positive_roots(&n)
            .iter()
            .map(|r| refined(&n, r))
            .filter(|z| *z < pole)
            .collect()
    };
    let (mut lo, mut hi) = (Rat::ZERO, Rat::ONE);
    assert_eq!(below_first_pole(&lo).len(), 2);
    assert!(below_first_pole(&hi).is_empty());
    let gap0 = {
        let z = below_first_pole(&lo);
        z[1] / z[0]
    };
    for _ in 0..40 {
        let mid = &(&lo + &hi) * &Rat::new(1.into(), 2.into());
        if below_first_pole(&mid).len() == 2 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let z = below_first_pole(&lo);
    assert!(
        z.len() == 2 && z[1] / z[0] < 1.0 + 1e-5 && gap0 > 1.001,
        "{z:?} {gap0}"
    );
}

/// The transfer function `tf` at the point `s` of `path`, numerator and
/// denominator divided by their gcd.
fn reduced_on_path(
    tf: &mms::UndampedTf,
    path: &Value,
    s: &poly::Rat,
) -> (poly::UPoly, poly::UPoly) {
    let point = path_point(path, s);
    let at = |p: &poly::Poly| {
        poly::UPoly::from_poly(&p.subs_point(&point), "Omega")
            .unwrap()
            .1
    };
    let (n, d) = (at(&tf.num), at(&tf.den));
    let g = n.gcd(&d);
    (n.div_exact(&g).unwrap(), d.div_exact(&g).unwrap())
}

/// A simple real root of `u` to about 50 bits, by halving its isolating
/// interval on exact signs.
fn refined(u: &poly::UPoly, r: &poly::RealRoot) -> f64 {
    let (mut lo, mut hi) = (r.lo.clone(), r.hi.clone());
    let half = poly::Rat::new(1.into(), 2.into());
    let low_sign = u.sign_at(&lo);
    for _ in 0..60 {
        if lo == hi {
            break;
        }
        let mid = &(&lo + &hi) * &half;
        if u.sign_at(&mid) == low_sign {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo.to_f64() + hi.to_f64())
}

/// A path whose polynomials are of degree at most one in `s`, with `s`
/// replaced by the polynomial `u`.
fn map_path(path: &Value, u: &str) -> Value {
    use poly::{Poly, Rat};
    let u: Poly = u.parse().unwrap();
    let mut out = path.clone();
    for (_, v) in out["parameters"].as_object_mut().unwrap() {
        for k in 0..2 {
            let p: Poly = v[k].as_str().unwrap().parse().unwrap();
            let (p0, p1) = (p.subs("s", &Rat::ZERO), p.subs("s", &Rat::ONE));
            let mapped = &p0 + &(&(&p1 - &p0) * &u);
            v[k] = json!(mapped.to_string());
        }
    }
    out
}

/// A double zero by continuity in the chart of a block mechanism, where
/// the one cancelled pole's wall is linear in no parameter (a factor of
/// 74 terms): N5-g2-a3.2-s5.2, `A^2RRAR`. Along the path `c1` and `c34`
/// are the mechanism's two determinants solved at the moving cancelled
/// root, rational functions of `s`.
#[test]
fn a_double_zero_on_a_cancelled_root_chart() {
    let id = "N5-g2-a3.2-s5.2";
    let path = json!({"parameters": {
        "c1": ["4443/21760000*s^2 + 91349931/10880000*s + 606944331/1280000",
               "5199/32000*s + 292383/32000"],
        "c12": ["13/80*s + 861/80", "1"],
        "c34": ["3360/19*s + 15417120/19", "154/19*s + 1922618/19"],
        "c45": ["80", "1"], "m1": ["1/1632*s + 13595/544", "1"],
        "m2": ["1/64000*s + 52017/64000", "1"], "m3": ["120", "1"], "m4": ["52", "1"],
        "m5": ["7/456*s + 37053/152", "1"]}});
    let verdict = json!({"type": "A^2RRAR", "status": "possible", "path": path});
    check_analysis(&one_verdict(id, verdict)).unwrap_or_else(|e| panic!("{e}"));
    meets_below_the_first_pole(id, &path);
}

/// A triple zero by continuity beside a kept double zero: in the chart of
/// N5-g2-a3.2-s5.2 where `m2` and `m3` are solved for a double zero at a
/// point that moves with `c1`, a simple zero crosses the double one
/// (`ARA^2ARRR` at s = 0, `ARAA^2RRR` at s = 1), so `ARA^3RRR` shows at
/// the crossing.
#[test]
fn a_triple_zero_by_a_crossing_beside_a_kept_double_zero() {
    let id = "N5-g2-a3.2-s5.2";
    let path = json!({"parameters": {
        "c1": ["-7/64*s + 399/64", "1"], "c12": ["9", "1"], "c34": ["9", "1"],
        "c45": ["7/2", "1"], "m1": ["13", "1"],
        "m2": ["29014814871/26214400*s^2 + 3241519263297/13107200*s + 226400093911719/26214400",
               "178339077/1310720*s^2 + 17553660579/655360*s + 1727781734133/1310720"],
        "m3": ["72152451/81920*s^2 + 6741794997/40960*s + 456957840339/81920",
               "2830779/20480*s^2 + 278629533/10240*s + 27425106891/20480"],
        "m4": ["52", "1"], "m5": ["7/5", "1"]}});
    let model = |t: &str, path: &Value| {
        one_verdict(id, json!({"type": t, "status": "possible", "path": path}))
    };
    check_analysis(&model("ARA^3RRR", &path)).unwrap_or_else(|e| panic!("{e}"));
    zeros_meet_beside_a_double_zero(id, &path, [2, 1]);

    // Forgeries: the claim moved to another place; the double zero not
    // kept (m2 nudged along the path, so that it is double at s = 0 only).
    let e = check_analysis(&model("ARRA^3RR", &path)).unwrap_err();
    assert!(
        e.to_string()
            .contains("the event gives ARA^3RRR, not ARRA^3RR"),
        "{e}"
    );
    let mut nudged = path.clone();
    nudged["parameters"]["m2"][1] = json!(
        "(178339077/1310720*s^2 + 17553660579/655360*s + 1727781734133/1310720)*(1 + s/1000)"
    );
    assert!(check_analysis(&model("ARA^3RRR", &nudged)).is_err());
}

/// Two double zeros by continuity: in a chart of N5-g2-a3.1-s4.1 that
/// keeps one double zero (`m1`, `m3` solved for it), a second pair of
/// zeros meets (`RRAAA^2RR` or `RRA^2AARR` at s = 0, the pair gone at
/// s = 1).
#[test]
fn two_double_zeros_by_continuity_beside_a_kept_one() {
    let id = "N5-g2-a3.1-s4.1";
    let path = json!({"parameters": {
        "c1": ["1300", "1"], "c12": ["1/20*s + 3", "1"], "c34": ["11", "1"], "c45": ["26", "1"],
        "m1": ["-110172612297/3125*s^2 + 41685429396402/15625*s - 152894699771616/3125",
               "-46247652/125*s^2 + 17204126544/625*s - 1599983768592/3125"],
        "m2": ["81/100", "1"],
        "m3": ["-33172997/50*s^2 + 6141597726/125*s - 582400416906/625",
               "-350361/25*s^2 + 130334292/125*s - 12121089156/625"],
        "m4": ["21/5", "1"], "m5": ["11", "1"]}});
    let verdict = json!({"type": "RRA^2A^2RR", "status": "possible", "path": path});
    check_analysis(&one_verdict(id, verdict)).unwrap_or_else(|e| panic!("{e}"));
    zeros_meet_beside_a_double_zero(id, &path, [1, 1]);
    // The same path does not show the double zeros in another gap.
    let moved = json!({"type": "RA^2A^2RRR", "status": "possible", "path": path});
    assert!(check_analysis(&one_verdict(id, moved)).is_err());
}

/// A second route to a path's event beside a kept double zero: exact root
/// isolation of the reduced numerator at points of the path. The
/// multiplicities of the positive zeros in order are one list at s = 0
/// and another at s = 1; halving where the list changes brings two
/// neighbouring zeros of multiplicities `meeting` together (to 1e-5),
/// while one zero stays double at every point visited.
fn zeros_meet_beside_a_double_zero(id: &str, path: &Value, meeting: [u32; 2]) {
    use poly::{positive_roots, Rat};
    let tf = Model::from_id(id).unwrap().undamped_tf();
    let zeros = |s: &Rat| -> Vec<(f64, u32)> {
        let (n, _) = reduced_on_path(&tf, path, s);
        let square_free = n.div_exact(&n.gcd(&n.derivative())).unwrap();
        positive_roots(&n)
            .iter()
            .map(|r| {
                let x = if r.lo == r.hi {
                    r.lo.to_f64()
                } else {
                    refined(&square_free, r)
                };
                (x, r.multiplicity)
            })
            .collect()
    };
    let multiplicities = |z: &[(f64, u32)]| z.iter().map(|(_, k)| *k).collect::<Vec<_>>();
    let (mut lo, mut hi) = (Rat::ZERO, Rat::ONE);
    let start = multiplicities(&zeros(&lo));
    assert_ne!(start, multiplicities(&zeros(&hi)));
    for _ in 0..40 {
        let mid = &(&lo + &hi) * &Rat::new(1.into(), 2.into());
        let z = zeros(&mid);
        assert_eq!(z.iter().filter(|(_, k)| *k == 2).count(), 1, "{z:?}");
        if multiplicities(&z) == start {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // The nearest neighbours of the meeting multiplicities, as a ratio.
    let closest = |z: &[(f64, u32)]| {
        let mut want = meeting;
        want.sort();
        z.windows(2)
            .filter(|w| {
                let mut k = [w[0].1, w[1].1];
                k.sort();
                k == want
            })
            .map(|w| w[1].0 / w[0].0)
            .fold(f64::INFINITY, f64::min)
    };
    let (first, last) = (zeros(&Rat::ZERO), zeros(&lo));
    assert!(closest(&first) > 1.001, "{first:?}");
    assert!(closest(&last) < 1.0 + 1e-5, "{last:?}");
}
