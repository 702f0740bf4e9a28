//! Diagnosis of what a model is missing: given a recording and a model
//! that should describe it, say whether the mismatch is only a parameter
//! error or some physics the model lacks, where it shows, and which effect
//! from a small library explains it best.
//!
//! Steps (issue 6):
//!
//! 1. **Noise.** Every line's log-error `e_k = ln(G_k / H_k)` has a noise
//!    standard deviation `sigma_k` per real and imaginary part: from the
//!    coherence if the recording has one (`var ln|H| = (1 - g^2) / (2 n
//!    g^2)` for `n` averages, [`DiagnoseOptions::averages`]), else one value
//!    from the scatter of the residual itself (the median absolute second
//!    difference, which a smooth model error does not reach: for white noise
//!    `var(e_{k+1} - 2 e_k + e_{k-1}) = 6 sigma^2`).
//! 2. **Calibration.** The chain's parameters are fitted within
//!    [`DiagnoseOptions::tolerance`] of their nominal values (clamped in
//!    log space), with a Gaussian prior of half that width so that moves
//!    the data do not ask for cost something. A parameter error is not
//!    missing physics; a parameter pinned at its bound is evidence that
//!    something else is wrong, and all parameters moved by one common
//!    factor are a gain error.
//! 3. **Mismatch.** The calibrated residual, normalised by the noise
//!    (`|e_k|^2 / (2 sigma_k^2)`, mean 1 for noise alone), smoothed over a
//!    few lines; runs above [`DiagnoseOptions::band_threshold`] are the
//!    bands where the model is wrong, each with its RMS errors.
//! 4. **Hypotheses.** Each effect of [`Effects`] (time delay, first-order
//!    lag, gain error, hysteretic damping, viscous friction to the ground)
//!    is added to the model with one parameter, fitted jointly with the
//!    chain's parameters (same bounds and prior) by Levenberg-Marquardt from
//!    the calibrated parameters and a start read off the residual.
//! 5. **Selection.** By the Bayesian information criterion on the
//!    noise-normalised cost: an effect is kept if its cost drop exceeds
//!    `ln(2 lines)` (the price of its one parameter) plus
//!    [`DiagnoseOptions::margin`]; kept effects are ranked by that score.
//!    If none is kept, the verdict is `none`.
//!
//! An extra mode (one more mass) is not among the hypotheses yet.
//!
//! ```
//! use frf::Frf;
//! use ident::diagnose::{diagnose, DiagnoseOptions, EffectKind};
//! use mms::model_file::{ModelFile, Motion};
//! use mms::response::{ChainResponse, Effects, Parameters};
//! use mms::{Model, Output};
//!
//! // The true system has a 0.3 ms dead time the model does not know of.
//! let a2 = Model::from_id("A2")?;
//! let truth = [0.01, 0.012, 0.02, 400.0, 900.0, 0.03, 0.05];
//! let f: Vec<f64> = (0..800).map(|k| 5.0 * 1.004f64.powi(k)).collect();
//! let delayed = Effects { time_delay_s: Some(3e-4), ..Effects::default() };
//! let h = ChainResponse::with_effects(&a2, Output::Position, &delayed)
//!     .eval_many(&truth, &f)?;
//! let data = Frf::new(f, h, None)?;
//! // The model's parameters are 10 % off.
//! let nominal: Vec<f64> = truth.iter().map(|p| p * 1.1).collect();
//! let model = ModelFile {
//!     model: a2,
//!     output: Output::Position,
//!     parameters: Parameters::from_values(&a2, nominal)?,
//!     gain: 1.0,
//!     motion: Motion::Translational,
//!     effects: Effects::default(),
//! };
//! let d = diagnose(&data, &model, &DiagnoseOptions::default())?;
//! assert_eq!(d.effects[0].kind, EffectKind::TimeDelay);
//! let delay = d.effects[0].parameters["delay_s"];
//! assert!((delay / 3e-4 - 1.0).abs() < 0.01);
//! assert!(d.after.rms_deg < 0.01 && d.before.rms_deg > 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::fit::solve_spd;
use frf::Frf;
use mms::model_file::ModelFile;
use mms::response::{ChainResponse, Effects, Parameters, ResponseError};
use num_complex::Complex64;
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::{LN_10, PI};

/// Options of [`diagnose`].
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnoseOptions {
    /// Calibration bound on masses and springs: each stays within a factor
    /// `1 + tolerance` of its nominal value (either way, in log space).
    pub tolerance: f64,
    /// The same for dampers, which are rarely known as well as masses and
    /// springs.
    pub damper_tolerance: f64,
    /// Number of averages behind the recording's coherence (used only if
    /// the recording has a coherence).
    pub averages: f64,
    /// Lines of the running mean of the normalised cost for the bands.
    pub band_window: usize,
    /// A band is where the smoothed normalised cost exceeds this (1: noise
    /// alone).
    pub band_threshold: f64,
    /// Narrower runs are not reported as bands.
    pub min_band_lines: usize,
    /// What an effect must gain beyond the BIC price of its parameter.
    pub margin: f64,
    /// Iteration limit of each Levenberg-Marquardt fit.
    pub max_iterations: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> DiagnoseOptions {
        DiagnoseOptions {
            tolerance: 0.2,
            damper_tolerance: 0.5,
            averages: 16.0,
            band_window: 9,
            band_threshold: 2.5,
            min_band_lines: 5,
            margin: 10.0,
            max_iterations: 60,
        }
    }
}

