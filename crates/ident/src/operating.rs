//! Two recordings of one rig at different operating points (standstill
//! and moving, two speeds, two excitation levels), compared feature by
//! feature.
//!
//! Each recording is classified on its own ([`crate::classify`]); the
//! features in the type are then paired by kind and frequency:
//!
//! - Two features of one kind pair when their frequencies differ by less
//!   than [`PAIRING_RANGE`] (a factor). A pair whose frequencies differ by
//!   more than the *resolution* of the two, the larger of their half-power
//!   half-widths `zeta f` and two line spacings, is a shifted mode; within
//!   it the feature holds for both.
//! - A resonance that only one recording shows, below every feature of
//!   the other and inside the other's band, with the other's low band
//!   free of features (its motion there is the rigid body's), is a
//!   stiffness to ground that only that operating point has: at
//!   standstill, the pre-sliding (Dahl) friction on which the rotor rests.
//!   Its stiffness is `J (2 pi f)^2`, with the rigid-body inertia `J` read
//!   from the other recording's low band (`|H| = 1 / (J w^2)` for a
//!   position output), in the units of the recording's input per unit of
//!   its output.
//! - Any other feature of one recording only is listed as such.
//!
//! ```
//! use frf::{Complex64, Frf};
//! use ident::operating::{compare_operating_points, Finding};
//! use ident::{classify, ClassifyOptions};
//! use mms::Output;
//!
//! // A two-mass drive seen at the motor: free (moving) and held by a
//! // spring to ground on the motor (standstill).
//! let f: Vec<f64> = (1..=3000).map(|k| 0.05 * k as f64).collect();
//! let drive = |ground: f64| -> Frf {
//!     let (j1, j2, c, d) = (1e-3, 1e-3, 40.0, 0.002);
//!     let h = f.iter().map(|&f| {
//!         let s = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
//!         let a = j1 * s * s + d * s + c + ground + 0.02 * ground.sqrt() * s;
//!         let b = j2 * s * s + d * s + c;
//!         b / (a * b - (d * s + c) * (d * s + c))
//!     }).collect();
//!     Frf::new(f.clone(), h, None).unwrap()
//! };
//! let (moving, still) = (drive(0.0), drive(4.0));
//! let o = ClassifyOptions { band_hz: Some((1.0, 150.0)), ..Default::default() };
//! let cm = classify(&moving, Output::Position, &o).unwrap();
//! let cs = classify(&still, Output::Position, &o).unwrap();
//! let cmp = compare_operating_points(&cs, &still, &cm, &moving);
//! let Some(Finding::PreSlidingFriction { freq_hz, stiffness, .. }) = cmp.findings.first() else {
//!     panic!("{cmp:?}");
//! };
//! // sqrt(4 / 2e-3) / 2 pi = 7.1 Hz on the whole inertia of 2e-3.
//! assert!((freq_hz / 7.1 - 1.0).abs() < 0.05);
//! assert!((stiffness.unwrap() / 4.0 - 1.0).abs() < 0.15);
//! ```

use crate::classify::ser_feature;
use crate::{Classification, ClassifiedFeature};
use frf::Frf;
use mms::analysis::Feature;
use mms::Output;
use serde::Serialize;
use std::f64::consts::PI;

/// Largest ratio of the frequencies of two features that can pair.
pub const PAIRING_RANGE: f64 = 1.25;

/// Which of the two recordings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Recording {
    /// The first recording given.
    First,
    /// The second one.
    Second,
}

/// A feature of one kind in both recordings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PairedFeature {
    /// Resonance or antiresonance.
    #[serde(serialize_with = "ser_feature")]
    pub kind: Feature,
    /// Its frequency in the first and the second recording (Hz).
    pub freq_hz: (f64, f64),
    /// The relative shift `f2 / f1 - 1`.
    pub shift: f64,
    /// The relative resolution of the pair (see the module docs).
    pub resolution: f64,
    /// Whether the shift exceeds the resolution.
    pub shifted: bool,
}

