//! Moment invariants, determinable parameters and structural equivalence
//! against Tab. 5 and Sec. 5 of the paper.

use mms::{
    degradation_free_models, equivalence_classes, identical_transfer_functions, identifiability,
    identifiability_with, moment_invariants, rule3_models, structural_equivalences,
    EquivalenceReason, Model, ParameterRenaming, Port, RankCertificate, RankOptions, Symmetry,
    TfPart, UndampedTf, OMEGA, PAPER_IDS,
};
use poly::{Poly, Rat};
use std::collections::BTreeMap;

fn model(id: &str) -> Model {
    Model::from_id(id).unwrap()
}

#[test]
fn tab5_is_reproduced_and_proven() {
    for (id, determinable, invariants) in mms::paper::TAB5 {
        let r = identifiability(&model(id));
        assert_eq!(r.parameters.len(), 5, "{id}");
        assert_eq!(r.nonconstant_invariants, invariants, "{id}");
        assert_eq!(r.determinable_parameters, determinable, "{id}");
        assert!(r.is_proven(), "{id}");
        assert_eq!(r.rank_upper_bound, determinable, "{id}");
        assert!(r.scaling_symmetries.is_empty(), "{id}");
        // Counting proves every entry but the rank-deficient B2, C2, C4,
        // which need the symbolic elimination.
        let expected = if determinable < invariants {
            RankCertificate::SymbolicElimination
        } else {
            RankCertificate::Counting
        };
        assert_eq!(r.certificate, expected, "{id}");
    }
}

#[test]
fn tab5_sampled_rank_agrees_without_symbolic_elimination() {
    let sampled_only = RankOptions {
        symbolic_work_limit: 0,
        ..RankOptions::default()
    };
    for (id, determinable, invariants) in mms::paper::TAB5 {
        let r = identifiability_with(&model(id), &sampled_only);
        assert_eq!(r.determinable_parameters, determinable, "{id}");
        if determinable < invariants {
            assert_eq!(r.certificate, RankCertificate::Sampled, "{id}");
            assert_eq!(r.rank_upper_bound, invariants, "{id}");
        }
        // Another seed gives the same rank.
        let other = RankOptions {
            seed: 12345,
            ..RankOptions::default()
        };
        assert_eq!(
            identifiability_with(&model(id), &other).determinable_parameters,
            determinable,
            "{id}"
        );
    }
}

/// Reverses the coefficients in Omega: the constant coefficient of the
/// denominator becomes the leading one.
fn reversed(tf: &UndampedTf) -> UndampedTf {
    let d = tf.num.degree(OMEGA).max(tf.den.degree(OMEGA)) as usize;
    let rev = |p: &Poly| {
        let mut c = p.coeffs_in(OMEGA);
        c.resize(d + 1, Poly::zero());
        c.reverse();
        Poly::from_coeffs_in(OMEGA, &c)
    };
    UndampedTf {
        num: rev(&tf.num),
        den: rev(&tf.den),
    }
}

#[test]
fn normalizing_by_the_constant_denominator_coefficient_counts_the_same() {
    // The paper normalizes "the first denominator coefficient"; whichever
    // end that is, the count of non-constant invariants is the same.
    for (id, _, invariants) in mms::paper::TAB5 {
        let tf = model(id).undamped_tf();
        let inv = moment_invariants(&reversed(&tf));
        let nonconstant = inv.iter().filter(|i| !i.is_constant()).count();
        assert_eq!(nonconstant, invariants, "{id}");
    }
}

#[test]
fn invariants_of_a2_follow_eqs_21_and_10() {
    let r = identifiability(&model("A2"));
    let text: Vec<String> = r.invariants.iter().map(|i| i.to_string()).collect();
    assert_eq!(
        text,
        [
            "Num Omega^1: -c12/(m1*m2)",
            "Num Omega^0: c12*c23/(m1*m2*m3)",
            "Den Omega^2: 1",
            "Den Omega^1: (-c12*m1*m3 - c12*m2*m3 - c23*m1*m2 - c23*m1*m3)/(m1*m2*m3)",
            "Den Omega^0: (c12*c23*m1 + c12*c23*m2 + c12*c23*m3)/(m1*m2*m3)",
        ]
    );
    assert_eq!(r.numerator_powers(), [1, 0]);
    assert_eq!(r.denominator_powers(), [2, 1, 0]);
    let lead = &r.invariants[2];
    assert_eq!(lead.part, TfPart::Denominator);
    assert_eq!(lead.constant_value(), Some(Rat::from(1)));
    assert_eq!(r.invariants[0].sign_on_positive_parameters(), Some(-1));
}