/// The effects the diagnosis tries (JSON `kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectKind {
    /// Dead time `e^(-s T)`; parameter `delay_s`.
    TimeDelay,
    /// First-order lag; parameter `corner_hz`.
    Lowpass,
    /// A wrong actuator or sensor constant; parameter `factor`.
    GainError,
    /// Structural damping of every spring; parameter `loss_factor`.
    HystereticDamping,
    /// Viscous damper from the driven mass to the ground; parameter
    /// `viscous_ns_per_m`. The time-domain diagnosis
    /// ([`crate::nonlinear`]) reports Coulomb friction under the same kind,
    /// with parameter `coulomb_n`.
    Friction,
    /// A dead zone in the spring next to the driven mass (time domain
    /// only, [`crate::nonlinear`]); parameter `gap`.
    Backlash,
    /// An unmodelled mass and compliance: the model refitted with one more
    /// mass (at the free end of the chain, or at its start for a free
    /// chain); parameters `resonance_hz` and `antiresonance_hz`, the
    /// features the extra mass adds.
    ExtraMode,
    /// Nothing is missing: the calibrated model explains the data.
    None,
}

impl EffectKind {
    /// The hypotheses tried, in a fixed order (ties keep it).
    pub const HYPOTHESES: [EffectKind; 5] = [
        EffectKind::TimeDelay,
        EffectKind::Lowpass,
        EffectKind::GainError,
        EffectKind::HystereticDamping,
        EffectKind::Friction,
    ];

    /// JSON name.
    pub fn as_str(self) -> &'static str {
        match self {
            EffectKind::TimeDelay => "time_delay",
            EffectKind::Lowpass => "lowpass",
            EffectKind::GainError => "gain_error",
            EffectKind::HystereticDamping => "hysteretic_damping",
            EffectKind::Friction => "friction",
            EffectKind::Backlash => "backlash",
            EffectKind::ExtraMode => "extra_mode",
            EffectKind::None => "none",
        }
    }

    /// Name of the effect's parameter (`None` for [`EffectKind::None`] and
    /// for [`EffectKind::ExtraMode`], which has two).
    pub fn parameter_name(self) -> Option<&'static str> {
        match self {
            EffectKind::ExtraMode => None,
            EffectKind::TimeDelay => Some("delay_s"),
            EffectKind::Lowpass => Some("corner_hz"),
            EffectKind::GainError => Some("factor"),
            EffectKind::HystereticDamping => Some("loss_factor"),
            EffectKind::Friction => Some("viscous_ns_per_m"),
            EffectKind::Backlash => Some("gap"),
            EffectKind::None => None,
        }
    }

    /// `base` with this effect set to `value`.
    fn apply(self, base: &Effects, value: f64) -> Effects {
        let mut e = *base;
        match self {
            EffectKind::TimeDelay => e.time_delay_s = Some(value),
            EffectKind::Lowpass => e.lowpass_hz = Some(value),
            EffectKind::GainError => e.gain_factor = Some(value),
            EffectKind::HystereticDamping => e.loss_factor = Some(value),
            EffectKind::Friction => e.viscous_friction = Some(value),
            EffectKind::Backlash => e.backlash_gap = Some(value),
            EffectKind::ExtraMode | EffectKind::None => {}
        }
        e
    }

    /// The value already in `base`, if any.
    fn current(self, base: &Effects) -> Option<f64> {
        match self {
            EffectKind::TimeDelay => base.time_delay_s,
            EffectKind::Lowpass => base.lowpass_hz,
            EffectKind::GainError => base.gain_factor,
            EffectKind::HystereticDamping => base.loss_factor,
            EffectKind::Friction => base.viscous_friction,
            EffectKind::Backlash => base.backlash_gap,
            EffectKind::ExtraMode | EffectKind::None => None,
        }
    }
}

/// A frequency band where the calibrated model misses the data by more
/// than the noise explains.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Band {
    /// Lowest line of the band, Hz.
    pub f_lo_hz: f64,
    /// Highest line of the band, Hz.
    pub f_hi_hz: f64,
    /// RMS of `20 log10 |G_rec / G_model|` over the band's lines.
    pub rms_db: f64,
    /// RMS of the wrapped phase difference over the band's lines.
    pub rms_deg: f64,
}

/// One hypothesis's outcome.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectVerdict {
    /// Which effect.
    pub kind: EffectKind,
    /// Its fitted parameter (empty for `none`).
    pub parameters: BTreeMap<String, f64>,
    /// Why, in words: the cost drop, the errors before and after.
    pub evidence: String,
    /// BIC improvement over the calibrated model without it, less the
    /// margin: positive means kept.
    pub score: f64,
}

/// RMS errors of a model against the recording.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FitSummary {
    /// RMS over the lines of `20 log10 |G_rec / G_model|`, dB.
    pub rms_db: f64,
    /// RMS over the lines of the wrapped phase difference, degrees.
    pub rms_deg: f64,
}

/// Before and after (the JSON `fit` object).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BeforeAfter {
    /// The calibrated model without a new effect.
    pub before: FitSummary,
    /// The model after the best kept effect (equal to `before` if none).
    pub after: FitSummary,
}

