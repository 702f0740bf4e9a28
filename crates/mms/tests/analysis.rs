//! The analysis engine against the paper's Tab. 3, and the soundness of its
//! witnesses by an exact recomputation along a second route.

use mms::analysis::{analyze, candidate_types, FrfType, SearchLimits, Status};
use mms::Model;
use poly::{Poly, Rat};
use std::collections::BTreeMap;

#[test]
fn tab3_is_reproduced_with_every_candidate_decided() {
    for (id, printed) in mms::paper::TAB3 {
        let a = analyze(&Model::from_id(id).unwrap(), &SearchLimits::default());
        let mut got: Vec<String> = a.possible().iter().map(|t| t.to_string()).collect();
        let mut want: Vec<String> = printed.iter().map(|s| s.to_string()).collect();
        got.sort();
        want.sort();
        assert_eq!(got, want, "{id}");
        assert!(a.unknown().is_empty(), "{id}: unknown {:?}", a.unknown());
        for v in &a.types {
            match v.status {
                Status::Possible => assert!(v.witness.is_some() && v.certificate.is_none()),
                Status::Impossible => assert!(v.witness.is_none() && v.certificate.is_some()),
                Status::Unknown => unreachable!(),
            }
        }
    }
}

/// The paper's "Pot. similar systems" column: the other models that can show
/// the same type, read off Tab. 3 by type.
#[test]
fn similar_systems_match_the_paper() {
    let all: Vec<_> = mms::paper::TAB3
        .iter()
        .map(|(id, _)| {
            (
                *id,
                analyze(&Model::from_id(id).unwrap(), &SearchLimits::default()),
            )
        })
        .collect();
    let similar = |id: &str, t: &str| -> Vec<&str> {
        let t: FrfType = t.parse().unwrap();
        all.iter()
            .filter(|(other, a)| *other != id && a.possible().contains(&&t))
            .map(|(other, _)| *other)
            .collect()
    };
    assert_eq!(similar("A4", "ARAR"), ["A1", "B1", "C1", "C3"]);
    assert_eq!(similar("A4", "AR"), ["B1", "B2"]);
    assert_eq!(similar("A2", "ARR"), ["A5"]);
    assert_eq!(similar("B2", "ARRA"), ["C2", "C4"]);
    assert!(similar("B2", "RR (nm)").is_empty());
    assert!(similar("B2", "C").is_empty());
}

/// Each witness, recomputed by a second route: the roots of num and den in
/// f64 (companion-free: closed forms for degree <= 2) agree with the claimed
/// order for the generic types of 3 masses.
#[test]
fn generic_witnesses_agree_with_floating_point_roots() {
    for (id, _) in mms::paper::TAB3 {
        let a = analyze(&Model::from_id(id).unwrap(), &SearchLimits::default());
        for v in a.types.iter().filter(|v| v.status == Status::Possible) {
            let t = &v.frf_type;
            let generic = t.tokens.iter().all(|k| k.multiplicity == 1)
                && t.resonances() == a.denominator.degree("Omega");
            if !generic {
                continue;
            }
            let w = v.witness.as_ref().unwrap();
            let num = real_roots_f64(&a.numerator, w);
            let den = real_roots_f64(&a.denominator, w);
            let mut all: Vec<(f64, char)> = num
                .iter()
                .filter(|r| **r > 0.0)
                .map(|r| (*r, 'A'))
                .chain(den.iter().map(|r| (*r, 'R')))
                .collect();
            all.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap());
            let mut text: String = all.iter().map(|x| x.1).collect();
            if num.iter().filter(|r| **r > 0.0).count() < a.numerator.degree("Omega") as usize {
                text.push_str(" (nm)");
            }
            assert_eq!(text, t.to_string(), "{id} at {w:?}");
        }
    }
}

fn real_roots_f64(p: &Poly, w: &BTreeMap<String, Rat>) -> Vec<f64> {
    let mut q = p.clone();
    for (k, v) in w {
        q = q.subs(k, v);
    }
    let c: Vec<f64> = q
        .coeffs_in("Omega")
        .iter()
        .map(|x| x.as_constant().map(|r| r.to_f64()).unwrap_or(0.0))
        .collect();
    match c.len() {
        0 | 1 => vec![],
        2 => vec![-c[0] / c[1]],
        3 => {
            let d = c[1] * c[1] - 4.0 * c[2] * c[0];
            if d < 0.0 {
                vec![]
            } else {
                vec![
                    (-c[1] - d.sqrt()) / (2.0 * c[2]),
                    (-c[1] + d.sqrt()) / (2.0 * c[2]),
                ]
            }
        }
        _ => panic!("degree > 2 not needed for 3 masses"),
    }
}