/// A feature of one recording only.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoneFeature {
    /// The recording that shows it.
    pub recording: Recording,
    /// Resonance or antiresonance.
    #[serde(serialize_with = "ser_feature")]
    pub kind: Feature,
    /// Its frequency (Hz).
    pub freq_hz: f64,
}

/// What the comparison names.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Finding {
    /// A stiffness to ground in one recording only (see the module docs).
    PreSlidingFriction {
        /// The recording that has it.
        recording: Recording,
        /// The resonance it makes (Hz).
        freq_hz: f64,
        /// `J (2 pi f)^2` in input units per output unit, when the other
        /// recording's low band gives the inertia `J`.
        stiffness: Option<f64>,
    },
    /// A mode that moved between the operating points.
    ModeShift {
        /// Resonance or antiresonance.
        #[serde(serialize_with = "ser_feature")]
        feature: Feature,
        /// From the first recording to the second (Hz).
        freq_hz: (f64, f64),
    },
}

/// The comparison of two operating points.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OperatingPointComparison {
    /// Features in both recordings, in increasing frequency.
    pub paired: Vec<PairedFeature>,
    /// Features of one recording only.
    pub lone: Vec<LoneFeature>,
    /// What differs beyond the resolution, named.
    pub findings: Vec<Finding>,
}