/// The result of [`diagnose`]. Serialises to the JSON of issue 6 (plus
/// `calibration`, `noise` and `rejected`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Bands of the calibrated residual beyond the noise, in frequency order.
    pub mismatch: Vec<Band>,
    /// Kept effects, best first; `[none]` if nothing is missing.
    pub effects: Vec<EffectVerdict>,
    /// Hypotheses that did not earn their parameter, best first.
    pub rejected: Vec<EffectVerdict>,
    /// Before (calibrated) and after (best effect) errors.
    pub fit: BeforeAfter,
    /// Evidence from the calibration: parameters pinned at their bounds,
    /// a common scale of all parameters.
    pub calibration: Vec<String>,
    /// The noise level per real/imaginary part of the log error (median
    /// over the lines), nepers.
    pub noise: f64,
    /// The model after the diagnosis: calibrated parameters and the best
    /// kept effect added to the input's effects.
    #[serde(serialize_with = "ser_model")]
    pub model_after: ModelFile,
    /// Copy of `fit.before`, for Rust callers.
    #[serde(skip)]
    pub before: FitSummary,
    /// Copy of `fit.after`, for Rust callers.
    #[serde(skip)]
    pub after: FitSummary,
}

pub(crate) fn ser_model<S: serde::Serializer>(m: &ModelFile, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut parameters = BTreeMap::new();
    for (k, v) in m.parameters.iter() {
        parameters.insert(k.to_string(), v);
    }
    let mut effects = BTreeMap::new();
    for kind in EffectKind::HYPOTHESES {
        if let (Some(v), Some(name)) = (kind.current(&m.effects), kind.parameter_name()) {
            let mut inner = BTreeMap::new();
            inner.insert(name, v);
            effects.insert(kind.as_str(), inner);
        }
    }
    // The time-domain effects' parameters (crate::nonlinear).
    if let Some(v) = m.effects.coulomb_friction {
        effects
            .entry("friction")
            .or_default()
            .insert("coulomb_n", v);
    }
    if let Some(v) = m.effects.backlash_gap {
        effects.entry("backlash").or_default().insert("gap", v);
    }
    let mut map = s.serialize_map(Some(5))?;
    map.serialize_entry("structure", &m.model.id())?;
    map.serialize_entry("output", m.output.as_str())?;
    map.serialize_entry("gain", &m.gain)?;
    map.serialize_entry("parameters", &parameters)?;
    map.serialize_entry("effects", &effects)?;
    map.end()
}

/// Why a diagnosis cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DiagnoseError {
    /// The model cannot be evaluated (bad parameters, a singular line).
    #[error(transparent)]
    Response(#[from] ResponseError),
    /// A line where the recording is zero or not finite.
    #[error("the recording is zero or not finite at {0} Hz")]
    BadLine(f64),
    /// A nominal parameter that is not positive and finite.
    #[error("nominal parameter {0} must be positive and finite")]
    Parameter(String),
    /// Too few lines for the parameters.
    #[error("{lines} lines for {parameters} parameters")]
    TooFewLines {
        /// Lines of the recording.
        lines: usize,
        /// Parameters to fit.
        parameters: usize,
    },
    /// Options out of range.
    #[error("invalid option: {0}")]
    Options(String),
}

/// The fitting problem shared by the calibration and every hypothesis.
struct Problem<'a> {
    file: &'a ModelFile,
    freq: &'a [f64],
    data: &'a [Complex64],
    /// `1 / sigma_k` per line.
    inv_sigma: Vec<f64>,
    nominal_ln: Vec<f64>,
    /// `1 / tau` of each parameter's log prior.
    prior: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// A fitted state: log-parameters (and the effect's log-value), cost.
#[derive(Clone, Debug)]
struct State {
    x: Vec<f64>,
    /// Noise-normalised data cost plus prior cost.
    cost: f64,
}

