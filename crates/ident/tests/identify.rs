//! Identification where the grid is coarser than the features: the
//! multisine grids of a short period.

use frf::Frf;
use ident::identify::{identify, IdentifyOptions};
use ident::notes::IdentifyNote;
use mms::response::{ChainResponse, Parameters};
use mms::{Model, Output, Port};
use num_complex::Complex64;

/// The FRF of `model` at `values` on the odd multiples of 2 Hz from 2 to
/// 38 Hz (a 4 Hz grid), noise-free.
fn coarse_frf(model: &Model, output: Output, values: &[f64]) -> Frf {
    let freq: Vec<f64> = (0..10).map(|k| 2.0 + 4.0 * k as f64).collect();
    let r = ChainResponse::new(model, output);
    let h: Vec<Complex64> = freq.iter().map(|&f| r.eval(values, f).unwrap()).collect();
    Frf::new(freq, h, None).unwrap()
}

/// A free two-mass drive read at the motor whose antiresonance (16.0 Hz)
/// and resonance (19.6 Hz) both fall between lines 4 Hz apart: no line
/// shows both, and the type read excludes the drive. The fits of the
/// structures that show the type miss the lines by far more than their
/// scatter; the other structures are fitted too, and the generating one is
/// among the best.
#[test]
fn a_mode_between_the_lines_is_found_from_the_fit() {
    let drive = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    // Antiresonance sqrt(c / m2), resonance sqrt(c (1/m1 + 1/m2)): with
    // m1 = 1, m2 = 0.5 their ratio is sqrt(1.5).
    let (m1, m2) = (1.0, 0.5);
    let c = m2 * (2.0 * std::f64::consts::PI * 16.0_f64).powi(2);
    let d = 0.002 * 2.0 * (c * m2).sqrt();
    let p = Parameters::from_values(&drive, vec![m1, m2, c, d]).unwrap();
    let frf = coarse_frf(&drive, Output::Position, p.values());
    let id = identify(&frf, Output::Position, &IdentifyOptions::default()).unwrap();
    // The type read misses a feature, so it excludes the drive: the lines
    // decide instead (with a mode more, or with every 2-mass structure).
    assert_ne!(id.classification.frf_type.to_string(), "AR");
    assert!(
        id.notes.iter().any(|n| matches!(
            n,
            IdentifyNote::MassesFromFit { masses: 2, .. }
                | IdentifyNote::TypeOpened { masses: 2, .. }
        )),
        "{:?}",
        id.notes
    );
    assert_eq!(id.masses, 2);
    let truth = drive.name();
    assert!(
        id.indistinguishable[0].contains(&truth),
        "{:?}",
        id.indistinguishable
    );
    // The masses come back from the lines alone (the gain is known).
    let best = id.candidates.iter().find(|k| k.id == truth).unwrap();
    for (got, want) in best.fit.parameters.values().iter().zip([m1, m2, c]) {
        assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
    }
}

/// The load of that drive, read from the motor's force, with its
/// resonance (1.5 Hz) below the first line (2 Hz): above the resonance
/// the load's inertance is negative, so the level read below the
/// features says the sensor counts the other way. The fits of that
/// polarity miss the lines, and those of the sensor's own explain them.
#[test]
fn a_polarity_read_above_a_missed_resonance_is_corrected_by_the_fit() {
    let drive = Model::new(2, 0, Port::new(1, 0), Port::new(2, 0)).unwrap();
    let (m1, m2) = (1.0, 0.5);
    let c = (2.0 * std::f64::consts::PI * 1.5_f64).powi(2) / (1.0 / m1 + 1.0 / m2);
    let d = 0.002 * 2.0 * (c * m2).sqrt();
    let p = Parameters::from_values(&drive, vec![m1, m2, c, d]).unwrap();
    let frf = coarse_frf(&drive, Output::Position, p.values());
    let id = identify(&frf, Output::Position, &IdentifyOptions::default()).unwrap();
    assert!(!id.sensor_reversed, "{:?}", id.notes);
    // The scale the report states is the one the fits used.
    assert!(id
        .notes
        .iter()
        .any(|n| matches!(n, IdentifyNote::GainKnown { gain } if *gain == 1.0)));
    assert!(id
        .notes
        .iter()
        .any(|n| matches!(n, IdentifyNote::PolarityFromFit { .. })));
    assert_eq!(id.masses, 2);
    assert!(
        id.indistinguishable[0].contains(&drive.name()),
        "{:?}",
        id.indistinguishable
    );
}
