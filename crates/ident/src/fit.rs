//! Fitting the physical parameters of one structure to a measured FRF:
//! Levenberg-Marquardt on the complex logarithm of the ratio model/data.
//!
//! The residual at line `k` is `ln(G(p, f_k) / H_k)`: its real part is the
//! log-magnitude error (in nepers; `20/ln 10` dB each), its imaginary part
//! the phase error in radians, wrapped to `(-pi, pi]` by taking the
//! argument of the ratio rather than of each factor. Both are
//! dimensionless, so lightly damped peaks and deep antiresonances weigh
//! alike, as they do on a Bode plot.
//!
//! Parameters are fitted as logarithms, which keeps them positive and makes
//! the steps scale-free (a mass of 1 g and a spring of 1e5 N/m move alike).
//! Dampers may go to (numerically) zero: their logarithms are bounded
//! below.
//!
//! Scale: multiplying every mass, spring and damper by `k` divides the FRF
//! by `k`, so with an unknown actuator or sensor constant the absolute
//! scale is not identifiable. [`Gain::Known`] fixes the constant (the FRF
//! is in force and position units, or converted); [`Gain::Fit`] fits it and
//! holds one parameter at its start value instead.
//!
//! ```
//! use frf::Frf;
//! use ident::fit::{fit, FitOptions};
//! use mms::response::{ChainResponse, Parameters};
//! use mms::{Model, Output};
//!
//! // Data from the paper's Tab. 7 model A1 (with some damping) ...
//! let a1 = Model::from_id("A1")?;
//! let truth = [0.0044, 0.0173, 0.0184, 46.8, 14.3, 0.002, 0.001];
//! let f: Vec<f64> = (1..=400).map(|k| 0.25 * k as f64).collect();
//! let h = ChainResponse::new(&a1, Output::Position).eval_many(&truth, &f)?;
//! let data = Frf::new(f, h, None)?;
//! // ... fitted from a start 30% off in every parameter.
//! let start: Vec<f64> = truth.iter().map(|p| p * 1.3).collect();
//! let start = Parameters::from_values(&a1, start)?;
//! let result = fit(&a1, Output::Position, &data, &start, &FitOptions::default())?;
//! assert!(result.rms_db < 1e-6);
//! for (got, want) in result.parameters.values().iter().zip(truth) {
//!     assert!((got / want - 1.0).abs() < 1e-6);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use frf::Frf;
use mms::response::{ChainResponse, Effects, Parameters, ResponseError};
use mms::{Model, Output};
use num_complex::Complex64;
use serde::Serialize;

/// What is known about the product of actuator and sensor constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gain {
    /// The FRF is `gain * G(p)` with this known gain (1: SI units).
    Known(f64),
    /// Fit the gain (its magnitude, and its sign: a sensor mounted the
    /// other way round gives a negative gain) from this start value; the
    /// parameter named by
    /// [`FitOptions::scale_parameter`] (default: the first mass) is held
    /// at its start value to fix the scale.
    Fit(f64),
}

/// Options of [`fit`].
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// How the gain is treated.
    pub gain: Gain,
    /// Parameter held fixed under [`Gain::Fit`]; `None`: the first mass.
    pub scale_parameter: Option<String>,
    /// Further parameters held at their start values.
    pub fixed: Vec<String>,
    /// Effects applied to the model (held fixed).
    pub effects: Effects,
    /// Iteration limit.
    pub max_iterations: usize,
    /// Stop when the relative decrease of the cost in an accepted step is
    /// below this.
    pub tolerance: f64,
    /// Weight of each line; `None`: from the data's standard deviation
    /// where it has one ([`uncertainty_weights`]), else all 1. Must have
    /// one entry per line, each finite and non-negative.
    pub weights: Option<Vec<f64>>,
}

impl Default for FitOptions {
    fn default() -> FitOptions {
        FitOptions {
            gain: Gain::Known(1.0),
            scale_parameter: None,
            fixed: Vec::new(),
            effects: Effects::default(),
            max_iterations: 200,
            tolerance: 1e-12,
            weights: None,
        }
    }
}