impl Problem<'_> {
    fn np(&self) -> usize {
        self.nominal_ln.len()
    }

    /// The prior's residual rows: each log-parameter's distance from its
    /// nominal value in prior standard deviations.
    fn prior_rows<'b>(&'b self, x: &'b [f64]) -> impl Iterator<Item = f64> + 'b {
        x.iter()
            .zip(&self.nominal_ln)
            .zip(&self.prior)
            .map(|((x, n), w)| (x - n) * w)
    }

    /// The effects at state `x` for hypothesis `kind`.
    fn effects(&self, kind: EffectKind, x: &[f64]) -> Effects {
        match kind {
            EffectKind::None => self.file.effects,
            k => k.apply(&self.file.effects, x[self.np()].exp()),
        }
    }

    /// Unweighted log errors `ln(G/H)` at state `x`.
    fn errors(&self, kind: EffectKind, x: &[f64]) -> Result<Vec<Complex64>, ResponseError> {
        let p: Vec<f64> = x[..self.np()].iter().map(|v| v.exp()).collect();
        let r =
            ChainResponse::with_effects(&self.file.model, self.file.output, &self.effects(kind, x));
        self.freq
            .iter()
            .zip(self.data)
            .map(|(&f, &h)| Ok((r.eval(&p, f)? * self.file.gain / h).ln()))
            .collect()
    }

    /// Weighted residuals (data rows, then prior rows) and, if asked, the
    /// Jacobian with respect to `x` (row-major).
    fn residuals(
        &self,
        kind: EffectKind,
        x: &[f64],
        jac: Option<&mut Vec<f64>>,
    ) -> Result<Vec<f64>, ResponseError> {
        let np = self.np();
        let nx = x.len();
        let p: Vec<f64> = x[..np].iter().map(|v| v.exp()).collect();
        let resp =
            ChainResponse::with_effects(&self.file.model, self.file.output, &self.effects(kind, x));
        let mut r = Vec::with_capacity(2 * self.freq.len() + np);
        let Some(jac) = jac else {
            for ((&f, &h), &w) in self.freq.iter().zip(self.data).zip(&self.inv_sigma) {
                let e = (resp.eval(&p, f)? * self.file.gain / h).ln();
                r.push(w * e.re);
                r.push(w * e.im);
            }
            r.extend(self.prior_rows(x));
            return Ok(r);
        };
        // The effect's column by a forward difference in its logarithm:
        // the effects enter the solver in several places, and one extra
        // evaluation per line is cheap next to the gradient.
        const STEP: f64 = 1e-6;
        let shifted = (kind != EffectKind::None).then(|| {
            let mut xs = x.to_vec();
            xs[np] += STEP;
            ChainResponse::with_effects(
                &self.file.model,
                self.file.output,
                &self.effects(kind, &xs),
            )
        });
        jac.clear();
        jac.reserve((2 * self.freq.len() + np) * nx);
        let mut grad = vec![Complex64::new(0.0, 0.0); np];
        for ((&f, &h), &w) in self.freq.iter().zip(self.data).zip(&self.inv_sigma) {
            let g = resp.eval_with_gradient(&p, f, &mut grad)?;
            let e = (g * self.file.gain / h).ln();
            r.push(w * e.re);
            r.push(w * e.im);
            let base = jac.len();
            jac.resize(base + 2 * nx, 0.0);
            for i in 0..np {
                // d ln G / d ln p = p (dG/dp) / G.
                let d = grad[i] * p[i] / g;
                jac[base + i] = w * d.re;
                jac[base + nx + i] = w * d.im;
            }
            if let Some(s) = &shifted {
                let d = (s.eval(&p, f)? / g).ln() / STEP;
                jac[base + np] = w * d.re;
                jac[base + nx + np] = w * d.im;
            }
        }
        r.extend(self.prior_rows(x));
        for i in 0..np {
            let base = jac.len();
            jac.resize(base + nx, 0.0);
            jac[base + i] = self.prior[i];
        }
        Ok(r)
    }

    /// Levenberg-Marquardt from `x0` with `x` clamped to `[lo, hi]` after
    /// every step (the effect's bounds appended for a hypothesis).
    fn fit(
        &self,
        kind: EffectKind,
        x0: Vec<f64>,
        lo: &[f64],
        hi: &[f64],
        max_iterations: usize,
    ) -> Result<State, ResponseError> {
        let nx = x0.len();
        let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
        let mut x = x0;
        let mut jac = Vec::new();
        let mut r = self.residuals(kind, &x, Some(&mut jac))?;
        let mut c = cost(&r);
        let mut lambda = 1e-3;
        for _ in 0..max_iterations {
            let (a, g) = crate::fit::normal_equations(&jac, &r, nx);
            let mut accepted = None;
            while lambda < 1e12 {
                let mut m = a.clone();
                for i in 0..nx {
                    m[i * nx + i] += lambda * a[i * nx + i].max(1e-12);
                }
                let Some(step) = solve_spd(&m, &g, nx) else {
                    lambda *= 4.0;
                    continue;
                };
                let trial: Vec<f64> = (0..nx)
                    .map(|i| (x[i] - step[i]).clamp(lo[i], hi[i]))
                    .collect();
                match self.residuals(kind, &trial, None) {
                    Ok(tr) if cost(&tr) < c => {
                        accepted = Some((trial, cost(&tr)));
                        lambda = (lambda / 3.0).max(1e-9);
                        break;
                    }
                    _ => lambda *= 4.0,
                }
            }
            let Some((trial, tc)) = accepted else { break };
            let rel = (c - tc) / c.max(f64::MIN_POSITIVE);
            x = trial;
            r = self.residuals(kind, &x, Some(&mut jac))?;
            c = cost(&r);
            // Relative 1e-9 of a cost of thousands of noise units is far
            // below any difference the selection looks at.
            if rel < 1e-9 {
                break;
            }
        }
        Ok(State { x, cost: c })
    }
}

/// Robust noise level of log errors: the median absolute second
/// difference, pooled over the real and imaginary parts, scaled to a
/// standard deviation (`1.4826 MAD`, `var` of a second difference `6
/// sigma^2`).
fn scatter(e: &[Complex64]) -> f64 {
    let mut d: Vec<f64> = e
        .windows(3)
        .flat_map(|w| {
            let s = w[2] - 2.0 * w[1] + w[0];
            [s.re.abs(), s.im.abs()]
        })
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    1.4826 * d[d.len() / 2] / 6f64.sqrt()
}

fn summary(e: &[Complex64]) -> FitSummary {
    let n = e.len().max(1) as f64;
    FitSummary {
        rms_db: (e.iter().map(|z| z.re * z.re).sum::<f64>() / n).sqrt() * 20.0 / LN_10,
        rms_deg: (e.iter().map(|z| z.im * z.im).sum::<f64>() / n)
            .sqrt()
            .to_degrees(),
    }
}