#[test]
fn candidate_counts_follow_from_compositions() {
    // a = r = 2: k=0: R^2 or RR (2 ways) x zeros {none, A, AA, A^2} with
    // interleavings; checked against a direct count by hand:
    // RR: nm(1) + A(3) + AA(6) + A^2(3) = 13; R^2: 1 + 2 + 3 + 2 = 8;
    // k=1: R with nm(1) + A(2) = 3; k=2: C = 1. Total 25.
    assert_eq!(candidate_types(2, 2).len(), 25);
    assert_eq!(candidate_types(0, 2).len(), 2); // RR, R^2
}

/// The simple-resonance theorem where it has work to do: N4-g1-a2.1-s3.1
/// has two blocks (m1 on c1; the free chain m2-m3-m4), and with
/// `c1 = m1 = 1`, unit masses and springs on the right their determinants
/// share the root `Omega = 1` (the right block's eigenvalues are 0, 1, 3),
/// so the unreduced denominator has a double root there. The exact
/// classification must still show no multiple resonance: the common pole
/// cancels, as the theorem says.
#[test]
fn shared_block_eigenvalue_cancels_instead_of_doubling() {
    use mms::analysis::frf_type_at;
    let m = Model::from_id("N4-g1-a2.1-s3.1").unwrap();
    let tf = m.undamped_tf();
    let point: BTreeMap<String, Rat> = m
        .undamped_parameters()
        .into_iter()
        .map(|p| (p, Rat::ONE))
        .collect();
    let mut den = tf.den.clone();
    for (k, v) in &point {
        den = den.subs(k, v);
    }
    // (Omega - 1)^2 divides the denominator at this point.
    let d1 = den.subs(mms::OMEGA, &Rat::ONE);
    let dd = den.derivative(mms::OMEGA).subs(mms::OMEGA, &Rat::ONE);
    assert!(d1.is_zero() && dd.is_zero(), "no double root: {den}");
    let t = frf_type_at(&tf.num, &tf.den, mms::OMEGA, &point).unwrap();
    assert!(!t.has_multiple_resonance(), "{t}");
    // And the analysis certifies every multiple-resonance type impossible.
    let a = analyze(&m, &SearchLimits::default());
    for v in &a.types {
        if v.frf_type.has_multiple_resonance() {
            assert_eq!(v.status, Status::Impossible, "{}", v.frf_type);
        }
    }
}

/// Item 2 of issue 4: a type rarer than 1 in 4000 log-uniform draws has a
/// witness. RRAARA of N4-g1-a2.1-s3.1 showed up 47 times in 20000 numeric
/// draws over [e^-4, e^4] (scripts, not this crate), far below the exact
/// search's 300 samples; the targeted search must find it, and the witness
/// must classify exactly (the independent checker re-verifies it too, in
/// the N=4 snapshot test).
#[test]
fn targeted_search_finds_a_rare_type() {
    use mms::analysis::frf_type_at;
    let m = Model::from_id("N4-g1-a2.1-s3.1").unwrap();
    let a = analyze(&m, &SearchLimits::default());
    let v = a
        .types
        .iter()
        .find(|v| v.frf_type.to_string() == "RRAARA")
        .unwrap();
    assert_eq!(v.status, Status::Possible);
    let w = v.witness.as_ref().unwrap();
    let tf = m.undamped_tf();
    assert_eq!(
        frf_type_at(&tf.num, &tf.den, mms::OMEGA, w).unwrap(),
        v.frf_type
    );
}

/// The statuses of an analysis, by type.
fn statuses(a: &mms::analysis::ModelAnalysis) -> std::collections::BTreeMap<String, Status> {
    a.types
        .iter()
        .map(|v| (v.frf_type.to_string(), v.status))
        .collect()
}

/// An analysis carries over to the other member of its renumbering class:
/// at 4 masses, where the search on each member alone decides every type,
/// each member's analysis renamed to the other member (its witnesses,
/// certificates, cancellations and critical factors in the other's
/// parameters) has the verdicts the other's own search finds, and the
/// independent checker accepts every renamed witness and certificate.
/// `analyze` completes a member's unknown types this way (class 39 of
/// 5 masses: docs/analysis.md), so both members give the same verdicts.
#[test]
fn analyses_carry_over_to_the_other_member_of_a_class() {
    use mms::analysis::analyze_alone;
    use mms::table::{AnalysisTable, Covers, TableModel};
    let limits = SearchLimits::default();
    let mut pairs = 0;
    for class in mms::equivalence_classes(4, mms::Symmetry::Renumbering).unwrap() {
        let [a, b] = class[..] else { continue };
        pairs += 1;
        let (alone_a, alone_b) = (analyze_alone(&a, &limits), analyze_alone(&b, &limits));
        assert!(alone_a.unknown().is_empty() && alone_b.unknown().is_empty());
        let carried = [alone_a.mirrored(&a), alone_b.mirrored(&b)];
        assert_eq!(statuses(&carried[0]), statuses(&alone_b), "{a} to {b}");
        assert_eq!(statuses(&carried[1]), statuses(&alone_a), "{b} to {a}");
        assert_eq!(carried[0].generic_id, b.id());
        let table = AnalysisTable::new(
            Covers::Models(vec![b.id(), a.id()]),
            carried.into_iter().map(TableModel::new).collect(),
        );
        mms::check::check_table(&table).unwrap_or_else(|e| panic!("{a}, {b}: {e}"));
    }
    assert!(pairs >= 20, "{pairs} classes of two members");
}