/// Compares the classifications `first` (of `first_frf`) and `second` (of
/// `second_frf`) of one rig at two operating points; see the module
/// documentation.
pub fn compare_operating_points(
    first: &Classification,
    first_frf: &Frf,
    second: &Classification,
    second_frf: &Frf,
) -> OperatingPointComparison {
    let ours: Vec<&ClassifiedFeature> = first.features.iter().filter(|f| f.in_type).collect();
    let theirs: Vec<&ClassifiedFeature> = second.features.iter().filter(|f| f.in_type).collect();
    // Greedy pairing by the closest frequency ratio, each feature once.
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, a) in ours.iter().enumerate() {
        for (j, b) in theirs.iter().enumerate() {
            let ratio = (b.freq_hz / a.freq_hz).ln().abs();
            if a.kind == b.kind && ratio < PAIRING_RANGE.ln() {
                pairs.push((ratio, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let (mut used_a, mut used_b) = (vec![false; ours.len()], vec![false; theirs.len()]);
    let mut paired = Vec::new();
    for (_, i, j) in pairs {
        if used_a[i] || used_b[j] {
            continue;
        }
        used_a[i] = true;
        used_b[j] = true;
        let (a, b) = (ours[i], theirs[j]);
        let resolution = [a, b]
            .iter()
            .zip([first_frf, second_frf])
            .map(|(f, frf)| {
                f.damping_ratio
                    .unwrap_or(0.0)
                    .max(2.0 * line_spacing(frf, f.freq_hz) / f.freq_hz)
            })
            .fold(0.0, f64::max);
        let shift = b.freq_hz / a.freq_hz - 1.0;
        paired.push(PairedFeature {
            kind: a.kind,
            freq_hz: (a.freq_hz, b.freq_hz),
            shift,
            resolution,
            shifted: shift.abs() > resolution,
        });
    }
    paired.sort_by(|a, b| a.freq_hz.0.total_cmp(&b.freq_hz.0));
    let mut lone: Vec<LoneFeature> = ours
        .iter()
        .zip(&used_a)
        .filter(|(_, &u)| !u)
        .map(|(f, _)| (Recording::First, f))
        .chain(
            theirs
                .iter()
                .zip(&used_b)
                .filter(|(_, &u)| !u)
                .map(|(f, _)| (Recording::Second, f)),
        )
        .map(|(recording, f)| LoneFeature {
            recording,
            kind: f.kind,
            freq_hz: f.freq_hz,
        })
        .collect();
    lone.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let mut findings = Vec::new();
    for l in &lone {
        let (other, other_frf, own) = match l.recording {
            Recording::First => (second, second_frf, first),
            Recording::Second => (first, first_frf, second),
        };
        let lowest_other = other
            .features
            .iter()
            .filter(|f| f.in_type)
            .map(|f| f.freq_hz)
            .fold(f64::INFINITY, f64::min);
        let below_all = l.freq_hz < lowest_other / PAIRING_RANGE;
        let seen_there = other.band_hz.0 < l.freq_hz;
        if l.kind == Feature::Resonance && below_all && seen_there {
            findings.push(Finding::PreSlidingFriction {
                recording: l.recording,
                freq_hz: l.freq_hz,
                stiffness: rigid_inertia(other_frf, own.output, other.band_hz.0, lowest_other)
                    .map(|j| j * (2.0 * PI * l.freq_hz).powi(2)),
            });
        }
    }
    findings.extend(
        paired
            .iter()
            .filter(|p| p.shifted)
            .map(|p| Finding::ModeShift {
                feature: p.kind,
                freq_hz: p.freq_hz,
            }),
    );
    OperatingPointComparison {
        paired,
        lone,
        findings,
    }
}

/// The spacing of the lines of `frf` near `f_hz`.
fn line_spacing(frf: &Frf, f_hz: f64) -> f64 {
    let f = frf.freq_hz();
    let k = f.partition_point(|&x| x < f_hz).clamp(1, f.len() - 1);
    f[k] - f[k - 1]
}

/// The rigid-body inertia `J` from the lines between the band's bottom
/// `lo` and half the first feature `first` (median of `1 / (|H| w^2)`
/// for a position output, `1 / (|H| w)` for a velocity, `1 / |H|` for an
/// acceleration); `None` without such lines.
fn rigid_inertia(frf: &Frf, output: Output, lo: f64, first: f64) -> Option<f64> {
    let hi = 0.5 * first;
    let mut j: Vec<f64> = frf
        .freq_hz()
        .iter()
        .zip(frf.response())
        .filter(|(&f, h)| f >= lo && f <= hi && h.norm() > 0.0)
        .map(|(&f, h)| {
            let w = 2.0 * PI * f;
            1.0 / (h.norm() * w.powi(2 - output.s_power() as i32))
        })
        .filter(|v| v.is_finite())
        .collect();
    if j.len() < 3 {
        return None;
    }
    j.sort_by(f64::total_cmp);
    Some(j[j.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{classify, ClassifyOptions};
    use frf::Complex64;

    /// A free two-mass drive seen at the motor (position per force), its
    /// coupling stiffness scaled by `stiffer`.
    fn drive(stiffer: f64) -> Frf {
        let f: Vec<f64> = (1..=3000).map(|k| 0.05 * k as f64).collect();
        let (j1, j2, c, d) = (1e-3, 1e-3, 40.0 * stiffer, 0.002);
        let h = f
            .iter()
            .map(|&f| {
                let s = Complex64::new(0.0, 2.0 * PI * f);
                let a = j1 * s * s + d * s + c;
                let b = j2 * s * s + d * s + c;
                b / (a * b - (d * s + c) * (d * s + c))
            })
            .collect();
        Frf::new(f, h, None).unwrap()
    }

    fn classified(frf: &Frf) -> Classification {
        let o = ClassifyOptions {
            band_hz: Some((1.0, 150.0)),
            ..Default::default()
        };
        classify(frf, Output::Position, &o).unwrap()
    }

    #[test]
    fn the_same_rig_twice_differs_in_nothing() {
        let a = drive(1.0);
        let c = classified(&a);
        let cmp = compare_operating_points(&c, &a, &c, &a);
        assert!(cmp.findings.is_empty(), "{cmp:?}");
        assert!(cmp.lone.is_empty());
        assert_eq!(cmp.paired.len(), 2);
    }

    #[test]
    fn a_stiffer_coupling_shifts_both_features_by_its_square_root() {
        let (a, b) = (drive(1.0), drive(1.21));
        let cmp = compare_operating_points(&classified(&a), &a, &classified(&b), &b);
        // Both frequencies scale with sqrt(c): +10 %.
        assert_eq!(cmp.findings.len(), 2, "{cmp:?}");
        for p in &cmp.paired {
            assert!(p.shifted && (p.shift - 0.1).abs() < 0.01, "{p:?}");
        }
        assert!(cmp
            .findings
            .iter()
            .all(|f| matches!(f, Finding::ModeShift { .. })));
    }
}