/// Bands of `e` (log errors; `sigma` per line) whose smoothed normalised
/// cost exceeds the threshold.
fn bands(freq: &[f64], e: &[Complex64], sigma: &[f64], o: &DiagnoseOptions) -> Vec<Band> {
    let n = e.len();
    let z: Vec<f64> = e
        .iter()
        .zip(sigma)
        .map(|(e, s)| e.norm_sqr() / (2.0 * s * s))
        .collect();
    let half = o.band_window / 2;
    let mut prefix = vec![0.0; n + 1];
    for k in 0..n {
        prefix[k + 1] = prefix[k] + z[k];
    }
    let above: Vec<bool> = (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half + 1).min(n));
            (prefix[b] - prefix[a]) / (b - a) as f64 > o.band_threshold
        })
        .collect();
    // Runs above the threshold, merged across gaps shorter than the window
    // (one noisy dip inside a band does not split it).
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < n {
        if !above[k] {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && above[k] {
            k += 1;
        }
        match runs.last_mut() {
            Some(last) if start - last.1 <= o.band_window => last.1 = k,
            _ => runs.push((start, k)),
        }
    }
    runs.into_iter()
        .filter(|(a, b)| b - a >= o.min_band_lines)
        .map(|(a, b)| {
            let s = summary(&e[a..b]);
            Band {
                f_lo_hz: freq[a],
                f_hi_hz: freq[b - 1],
                rms_db: s.rms_db,
                rms_deg: s.rms_deg,
            }
        })
        .collect()
}

