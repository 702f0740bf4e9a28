//! Enumeration against Tab. 1 of the paper and equivalence classes against
//! a brute-force search over all renumberings.

use itertools::Itertools;
use mms::{Model, Symmetry};
use std::collections::BTreeMap;

#[test]
fn table_1_counts() {
    // Tab. 1: basic, degradation-free, + redundancy-free for N = 1..5.
    let basic = [1, 8, 34, 104, 259];
    let free = [1, 5, 17, 50, 129];
    let rule3 = [1, 3, 11, 29, 73];
    for n in 1..=5 {
        assert_eq!(
            mms::basic_models(n).unwrap().len(),
            basic[n - 1],
            "basic N={n}"
        );
        assert_eq!(
            mms::degradation_free_models(n).unwrap().len(),
            free[n - 1],
            "rule 2 N={n}"
        );
        assert_eq!(
            mms::rule3_models(n).unwrap().len(),
            rule3[n - 1],
            "rule 3 N={n}"
        );
    }
}

#[test]
fn basic_count_matches_closed_form() {
    // Rule (1) factorises: for each gap g there are (g+1)^2 (N-g)^2 choices.
    for n in 1..=mms::MAX_MASSES {
        let want: usize = (0..n).map(|g| (g + 1).pow(2) * (n - g).pow(2)).sum();
        assert_eq!(mms::basic_models(n).unwrap().len(), want);
        let want2: usize = (n * n) + (1..n).map(|g| g * g * (n - g).pow(2)).sum::<usize>();
        assert_eq!(mms::degradation_free_models(n).unwrap().len(), want2);
    }
}

#[test]
fn limits_are_errors() {
    assert_eq!(mms::basic_models(0), Err(mms::ModelError::NoMasses));
    assert!(matches!(
        mms::counts(mms::MAX_MASSES + 1),
        Err(mms::ModelError::TooManyMasses { .. })
    ));
}

#[test]
fn lists_are_sorted_and_unique() {
    for n in 1..=5 {
        let v = mms::basic_models(n).unwrap();
        assert!(v.windows(2).all(|w| w[0] < w[1]));
        for m in &v {
            assert_eq!(Model::from_id(&m.id()).unwrap(), *m);
        }
    }
}

/// Classes by brute force: union of every degradation-free model with every
/// image under every permutation of the masses 1..N that maps the chain onto
/// a chain (the definition of a renumbering), optionally also with the
/// reciprocal model.
fn brute_force_classes(n: usize, reciprocity: bool) -> Vec<Vec<Model>> {
    let models = mms::degradation_free_models(n).unwrap();
    let index: BTreeMap<Model, usize> = models.iter().enumerate().map(|(i, m)| (*m, i)).collect();
    let mut parent: Vec<usize> = (0..models.len()).collect();
    fn find(p: &mut [usize], i: usize) -> usize {
        let mut r = i;
        while p[r] != r {
            r = p[r];
        }
        p[i] = r;
        r
    }
    for perm in (1..=n).permutations(n) {
        let mut full = vec![0];
        full.extend(perm);
        for (i, m) in models.iter().enumerate() {
            if let Some(img) = m.renumber(&full) {
                let j = index[&img]; // images of degradation-free models are degradation-free
                let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                parent[a] = b;
            }
        }
    }
    if reciprocity {
        for (i, m) in models.iter().enumerate() {
            let j = index[&m.reciprocal()];
            let (a, b) = (find(&mut parent, i), find(&mut parent, j));
            parent[a] = b;
        }
    }
    let mut groups: BTreeMap<usize, Vec<Model>> = BTreeMap::new();
    for (i, m) in models.iter().enumerate() {
        let r = find(&mut parent, i);
        groups.entry(r).or_default().push(*m);
    }
    let mut out: Vec<Vec<Model>> = groups.into_values().collect();
    out.sort();
    out
}

#[test]
fn classes_match_brute_force_over_all_permutations() {
    for n in 1..=6 {
        for (sym, rec) in [
            (Symmetry::Renumbering, false),
            (Symmetry::RenumberingAndReciprocity, true),
        ] {
            let lib = mms::equivalence_classes(n, sym).unwrap();
            assert_eq!(lib, brute_force_classes(n, rec), "N={n} {sym:?}");
        }
    }
}

