//! Back-solving (issue "identification", item 4) against the paper's
//! Tabs. 4, 6 and 7, with an independent numerical check of every solution,
//! round trips over all structures, and bad inputs.

use mms::backsolve::{
    back_solve, back_solve_with, invariant_relations, BackSolution, BackSolveError, Family, Limits,
    NoSolution, Solution, Target,
};
use mms::{Model, PAPER_IDS};
use poly::Rat;
use std::time::{Duration, Instant};

/// Relative tolerance for the paper's printed values: the A1 input of
/// Tab. 7 is itself rounded to three digits, and so are the outputs.
const PRINTED: f64 = 0.03;

/// Relative tolerance of the independent numerical check (f64 solve of
/// `(C - Omega*M) x = b` against the exact target, away from poles and
/// zeros), far above f64 rounding and far below any real mismatch.
const NUMERIC: f64 = 1e-6;

fn model(id: &str) -> Model {
    Model::from_id(id).unwrap()
}

fn timed(m: &Model, t: &Target) -> (BackSolution, Duration) {
    let t0 = Instant::now();
    let r = back_solve(m, t).unwrap();
    (r, t0.elapsed())
}

/// The undamped inertance of `m` at `values` by a route independent of the
/// symbolic transfer functions: the chain matrices assembled here in f64,
/// `(C - Omega*M) x = b` solved by Gaussian elimination with partial
/// pivoting, inertance `= -Omega * c^T x`.
fn inertance_f64(m: &Model, values: &[f64], omega: f64) -> f64 {
    let n = m.n_masses();
    let names = m.undamped_parameters();
    let get = |name: &str| values[names.iter().position(|p| p == name).unwrap()];
    let mut a = vec![vec![0.0; n + 1]; n];
    for (i, row) in a.iter_mut().enumerate() {
        row[i] -= omega * get(&mms::mass_name(i + 1));
    }
    for i in (0..n).filter(|&i| m.has_link(i)) {
        let c = get(&mms::spring_name(i));
        a[i][i] += c;
        if i >= 1 {
            a[i - 1][i - 1] += c;
            a[i - 1][i] -= c;
            a[i][i - 1] -= c;
        }
    }
    let b = m.input_vector();
    for (row, bi) in a.iter_mut().zip(&b) {
        row[n] = *bi as f64;
    }
    for col in 0..n {
        let p = (col..n)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap();
        a.swap(col, p);
        let pivot = a[col].clone();
        for row in a.iter_mut().skip(col + 1) {
            let f = row[col] / pivot[col];
            for (x, p) in row.iter_mut().zip(&pivot).skip(col) {
                *x -= f * p;
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (a[r][n] - s) / a[r][r];
    }
    let c = m.output_vector();
    -omega
        * c.iter()
            .zip(&x)
            .map(|(ci, xi)| *ci as f64 * xi)
            .sum::<f64>()
}

/// Compares the solved model's inertance with the target at several
/// frequencies away from poles and zeros.
fn check_numerically(m: &Model, values: &[f64], t: &Target) {
    let mut checked = 0;
    for k in 0..40 {
        let omega = 10f64.powf(1.0 + k as f64 / 8.0);
        let want = t.eval_f64(omega);
        let got = inertance_f64(m, values, omega);
        // Skip points close to a pole or zero, where f64 cancellation rules.
        let den: f64 = t
            .den()
            .iter()
            .rev()
            .fold(0.0, |acc, c| acc * omega + c.to_f64());
        let scale: f64 = t
            .den()
            .iter()
            .enumerate()
            .map(|(i, c)| c.to_f64().abs() * omega.powi(i as i32))
            .sum();
        if den.abs() < 1e-3 * scale || want.abs() < 1e-6 {
            continue;
        }
        assert!(
            (got - want).abs() <= NUMERIC * want.abs(),
            "{} at Omega = {omega}: {got} vs target {want} ({values:?})",
            m.name()
        );
        checked += 1;
    }
    assert!(checked >= 10, "too few frequencies checked");
}

fn check_all(m: &Model, r: &BackSolution, t: &Target) {
    for s in r.points() {
        check_numerically(m, &s.values, t);
    }
    for f in r.families() {
        assert!(
            !f.samples.is_empty(),
            "{}: a family without samples",
            m.name()
        );
        for s in &f.samples {
            check_numerically(m, s, t);
        }
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

fn matches_printed(s: &Solution, printed: &[f64]) -> bool {
    s.values
        .iter()
        .zip(printed)
        .all(|(&v, &p)| close(v, p, PRINTED))
}

// Tab. 7: the A1 fit of the stacker crane and the other collocated models.
const TAB7_A1: [f64; 5] = mms::paper::TAB7[0].1;

#[test]
fn tab7_collocated_models_from_the_a1_fit() {
    let a1 = model("A1");
    let target = Target::from_model_f64(&a1, &TAB7_A1).unwrap();
    // (ID, printed solutions in m1 m2 m3 then the springs of the model).
    // B1: exact m2 = 0.004979 (printed 0.0049, 1.6 % off: within the
    // rounding of the three-digit A1 input).
    let ids = ["A1", "A4", "B1", "C1", "C3"];
    let table: Vec<(&str, Vec<[f64; 5]>)> = ids
        .iter()
        .map(|id| (*id, mms::paper::tab7_rows(id)))
        .collect();
    for (id, printed) in &table {
        let m = model(id);
        let (r, dt) = timed(&m, &target);
        let BackSolution::Points(points) = &r else {
            panic!("{id}: expected finitely many solutions, got {r}");
        };
        assert_eq!(points.len(), printed.len(), "{id}: {r}");
        for p in printed {
            let s = points.iter().find(|s| matches_printed(s, p));
            assert!(s.is_some(), "{id}: no solution near the printed {p:?}: {r}");
        }
        for s in points {
            println!("Tab. 7 {id}: {s}  ({dt:?})");
        }
        check_all(&m, &r, &target);
    }
}

#[test]
fn tab7_a1_gives_back_its_exact_input() {
    let a1 = model("A1");
    let target = Target::from_model_f64(&a1, &TAB7_A1).unwrap();
    let r = back_solve(&a1, &target).unwrap();
    assert_eq!(r.points().len(), 1);
    let s = &r.points()[0];
    for (x, v) in s.exact.iter().zip(TAB7_A1) {
        assert_eq!(x.as_rational(), Some(Rat::from_f64(v).unwrap()));
    }
    assert_eq!(s.values, TAB7_A1);
}

#[test]
fn tab7_a4_and_b1_solutions_are_irrational_and_exactly_described() {
    let target = Target::from_model_f64(&model("A1"), &TAB7_A1).unwrap();
    for id in ["A4", "B1"] {
        let r = back_solve(&model(id), &target).unwrap();
        for s in r.points() {
            for x in &s.exact {
                // The value lies in its isolating interval and is a root of
                // the minimal polynomial (sign change or exact).
                assert!(x.lo.to_f64() <= x.value && x.value <= x.hi.to_f64());
                if x.lo != x.hi {
                    assert!(x.poly.sign_at(&x.lo) * x.poly.sign_at(&x.hi) < 0);
                }
            }
            // The two solutions are conjugate: some parameter is irrational.
            assert!(s.exact.iter().any(|x| !x.is_rational()), "{id}: {s}");
        }
    }
}

// Tab. 4: A2 generating, A5 to be built.
const TAB4_A2: [f64; 5] = [0.01, 0.01, 0.02, 100.0, 100.0];

fn free_index(f: &Family) -> usize {
    f.parameters.iter().position(|p| p == &f.free[0]).unwrap()
}

#[test]
fn tab4_a5_reproduces_a2_as_a_one_parameter_family() {
    let a2 = model("A2");
    let a5 = model("A5");
    let target = Target::from_model_f64(&a2, &TAB4_A2).unwrap();
    let (r, dt) = timed(&a5, &target);
    let BackSolution::Families { families, isolated } = &r else {
        panic!("A5: expected a family, got {r}");
    };
    assert!(isolated.is_empty());
    assert_eq!(families.len(), 1);
    let fam = &families[0];
    assert_eq!(fam.dimension(), 1);
    println!("Tab. 4 A5 ({dt:?}):\n{fam}");
    check_all(&a5, &r, &target);

    // The exact member: A5 is the reciprocal of the mirrored A2 (m1 <-> m3,
    // c12 <-> c23), so (0.02, 0.01, 0.01, 100, 100) is in the family, exactly.
    let mirrored = [0.02, 0.01, 0.01, 100.0, 100.0];
    let exact: Vec<Rat> = mirrored
        .iter()
        .map(|&v| Rat::from_f64(v).unwrap())
        .collect();
    let i = free_index(fam);
    assert_eq!(fam.member(&[exact[i].clone()]), Some(exact.clone()));

    // The paper's A5 point (m1 0.063, m2 0.015, m3 0.010, spring 444 printed
    // under c1, which A5 does not have, and c23 173) is NOT in the family,
    // under either reading of 444 (c12 or the c1 column): every member has
    // m1 + m2 + m3 = 0.04 exactly, since the target's rigid-body inertance
    // 1/(m1 + m2 + m3) = 25 1/kg at Omega = 0 is fixed, but the printed
    // masses add up to 0.088. The printed set gives poles at 18.7 and
    // 36.2 Hz and a zero at 13.4 Hz instead of A2's 13.5 and 26.5 Hz and
    // 11.3 Hz: Tab. 4's A5 values cannot reproduce the A2 FRF exactly (they
    // are presumably a rounded or mis-transcribed optimizer result).
    let paper = [0.063, 0.015, 0.010, 444.0, 173.0];
    for s in &fam.samples {
        assert!(close(s.iter().take(3).sum::<f64>(), 0.04, 1e-9));
    }
    let member = fam.member_f64(&[paper[i]]);
    if let Some(mm) = &member {
        println!(
            "A5 member at {} = {}: {mm:?} (paper {paper:?})",
            fam.free[0], paper[i]
        );
        assert!(!mm.iter().zip(&paper).all(|(a, b)| close(*a, *b, PRINTED)));
    }
    let paper_target = Target::from_model_f64(&a5, &paper).unwrap();
    assert_ne!(paper_target, target);
    println!(
        "paper A5 inertance at Omega = 0: {} (target {})",
        paper_target.eval_f64(0.0),
        target.eval_f64(0.0)
    );
}

#[test]
fn tab4_a2_itself_is_a_family_containing_the_generating_model() {
    let a2 = model("A2");
    let target = Target::from_model_f64(&a2, &TAB4_A2).unwrap();
    let (r, dt) = timed(&a2, &target);
    let fam = &r.families()[0];
    assert_eq!(fam.dimension(), 1);
    println!("A2 from A2 ({dt:?}):\n{fam}");
    let exact: Vec<Rat> = TAB4_A2.iter().map(|&v| Rat::from_f64(v).unwrap()).collect();
    let i = free_index(fam);
    assert_eq!(fam.member(&[exact[i].clone()]), Some(exact.clone()));
    assert!(fam.intervals.iter().any(|iv| iv.contains_f64(TAB4_A2[i])));
    check_all(&a2, &r, &target);
    // A3 cannot: its numerator is a constant.
    assert!(matches!(
        back_solve(&model("A3"), &target).unwrap().no_solution(),
        Some(NoSolution::Degree { .. })
    ));
}

// Tab. 6 / Sec. 5: B2 generating, C2 to be built.
const TAB6_B2: [f64; 5] = [0.01, 0.01, 0.01, 100.0, 200.0];

#[test]
fn tab6_c2_cannot_reproduce_b2() {
    let b2 = model("B2");
    let target = Target::from_model_f64(&b2, &TAB6_B2).unwrap();
    for id in ["C2", "C4"] {
        let (r, dt) = timed(&model(id), &target);
        println!("Tab. 6 {id} ({dt:?}): {r}");
        let Some(NoSolution::ViolatedRelation {
            relation,
            value,
            relative,
        }) = r.no_solution()
        else {
            panic!("{id}: expected a violated relation, got {r}");
        };
        // The C2/C4 linkage (eqs. (62)-(63)): den = m3*num + c12*m3^2*Omega,
        // so Den(0)/Num(0) = lc(Den)/lc(Num) (= m3). For B2 these are
        // m2 + m3 = 0.02 and m1 = 0.01.
        assert_eq!(relation.to_string(), "d0*n2 - d2*n0");
        assert!(!value.is_zero());
        // |0.02 - 0.01| / (0.02 + 0.01), after dividing by n0*n2.
        assert!((relative - 1.0 / 3.0).abs() < 1e-12, "{relative}");
        let n = target.num();
        let d = target.den();
        let ratio0 = d[0].to_f64() / n[0].to_f64();
        let ratio2 = d[2].to_f64() / n[2].to_f64();
        assert!(close(ratio0, 0.02, 1e-12) && close(ratio2, 0.01, 1e-12));
    }
    // The paper's fitted C2 of Tab. 6 satisfies the relation (as every C2
    // does) and so is a different transfer function.
    let c2_fit =
        Target::from_model_f64(&model("C2"), &[0.011, 0.0044, 0.030, 190.0, 96.0]).unwrap();
    assert_ne!(c2_fit, target);
    // B2 itself: a one-parameter family (4 of 5 parameters determinable)
    // containing the generating parameters.
    let (r, _) = timed(&b2, &target);
    let fam = &r.families()[0];
    let exact: Vec<Rat> = TAB6_B2.iter().map(|&v| Rat::from_f64(v).unwrap()).collect();
    assert_eq!(fam.member(&[exact[free_index(fam)].clone()]), Some(exact));
    check_all(&b2, &r, &target);
}

#[test]
fn invariant_relations_exist_exactly_for_rank_deficient_structures() {
    for (id, det, inv) in mms::paper::TAB5 {
        let r = invariant_relations(&model(id));
        assert_eq!(!r.is_empty(), det < inv, "{id}: {r:?}");
    }
}

/// A small deterministic generator for the round trips.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Positive values for `m`: masses in [0.002, 0.05], springs in [10, 500],
    /// rounded to four significant digits (as a user would type them).
    fn params(&mut self, m: &Model) -> Vec<f64> {
        let round = |x: f64| {
            let e = 10f64.powi(3 - x.log10().floor() as i32);
            (x * e).round() / e
        };
        let masses = m.n_masses();
        (0..m.undamped_parameters().len())
            .map(|i| {
                let u = self.next();
                if i < masses {
                    round(0.002 * 25f64.powf(u))
                } else {
                    round(10.0 * 50f64.powf(u))
                }
            })
            .collect()
    }
}

fn contains_generating(r: &BackSolution, values: &[f64]) -> bool {
    let exact: Vec<Rat> = values.iter().map(|&v| Rat::from_f64(v).unwrap()).collect();
    let as_point = r.points().iter().any(|s| {
        s.exact
            .iter()
            .zip(&exact)
            .all(|(x, e)| x.as_rational().as_ref() == Some(e))
    });
    let in_family = r.families().iter().any(|f| f.contains(&exact));
    as_point || in_family
}

#[test]
fn round_trip_all_three_mass_structures() {
    let mut rng = Lcg(20240611);
    let mut worst = Duration::ZERO;
    for (id, det, _) in mms::paper::TAB5 {
        let m = model(id);
        for _ in 0..6 {
            let v = rng.params(&m);
            let target = Target::from_model_f64(&m, &v).unwrap();
            let (r, dt) = timed(&m, &target);
            worst = worst.max(dt);
            assert!(contains_generating(&r, &v), "{id} {v:?}: {r}");
            if det == 5 {
                // Fully determinable: finitely many, the input among them.
                assert!(matches!(r, BackSolution::Points(_)), "{id}: {r}");
            } else {
                let fam = &r.families()[0];
                assert_eq!(fam.dimension(), 5 - det, "{id}: {r}");
            }
            check_all(&m, &r, &target);
        }
    }
    println!("round trips: slowest back-solve {worst:?}");
}

#[test]
fn cross_structure_targets_are_consistent() {
    // Every collocated 3-mass structure reproduces every other one's
    // generic target, and each solution reproduces the target numerically.
    let mut rng = Lcg(7);
    let collocated = ["A1", "A4", "B1", "C1", "C3"];
    for gen in collocated {
        let g = model(gen);
        let v = rng.params(&g);
        let target = Target::from_model_f64(&g, &v).unwrap();
        for id in PAPER_IDS.iter().map(|p| p.0) {
            let m = model(id);
            let (r, dt) = timed(&m, &target);
            assert!(dt < Duration::from_secs(5), "{id}: {dt:?}");
            check_all(&m, &r, &target);
        }
    }
}

#[test]
fn four_mass_chains_round_trip_or_fail_with_a_typed_error() {
    // Four masses, 7 parameters: feasible for the chains whose elimination
    // stays small; the others must stop with a typed error within the
    // budget instead of hanging.
    let mut rng = Lcg(99);
    let limits = Limits {
        max_time: Duration::from_secs(3),
        ..Limits::default()
    };
    let mut solved = 0;
    for id in ["N4-g0-a1.0-s2.0", "N4-g0-a1.0-s3.0", "N4-g0-a1.0-s1.0"] {
        let m = model(id);
        let v = rng.params(&m);
        let target = Target::from_model_f64(&m, &v).unwrap();
        let t0 = Instant::now();
        let r = back_solve_with(&m, &target, &limits);
        let dt = t0.elapsed();
        assert!(dt < Duration::from_secs(30), "{}: {dt:?}", m.id());
        match r {
            Ok(r) => {
                println!(
                    "N=4 {}: {} point(s), {} family(ies) ({dt:?})",
                    m.id(),
                    r.points().len(),
                    r.families().len()
                );
                assert!(contains_generating(&r, &v), "{}: {r}", m.id());
                check_all(&m, &r, &target);
                solved += 1;
            }
            Err(e) => {
                println!("N=4 {}: {e} ({dt:?})", m.id());
                assert!(matches!(
                    e,
                    BackSolveError::LimitExceeded(_) | BackSolveError::Unsupported(_)
                ));
            }
        }
    }
    println!("N=4: {solved} structures solved");
    assert!(solved > 0);
}

#[test]
fn bad_inputs_give_typed_errors_or_reasons() {
    let a1 = model("A1");
    assert_eq!(
        Target::new(vec![Rat::ONE], vec![Rat::ZERO]),
        Err(BackSolveError::ZeroDenominator)
    );
    assert_eq!(
        Target::new(vec![], vec![Rat::ONE]),
        Err(BackSolveError::ZeroNumerator)
    );
    assert!(matches!(
        Target::from_f64(&[f64::NAN], &[1.0]),
        Err(BackSolveError::NonFinite(_))
    ));
    assert!(matches!(
        Target::from_model_f64(&a1, &[1.0, 2.0]),
        Err(BackSolveError::ParameterCount {
            expected: 5,
            got: 2,
            ..
        })
    ));
    assert!(matches!(
        Target::from_model_f64(&a1, &[1.0, 2.0, -3.0, 4.0, 5.0]),
        Err(BackSolveError::NonPositiveParameter { .. })
    ));
    // A numerator of degree 3: no 3-mass chain has it.
    let t = Target::from_f64(&[1.0, -2.0, 3.0, -4.0], &[5.0, -6.0, 7.0]).unwrap();
    for (id, ..) in PAPER_IDS {
        let r = back_solve(&model(id), &t).unwrap();
        assert!(
            matches!(r.no_solution(), Some(NoSolution::Degree { .. })),
            "{id}: {r}"
        );
    }
    // The right degrees but the wrong sign pattern (all coefficients
    // positive: the denominator of a chain alternates in sign).
    let t = Target::from_f64(&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0]).unwrap();
    let r = back_solve(&a1, &t).unwrap();
    assert!(
        matches!(r.no_solution(), Some(NoSolution::SignPattern { .. })),
        "{r}"
    );
    // Right signs, but resonances not interlaced with the antiresonances:
    // num (Omega-1)(Omega-2), den (Omega-3)(Omega-4) has no A1 realisation.
    let t = Target::from_f64(&[2.0, -3.0, 1.0], &[12.0, -7.0, 1.0]).unwrap();
    let r = back_solve(&a1, &t).unwrap();
    assert!(r.no_solution().is_some(), "{r}");
    println!("non-interlaced target for A1: {}", r.no_solution().unwrap());
    // Limits: a model too large for the given limits fails fast.
    let tight = Limits {
        max_parameters: 4,
        ..Limits::default()
    };
    let t = Target::from_model_f64(&a1, &TAB7_A1).unwrap();
    assert!(matches!(
        back_solve_with(&a1, &t, &tight),
        Err(BackSolveError::LimitExceeded(_))
    ));
}

#[test]
fn every_three_mass_structure_back_solves_quickly() {
    // Targets from f64 parameters (dyadic rationals with ~50-bit
    // numerators): the Tab. 7, Tab. 4 and Tab. 6 generating models against
    // all eleven structures.
    let targets = [("A1", TAB7_A1), ("A2", TAB4_A2), ("B2", TAB6_B2)];
    let mut worst = (Duration::ZERO, String::new());
    for (gen, v) in targets {
        let target = Target::from_model_f64(&model(gen), &v).unwrap();
        for (id, ..) in PAPER_IDS {
            let (r, dt) = timed(&model(id), &target);
            check_all(&model(id), &r, &target);
            if dt > worst.0 {
                worst = (dt, format!("{id} for the {gen} target"));
            }
        }
    }
    println!("slowest: {} in {:?}", worst.1, worst.0);
    // Generous for unoptimised builds; a release build needs milliseconds.
    assert!(worst.0 < Duration::from_secs(2), "{worst:?}");
}
