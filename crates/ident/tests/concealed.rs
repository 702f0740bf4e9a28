//! A fixed slice of the concealed-effect benchmark ([`ident::concealed`],
//! `mms benchmark`): the first 100 cases of one seed, diagnosed and (the
//! controls) identified, with the scores asserted against thresholds.
//! The targets are for the large run on a fresh seed (docs/diagnosis.md);
//! this slice guards against regressions: its thresholds sit a few cases
//! below what the slice measured when they were set, so that a change
//! that loses more fails here.

use ident::concealed::{case, run_case, Outcome, Summary};
use rayon::prelude::*;

/// The slice's seed and size.
const SEED: u64 = 20_261_207;
const CASES: usize = 100;

#[test]
fn a_fixed_slice_of_the_benchmark_scores_above_its_thresholds() {
    let outcomes: Vec<Outcome> = (0..CASES)
        .into_par_iter()
        .map(|i| run_case(&case(SEED, i).expect("a case")))
        .collect();
    let s = Summary::of(&outcomes);
    for o in &outcomes {
        if !o.right {
            eprintln!(
                "case {}: {} {:?} concealed {:?} -> {} ({})",
                o.index,
                o.cell.excitation,
                o.cell.closed_loop,
                o.concealed.iter().map(|c| c.kind).collect::<Vec<_>>(),
                o.headline.as_str(),
                o.reason
            );
        }
    }
    eprintln!(
        "effects {}/{}, controls {}/{}, identification {}/{} and {}/{}",
        s.effect_right.hits,
        s.effect_right.of,
        s.controls_clean.hits,
        s.controls_clean.of,
        s.identified[0].hits,
        s.identified[0].of,
        s.identified[1].hits,
        s.identified[1].of
    );
    assert_eq!(s.errors, 0, "a diagnosis failed");
    assert!(s.effect_right.rate() >= EFFECTS, "{:?}", s.effect_right);
    assert!(
        s.controls_clean.rate() >= CONTROLS,
        "{:?}",
        s.controls_clean
    );
    let identified = ident::concealed::Share {
        hits: s.identified[0].hits + s.identified[1].hits,
        of: s.identified[0].of + s.identified[1].of,
    };
    assert!(identified.rate() >= IDENTIFIED, "{identified:?}");
    // Where the headline is right, its parameter is near the truth.
    let within = s
        .parameter_within_15
        .values()
        .fold((0, 0), |(h, n), x| (h + x.hits, n + x.of));
    assert!(
        within.0 as f64 >= PARAMETERS * within.1 as f64,
        "{within:?}"
    );
}

/// Thresholds of the slice (see the module documentation), set when the
/// slice measured 38 of 54 effects right, 44 of 46 controls clean and 33
/// of 46 controls identified (generator version 4); version 5, whose dead
/// times of a fraction of a sample are kept, measures 39 of 54, 44 of 46
/// and 33 of 46 (with the sampled FRF compared exactly).
const EFFECTS: f64 = 0.65;
const CONTROLS: f64 = 0.91;
const IDENTIFIED: f64 = 0.65;
const PARAMETERS: f64 = 0.75;

/// The generator makes what the benchmark claims (checked case by case
/// against its specification, on another seed than the slice): chains of
/// 2 to 5 masses (one more with an extra mode), at most two concealed
/// effects, each where it can show (Coulomb friction, backlash and offset
/// in time records, an offset only inside a loop, hysteretic damping only
/// in FRF files), time records of 10^4 to 10^6 samples of a position or
/// velocity, every nominal parameter within 30 % of the truth's, and the
/// controls at least a quarter of 120 cases (a third is drawn: 35 %).
#[test]
fn the_generator_draws_what_the_benchmark_claims() {
    use ident::concealed::Record;
    use ident::diagnose::EffectKind;
    let cases: Vec<_> = (0..120)
        .into_par_iter()
        .map(|i| case(SEED + 1, i).expect("a case"))
        .collect();
    let mut controls = 0;
    for c in &cases {
        let n = c.nominal.model.n_masses();
        assert!((2..=5).contains(&n), "case {}: {n} masses", c.index);
        let kinds: Vec<EffectKind> = c.concealed.iter().map(|x| x.kind).collect();
        assert!(kinds.len() <= 2, "case {}: {kinds:?}", c.index);
        controls += usize::from(kinds.is_empty());
        let extra = kinds.contains(&EffectKind::ExtraMode);
        assert_eq!(c.truth.model.n_masses(), n + usize::from(extra));
        if !extra {
            let (t, m) = (c.truth.parameters.values(), c.nominal.parameters.values());
            for (a, b) in t.iter().zip(m.iter()) {
                assert!(
                    (b / a - 1.0).abs() <= 0.3 + 1e-9,
                    "case {}: {a} {b}",
                    c.index
                );
            }
        }
        let time_kind = |k: &EffectKind| {
            matches!(
                k,
                EffectKind::CoulombFriction | EffectKind::Backlash | EffectKind::Offset
            )
        };
        match &c.record {
            Record::Frf { frf, .. } => {
                assert!(!kinds.iter().any(time_kind), "case {}", c.index);
                assert_eq!(frf.len(), c.sensors.len());
            }
            Record::Time {
                samples,
                closed_loop,
                ..
            } => {
                let len = samples[0].u.len();
                assert!(
                    (10_000..=1_000_000).contains(&len),
                    "case {}: {len}",
                    c.index
                );
                assert!(!kinds.contains(&EffectKind::HystereticDamping));
                if kinds.contains(&EffectKind::Offset) {
                    assert!(closed_loop.is_some(), "case {}", c.index);
                }
                assert!(
                    matches!(
                        c.nominal.output,
                        mms::Output::Position | mms::Output::Velocity
                    ),
                    "case {}",
                    c.index
                );
            }
        }
    }
    assert!(4 * controls >= cases.len(), "{controls} controls");
}