#[test]
fn class_counts_closed_form() {
    // Burnside, worked by hand: free part of length L = N - g has L^2
    // (act+, meas+) pairs, L of them... fixed by the reversal only when both
    // sit on the middle mass (L odd): 1 fixed pair. The grounded part gives
    // (g^2) choices of (act-, meas-) for g > 0, 1 for g = 0.
    for n in 1..=mms::MAX_MASSES {
        let want: usize = (0..n)
            .map(|g| {
                let l = n - g;
                let ground = if g == 0 { 1 } else { g * g };
                let fixed = if l % 2 == 1 { 1 } else { 0 };
                ground * (l * l + fixed) / 2
            })
            .sum();
        let got = mms::counts(n).unwrap();
        assert_eq!(got.classes, want, "N={n}");
    }
}

#[test]
fn renumbering_is_the_identity_on_the_grounded_part() {
    // A renumbering that moves a mass of the grounded part never maps the
    // chain onto a chain (gap > 0).
    for m in mms::degradation_free_models(4).unwrap() {
        for perm in (1..=4).permutations(4) {
            let mut full = vec![0];
            full.extend(perm.iter().copied());
            if let Some(img) = m.renumber(&full) {
                assert_eq!(img.gap(), m.gap());
                for (i, &p) in full.iter().enumerate().take(m.gap() + 1) {
                    assert_eq!(p, i, "{m} {full:?}");
                }
                assert!(img == m || img == m.mirrored());
            }
        }
    }
}

#[test]
fn paper_set_for_three_masses_is_one_per_class() {
    let r = mms::redundancy_report(3, Symmetry::Renumbering).unwrap();
    assert_eq!((r.rule3_count, r.class_count), (11, 11));
    assert!(r.rule3_is_exact());
    // With reciprocity as well, C2 ~ C4 (reciprocal) and A2 ~ A5 (A2's
    // reciprocal act (2,0), sensor (1,0) is the mirror image of A5): the
    // paper's Tab. 3 lists both pairs as "potentially similar".
    let r = mms::redundancy_report(3, Symmetry::RenumberingAndReciprocity).unwrap();
    let ids: Vec<Vec<String>> = r
        .rule3_duplicates
        .iter()
        .map(|c| c.iter().map(Model::name).collect())
        .collect();
    assert_eq!(ids, [["A2", "A5"], ["C2", "C4"]]);
    assert!(r.unrepresented.is_empty());
}

#[test]
fn rule3_versus_classes_for_four_and_five_masses() {
    // N = 4: 30 classes, rule (3) keeps 29: no class has two kept members,
    // one class has none: {act (2,0), sensor (1,0)} ~ {act (3,0), sensor (4,0)}.
    // Both violate n_act+ <= n_meas+ resp. n_act+ <= ceil(4/2); the class is
    // the reciprocal of the kept A-type model act (1,0), sensor (2,0).
    let r = mms::redundancy_report(4, Symmetry::Renumbering).unwrap();
    assert_eq!((r.rule3_count, r.class_count), (29, 30));
    assert!(r.rule3_duplicates.is_empty());
    let un: Vec<Vec<String>> = r
        .unrepresented
        .iter()
        .map(|c| c.iter().map(Model::id).collect())
        .collect();
    assert_eq!(un, [["N4-g0-a2.0-s1.0", "N4-g0-a3.0-s4.0"]]);
    for class in &r.unrepresented {
        // every unrepresented class is covered by the reciprocal of a kept model
        assert!(class.iter().any(|m| m.reciprocal().satisfies_rule3()));
    }
    let r5 = mms::redundancy_report(5, Symmetry::Renumbering).unwrap();
    assert_eq!(r5.rule3_count, 73);
    assert_eq!(r5.class_count, mms::counts(5).unwrap().classes);
    assert_eq!(
        r5.rule3_count + r5.unrepresented.len()
            - r5.rule3_duplicates
                .iter()
                .map(|d| d.len() - 1)
                .sum::<usize>(),
        r5.class_count
    );
}

#[test]
fn rule3_sits_between_the_two_notions_of_redundancy() {
    // Computed for N = 1..MAX_MASSES: rule (3) never keeps two renumberings
    // of one model, but from N = 4 on it misses renumbering classes; every
    // missed class is the reciprocal of a kept one, so rule (3) does cover
    // every class of renumbering + reciprocity (with duplicates from N = 3).
    for n in 1..=mms::MAX_MASSES {
        let r = mms::redundancy_report(n, Symmetry::Renumbering).unwrap();
        assert!(r.rule3_duplicates.is_empty(), "N={n}");
        assert_eq!(r.unrepresented.is_empty(), n <= 3, "N={n}");
        let r = mms::redundancy_report(n, Symmetry::RenumberingAndReciprocity).unwrap();
        assert!(r.unrepresented.is_empty(), "N={n}");
        assert_eq!(r.rule3_duplicates.is_empty(), n <= 2, "N={n}");
    }
}