/// An analysis carries over to the reciprocal model (actuator and sensor
/// swapped): the transfer function is the same by reciprocity (checked
/// here on the derived polynomials), the reciprocal's own search, run
/// apart, finds the same verdicts at 4 masses, and the independent checker
/// accepts the carried witnesses and certificates against the reciprocal
/// model, whose transfer function it derives itself.
#[test]
fn analyses_carry_over_to_the_reciprocal_model() {
    use mms::analysis::{analysis_source, analyze_alone};
    use mms::table::{AnalysisTable, Covers, TableModel};
    let limits = SearchLimits::default();
    let mut twins = 0;
    for m in mms::class_representatives(4).unwrap() {
        let r = m.reciprocal();
        if r.representative() == m || analysis_source(&m) != m {
            continue; // its own reciprocal's class, or met from the other side
        }
        twins += 1;
        assert_eq!(m.undamped_tf(), r.undamped_tf(), "{m}: reciprocity");
        let alone = analyze_alone(&m, &limits);
        let carried = alone.carried_over(&m, &r).expect("the reciprocal");
        assert_eq!(carried.generic_id, r.id());
        assert_eq!(
            statuses(&carried),
            statuses(&analyze_alone(&r, &limits)),
            "{m} to {r}"
        );
        let table =
            AnalysisTable::new(Covers::Models(vec![r.id()]), vec![TableModel::new(carried)]);
        mms::check::check_table(&table).unwrap_or_else(|e| panic!("{m} to {r}: {e}"));
        assert!(alone
            .carried_over(&m, &mms::Model::from_id("A1").unwrap())
            .is_none());
    }
    assert!(twins >= 8, "{twins} pairs of reciprocal classes");
}

/// Both members of every renumbering class of 5 masses give the same
/// verdicts through `analyze`, and the checker accepts both members'
/// witnesses and certificates. About 20 minutes on two cores in release,
/// so not in CI: run with `cargo test --release -p mms --test analysis --
/// --ignored every_class_of_five`; the last run is in docs/performance.md.
#[test]
#[ignore = "about 20 minutes in release; run by hand, result in docs/performance.md"]
fn every_class_of_five_masses_gives_its_members_the_same_verdicts() {
    use mms::table::{AnalysisTable, Covers, TableModel};
    use std::sync::atomic::{AtomicUsize, Ordering};
    let limits = SearchLimits::default();
    let classes = mms::equivalence_classes(5, mms::Symmetry::Renumbering).unwrap();
    let pairs: Vec<(Model, Model)> = classes
        .iter()
        .filter_map(|c| match c[..] {
            [a, b] => Some((a, b)),
            _ => None,
        })
        .collect();
    let next = AtomicUsize::new(0);
    let differing = std::sync::Mutex::new(Vec::new());
    // Two workers, each taking the next class, with a main thread's stack
    // (the exact algebra recurses deeply).
    std::thread::scope(|s| {
        for _ in 0..2 {
            let worker = std::thread::Builder::new().stack_size(8 << 20);
            worker
                .spawn_scoped(s, || loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(a, b)) = pairs.get(i) else { break };
                    let (full_a, full_b) = (analyze(&a, &limits), analyze(&b, &limits));
                    if statuses(&full_a) != statuses(&full_b) {
                        differing.lock().unwrap().push(format!("{a} / {b}"));
                    }
                    let table = AnalysisTable::new(
                        Covers::Models(vec![a.id(), b.id()]),
                        vec![TableModel::new(full_a), TableModel::new(full_b)],
                    );
                    mms::check::check_table(&table).unwrap_or_else(|e| panic!("{a}, {b}: {e}"));
                })
                .expect("a worker thread");
        }
    });
    let differing = differing.into_inner().unwrap();
    assert!(differing.is_empty(), "{differing:?}");
    eprintln!(
        "{} classes of two members: the same verdicts, all checked",
        pairs.len()
    );
}
