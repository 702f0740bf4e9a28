//! Two recordings of one rig at different operating points (standstill
//! and moving, two speeds, two excitation levels), compared feature by
//! feature.
//!
//! Each recording is classified on its own ([`crate::classify()`]); the
//! features in the type are then paired by kind and frequency:
//!
//! - Two features of one kind pair when their frequencies differ by less
//!   than [`PAIRING_RANGE`] (a factor).
//! - Each paired feature is fitted locally in each recording, as the
//!   amplitude comparison fits its modes ([`crate::amplitude`]): a
//!   second-order rational fit on the lines around it (an antiresonance
//!   as the resonance of `1 / H`), each line weighted by its uncertainty
//!   ([`frf::uncertainty::line_uncertainty`]), which gives its frequency
//!   and damping ratio with their standard deviations. Where the fit's
//!   frequency (damping) differs from the classification's, the local
//!   model misses part of the data (a skewed peak, a neighbour's tail):
//!   that difference is added to the standard deviation in quadrature. A
//!   frequency or a damping that differs by more than [`Z_THRESHOLD`]
//!   standard deviations of the difference is a change beyond the noise:
//!   a shifted mode, or a damping change; within it the feature holds for
//!   both. Where a local
//!   fit fails, the pair falls back to its *resolution*, the larger of the
//!   half-power half-widths `zeta f` and two line spacings.
//! - A resonance that only one recording shows, below every feature of
//!   the other and inside the other's band, with the other's low band
//!   free of features (its motion there is the rigid body's) and no
//!   antiresonance of its own beside it (which would make it a mode of
//!   the structure), while the recordings share at least one feature (one
//!   structure at two operating points), is a stiffness to ground that
//!   only that operating point has: at
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

use crate::amplitude::{local_mode, window, z_score, ModeEstimate};
use crate::classify::ser_feature;
use crate::{Classification, ClassifiedFeature};
use frf::uncertainty::line_uncertainty;
use frf::{Complex64, Frf};
use mms::analysis::Feature;
use mms::Output;
use serde::Serialize;
use std::f64::consts::PI;

/// Largest ratio of the frequencies of two features that can pair.
pub const PAIRING_RANGE: f64 = 1.25;

pub use crate::amplitude::Z_THRESHOLD;