#[test]
fn invariants_determine_the_transfer_function() {
    // Rebuilding num/den from the invariants gives the TF divided by lc(den).
    let mut rng = 7u64;
    for m in rule3_models(3).unwrap() {
        let tf = m.undamped_tf();
        let inv = moment_invariants(&tf);
        let point: BTreeMap<String, Rat> = m
            .undamped_parameters()
            .into_iter()
            .map(|p| {
                rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1);
                (p, Rat::from((rng >> 40) as i64 % 97 + 1))
            })
            .collect();
        let lead = tf.den.lead_in(OMEGA).eval(&point).unwrap();
        for i in &inv {
            let p = match i.part {
                TfPart::Numerator => &tf.num,
                TfPart::Denominator => &tf.den,
            };
            let coef = p.coeffs_in(OMEGA)[i.power as usize].eval(&point).unwrap();
            assert_eq!(i.eval(&point).unwrap(), &coef / &lead, "{m} {i}");
        }
    }
}

#[test]
fn a2_and_a5_are_structurally_equivalent() {
    // Sec. 5, first example: same symbolic form, all 4 non-constant
    // invariants independent in both (Vajda's criterion).
    let a2 = identifiability(&model("A2"));
    let a5 = identifiability(&model("A5"));
    assert!(a2.same_form(&a5));
    assert!(a2.invariants_independent() && a5.invariants_independent());
    assert!(a2.structurally_equivalent_by_invariants(&a5));
    // Stronger: A5 is the mirrored A2 with actuator and sensor swapped, so
    // the transfer functions are identical after m1 <-> m3, c12 <-> c23.
    assert_eq!(model("A5"), model("A2").mirrored().reciprocal());
    let (renaming, factor) = identical_transfer_functions(&model("A2"), &model("A5")).unwrap();
    assert_eq!(renaming, ParameterRenaming::Mirror);
    assert!(factor.is_one());
    let groups = structural_equivalences(&[model("A2"), model("A5")]);
    assert_eq!(groups.len(), 1);
    assert_eq!(groups[0].models(), [model("A2"), model("A5")]);
}

#[test]
fn c2_and_c4_are_identical_by_reciprocity() {
    let (c2, c4) = (model("C2"), model("C4"));
    assert_eq!(c4, c2.reciprocal());
    assert_eq!(c2.undamped_tf(), c4.undamped_tf());
    let (renaming, factor) = identical_transfer_functions(&c2, &c4).unwrap();
    assert_eq!(renaming, ParameterRenaming::Identity);
    assert!(factor.is_one());
    let groups = structural_equivalences(&[c4, c2]);
    assert_eq!(groups.len(), 1);
    assert_eq!(groups[0].representative, c4);
    assert_eq!(
        groups[0].members[0].reason,
        EquivalenceReason::IdenticalTransferFunction {
            renaming: ParameterRenaming::Identity,
            factor: Rat::from(1),
        }
    );
}

#[test]
fn c2_is_not_equivalent_to_b2() {
    // Sec. 5, second example: same form, but only 4 of 5 determinable.
    let b2 = identifiability(&model("B2"));
    let c2 = identifiability(&model("C2"));
    assert!(b2.same_form(&c2));
    assert!(!b2.structurally_equivalent_by_invariants(&c2));
    assert!(structural_equivalences(&[model("B2"), model("C2")]).is_empty());
}

#[test]
fn groups_of_the_eleven_paper_models() {
    let models: Vec<Model> = PAPER_IDS.iter().map(|(id, ..)| model(id)).collect();
    let groups = structural_equivalences(&models);
    let names: Vec<Vec<String>> = groups
        .iter()
        .map(|g| g.models().iter().map(Model::name).collect())
        .collect();
    assert_eq!(
        names,
        [
            vec!["A1", "A4", "B1", "C1", "C3"],
            vec!["A2", "A5"],
            vec!["C2", "C4"],
        ]
    );
    // The collocated group is held together by Vajda's criterion.
    assert!(groups[0]
        .members
        .iter()
        .all(|e| e.reason == EquivalenceReason::IndependentMomentInvariants));
    // Duplicates in the input change nothing.
    let mut twice = models.clone();
    twice.extend(models.iter().rev());
    assert_eq!(structural_equivalences(&twice), groups);
}

#[test]
fn mirrored_and_reciprocal_models_have_identical_transfer_functions() {
    for m in degradation_free_models(4).unwrap() {
        for other in [m.mirrored(), m.reciprocal(), m.mirrored().reciprocal()] {
            let (_, factor) = identical_transfer_functions(&m, &other).unwrap();
            assert!(factor.is_one(), "{m}");
        }
        assert_eq!(
            identical_transfer_functions(&m, &m.reciprocal()).unwrap().0,
            ParameterRenaming::Identity
        );
    }
    let a2 = model("A2");
    assert_eq!(
        identical_transfer_functions(&a2, &a2.mirrored()).unwrap().0,
        ParameterRenaming::Mirror
    );
}

