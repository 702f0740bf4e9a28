//! Whether a verdict holds on other cuts of the same record.
//!
//! A verdict read from one H1 estimate may be an accident of its segment
//! length (a sharp antiresonance one line wide) or of one stretch of the
//! record (a disturbance, a drift). [`verdict_stability`] identifies again
//! from each half of the record, at the same segment length, and from the
//! whole record at half the segment length (twice the averages, half the
//! resolution; periodic records have their period fixed, so only the
//! halves), and compares the FRF type and the best structure with the
//! verdict on the whole record. A verdict that flips is uncertain.
//!
//! ```
//! use frf::welch::{h1, WelchOptions};
//! use ident::identify::{identify, IdentifyOptions};
//! use ident::stability::verdict_stability;
//! use mms::response::Effects;
//! use mms::simulate::{SimOptions, Simulator};
//! use mms::{Model, Output};
//!
//! // A two-mass drive driven by white noise, sensed at the motor.
//! let model = Model::from_id("N2-g0-a1.0-s1.0")?;
//! // m1, m2, c12, d12: antiresonance 112 Hz, resonance 159 Hz
//! let p = [1e-3, 1e-3, 5e2, 0.01];
//! let fs = 2000.0;
//! let mut state = 9u64;
//! let u: Vec<f64> = (0..65536)
//!     .map(|_| {
//!         state ^= state << 13; state ^= state >> 7; state ^= state << 17;
//!         (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
//!     })
//!     .collect();
//! let sim = Simulator::with_parts(&model, Output::Position, &p, 1.0, &Effects::default(), fs, &SimOptions::default())?;
//! let y = sim.run(&u)?;
//! let est = h1(&u, &y, fs, &WelchOptions::default())?;
//! let options = IdentifyOptions::default();
//! let id = identify(&est.frf, Output::Position, &options)?;
//! let samples = frf::Samples { u, y, fs, excitation: None };
//! let s = verdict_stability(&samples, &WelchOptions::default(), est.nfft, Output::Position, &options, &id);
//! assert_eq!(s.runs.len(), 3);
//! assert!(s.stable(), "{s:?}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::identify::{identify, Identification, IdentifyOptions};
use frf::welch::WelchOptions;
use frf::Samples;
use mms::Output;
use serde::Serialize;

/// Which cut of the record a rerun used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "cut", content = "nfft")]
pub enum Cut {
    /// The first half of the samples, same segment length.
    FirstHalf,
    /// The second half, same segment length.
    SecondHalf,
    /// The whole record at this (shorter) segment length.
    SegmentLength(usize),
}

/// The verdict of one rerun.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rerun {
    /// The cut.
    pub cut: Cut,
    /// Its FRF type, `None` when it could not be identified.
    pub frf_type: Option<String>,
    /// Its best group of indistinguishable structures.
    pub best_group: Vec<String>,
    /// Why it could not be identified, if it could not.
    pub error: Option<String>,
    /// Same FRF type as the whole record's verdict.
    pub same_type: bool,
    /// The whole record's best structure is in this run's best group.
    pub same_structure: bool,
}

/// The reruns of a verdict; see the module docs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stability {
    /// One per cut.
    pub runs: Vec<Rerun>,
}

impl Stability {
    /// No rerun flipped the type or the best structure.
    pub fn stable(&self) -> bool {
        self.runs.iter().all(|r| r.same_type && r.same_structure)
    }
}

/// Reruns the identification of the recording's `samples` (estimated with
/// `welch` at segment length `nfft` into `verdict`; from the excitation if
/// the samples have one) on the halves of the record and at half the
/// segment length; see the module docs.
pub fn verdict_stability(
    samples: &Samples,
    welch: &WelchOptions,
    nfft: usize,
    output: Output,
    options: &IdentifyOptions,
    verdict: &Identification,
) -> Stability {
    let n = samples.u.len().min(samples.y.len());
    let half = n / 2;
    let same = WelchOptions {
        nfft: welch.period.is_none().then_some(nfft),
        ..welch.clone()
    };
    let mut cuts: Vec<(Cut, std::ops::Range<usize>, WelchOptions)> = vec![
        (Cut::FirstHalf, 0..half, same.clone()),
        (Cut::SecondHalf, half..n, same),
    ];
    if welch.period.is_none() && nfft >= 128 {
        cuts.push((
            Cut::SegmentLength(nfft / 2),
            0..n,
            WelchOptions {
                nfft: Some(nfft / 2),
                ..welch.clone()
            },
        ));
    }
    let want_type = verdict.classification.frf_type.to_string();
    let want_best = verdict.candidates.first().map(|c| c.id.clone());
    let runs = cuts
        .into_iter()
        .map(|(cut, range, w)| {
            let result = samples
                .frf(range, &w)
                .map_err(|e| e.to_string())
                .and_then(|frf| identify(&frf, output, options).map_err(|e| e.to_string()));
            match result {
                Ok(id) => {
                    let frf_type = id.classification.frf_type.to_string();
                    let best_group = id.indistinguishable.first().cloned().unwrap_or_default();
                    Rerun {
                        cut,
                        same_type: frf_type == want_type,
                        same_structure: want_best.as_ref().is_some_and(|b| best_group.contains(b)),
                        frf_type: Some(frf_type),
                        best_group,
                        error: None,
                    }
                }
                Err(e) => Rerun {
                    cut,
                    frf_type: None,
                    best_group: Vec::new(),
                    error: Some(e),
                    same_type: false,
                    same_structure: false,
                },
            }
        })
        .collect();
    Stability { runs }
}