/// The result of [`fit`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fit {
    /// Fitted parameters, in the model's order.
    #[serde(serialize_with = "ser_parameters")]
    pub parameters: Parameters,
    /// Fitted (or known) gain.
    pub gain: f64,
    /// RMS over the lines of `20 log10 |G / H|`, dB.
    pub rms_db: f64,
    /// RMS over the lines of the wrapped phase difference, degrees.
    pub rms_deg: f64,
    /// Accepted Levenberg-Marquardt steps.
    pub iterations: usize,
    /// True if the cost stopped decreasing before the iteration limit.
    pub converged: bool,
}

fn ser_parameters<S: serde::Serializer>(p: &Parameters, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(Some(p.names().len()))?;
    for (k, v) in p.iter() {
        m.serialize_entry(k, &v)?;
    }
    m.end()
}

/// Why a fit cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Bad start values or a frequency the model cannot be evaluated at.
    #[error(transparent)]
    Response(#[from] ResponseError),
    /// A parameter to hold fixed that the model does not have.
    #[error("unknown parameter {0} to hold fixed")]
    UnknownParameter(String),
    /// Weights of the wrong length or with bad values.
    #[error("weights: {0}")]
    Weights(String),
    /// Outputs that are not one chain read by several sensors.
    #[error("outputs: {0}")]
    Outputs(String),
    /// A line where the measured response is zero (its logarithm is
    /// undefined).
    #[error("the measured response is zero at {0} Hz")]
    ZeroResponse(f64),
    /// Fewer weighted lines than free parameters.
    #[error("{lines} usable lines for {parameters} free parameters")]
    TooFewLines {
        /// Lines with positive weight.
        lines: usize,
        /// Free parameters.
        parameters: usize,
    },
}

/// Lower bound of a damper's logarithm relative to its mass/spring scale:
/// dampers below `1e-9` of their start are numerically zero.
const LOG_DAMPER_FLOOR: f64 = -20.7;

/// One output of a fit: its response and the lines it is fitted to.
struct Channel<'a> {
    response: ChainResponse,
    freq: &'a [f64],
    data: &'a [Complex64],
    weights: Vec<f64>,
}

struct Problem<'a> {
    channels: Vec<Channel<'a>>,
    /// Index into the full parameter vector of each free parameter.
    free: Vec<usize>,
    fit_gain: bool,
}

impl Problem<'_> {
    /// Residuals (2 per line, the outputs one after the other) at full
    /// parameters `p` and `gain`, and, if asked, the Jacobian with respect
    /// to `ln p_free` (and `ln gain`), row-major with `free.len() +
    /// fit_gain` columns.
    fn eval(
        &self,
        p: &[f64],
        gain: f64,
        jac: Option<&mut Vec<f64>>,
    ) -> Result<Vec<f64>, ResponseError> {
        let np = self.channels[0].response.n_parameters();
        let nc = self.free.len() + usize::from(self.fit_gain);
        let lines: usize = self.channels.iter().map(|c| c.freq.len()).sum();
        let mut r = Vec::with_capacity(2 * lines);
        let mut grad = vec![Complex64::new(0.0, 0.0); np];
        let want_jac = jac.is_some();
        let mut j = Vec::new();
        if want_jac {
            j.reserve(2 * lines * nc);
        }
        for c in &self.channels {
            for ((&f, &h), &w) in c.freq.iter().zip(c.data).zip(&c.weights) {
                let g = if want_jac {
                    c.response.eval_with_gradient(p, f, &mut grad)?
                } else {
                    c.response.eval(p, f)?
                } * gain;
                let e = (g / h).ln();
                r.push(w * e.re);
                r.push(w * e.im);
                if want_jac {
                    // d ln G / d ln p = p (dG/dp) / G; the gain scales G and
                    // its derivatives alike.
                    // Two rows: real parts, then imaginary parts.
                    let base = j.len();
                    j.resize(base + 2 * nc, 0.0);
                    let inv = gain / g;
                    for (k, &i) in self.free.iter().enumerate() {
                        let d = grad[i] * inv * p[i];
                        j[base + k] = w * d.re;
                        j[base + nc + k] = w * d.im;
                    }
                    if self.fit_gain {
                        j[base + nc - 1] = w;
                    }
                }
            }
        }
        if let Some(out) = jac {
            *out = j;
        }
        Ok(r)
    }
}

