//! Identification of an FRF with far more lines than it needs.

use frf::{Complex64, Frf};
use ident::identify::{identify, IdentifyOptions, MAX_LINES};
use ident::notes::IdentifyNote;
use mms::response::ChainResponse;
use mms::xorshift::XorShift;
use mms::{Model, Output, Port};

/// A million lines of a free two-mass drive with 1 % noise per line: the
/// lines are averaged into bins (linear work), the type and structure are
/// a collocated two-mass drive's, and the parameters come back within
/// 0.5 % of the truth. Before the bins, the classification's work grew with
/// the square of the lines (over 5 minutes for this FRF).
#[test]
fn a_million_lines_are_identified_on_their_bins() {
    let drive = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    let truth = [0.02, 0.05, 3000.0, 0.2];
    let n = 1_000_000;
    let f: Vec<f64> = (0..n)
        .map(|k| 1.0 + 999.0 * k as f64 / (n - 1) as f64)
        .collect();
    let mut rng = XorShift::new(9);
    let h: Vec<Complex64> = ChainResponse::new(&drive, Output::Position)
        .eval_many(&truth, &f)
        .unwrap()
        .into_iter()
        .map(|z| {
            let e = Complex64::new(rng.normal(), rng.normal()) * (0.01 / 2f64.sqrt());
            z * (Complex64::new(1.0, 0.0) + e)
        })
        .collect();
    let frf = Frf::new(f, h, None).unwrap();
    let start = std::time::Instant::now();
    let id = identify(&frf, Output::Position, &IdentifyOptions::default()).unwrap();
    eprintln!("{:.2} s", start.elapsed().as_secs_f64());
    assert_eq!(id.classification.frf_type.to_string(), "AR");
    assert!(
        id.notes.contains(&IdentifyNote::Binned {
            lines: n,
            max_bins: MAX_LINES
        }),
        "{:?}",
        id.notes
    );
    let best = id
        .candidates
        .iter()
        .find(|c| c.model == drive)
        .expect("the collocated drive is a candidate");
    // Ranked first or among the structures the FRF cannot tell from the
    // first (the grounded twin N2-g1-a2.1-s2.1 has the same FRFs).
    assert!(
        id.indistinguishable[0].contains(&best.id),
        "{:?}",
        id.indistinguishable
    );
    for (got, want) in best.fit.parameters.values().iter().zip(truth) {
        assert!((got / want - 1.0).abs() < 0.005, "{got} vs {want}");
    }
}