/// Diagnoses what `model` misses of `data`; see the module docs.
pub fn diagnose(
    data: &Frf,
    model: &ModelFile,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let o = options;
    for (name, ok) in [
        ("tolerance", o.tolerance > 0.0 && o.tolerance.is_finite()),
        (
            "damper_tolerance",
            o.damper_tolerance > 0.0 && o.damper_tolerance.is_finite(),
        ),
        ("averages", o.averages >= 1.0 && o.averages.is_finite()),
        ("band_window", o.band_window >= 1),
        ("band_threshold", o.band_threshold.is_finite()),
        ("margin", o.margin.is_finite()),
    ] {
        if !ok {
            return Err(DiagnoseError::Options(name.into()));
        }
    }
    if !(model.gain.is_finite() && model.gain != 0.0) {
        return Err(DiagnoseError::Options(format!("model gain {}", model.gain)));
    }
    let freq = data.freq_hz();
    let h = data.response();
    if let Some(k) = h
        .iter()
        .position(|z| !(z.norm() > 0.0 && z.norm().is_finite()))
    {
        return Err(DiagnoseError::BadLine(freq[k]));
    }
    let names = model.model.parameters();
    let np = names.len();
    if data.len() < np + 2 {
        return Err(DiagnoseError::TooFewLines {
            lines: data.len(),
            parameters: np + 1,
        });
    }
    let mut nominal_ln = Vec::with_capacity(np);
    for (name, v) in model.parameters.iter() {
        if !(v > 0.0 && v.is_finite()) {
            return Err(DiagnoseError::Parameter(name.to_string()));
        }
        nominal_ln.push(v.ln());
    }
    let n_undamped = model.model.n_masses() + model.model.springs().len();
    let width: Vec<f64> = (0..np)
        .map(|i| {
            if i < n_undamped {
                o.tolerance.ln_1p()
            } else {
                o.damper_tolerance.ln_1p()
            }
        })
        .collect();
    let mut problem = Problem {
        file: model,
        freq,
        data: h,
        inv_sigma: vec![1.0; freq.len()],
        lo: nominal_ln.iter().zip(&width).map(|(v, w)| v - w).collect(),
        hi: nominal_ln.iter().zip(&width).map(|(v, w)| v + w).collect(),
        // The prior's standard deviation is half the tolerance: the bound
        // is its two-sigma point.
        prior: width.iter().map(|w| 2.0 / w).collect(),
        nominal_ln: nominal_ln.clone(),
    };

    // Noise: from the coherence, else from the scatter of the nominal
    // residual, then again from the calibrated one (a badly wrong nominal
    // model can have sharp residual features at its resonances).
    let coherence_sigma: Option<Vec<f64>> = data.coherence().map(|c| {
        c.iter()
            .map(|&g| {
                let g2 = g.clamp(1e-6, 1.0 - 1e-9);
                ((1.0 - g2) / (2.0 * o.averages * g2)).sqrt().max(1e-6)
            })
            .collect()
    });
    let set_sigma = |p: &mut Problem, e: &[Complex64]| -> Vec<f64> {
        let sigma = match &coherence_sigma {
            Some(s) => s.clone(),
            None => vec![scatter(e).max(1e-6); e.len()],
        };
        p.inv_sigma = sigma.iter().map(|s| 1.0 / s).collect();
        sigma
    };
    let e0 = problem.errors(EffectKind::None, &nominal_ln)?;
    set_sigma(&mut problem, &e0);
    let (lo, hi) = (problem.lo.clone(), problem.hi.clone());
    let first = problem.fit(
        EffectKind::None,
        nominal_ln.clone(),
        &lo,
        &hi,
        o.max_iterations,
    )?;
    let e1 = problem.errors(EffectKind::None, &first.x)?;
    let sigma = set_sigma(&mut problem, &e1);
    let calibrated = problem.fit(EffectKind::None, first.x, &lo, &hi, o.max_iterations)?;
    let e_before = problem.errors(EffectKind::None, &calibrated.x)?;
    let before = summary(&e_before);
    let mismatch = bands(freq, &e_before, &sigma, o);

    let mut calibration = Vec::new();
    for i in 0..np {
        let d = calibrated.x[i] - nominal_ln[i];
        if d.abs() > 0.999 * width[i] {
            calibration.push(format!(
                "{} pinned at its {} bound ({:+.1} %)",
                names[i],
                if d > 0.0 { "upper" } else { "lower" },
                100.0 * d.exp_m1()
            ));
        }
    }
    let common = (0..np)
        .map(|i| calibrated.x[i] - nominal_ln[i])
        .sum::<f64>()
        / np as f64;
    if common.abs() > 0.5 * o.tolerance.ln_1p() {
        calibration.push(format!(
            "all parameters moved by a common factor {:.3} (a gain error looks like this)",
            common.exp()
        ));
    }

    // Hypotheses.
    let rows = (2 * freq.len()) as f64;
    let price = rows.ln() + o.margin;
    let f_lo = freq.iter().cloned().fold(f64::INFINITY, f64::min);
    let f_hi = freq.iter().cloned().fold(0.0, f64::max);
    let total_mass: f64 = (0..model.model.n_masses())
        .map(|i| calibrated.x[i].exp())
        .sum();
    let mut verdicts: Vec<(EffectVerdict, State)> = Vec::new();
    for kind in EffectKind::HYPOTHESES {
        let (lo_e, hi_e) = match kind {
            EffectKind::TimeDelay => (1e-3 / f_hi, 1.0 / f_lo),
            EffectKind::Lowpass => (0.1 * f_lo, 1e3 * f_hi),
            EffectKind::GainError => (0.01, 100.0),
            EffectKind::HystereticDamping => (1e-5, 1.0),
            EffectKind::Friction => (
                1e-4 * total_mass * 2.0 * PI * f_lo,
                1e2 * total_mass * 2.0 * PI * f_hi,
            ),
            EffectKind::ExtraMode | EffectKind::Backlash | EffectKind::None => continue,
        };
        // Starts: the present value if the model has the effect already,
        // a value read off the residual where that is direct, else the
        // best of a coarse log grid (evaluated without refitting).
        let mut starts: Vec<f64> = kind.current(&model.effects).into_iter().collect();
        match kind {
            EffectKind::TimeDelay => {
                // The phase error of a missing delay is -w T: least squares.
                let (mut num, mut den) = (0.0, 0.0);
                for (&f, e) in freq.iter().zip(&e_before) {
                    let w = 2.0 * PI * f;
                    num += w * e.im;
                    den += w * w;
                }
                starts.push(num / den);
            }
            EffectKind::GainError => {
                let mean = e_before.iter().map(|e| e.re).sum::<f64>() / e_before.len() as f64;
                starts.push((-mean).exp());
            }
            _ => {}
        }
        for k in 0..7 {
            starts.push(lo_e * (hi_e / lo_e).powf((k as f64 + 0.5) / 7.0));
        }
        let mut best: Option<(f64, Vec<f64>)> = None;
        for s in starts {
            let mut x = calibrated.x.clone();
            x.push(s.clamp(lo_e, hi_e).ln());
            let Ok(r) = problem.residuals(kind, &x, None) else {
                continue;
            };
            let c: f64 = r.iter().map(|v| v * v).sum();
            if best.as_ref().is_none_or(|b| c < b.0) {
                best = Some((c, x));
            }
        }
        let Some((_, x0)) = best else { continue };
        let mut lo_k = lo.clone();
        lo_k.push(lo_e.ln());
        let mut hi_k = hi.clone();
        hi_k.push(hi_e.ln());
        let Ok(state) = problem.fit(kind, x0, &lo_k, &hi_k, o.max_iterations) else {
            continue;
        };
        let value = state.x[np].exp();
        let drop = calibrated.cost - state.cost;
        let score = drop - price;
        let after = summary(&problem.errors(kind, &state.x)?);
        let mut parameters = BTreeMap::new();
        if let Some(name) = kind.parameter_name() {
            parameters.insert(name.to_string(), value);
        }
        let evidence = format!(
            "cost {:.1} -> {:.1} noise units (price {:.1}); {:.3} dB / {:.2} deg -> {:.3} dB / {:.2} deg",
            calibrated.cost, state.cost, price, before.rms_db, before.rms_deg, after.rms_db, after.rms_deg
        );
        verdicts.push((
            EffectVerdict {
                kind,
                parameters,
                evidence,
                score,
            },
            state,
        ));
    }
    // An extra mode: refit with one more mass; three more parameters.
    let mut extra_after: Option<(ModelFile, FitSummary)> = None;
    if let Some((verdict, file, summary_after)) = extra_mode(
        &problem,
        &calibrated,
        &e_before,
        rows,
        o,
        (before, calibrated.cost),
    ) {
        extra_after = Some((file, summary_after));
        verdicts.push((
            verdict,
            State {
                x: Vec::new(),
                cost: f64::NAN,
            },
        ));
    }
    // Best first; ties keep the fixed hypothesis order (stable sort).
    verdicts.sort_by(|a, b| b.0.score.total_cmp(&a.0.score));
    let (kept, rejected): (Vec<_>, Vec<_>) = verdicts.into_iter().partition(|v| v.0.score > 0.0);

    let (after, model_after) = match (kept.first(), extra_after) {
        (Some((v, _)), Some((file, summary_after))) if v.kind == EffectKind::ExtraMode => {
            (summary_after, file)
        }
        (first, _) => {
            let (after_kind, after_x) = match first {
                Some((v, s)) => (v.kind, s.x.clone()),
                None => (EffectKind::None, calibrated.x.clone()),
            };
            let after = summary(&problem.errors(after_kind, &after_x)?);
            let model_after = ModelFile {
                parameters: Parameters::from_values(
                    &model.model,
                    after_x[..np].iter().map(|v| v.exp()).collect(),
                )?,
                effects: problem.effects(after_kind, &after_x),
                ..model.clone()
            };
            (after, model_after)
        }
    };
    let effects = if kept.is_empty() {
        vec![EffectVerdict {
            kind: EffectKind::None,
            parameters: BTreeMap::new(),
            evidence: match rejected.first() {
                Some((v, _)) => format!(
                    "no effect earns its parameter; best was {} ({})",
                    v.kind.as_str(),
                    v.evidence
                ),
                None => "no hypothesis could be fitted".into(),
            },
            score: 0.0,
        }]
    } else {
        kept.into_iter().map(|v| v.0).collect()
    };
    let mut noise: Vec<f64> = sigma.clone();
    noise.sort_by(f64::total_cmp);
    Ok(Diagnosis {
        mismatch,
        effects,
        rejected: rejected.into_iter().map(|v| v.0).collect(),
        fit: BeforeAfter { before, after },
        calibration,
        noise: noise[noise.len() / 2],
        model_after,
        before,
        after,
    })
}