/// Fits `model`'s parameters (with `output` and `options.effects`) to
/// `data`, starting from `start`. See the module docs for the cost.
pub fn fit(
    model: &Model,
    output: Output,
    data: &Frf,
    start: &Parameters,
    options: &FitOptions,
) -> Result<Fit, FitError> {
    Ok(fit_outputs(&[(*model, data)], output, start, options)?.fit)
}

/// The result of [`fit_outputs`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputsFit {
    /// The one parameter set and gain; its RMS errors are over the lines
    /// of every output together.
    pub fit: Fit,
    /// RMS errors of each output in its order: `(dB, degrees)`.
    pub per_output: Vec<(f64, f64)>,
}

/// Fits one parameter set to several outputs of the same chain at once:
/// each `(model, data)` is the chain read by one sensor (the models share
/// their masses, gap and actuator and differ in the sensor) and its
/// measured FRF. The cost is the sum of every output's cost; one gain
/// serves all (the sensors count in the same units). `options.weights`
/// apply to a single output only; several outputs are weighted by their
/// own uncertainty ([`uncertainty_weights`]) or alike.
///
/// ```
/// use frf::Frf;
/// use ident::fit::{fit_outputs, FitOptions};
/// use mms::response::{ChainResponse, Parameters};
/// use mms::{Model, Output, Port};
///
/// // A free two-mass chain driven at mass 1, read at both masses.
/// let motor = Model::new(2, 0, Port::new(1, 0), Port::new(1, 0))?;
/// let load = Model::new(2, 0, Port::new(1, 0), Port::new(2, 0))?;
/// let truth = [0.02, 0.05, 3000.0, 0.4];
/// let f: Vec<f64> = (1..=300).map(|k| 0.5 * k as f64).collect();
/// let frf = |m: &Model| -> Result<Frf, Box<dyn std::error::Error>> {
///     let h = ChainResponse::new(m, Output::Position).eval_many(&truth, &f)?;
///     Ok(Frf::new(f.clone(), h, None)?)
/// };
/// let (h1, h2) = (frf(&motor)?, frf(&load)?);
/// let start = Parameters::from_values(&motor, truth.iter().map(|p| p * 1.2).collect())?;
/// let both = fit_outputs(&[(motor, &h1), (load, &h2)], Output::Position, &start, &FitOptions::default())?;
/// assert!(both.fit.rms_db < 1e-6 && both.per_output.len() == 2);
/// for (got, want) in both.fit.parameters.values().iter().zip(truth) {
///     assert!((got / want - 1.0).abs() < 1e-6);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn fit_outputs(
    outputs: &[(Model, &Frf)],
    output: Output,
    start: &Parameters,
    options: &FitOptions,
) -> Result<OutputsFit, FitError> {
    let Some(&(model, _)) = outputs.first() else {
        return Err(FitError::Outputs("no output to fit".into()));
    };
    let model = &model;
    for (m, _) in &outputs[1..] {
        if m.n_masses() != model.n_masses()
            || m.gap() != model.gap()
            || m.actuator() != model.actuator()
        {
            return Err(FitError::Outputs(format!(
                "{} and {} are not one chain read by two sensors",
                model.id(),
                m.id()
            )));
        }
    }
    let names = model.parameters();
    let mut channels = Vec::with_capacity(outputs.len());
    for (m, data) in outputs {
        let n_lines = data.len();
        let weights = match &options.weights {
            None => uncertainty_weights(data).unwrap_or_else(|| vec![1.0; n_lines]),
            Some(_) if outputs.len() > 1 => {
                return Err(FitError::Weights(
                    "per-line weights apply to a single output".into(),
                ))
            }
            Some(w) => {
                if w.len() != n_lines {
                    return Err(FitError::Weights(format!(
                        "{} weights for {n_lines} lines",
                        w.len()
                    )));
                }
                if let Some(x) = w.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
                    return Err(FitError::Weights(format!("bad weight {x}")));
                }
                w.clone()
            }
        };
        if let Some(k) = data.response().iter().position(|h| h.norm() == 0.0) {
            return Err(FitError::ZeroResponse(data.freq_hz()[k]));
        }
        channels.push(Channel {
            response: ChainResponse::with_effects(m, output, &options.effects),
            freq: data.freq_hz(),
            data: data.response(),
            weights,
        });
    }
    let mut held: Vec<usize> = Vec::new();
    for name in &options.fixed {
        let i = names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| FitError::UnknownParameter(name.clone()))?;
        held.push(i);
    }
    let (fit_gain, mut gain) = match options.gain {
        Gain::Known(g) => (false, g),
        Gain::Fit(g) => {
            let scale = options
                .scale_parameter
                .clone()
                .unwrap_or_else(|| "m1".into());
            let i = names
                .iter()
                .position(|n| *n == scale)
                .ok_or(FitError::UnknownParameter(scale))?;
            held.push(i);
            (true, g)
        }
    };
    let free: Vec<usize> = (0..names.len()).filter(|i| !held.contains(i)).collect();
    let nc = free.len() + usize::from(fit_gain);
    let usable: usize = channels
        .iter()
        .map(|c| c.weights.iter().filter(|&&w| w > 0.0).count())
        .sum();
    if 2 * usable < nc {
        return Err(FitError::TooFewLines {
            lines: usable,
            parameters: nc,
        });
    }
    let problem = Problem {
        channels,
        free,
        fit_gain,
    };

    // Dampers start at zero sometimes; give them a floor so their
    // logarithm exists, relative to the scale of the springs.
    let mut p = start.values().to_vec();
    let n_masses = model.n_masses();
    let n_links = model.springs().len();
    let floor: Vec<f64> = (0..p.len())
        .map(|i| {
            if i >= n_masses + n_links {
                let c = p[i - n_links].max(f64::MIN_POSITIVE);
                let m = p[..n_masses].iter().sum::<f64>();
                (c * m).sqrt() * LOG_DAMPER_FLOOR.exp()
            } else {
                0.0
            }
        })
        .collect();
    // Every value stays in its physical range (mms::ranges), so the model
    // written reads back; a parameter pinned at a bound is a degenerate fit
    // the notes report.
    let ln_bounds: Vec<(f64, f64)> = names
        .iter()
        .zip(&floor)
        .map(|(n, fl)| {
            let (lo, hi) = mms::ranges::of_parameter(n).ln_bounds();
            (lo.max(fl.max(f64::MIN_POSITIVE).ln()), hi)
        })
        .collect();
    for (x, (lo, hi)) in p.iter_mut().zip(&ln_bounds) {
        *x = x.clamp(lo.exp(), hi.exp());
    }
    let (gain_lo, gain_hi) = mms::ranges::GAIN.ln_bounds();
    if fit_gain {
        gain = mms::ranges::GAIN.clamp(gain);
    }

    let cost = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    // A fitted gain may be negative (a sensor or actuator mounted the
    // other way round): start from the sign that fits better.
    if fit_gain {
        let flipped = problem.eval(&p, -gain, None)?;
        if cost(&flipped) < cost(&problem.eval(&p, gain, None)?) {
            gain = -gain;
        }
    }
    let mut jac = Vec::new();
    let mut r = problem.eval(&p, gain, Some(&mut jac))?;
    let mut c = cost(&r);
    let mut lambda = 1e-3;
    let mut nu = 2.0;
    let mut iterations = 0;
    let mut converged = false;
    let rows = r.len();
    for _ in 0..options.max_iterations {
        let (a, g) = normal_equations(&jac, &r, nc);
        let mut accepted = false;
        while lambda < 1e16 {
            let mut m = a.clone();
            for i in 0..nc {
                // Marquardt's scaling, with a floor for directions the data
                // barely see.
                m[i * nc + i] += lambda * a[i * nc + i].max(1e-12 * (1.0 + c));
            }
            let Some(step) = solve_spd(&m, &g, nc) else {
                lambda *= nu;
                nu *= 2.0;
                continue;
            };
            let mut trial = p.clone();
            for (k, &i) in problem.free.iter().enumerate() {
                let (lo, hi) = ln_bounds[i];
                trial[i] = (trial[i].ln() - step[k]).clamp(lo, hi).exp();
            }
            let trial_gain = if fit_gain {
                gain.signum()
                    * (gain.abs().ln() - step[nc - 1])
                        .clamp(gain_lo, gain_hi)
                        .exp()
            } else {
                gain
            };
            let mut trial_jac = Vec::new();
            let Ok(tr) = problem.eval(&trial, trial_gain, Some(&mut trial_jac)) else {
                lambda *= nu;
                nu *= 2.0;
                continue;
            };
            let tc = cost(&tr);
            // Predicted decrease of the linear model, for the gain ratio.
            let predicted: f64 = (0..nc)
                .map(|i| step[i] * (lambda * a[i * nc + i].max(1e-12 * (1.0 + c)) * step[i] + g[i]))
                .sum();
            if tc < c {
                let rho = (c - tc) / predicted.max(f64::MIN_POSITIVE);
                lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                let rel = (c - tc) / c.max(f64::MIN_POSITIVE);
                p = trial;
                gain = trial_gain;
                r = tr;
                jac = trial_jac;
                c = tc;
                iterations += 1;
                accepted = true;
                let max_step = step.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                if rel < options.tolerance || max_step < 1e-10 || c < 1e-28 * rows as f64 {
                    converged = true;
                }
                break;
            }
            lambda *= nu;
            nu *= 2.0;
        }
        if !accepted || converged {
            converged = true;
            break;
        }
    }
    // With unit weights the residuals are the log errors themselves.
    let mut per_output = Vec::with_capacity(problem.channels.len());
    let mut offset = 0;
    for (c, (_, data)) in problem.channels.iter().zip(outputs) {
        let rows = 2 * c.freq.len();
        per_output.push(if c.weights.iter().all(|&w| w == 1.0) {
            let n = c.freq.len() as f64;
            let (mut sm, mut sp) = (0.0, 0.0);
            for pair in r[offset..offset + rows].chunks_exact(2) {
                sm += pair[0] * pair[0];
                sp += pair[1] * pair[1];
            }
            (
                (sm / n).sqrt() * 20.0 / std::f64::consts::LN_10,
                (sp / n).sqrt().to_degrees(),
            )
        } else {
            rms_errors(&c.response, &p, gain, data)?
        });
        offset += rows;
    }
    // Over every line of every output.
    let lines: Vec<f64> = problem
        .channels
        .iter()
        .map(|c| c.freq.len() as f64)
        .collect();
    let total: f64 = lines.iter().sum();
    let pooled = |pick: fn(&(f64, f64)) -> f64| {
        (per_output
            .iter()
            .zip(&lines)
            .map(|(e, n)| pick(e).powi(2) * n)
            .sum::<f64>()
            / total)
            .sqrt()
    };
    let (rms_db, rms_deg) = if per_output.len() == 1 {
        per_output[0]
    } else {
        (pooled(|e| e.0), pooled(|e| e.1))
    };
    // exp(ln(bound)) rounds to either side of the bound: a parameter at
    // its bound is set to it exactly.
    for (x, n) in p.iter_mut().zip(&names) {
        let range = mms::ranges::of_parameter(n);
        *x = range.clamp(*x);
        if *x != 0.0 && *x <= range.min * (1.0 + 1e-9) {
            *x = range.min;
        } else if *x >= range.max * (1.0 - 1e-9) {
            *x = range.max;
        }
    }
    if fit_gain {
        gain = mms::ranges::GAIN.clamp(gain);
    }
    Ok(OutputsFit {
        fit: Fit {
            parameters: Parameters::from_values(model, p)?,
            gain,
            rms_db,
            rms_deg,
            iterations,
            converged,
        },
        per_output,
    })
}