#[test]
fn swapping_only_the_plus_points_keeps_the_transfer_function() {
    // With a gap the chain splits into a grounded block G and a free block
    // F, and the receptance is F[meas+][act+] + G[meas-][act-]: swapping
    // only the plus points (or only the minus points) of actuator and sensor
    // keeps it, by the symmetry of F (resp. G). For 3 masses this is plain
    // reciprocity or mirroring up to 4 masses; from 5 masses on it relates
    // models of different renumbering-and-reciprocity classes.
    let p = Port::new;
    let a = Model::new(5, 2, p(3, 1), p(4, 2)).unwrap();
    let b = Model::new(5, 2, p(4, 1), p(3, 2)).unwrap();
    assert!(!a.orbit(Symmetry::RenumberingAndReciprocity).contains(&b));
    assert_eq!(
        identical_transfer_functions(&a, &b),
        Some((ParameterRenaming::Identity, Rat::from(1)))
    );
    let groups = structural_equivalences(&[a, b]);
    assert_eq!(groups.len(), 1);
    assert_eq!(groups[0].models(), [a, b]);
}

#[test]
fn n4_ranks_are_bounded_and_proven() {
    let classes = equivalence_classes(4, Symmetry::Renumbering).unwrap();
    assert_eq!(classes.len(), 30);
    let mut deficient = 0;
    for class in &classes {
        let first = identifiability(&class[0]);
        for m in class {
            let r = identifiability(m);
            let k = r.parameters.len();
            assert_eq!(k, 7, "{m}");
            assert!(
                r.determinable_parameters <= k.min(r.nonconstant_invariants),
                "{m}"
            );
            assert!(r.determinable_parameters <= r.rank_upper_bound, "{m}");
            assert!(r.is_proven(), "{m}");
            assert!(r.scaling_symmetries.is_empty(), "{m}");
            // Renumbering renames the parameters and changes nothing else.
            assert_eq!(r.determinable_parameters, first.determinable_parameters);
            assert_eq!(r.nonconstant_invariants, first.nonconstant_invariants);
            assert!(r.same_form(&first), "{m}");
        }
        // Rank-deficient: exactly gap >= 1 with actuator and sensor not
        // collocated (B2, C2, C4 for three masses).
        let m = class[0];
        let expect_deficient = m.gap() >= 1 && !m.is_collocated();
        assert_eq!(!first.invariants_independent(), expect_deficient, "{m}");
        deficient += usize::from(expect_deficient);
    }
    assert_eq!(deficient, 15);
}

#[test]
fn n4_equivalence_groups_contain_the_reciprocity_classes() {
    let models = degradation_free_models(4).unwrap();
    let groups = structural_equivalences(&models);
    for class in equivalence_classes(4, Symmetry::RenumberingAndReciprocity).unwrap() {
        if class.len() < 2 {
            continue;
        }
        let g = groups
            .iter()
            .find(|g| g.models().contains(&class[0]))
            .unwrap();
        for m in &class {
            assert!(g.models().contains(m), "{m}");
        }
    }
    // Every member of a group is related to its representative directly.
    for g in &groups {
        let rep = identifiability(&g.representative);
        for e in &g.members {
            match &e.reason {
                EquivalenceReason::IdenticalTransferFunction { renaming, factor } => {
                    assert_eq!(
                        identical_transfer_functions(&g.representative, &e.model),
                        Some((*renaming, factor.clone()))
                    );
                }
                EquivalenceReason::IndependentMomentInvariants => {
                    assert!(rep.structurally_equivalent_by_invariants(&identifiability(&e.model)));
                }
            }
        }
    }
}

#[test]
fn degraded_model_loses_the_hidden_parameters() {
    // Gap 1, actuator against the ground: m1 (and c1) never excited; the
    // common factor m1*Omega - c1 cancels and the invariants do not depend
    // on m1 or c1, which shows up as two scaling symmetries.
    let m = Model::new(3, 1, Port::new(2, 0), Port::new(2, 1)).unwrap();
    let r = identifiability(&m);
    assert_eq!(r.nonconstant_invariants, 3);
    assert_eq!(r.determinable_parameters, 3);
    assert_eq!(r.rank_upper_bound, 3);
    let sym: Vec<String> = r.scaling_symmetries.iter().map(|s| s.to_string()).collect();
    assert_eq!(sym, ["m1^1", "c1^1"]);
}

#[test]
fn one_mass() {
    let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    let r = identifiability(&m);
    assert_eq!(r.parameters, ["m1"]);
    assert_eq!(r.nonconstant_invariants, 1); // the gain 1/m1
    assert_eq!(r.determinable_parameters, 1);
    assert!(r.is_locally_identifiable());
}

#[test]
fn serializes_to_json() {
    let r = identifiability(&model("B2"));
    let v = serde_json::to_value(&r).unwrap();
    assert_eq!(v["determinable_parameters"], 4);
    assert_eq!(v["certificate"], "SymbolicElimination");
    assert_eq!(v["invariants"][0]["numerator"], "1");
    assert_eq!(v["invariants"][0]["denominator"], "m1");
    let g = structural_equivalences(&[model("C2"), model("C4")]);
    let v = serde_json::to_value(&g).unwrap();
    assert_eq!(
        v[0]["members"][0]["reason"]["IdenticalTransferFunction"]["factor"],
        "1"
    );
}