/// Places one more mass in the chain: at the free end, and (free chains
/// only) before the first mass. Each placement is the extended model and,
/// for every parameter of it, the index of the same parameter in the
/// original model (`None` for the three new ones).
fn extended_models(m: &mms::Model) -> Vec<(mms::Model, Vec<Option<usize>>)> {
    let n = m.n_masses();
    let old = m.parameters();
    let mut out = Vec::new();
    let mut placements: Vec<(mms::Model, usize)> = Vec::new();
    if n < mms::MAX_MASSES {
        if let Ok(e) = mms::Model::new(n + 1, m.gap(), m.actuator(), m.sensor()) {
            placements.push((e, 0));
        }
        if m.gap() == 0 {
            let shift = |p: mms::Port| mms::Port::new(p.plus + 1, p.minus);
            if let Ok(e) = mms::Model::new(n + 1, 0, shift(m.actuator()), shift(m.sensor())) {
                placements.push((e, 1));
            }
        }
    }
    for (e, offset) in placements {
        // Masses and links of the original keep their names up to the
        // index offset.
        let rename = |name: &str| -> String {
            let (kind, rest) = name.split_at(1);
            if kind == "m" {
                let i: usize = rest.parse().unwrap_or(0);
                mms::mass_name(i + offset)
            } else {
                // Link names: the link's lower node index i (0 = ground).
                let i = link_index(rest);
                if kind == "c" {
                    mms::spring_name(i + offset)
                } else {
                    mms::damper_name(i + offset)
                }
            }
        };
        let renamed: Vec<String> = old.iter().map(|p| rename(p)).collect();
        let map = e
            .parameters()
            .iter()
            .map(|p| renamed.iter().position(|r| r == p))
            .collect();
        out.push((e, map));
    }
    out
}

/// The lower node index of a link name's digits (`1` -> 0, `12` -> 1,
/// `9_10` -> 9).
fn link_index(digits: &str) -> usize {
    if let Some((a, _)) = digits.split_once('_') {
        return a.parse().unwrap_or(0);
    }
    if digits == "1" {
        0
    } else {
        digits[..digits.len() - 1].parse().unwrap_or(0)
    }
}