/// The model error every fit leaves, in nepers (0.43 dB, 2.9 deg): it
/// keeps the best-measured lines from outweighing the rest by orders of
/// magnitude where no chain model is exact.
pub const MODEL_FLOOR: f64 = 0.05;

/// Fit weights from the data's standard deviation: `1 / sqrt(s^2 + f^2)`
/// with `s` a line's relative standard deviation and `f` the
/// [`MODEL_FLOOR`], scaled to mean 1 over the lines that carry
/// information (`0` for a line without: an infinite standard deviation).
/// `None` when the data have no standard deviation.
///
/// ```
/// use frf::{Complex64, Frf};
/// let frf = Frf::new(vec![1.0, 2.0, 3.0], vec![Complex64::new(2.0, 0.0); 3], None)?
///     .with_std_dev(vec![0.0, 2.0, f64::INFINITY])?;
/// let w = ident::fit::uncertainty_weights(&frf).unwrap();
/// // relative 0 and 1: 1/0.05 and 1/sqrt(1.0025), scaled to mean 1
/// assert!((w[0] / w[1] - 1.0025f64.sqrt() / 0.05).abs() < 1e-9);
/// assert_eq!(w[2], 0.0);
/// assert!((w[0] + w[1] - 2.0).abs() < 1e-12);
/// # Ok::<(), frf::FrfError>(())
/// ```
pub fn uncertainty_weights(data: &Frf) -> Option<Vec<f64>> {
    let rel = data.relative_std_dev()?;
    let raw: Vec<f64> = rel
        .iter()
        .map(|s| {
            if s.is_finite() {
                1.0 / (s * s + MODEL_FLOOR * MODEL_FLOOR).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let informative = raw.iter().filter(|&&w| w > 0.0).count();
    if informative == 0 {
        return Some(raw);
    }
    let mean = raw.iter().sum::<f64>() / informative as f64;
    Some(raw.iter().map(|w| w / mean).collect())
}

/// RMS over the lines of `20 log10 |G/H|` (dB) and of the wrapped phase
/// of `G/H` (degrees), unweighted.
pub fn rms_errors(
    response: &ChainResponse,
    p: &[f64],
    gain: f64,
    data: &Frf,
) -> Result<(f64, f64), ResponseError> {
    let mut sdb = 0.0;
    let mut sdeg = 0.0;
    for (&f, &h) in data.freq_hz().iter().zip(data.response()) {
        let e = (response.eval(p, f)? * gain / h).ln();
        sdb += (e.re * 20.0 / std::f64::consts::LN_10).powi(2);
        sdeg += e.im.to_degrees().powi(2);
    }
    let n = data.len() as f64;
    Ok(((sdb / n).sqrt(), (sdeg / n).sqrt()))
}

/// The normal equations `A = J^T J`, `g = J^T r` of a row-major Jacobian
/// with `n` columns (`A` row-major, symmetric).
pub(crate) fn normal_equations(jac: &[f64], r: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = vec![0.0; n * n];
    let mut g = vec![0.0; n];
    for (k, &rk) in r.iter().enumerate() {
        let row = &jac[k * n..(k + 1) * n];
        for i in 0..n {
            g[i] += row[i] * rk;
            for j in 0..=i {
                a[i * n + j] += row[i] * row[j];
            }
        }
    }
    for i in 0..n {
        for j in 0..i {
            a[j * n + i] = a[i * n + j];
        }
    }
    (a, g)
}

/// Solves the symmetric positive definite system `m x = b` by Cholesky;
/// `None` if `m` is not numerically positive definite.
pub(crate) fn solve_spd(m: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = m[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] -= l[i * n + k] * y[k];
        }
        y[i] /= l[i * n + i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            y[i] -= l[k * n + i] * y[k];
        }
        y[i] /= l[i * n + i];
    }
    Some(y)
}