/// Whether two frequencies lie within [`PAIRING_RANGE`] of each other: one
/// feature, in two recordings or two readings.
pub fn within_pairing_range(a_hz: f64, b_hz: f64) -> bool {
    (a_hz / b_hz).ln().abs() < PAIRING_RANGE.ln()
}

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
    /// Its frequency in the first and the second recording (Hz): the
    /// local fits' where both fit, else the classification's.
    pub freq_hz: (f64, f64),
    /// The relative shift `f2 / f1 - 1`.
    pub shift: f64,
    /// Each recording's local fit of the feature (frequency, damping and
    /// their standard deviations), when both fit.
    pub fits: Option<(ModeEstimate, ModeEstimate)>,
    /// The standard deviation of the frequency in each recording (Hz): the
    /// local fit's, and the fit's distance from the classification's
    /// frequency (with `fits`; see the module docs).
    pub sd_hz: Option<(f64, f64)>,
    /// The standard deviation of the damping ratio in each recording, by
    /// the same rule (with `fits`).
    pub damping_sd: Option<(f64, f64)>,
    /// The frequency difference of the fits in standard deviations of the
    /// difference (with `fits`).
    pub shift_z: Option<f64>,
    /// The damping difference of the fits in standard deviations (with
    /// `fits`).
    pub damping_z: Option<f64>,
    /// The relative resolution of the pair without fits (see the module
    /// docs).
    pub resolution: f64,
    /// Whether the frequency changed beyond the noise (the resolution
    /// without fits).
    pub shifted: bool,
    /// Whether the damping changed beyond the noise (never without fits).
    pub damping_changed: bool,
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
        /// The difference in its standard deviations, when both recordings
        /// fit the feature locally.
        z: Option<f64>,
    },
    /// A feature whose damping ratio changed between the operating points
    /// (e.g. friction or a joint's damping that depends on the speed).
    DampingChange {
        /// Resonance or antiresonance.
        #[serde(serialize_with = "ser_feature")]
        feature: Feature,
        /// Its frequency in the first and the second recording (Hz).
        freq_hz: (f64, f64),
        /// The damping ratio in the first and the second recording.
        damping: (f64, f64),
        /// The difference in its standard deviations.
        z: f64,
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
    let (lines_a, lines_b) = (Lines::new(first_frf), Lines::new(second_frf));
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
        let fits = lines_a
            .fit(&ours, i)
            .zip(lines_b.fit(&theirs, j))
            .filter(|(x, y)| {
                // Each fit must describe the feature it was started at.
                (x.f_hz / a.freq_hz).ln().abs() < 0.5 * PAIRING_RANGE.ln()
                    && (y.f_hz / b.freq_hz).ln().abs() < 0.5 * PAIRING_RANGE.ln()
            });
        // Two estimates of one feature that differ by more than the noise
        // say the local model misses something: the difference counts as
        // a systematic uncertainty.
        let sd = |e: &ModeEstimate, f: &ClassifiedFeature| {
            (
                e.f_sigma_hz.hypot(e.f_hz - f.freq_hz),
                e.damping_sigma
                    .hypot(f.damping_ratio.map_or(0.0, |z| e.damping - z)),
            )
        };
        let sds = fits.map(|(x, y)| (sd(&x, a), sd(&y, b)));
        let shift_z = fits
            .zip(sds)
            .map(|((x, y), (u, v))| z_score(y.f_hz - x.f_hz, u.0, v.0));
        let damping_z = fits
            .zip(sds)
            .map(|((x, y), (u, v))| z_score(y.damping - x.damping, u.1, v.1));
        let freq_hz = fits.map_or((a.freq_hz, b.freq_hz), |(x, y)| (x.f_hz, y.f_hz));
        let shift = freq_hz.1 / freq_hz.0 - 1.0;
        paired.push(PairedFeature {
            kind: a.kind,
            freq_hz,
            shift,
            fits,
            sd_hz: sds.map(|(u, v)| (u.0, v.0)),
            damping_sd: sds.map(|(u, v)| (u.1, v.1)),
            shift_z,
            damping_z,
            resolution,
            shifted: match shift_z {
                Some(z) => z.abs() > Z_THRESHOLD,
                None => shift.abs() > resolution,
            },
            damping_changed: damping_z.is_some_and(|z| z.abs() > Z_THRESHOLD),
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
    for l in lone.iter().filter(|_| !paired.is_empty()) {
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
        // A spring to ground adds a resonance alone; a resonance with an
        // antiresonance of its own beside it is a mode of the structure.
        let own_antiresonance = lone.iter().any(|m| {
            m.recording == l.recording
                && m.kind == Feature::Antiresonance
                && within_pairing_range(m.freq_hz, l.freq_hz)
        });
        if l.kind == Feature::Resonance && below_all && seen_there && !own_antiresonance {
            findings.push(Finding::PreSlidingFriction {
                recording: l.recording,
                freq_hz: l.freq_hz,
                stiffness: rigid_inertia(other_frf, own.output, other.band_hz.0, lowest_other)
                    .map(|j| j * (2.0 * PI * l.freq_hz).powi(2)),
            });
        }
    }
    for p in &paired {
        if p.shifted {
            findings.push(Finding::ModeShift {
                feature: p.kind,
                freq_hz: p.freq_hz,
                z: p.shift_z,
            });
        }
        if let (true, Some((x, y)), Some(z)) = (p.damping_changed, p.fits, p.damping_z) {
            findings.push(Finding::DampingChange {
                feature: p.kind,
                freq_hz: p.freq_hz,
                damping: (x.damping, y.damping),
                z,
            });
        }
    }
    OperatingPointComparison {
        paired,
        lone,
        findings,
    }
}

/// The lines of one recording that carry information, with their
/// relative uncertainty, for the local fits of its features.
struct Lines {
    freq: Vec<f64>,
    response: Vec<Complex64>,
    sigma: Vec<f64>,
}

impl Lines {
    fn new(frf: &Frf) -> Lines {
        let u = line_uncertainty(frf, None);
        let mut l = Lines {
            freq: Vec::new(),
            response: Vec::new(),
            sigma: Vec::new(),
        };
        for ((&f, &h), &s) in frf.freq_hz().iter().zip(frf.response()).zip(&u.relative) {
            if f > 0.0 && h.norm() > 0.0 && s.is_finite() && s > 0.0 {
                l.freq.push(f);
                l.response.push(h);
                l.sigma.push(s);
            }
        }
        l
    }

    /// The local fit of `features[j]` between its neighbours of the same
    /// kind (an antiresonance as the resonance of `1 / H`, which has the
    /// same relative uncertainty).
    fn fit(&self, features: &[&ClassifiedFeature], j: usize) -> Option<ModeEstimate> {
        let kind = features[j].kind;
        let h: Vec<Complex64> = match kind {
            Feature::Antiresonance => self.response.iter().map(|h| h.inv()).collect(),
            _ => self.response.clone(),
        };
        let same: Vec<&ClassifiedFeature> = features
            .iter()
            .filter(|f| f.kind == kind)
            .copied()
            .collect();
        let k = same.iter().position(|f| std::ptr::eq(*f, features[j]))?;
        if self.freq.len() < 9 {
            return None;
        }
        // Each feature's line: the largest |h| within two lines of its
        // frequency (the classification's frequency lies between lines).
        let peaks: Vec<usize> = same
            .iter()
            .map(|f| {
                let c = self.freq.partition_point(|&x| x < f.freq_hz);
                let (a, b) = (c.saturating_sub(2), (c + 2).min(self.freq.len() - 1));
                (a..=b)
                    .max_by(|&x, &y| h[x].norm().total_cmp(&h[y].norm()))
                    .unwrap_or(a)
            })
            .collect();
        if peaks.windows(2).any(|w| w[0] >= w[1]) {
            return None;
        }
        let (a, b) = window(&h, &peaks, k);
        local_mode(
            &self.freq[a..=b],
            &h[a..=b],
            &self.sigma[a..=b],
            self.freq[peaks[k]],
        )
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
        noisy_drive(stiffer, 1.0, 0.0, 0)
    }

    /// [`drive`] with the coupling's damper scaled by `damper` and
    /// relative complex noise of `noise` (its standard deviation carried
    /// as the FRF's, as an estimate would carry it), drawn from `seed`.
    fn noisy_drive(stiffer: f64, damper: f64, noise: f64, seed: u64) -> Frf {
        let mut rng = mms::xorshift::XorShift::new(seed);
        let f: Vec<f64> = (1..=3000).map(|k| 0.05 * k as f64).collect();
        let (j1, j2, c, d) = (1e-3, 1e-3, 40.0 * stiffer, 0.002 * damper);
        let h: Vec<Complex64> = f
            .iter()
            .map(|&f| {
                let s = Complex64::new(0.0, 2.0 * PI * f);
                let a = j1 * s * s + d * s + c;
                let b = j2 * s * s + d * s + c;
                let e = Complex64::new(rng.normal(), rng.normal()) * (noise / 2f64.sqrt());
                b / (a * b - (d * s + c) * (d * s + c)) * (1.0 + e)
            })
            .collect();
        let frf = Frf::new(f, h.clone(), None).unwrap();
        if noise > 0.0 {
            frf.with_std_dev(h.iter().map(|h| noise * h.norm()).collect())
                .unwrap()
        } else {
            frf
        }
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
        // Both frequencies scale with sqrt(c): +10 %; the damping ratios,
        // d / (2 sqrt(c m))-like with the damper unchanged, fall by 1.1.
        for p in &cmp.paired {
            assert!(p.shifted && (p.shift - 0.1).abs() < 0.01, "{p:?}");
            let (x, y) = p.fits.unwrap();
            assert!((x.damping / y.damping / 1.1 - 1.0).abs() < 0.01, "{p:?}");
        }
        let count = |shift: bool| {
            cmp.findings
                .iter()
                .filter(|f| matches!(f, Finding::ModeShift { .. }) == shift)
                .count()
        };
        assert_eq!((count(true), count(false)), (2, 2), "{cmp:?}");
    }

    /// Two recordings of one drive with independent noise of 1 %: every
    /// feature holds for both, in frequency and damping, within the noise.
    #[test]
    fn independent_noise_alone_changes_nothing() {
        let (a, b) = (
            noisy_drive(1.0, 1.0, 0.01, 1),
            noisy_drive(1.0, 1.0, 0.01, 2),
        );
        let cmp = compare_operating_points(&classified(&a), &a, &classified(&b), &b);
        assert!(cmp.findings.is_empty(), "{cmp:?}");
        assert_eq!(cmp.paired.len(), 2);
        for p in &cmp.paired {
            assert!(
                p.fits.is_some() && p.shift_z.unwrap().abs() < Z_THRESHOLD,
                "{p:?}"
            );
        }
    }

    /// A coupling 1 % stiffer moves both features by 0.5 % (the square
    /// root), less than their half-power half-width (the resolution rule
    /// would not see it), but far beyond the noise of 0.1 %: named, with
    /// the shift within 0.05 points of the exact 0.499 %.
    #[test]
    fn a_shift_below_the_half_power_width_but_beyond_the_noise_is_named() {
        let (a, b) = (
            noisy_drive(1.0, 1.0, 0.001, 3),
            noisy_drive(1.01, 1.0, 0.001, 4),
        );
        let cmp = compare_operating_points(&classified(&a), &a, &classified(&b), &b);
        let exact = 1.01f64.sqrt() - 1.0;
        for p in &cmp.paired {
            assert!(p.shift.abs() < p.resolution, "{p:?}");
            assert!(p.shifted && (p.shift - exact).abs() < 5e-4, "{p:?}");
        }
        let shifts = cmp
            .findings
            .iter()
            .filter(|f| matches!(f, Finding::ModeShift { .. }))
            .count();
        assert_eq!(shifts, 2, "{cmp:?}");
    }

    /// The coupling's damper tripled: both features keep their frequency
    /// and change their damping ratio, which the local fits measure: the
    /// damping ratio of the resonance is `d w / (2 c)`-like, so it triples
    /// (within 10 %).
    #[test]
    fn a_damping_change_is_named_without_a_mode_shift() {
        let (a, b) = (
            noisy_drive(1.0, 1.0, 0.005, 5),
            noisy_drive(1.0, 3.0, 0.005, 6),
        );
        let cmp = compare_operating_points(&classified(&a), &a, &classified(&b), &b);
        assert!(
            !cmp.findings
                .iter()
                .any(|f| matches!(f, Finding::ModeShift { .. })),
            "{cmp:?}"
        );
        let damping: Vec<(f64, f64)> = cmp
            .findings
            .iter()
            .filter_map(|f| match f {
                Finding::DampingChange { damping, .. } => Some(*damping),
                _ => None,
            })
            .collect();
        assert_eq!(damping.len(), 2, "{cmp:?}");
        for (x, y) in damping {
            assert!((y / x / 3.0 - 1.0).abs() < 0.1, "{x} -> {y}");
        }
    }

    /// Two recordings that share no feature are not one structure at two
    /// operating points: a low resonance of one of them is not named
    /// pre-sliding friction.
    #[test]
    fn no_pre_sliding_friction_without_a_shared_feature() {
        let a = drive(1.0);
        let b = drive(9.0);
        let cmp = compare_operating_points(&classified(&a), &a, &classified(&b), &b);
        assert!(cmp.paired.is_empty(), "{cmp:?}");
        assert!(cmp.findings.is_empty(), "{cmp:?}");
    }
}