/// The extra-mode hypothesis: for each placement and each of the largest
/// residual peaks, a small new mass tuned to the peak, then all parameters
/// refitted (the old ones under the calibration's bounds and prior, the new
/// ones free within two decades). Scored like the other hypotheses, with
/// three parameters' price.
fn extra_mode(
    problem: &Problem,
    calibrated: &State,
    e_before: &[Complex64],
    rows: f64,
    o: &DiagnoseOptions,
    (before, before_cost): (FitSummary, f64),
) -> Option<(EffectVerdict, ModelFile, FitSummary)> {
    let file = problem.file;
    let n = file.model.n_masses();
    let np = problem.np();
    let old: Vec<f64> = calibrated.x[..np].iter().map(|v| v.exp()).collect();
    let smallest = old[..n].iter().cloned().fold(f64::INFINITY, f64::min);
    // The three largest local maxima of the residual's magnitude.
    let mag: Vec<f64> = e_before.iter().map(|e| e.norm()).collect();
    let mut peaks: Vec<usize> = (1..mag.len().saturating_sub(1))
        .filter(|&k| mag[k] >= mag[k - 1] && mag[k] >= mag[k + 1])
        .collect();
    peaks.sort_by(|&a, &b| mag[b].total_cmp(&mag[a]));
    peaks.truncate(3);
    let price = 3.0 * rows.ln() + o.margin;
    // (cost, extended model file, state, the problem's centre, prior and
    // bounds).
    type Best = (
        f64,
        ModelFile,
        State,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
    );
    let mut best: Option<Best> = None;
    for (ext, map) in extended_models(&file.model) {
        let names = ext.parameters();
        let n_links = ext.springs().len();
        for &k in &peaks {
            let w = 2.0 * PI * problem.freq[k];
            let m_new = 0.2 * smallest;
            let c_new = m_new * w * w;
            let d_new = 2.0 * 0.02 * (c_new * m_new).sqrt();
            let values: Vec<f64> = names
                .iter()
                .enumerate()
                .map(|(i, _)| match map[i] {
                    Some(j) => old[j],
                    None if i < ext.n_masses() => m_new,
                    None if i < ext.n_masses() + n_links => c_new,
                    None => d_new,
                })
                .collect();
            let Ok(parameters) = Parameters::from_values(&ext, values.clone()) else {
                continue;
            };
            let ext_file = ModelFile {
                model: ext,
                parameters,
                ..file.clone()
            };
            let nominal_ln: Vec<f64> = values.iter().map(|v| v.ln()).collect();
            let wide = 100f64.ln();
            let index = |i: usize| map[i].map(|j| (problem.lo[j], problem.hi[j], problem.prior[j]));
            let lo: Vec<f64> = (0..values.len())
                .map(|i| index(i).map_or(nominal_ln[i] - wide, |b| b.0))
                .collect();
            let hi: Vec<f64> = (0..values.len())
                .map(|i| index(i).map_or(nominal_ln[i] + wide, |b| b.1))
                .collect();
            // The old parameters keep their prior around their *nominal*
            // values (as in the calibration); the new ones have none.
            let prior: Vec<f64> = (0..values.len())
                .map(|i| index(i).map_or(0.0, |b| b.2))
                .collect();
            let centre: Vec<f64> = (0..values.len())
                .map(|i| map[i].map_or(nominal_ln[i], |j| problem.nominal_ln[j]))
                .collect();
            let ext_problem = Problem {
                file: &ext_file,
                freq: problem.freq,
                data: problem.data,
                inv_sigma: problem.inv_sigma.clone(),
                nominal_ln: centre.clone(),
                prior: prior.clone(),
                lo: lo.clone(),
                hi: hi.clone(),
            };
            // A short fit ranks the placements and peaks; only the best is
            // finished (below), which keeps the hypothesis within the
            // diagnosis's time budget.
            let Ok(state) = ext_problem.fit(EffectKind::None, nominal_ln, &lo, &hi, 12) else {
                continue;
            };
            if best.as_ref().is_none_or(|b| state.cost < b.0) {
                best = Some((state.cost, ext_file.clone(), state, centre, prior, lo, hi));
            }
        }
    }
    let (_, ext_file, screened, centre, prior, lo, hi) = best?;
    let ext = ext_file.model;
    let ext_problem = Problem {
        file: &ext_file,
        freq: problem.freq,
        data: problem.data,
        inv_sigma: problem.inv_sigma.clone(),
        nominal_ln: centre,
        prior,
        lo: lo.clone(),
        hi: hi.clone(),
    };
    let state = ext_problem
        .fit(EffectKind::None, screened.x, &lo, &hi, o.max_iterations)
        .ok()?;
    let cost = state.cost;
    let score = before_cost - cost - price;
    let errors = ext_problem.errors(EffectKind::None, &state.x).ok()?;
    let after = summary(&errors);
    let values: Vec<f64> = state.x.iter().map(|v| v.exp()).collect();
    let parameters = Parameters::from_values(&ext, values).ok()?;
    let added = added_features(&file.model, &old, &ext, parameters.values());
    let mut params = BTreeMap::new();
    if let Some((r, a)) = added {
        params.insert("resonance_hz".to_string(), r);
        if let Some(a) = a {
            params.insert("antiresonance_hz".to_string(), a);
        }
    }
    let evidence = format!(
        "one more mass ({} masses, {}): cost {:.1} -> {:.1} noise units (price {:.1}); {:.3} dB / {:.2} deg -> {:.3} dB / {:.2} deg",
        ext.n_masses(),
        ext.id(),
        before_cost,
        cost,
        price,
        before.rms_db,
        before.rms_deg,
        after.rms_db,
        after.rms_deg
    );
    let model_after = ModelFile {
        model: ext,
        parameters,
        ..file.clone()
    };
    Some((
        EffectVerdict {
            kind: EffectKind::ExtraMode,
            parameters: params,
            evidence,
            score,
        },
        model_after,
        after,
    ))
}

/// The resonance (and antiresonance, if any) the extended model has beyond
/// the original's: the undamped features of each, matched by proximity,
/// the unmatched ones reported (Hz).
fn added_features(
    m: &mms::Model,
    p: &[f64],
    ext: &mms::Model,
    q: &[f64],
) -> Option<(f64, Option<f64>)> {
    let features = |model: &mms::Model, values: &[f64]| -> (Vec<f64>, Vec<f64>) {
        let nu = model.undamped_parameters().len();
        let (num, den) = crate::start::UndampedCoefficients::new(model).eval(&values[..nu]);
        let hz = |c: &[f64]| -> Vec<f64> {
            crate::start::roots(c)
                .iter()
                .filter(|z| z.re > 0.0 && z.im.abs() <= 1e-6 * z.norm())
                .map(|z| z.re.sqrt() / (2.0 * PI))
                .collect()
        };
        (hz(&num), hz(&den))
    };
    let (za, pa) = features(m, p);
    let (zb, pb) = features(ext, q);
    // The new feature is the one of the extended list farthest (in log
    // frequency) from every feature of the original.
    let extra = |old: &[f64], new: &[f64]| -> Option<f64> {
        new.iter()
            .map(|&f| {
                let d = old
                    .iter()
                    .map(|&g| (f / g).ln().abs())
                    .fold(f64::INFINITY, f64::min);
                (d, f)
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, f)| f)
    };
    let r = extra(&pa, &pb)?;
    Some((
        r,
        if zb.len() > za.len() {
            extra(&za, &zb)
        } else {
            None
        },
    ))
}
