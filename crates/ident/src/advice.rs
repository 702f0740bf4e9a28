//! Which extra sensor would separate candidates that one FRF cannot.
//!
//! Candidates that fit the measured FRF equally well still predict
//! different motions of their other masses. For each mass `k` (counted
//! from the ground side of the chain, the paper's numbering) this module
//! compares what a position sensor at mass `k` would read under each pair
//! of candidates, over the measured band, and reports the sensors that
//! tell the pairs apart: the paper's proposed future work of temporary
//! extra sensors, made concrete.
//!
//! ```
//! use ident::advice::{sensor_advice, Candidate};
//! use mms::response::Parameters;
//! use mms::Model;
//!
//! // The paper's Sec. 5: A5 reproduces the FRF of A2 exactly (Tab. 4's A2;
//! // this A5 is its mirror image, one member of the exact family).
//! let a2 = Model::from_id("A2")?;
//! let a5 = Model::from_id("A5")?;
//! let p2 = Parameters::from_values(&a2, vec![0.01, 0.01, 0.02, 100.0, 100.0, 0.01, 0.01])?;
//! let p5 = Parameters::from_values(&a5, vec![0.02, 0.01, 0.01, 100.0, 100.0, 0.01, 0.01])?;
//! let freq: Vec<f64> = (1..=200).map(|k| 0.5 * k as f64).collect();
//! let advice = sensor_advice(
//!     &[Candidate { name: "A2".into(), model: a2, parameters: p2, gain: 1.0 },
//!       Candidate { name: "A5".into(), model: a5, parameters: p5, gain: 1.0 }],
//!     &freq,
//!     3.0,
//! )?;
//! // They predict different motions of the other masses: an extra sensor
//! // separates them (on this band, one at any of the three masses does).
//! assert!(!advice.is_empty());
//! assert!(advice[0].min_difference_db > 3.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use mms::response::{ChainResponse, Parameters, ResponseError};
use mms::{Model, Output};
use serde::Serialize;

/// One fitted candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// Name in reports (the paper ID or generic ID).
    pub name: String,
    /// The structure.
    pub model: Model,
    /// Its fitted parameters.
    pub parameters: Parameters,
    /// Its fitted gain.
    pub gain: f64,
}

/// An extra position sensor and the candidate pairs it separates.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorAdvice {
    /// The mass the sensor reads, counted from the ground side (1-based).
    pub mass: usize,
    /// The pairs of candidate names it separates.
    pub separates: Vec<(String, String)>,
    /// Over the separated pairs, the smallest RMS difference (dB) of the
    /// readings the two candidates predict.
    pub min_difference_db: f64,
}

/// The sensors (one per mass that exists in every candidate) that separate
/// at least one pair of `candidates` by more than `threshold_db` RMS over
/// `freq_hz`; best first: most pairs separated, then largest smallest
/// difference, then lowest mass index.
pub fn sensor_advice(
    candidates: &[Candidate],
    freq_hz: &[f64],
    threshold_db: f64,
) -> Result<Vec<SensorAdvice>, ResponseError> {
    let Some(n) = candidates.iter().map(|c| c.model.n_masses()).min() else {
        return Ok(Vec::new());
    };
    // by_mass[k][c][f]: the reading of a sensor at mass k+1 under
    // candidate c at line f.
    let mut by_mass = vec![Vec::with_capacity(candidates.len()); n];
    for c in candidates {
        let g = ChainResponse::new(&c.model, Output::Position);
        let mut per_mass = vec![Vec::with_capacity(freq_hz.len()); n];
        for &f in freq_hz {
            let x = g.mass_positions(c.parameters.values(), f)?;
            for (slot, xk) in per_mass.iter_mut().zip(x) {
                slot.push(xk * c.gain);
            }
        }
        for (k, reading) in per_mass.into_iter().enumerate() {
            by_mass[k].push(reading);
        }
    }
    let mut out = Vec::new();
    for (k, readings) in by_mass.iter().enumerate() {
        let mut separates = Vec::new();
        let mut min_diff = f64::INFINITY;
        for i in 0..candidates.len() {
            for j in i + 1..candidates.len() {
                let d = rms_db(&readings[i], &readings[j]);
                if d > threshold_db {
                    separates.push((candidates[i].name.clone(), candidates[j].name.clone()));
                    min_diff = min_diff.min(d);
                }
            }
        }
        if !separates.is_empty() {
            out.push(SensorAdvice {
                mass: k + 1,
                separates,
                min_difference_db: min_diff,
            });
        }
    }
    out.sort_by(|a, b| {
        b.separates
            .len()
            .cmp(&a.separates.len())
            .then(b.min_difference_db.total_cmp(&a.min_difference_db))
            .then(a.mass.cmp(&b.mass))
    });
    Ok(out)
}

/// RMS of `20 log10 |a/b|` over the lines where both are non-zero; a
/// reading that is identically zero under one candidate and not under the
/// other counts as infinitely different.
fn rms_db(a: &[num_complex::Complex64], b: &[num_complex::Complex64]) -> f64 {
    let mut s = 0.0;
    let mut n = 0usize;
    for (x, y) in a.iter().zip(b) {
        let (nx, ny) = (x.norm(), y.norm());
        if nx == 0.0 && ny == 0.0 {
            continue;
        }
        if nx == 0.0 || ny == 0.0 {
            return f64::INFINITY;
        }
        s += (20.0 * (nx / ny).log10()).powi(2);
        n += 1;
    }
    if n == 0 {
        0.0
    } else {
        (s / n as f64).sqrt()
    }
}
