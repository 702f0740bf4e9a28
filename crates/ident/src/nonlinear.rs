//! Time-domain diagnosis of nonlinear effects: given the sampled input
//! `u[k]` (actuator force before the model's gain), output `y[k]` and a
//! model that should describe them, decide whether Coulomb friction
//! (`friction {coulomb_n}`) or backlash (`backlash {gap}`) is missing, or
//! nothing ([`diagnose_time`]).
//!
//! Steps (issue 6, time-domain part):
//!
//! 1. **Evidence** the FRF alone cannot give: the H1 estimate's coherence
//!    (a nonlinearity turns part of the output into "noise" uncorrelated
//!    with the input), the FRF of the record's first half against its
//!    second half (amplitude dependence when the two halves have different
//!    input levels, compared with the coherence's noise), and, for a
//!    periodic input with unexcited lines, the output at unexcited odd and
//!    even lines (odd harmonics are the mark of an odd nonlinearity such as
//!    friction or backlash).
//! 2. **Calibration.** The model is simulated with [`mms::simulate`] from
//!    the recorded input; Levenberg-Marquardt on the time-domain output
//!    error adjusts the chain's parameters (log scale, forward-difference
//!    Jacobian) within `1 + tolerance` of their nominal values (dampers
//!    within `1 + damper_tolerance`).
//! 3. **Hypotheses.** Each effect's parameter is first placed by a log grid
//!    and a golden-section search with the calibrated chain held fixed,
//!    then fitted jointly with the chain's parameters by the same
//!    Levenberg-Marquardt.
//! 4. **Selection** by the Bayesian information criterion of a Gaussian
//!    output error: an effect's score is `n ln(RSS_0 / RSS_1) - ln n -
//!    margin` for `n` samples, kept if positive and, when the calibrated
//!    linear model leaves more than [`TimeOptions::adequate`] of the output
//!    RMS, if it removes at least [`TimeOptions::min_share`] of that
//!    residual's energy; else the verdict is
//!    `none` (the calibrated linear model explains the record within its
//!    noise).
//!
//! ```
//! use ident::diagnose::EffectKind;
//! use ident::nonlinear::{diagnose_time, TimeOptions};
//! use mms::model_file::{ModelFile, Motion};
//! use mms::response::{Effects, Parameters};
//! use mms::simulate::simulate;
//! use mms::{Model, Output, Port};
//!
//! // One 2 kg mass on a spring to nothing (a free mass) with 0.8 N of dry
//! // friction, pushed by a two-tone force.
//! let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0))?;
//! let truth = ModelFile {
//!     model: m,
//!     output: Output::Velocity,
//!     parameters: Parameters::from_values(&m, vec![2.0])?,
//!     gain: 1.0,
//!     motion: Motion::Translational,
//!     effects: Effects { coulomb_friction: Some(0.8), ..Effects::default() },
//! };
//! let fs = 200.0;
//! let u: Vec<f64> = (0..800)
//!     .map(|k| {
//!         let t = k as f64 / fs;
//!         2.0 * (2.0 * std::f64::consts::PI * 1.5 * t).sin() + (17.0 * t).cos()
//!     })
//!     .collect();
//! let y = simulate(&truth, &u, fs)?;
//! // The nominal model: no friction, the mass 5 % off.
//! let nominal = ModelFile {
//!     parameters: Parameters::from_values(&m, vec![2.1])?,
//!     effects: Effects::default(),
//!     ..truth.clone()
//! };
//! let d = diagnose_time(&u, &y, fs, &nominal, &TimeOptions::default())?;
//! assert_eq!(d.effects[0].kind, EffectKind::Friction);
//! assert!((d.effects[0].parameters["coulomb_n"] / 0.8 - 1.0).abs() < 0.01);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::diagnose::{Band, Diagnosis, EffectKind, EffectVerdict};
use crate::fit::solve_spd;
use frf::welch::{h1, WelchOptions};
use frf::Frf;
use mms::model_file::ModelFile;
use mms::response::{Effects, Parameters};
use mms::simulate::{default_backlash_link, SimOptions, SimulateError, Simulator};
use num_complex::Complex64;
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::LN_10;

/// Options of [`diagnose_time`].
#[derive(Clone, Debug, PartialEq)]
pub struct TimeOptions {
    /// Calibration bound on masses and springs: each stays within a factor
    /// `1 + tolerance` of its nominal value.
    pub tolerance: f64,
    /// The same for dampers (and a viscous friction the model has).
    pub damper_tolerance: f64,
    /// What an effect must gain beyond the BIC price of its parameter.
    pub margin: f64,
    /// The share of the calibrated model's residual energy an effect must
    /// remove as well, when that residual exceeds [`TimeOptions::adequate`]
    /// of the output RMS. BIC alone counts every sample as independent
    /// noise; when the linear model misses structure (modes it lacks), a
    /// small relative gain over tens of thousands of samples would pass it.
    pub min_share: f64,
    /// The relative RMS error below which the calibrated linear model
    /// counts as adequate, so that BIC alone decides.
    pub adequate: f64,
    /// Iteration limit of each Levenberg-Marquardt fit.
    pub max_iterations: usize,
    /// Also run the frequency-domain diagnosis ([`crate::diagnose`]) on
    /// the record's H1 estimate (its verdict is reported, not merged).
    pub frequency_domain: bool,
    /// How the H1 estimates behind the FRF figures (`rms_db`, `rms_deg`)
    /// and the evidence are made: the user's segment length or period, so
    /// that they describe the lines the user looks at.
    pub welch: WelchOptions,
}

impl Default for TimeOptions {
    fn default() -> TimeOptions {
        TimeOptions {
            tolerance: 0.2,
            damper_tolerance: 0.5,
            margin: 10.0,
            min_share: 0.1,
            adequate: 0.05,
            max_iterations: 30,
            frequency_domain: false,
            welch: WelchOptions::default(),
        }
    }
}

/// Errors of a model against the record, in the frequency and the time
/// domain.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimeFit {
    /// RMS of `20 log10 |H1_rec / H1_model|` over the lines with coherence
    /// of at least 0.5, where `H1_model` is the H1 estimate of the
    /// simulated output from the same input.
    pub rms_db: f64,
    /// RMS of the wrapped phase difference over the same lines, degrees.
    pub rms_deg: f64,
    /// RMS of the time-domain output error `y - y_model`, in the output's
    /// units.
    pub rms_time: f64,
    /// `rms_time` over the RMS of `y`.
    pub rms_time_rel: f64,
}

/// Before (the calibrated linear model) and after (the best kept effect).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimeBeforeAfter {
    /// The calibrated model without a new effect.
    pub before: TimeFit,
    /// The model after the best kept effect (equal to `before` if none).
    pub after: TimeFit,
}

/// The result of [`diagnose_time`]: the JSON of the frequency-domain
/// [`Diagnosis`] (`mismatch`, `effects`, `rejected`, `fit`, `calibration`,
/// `noise`, `model_after`) plus `evidence`, `samples`, `fs` and, if asked
/// for, the frequency-domain diagnosis of the H1 estimate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimeDiagnosis {
    /// Mismatch bands of the frequency-domain diagnosis of the H1
    /// estimate (empty unless [`TimeOptions::frequency_domain`]).
    pub mismatch: Vec<Band>,
    /// Kept effects, best first; `[none]` if nothing is missing.
    pub effects: Vec<EffectVerdict>,
    /// Hypotheses that did not earn their parameter, best first.
    pub rejected: Vec<EffectVerdict>,
    /// Errors before and after.
    pub fit: TimeBeforeAfter,
    /// Calibration notes: parameters pinned at their bounds.
    pub calibration: Vec<String>,
    /// Nonlinearity evidence: coherence, amplitude dependence, harmonics.
    pub evidence: Vec<String>,
    /// RMS of the time-domain residual of the model after the diagnosis
    /// (output units): the noise plus what no hypothesis explains.
    pub noise: f64,
    /// The calibrated model with the best kept effect.
    #[serde(serialize_with = "crate::diagnose::ser_model")]
    pub model_after: ModelFile,
    /// Samples in the record.
    pub samples: usize,
    /// Sample rate, Hz.
    pub fs: f64,
    /// The frequency-domain diagnosis of the H1 estimate (linear effects),
    /// if asked for and possible.
    pub frequency_domain: Option<Diagnosis>,
}

/// Why a time-domain diagnosis cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TimeDiagnoseError {
    /// The model cannot be simulated.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// Bad samples or options.
    #[error("{0}")]
    Input(String),
}

/// The effects the time-domain diagnosis tries.
const HYPOTHESES: [EffectKind; 2] = [EffectKind::Friction, EffectKind::Backlash];

/// The output-error problem: which parameters move, their bounds.
struct Problem<'a> {
    file: &'a ModelFile,
    u: &'a [f64],
    y: &'a [f64],
    fs: f64,
    /// Indices (in the model's parameter order) of the fitted parameters;
    /// `usize::MAX` stands for the model's viscous friction.
    free: Vec<usize>,
}

impl Problem<'_> {
    /// The model at log-parameters `x` (the free ones, then the effect's
    /// log-value for `kind`).
    fn model(&self, kind: EffectKind, x: &[f64]) -> Result<ModelFile, TimeDiagnoseError> {
        let mut values = self.file.parameters.values().to_vec();
        let mut effects = self.file.effects;
        for (&i, &v) in self.free.iter().zip(x) {
            if i == usize::MAX {
                effects.viscous_friction = Some(v.exp());
            } else {
                values[i] = v.exp();
            }
        }
        match kind {
            EffectKind::Friction => effects.coulomb_friction = Some(x[self.free.len()].exp()),
            EffectKind::Backlash => effects.backlash_gap = Some(x[self.free.len()].exp()),
            _ => {}
        }
        let parameters = Parameters::from_values(&self.file.model, values)
            .map_err(|e| TimeDiagnoseError::Simulate(e.into()))?;
        Ok(ModelFile {
            parameters,
            effects,
            ..self.file.clone()
        })
    }

    fn simulate(&self, kind: EffectKind, x: &[f64]) -> Result<Vec<f64>, TimeDiagnoseError> {
        let m = self.model(kind, x)?;
        Ok(Simulator::new(&m, self.fs, &SimOptions::default())?.run(self.u)?)
    }

    /// Residual `y - y_model` and its sum of squares (infinite if the
    /// simulation fails, so a search steps away from there).
    fn residual(&self, kind: EffectKind, x: &[f64]) -> (Vec<f64>, f64) {
        match self.simulate(kind, x) {
            Ok(s) => {
                let r: Vec<f64> = self.y.iter().zip(&s).map(|(a, b)| a - b).collect();
                let rss = r.iter().map(|v| v * v).sum();
                (r, rss)
            }
            Err(_) => (Vec::new(), f64::INFINITY),
        }
    }

    /// Levenberg-Marquardt on the output error from `x`, each step clamped
    /// to `[lo, hi]`. Returns the state and its RSS.
    fn fit(
        &self,
        kind: EffectKind,
        mut x: Vec<f64>,
        lo: &[f64],
        hi: &[f64],
        iterations: usize,
    ) -> (Vec<f64>, f64) {
        let p = x.len();
        let (mut r, mut rss) = self.residual(kind, &x);
        if !rss.is_finite() || p == 0 {
            return (x, rss);
        }
        let mut lambda = 1e-3;
        for _ in 0..iterations {
            // Forward differences in the log-parameters.
            let mut jac: Vec<Vec<f64>> = Vec::with_capacity(p);
            for i in 0..p {
                let mut xi = x.clone();
                let step = if xi[i] + 1e-4 > hi[i] { -1e-4 } else { 1e-4 };
                xi[i] += step;
                let (ri, rssi) = self.residual(kind, &xi);
                if !rssi.is_finite() {
                    return (x, rss);
                }
                // d(model)/dx = -(d residual)/dx.
                jac.push(r.iter().zip(&ri).map(|(a, b)| (a - b) / step).collect());
            }
            let mut a = vec![0.0; p * p];
            let mut g = vec![0.0; p];
            for i in 0..p {
                for j in 0..=i {
                    let s: f64 = jac[i].iter().zip(&jac[j]).map(|(a, b)| a * b).sum();
                    a[i * p + j] = s;
                    a[j * p + i] = s;
                }
                g[i] = jac[i].iter().zip(&r).map(|(a, b)| a * b).sum();
            }
            let mut improved = false;
            for _ in 0..8 {
                let mut m = a.clone();
                for i in 0..p {
                    m[i * p + i] += lambda * a[i * p + i] + 1e-12 * (1.0 + a[i * p + i]);
                }
                let Some(d) = solve_spd(&m, &g, p) else {
                    lambda *= 10.0;
                    continue;
                };
                let xn: Vec<f64> = (0..p).map(|i| (x[i] + d[i]).clamp(lo[i], hi[i])).collect();
                let (rn, rssn) = self.residual(kind, &xn);
                if rssn < rss {
                    let gain = (rss - rssn) / rss;
                    x = xn;
                    r = rn;
                    rss = rssn;
                    lambda = (lambda / 3.0).max(1e-9);
                    improved = gain > 1e-7;
                    break;
                }
                lambda *= 4.0;
            }
            if !improved {
                break;
            }
        }
        (x, rss)
    }
}

/// Golden-section search of `f` over `[a, b]` (log values), from a
/// bracket around the best grid point.
fn golden(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64, iterations: usize) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iterations {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc < fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

/// The time-domain diagnosis of `u`, `y` (sampled at `fs`) against
/// `model`; see the module documentation.
pub fn diagnose_time(
    u: &[f64],
    y: &[f64],
    fs: f64,
    model: &ModelFile,
    o: &TimeOptions,
) -> Result<TimeDiagnosis, TimeDiagnoseError> {
    let bad = |s: String| Err(TimeDiagnoseError::Input(s));
    if u.len() != y.len() {
        return bad(format!("u has {} samples, y {}", u.len(), y.len()));
    }
    if u.len() < 64 {
        return bad(format!("{} samples: at least 64 are needed", u.len()));
    }
    if let Some(k) = y.iter().position(|v| !v.is_finite()) {
        return bad(format!("output sample {k} is not finite"));
    }
    if !(fs.is_finite() && fs > 0.0) {
        return bad(format!("sample rate {fs} Hz must be positive and finite"));
    }
    if !(o.tolerance > 0.0 && o.damper_tolerance > 0.0 && o.margin.is_finite()) {
        return bad("tolerances must be positive, the margin finite".into());
    }
    let n = u.len();
    // Check the model can be simulated at all before any search.
    Simulator::new(model, fs, &SimOptions::default())?;

    // Free parameters: every positive one (a zero damper stays zero), and a
    // viscous friction the model has.
    let names = model.model.parameters();
    let values = model.parameters.values();
    let mut free = Vec::new();
    let (mut lo, mut hi, mut x0) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |i: usize, v: f64, damper: bool| {
        let t = if damper {
            o.damper_tolerance
        } else {
            o.tolerance
        };
        let c = v.ln();
        free.push(i);
        x0.push(c);
        lo.push(c - (1.0 + t).ln());
        hi.push(c + (1.0 + t).ln());
    };
    for (i, (name, &v)) in names.iter().zip(values).enumerate() {
        if v > 0.0 {
            push(i, v, name.starts_with('d'));
        }
    }
    if let Some(v) = model.effects.viscous_friction.filter(|&v| v > 0.0) {
        push(usize::MAX, v, true);
    }
    let problem = Problem {
        file: model,
        u,
        y,
        fs,
        free,
    };
    let np = problem.free.len();

    // Evidence from the H1 estimates.
    let mut evidence = Vec::new();
    let welch = &o.welch;
    let measured = h1(u, y, fs, welch).ok();
    if let Some(est) = &measured {
        evidence.extend(coherence_evidence(&est.frf));
    }
    evidence.extend(amplitude_evidence(u, y, fs, welch));
    evidence.extend(harmonic_evidence(u, y));

    // Calibration of the linear chain (with the model's own effects).
    let x_nominal = x0.clone();
    let (x_cal, rss_cal) = problem.fit(EffectKind::None, x0, &lo, &hi, o.max_iterations);
    if !rss_cal.is_finite() {
        return bad("the nominal model cannot be simulated on this record".into());
    }
    let mut calibration = Vec::new();
    for (k, &i) in problem.free.iter().enumerate() {
        let name = if i == usize::MAX {
            "friction.viscous_ns_per_m"
        } else {
            names[i].as_str()
        };
        let at = |b: f64| (x_cal[k] - b).abs() < 1e-6;
        if at(lo[k]) || at(hi[k]) {
            calibration.push(format!(
                "{name} pinned at its {} bound ({:.4e}, nominal {:.4e})",
                if at(lo[k]) { "lower" } else { "upper" },
                x_cal[k].exp(),
                (0.5 * (lo[k] + hi[k])).exp()
            ));
        }
    }
    let y_cal = problem.simulate(EffectKind::None, &x_cal)?;
    let before = time_fit(u, y, &y_cal, fs, welch, measured.as_ref().map(|e| &e.frf));
    let price = (n as f64).ln() + o.margin;

    // Scale of each effect's parameter.
    let scale = model.gain * model.effects.gain_factor.unwrap_or(1.0);
    let f_max = u.iter().fold(0.0f64, |a, v| a.max(v.abs())) * scale.abs();
    let cal_model = problem.model(EffectKind::None, &x_cal)?;
    let deflection = default_backlash_link(&model.model).and_then(|i| {
        let x = Simulator::new(&cal_model, fs, &SimOptions::default())
            .ok()?
            .positions(u)
            .ok()?;
        let node = |v: &[f64], k: usize| if k == 0 { 0.0 } else { v[k - 1] };
        Some(
            x.iter()
                .map(|p| (node(p, i + 1) - node(p, i)).abs())
                .fold(0.0f64, f64::max),
        )
    });

    let mut verdicts: Vec<(EffectVerdict, Vec<f64>, f64)> = Vec::new();
    for kind in HYPOTHESES {
        let (lo_e, hi_e) = match kind {
            EffectKind::Friction if f_max > 0.0 => (1e-4 * f_max, f_max),
            EffectKind::Backlash => match deflection {
                Some(d) if d > 0.0 => (1e-4 * d, 4.0 * d),
                _ => continue,
            },
            _ => continue,
        };
        let (ll, lh) = (lo_e.ln(), hi_e.ln());
        let mut lo_k = lo.clone();
        lo_k.push(ll);
        let mut hi_k = hi.clone();
        hi_k.push(lh);
        let mut best: Option<(Vec<f64>, f64)> = None;
        // From the calibrated chain and from the nominal one: a large
        // effect can pull the linear calibration far off.
        for base in [&x_cal, &x_nominal] {
            let with = |v: f64| -> f64 {
                let mut x = base.clone();
                x.push(v);
                problem.residual(kind, &x).1
            };
            // A log grid with the calibrated chain held fixed; from each of
            // its (up to three best) local minima a golden section between the
            // neighbours, then the joint fit with the chain: the calibrated
            // chain has absorbed part of the effect, so the grid's best point
            // need not be the joint fit's.
            let grid: Vec<f64> = (0..9).map(|k| ll + (lh - ll) * k as f64 / 8.0).collect();
            let costs: Vec<f64> = grid.iter().map(|&v| with(v)).collect();
            let mut minima: Vec<usize> = (0..9)
                .filter(|&k| {
                    (k == 0 || costs[k] <= costs[k - 1]) && (k == 8 || costs[k] <= costs[k + 1])
                })
                .collect();
            minima.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
            minima.truncate(3);
            for &m in &minima {
                let (a, b) = (grid[m.saturating_sub(1)], grid[(m + 1).min(8)]);
                let (v, _) = golden(a, b, with, 14);
                let mut x = base.clone();
                x.push(v);
                let (x, rss) = problem.fit(kind, x, &lo_k, &hi_k, o.max_iterations);
                if rss.is_finite() && best.as_ref().is_none_or(|b| rss < b.1) {
                    best = Some((x, rss));
                }
            }
        }
        let Some((mut x, mut rss)) = best else {
            continue;
        };
        // Polish: the chain and the effect trade off along a narrow valley
        // where the joint fit may stall; alternate a golden section on the
        // effect (chain fixed) with a fresh joint fit.
        for _ in 0..2 {
            let at = |v: f64| -> f64 {
                let mut xv = x.clone();
                xv[np] = v;
                problem.residual(kind, &xv).1
            };
            let c = x[np];
            let (v, _) = golden((c - 0.4).max(ll), (c + 0.4).min(lh), at, 12);
            let mut xv = x.clone();
            xv[np] = v;
            let (xn, rn) = problem.fit(kind, xv, &lo_k, &hi_k, o.max_iterations);
            if rn < rss * (1.0 - 1e-6) {
                x = xn;
                rss = rn;
            } else {
                break;
            }
        }
        let value = x[np].exp();
        let gain_bic = n as f64 * (rss_cal / rss).ln();
        let share = 1.0 - rss / rss_cal;
        let enough = share >= o.min_share || before.rms_time_rel <= o.adequate;
        let score = if enough {
            gain_bic - price
        } else {
            (gain_bic - price).min(-1.0)
        };
        let y_k = problem.simulate(kind, &x)?;
        let after = time_fit(u, y, &y_k, fs, welch, measured.as_ref().map(|e| &e.frf));
        let pname = if kind == EffectKind::Friction {
            "coulomb_n"
        } else {
            "gap"
        };
        let mut evidence = format!(
            "time-domain error {:.4e} -> {:.4e} ({:.2} % -> {:.2} % of the output RMS); \
             BIC gain {:.1} (price {:.1}); FRF {:.3} dB / {:.2} deg -> {:.3} dB / {:.2} deg",
            before.rms_time,
            after.rms_time,
            100.0 * before.rms_time_rel,
            100.0 * after.rms_time_rel,
            gain_bic,
            price,
            before.rms_db,
            before.rms_deg,
            after.rms_db,
            after.rms_deg
        );
        if !enough {
            evidence.push_str(&format!(
                "; removes only {:.1} % of the calibrated misfit (at least {:.0} % needed \
                 when the linear model leaves more than {:.0} % of the output RMS): the linear \
                 model misses more than this effect explains",
                100.0 * share,
                100.0 * o.min_share,
                100.0 * o.adequate
            ));
        }
        let mut parameters = BTreeMap::new();
        parameters.insert(pname.to_string(), value);
        verdicts.push((
            EffectVerdict {
                kind,
                parameters,
                evidence,
                score,
                // One effect at a time in the time domain.
                step: 1,
            },
            x,
            rss,
        ));
    }
    verdicts.sort_by(|a, b| b.0.score.total_cmp(&a.0.score));
    let (kept, rejected): (Vec<_>, Vec<_>) = verdicts.into_iter().partition(|v| v.0.score > 0.0);
    let (after_kind, after_x, after_rss) = match kept.first() {
        Some((v, x, rss)) => (v.kind, x.clone(), *rss),
        None => (EffectKind::None, x_cal.clone(), rss_cal),
    };
    let after = match kept.first() {
        Some(_) => {
            let y_k = problem.simulate(after_kind, &after_x)?;
            time_fit(u, y, &y_k, fs, welch, measured.as_ref().map(|e| &e.frf))
        }
        None => before,
    };
    let model_after = problem.model(after_kind, &after_x)?;
    let effects = if kept.is_empty() {
        vec![EffectVerdict {
            kind: EffectKind::None,
            step: 0,
            parameters: BTreeMap::new(),
            evidence: match rejected.first() {
                Some((v, _, _)) => format!(
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

    let frequency_domain = match (&measured, o.frequency_domain) {
        (Some(est), true) => linear_diagnosis(&est.frf, model),
        _ => None,
    };
    Ok(TimeDiagnosis {
        mismatch: frequency_domain
            .as_ref()
            .map(|d| d.mismatch.clone())
            .unwrap_or_default(),
        effects,
        rejected: rejected.into_iter().map(|v| v.0).collect(),
        fit: TimeBeforeAfter { before, after },
        calibration,
        evidence,
        noise: (after_rss / n as f64).sqrt(),
        model_after,
        samples: n,
        fs,
        frequency_domain,
    })
}

/// The frequency-domain diagnosis on the trusted band of the H1 estimate.
fn linear_diagnosis(frf: &Frf, model: &ModelFile) -> Option<Diagnosis> {
    let (lo, hi) = crate::classify(frf, model.output, &crate::ClassifyOptions::default())
        .map(|c| c.band_hz)
        .ok()?;
    let data = frf.band(lo.max(f64::MIN_POSITIVE), hi)?;
    let mut m = model.clone();
    // The FRF knows nothing of the nonlinear effects.
    m.effects = Effects {
        coulomb_friction: None,
        backlash_gap: None,
        ..m.effects
    };
    crate::diagnose::diagnose(&data, &m, &crate::diagnose::DiagnoseOptions::default()).ok()
}

/// Lines worth comparing: coherence of at least 0.5 (all lines if the
/// estimate has none, or none qualifies).
fn good_lines(frf: &Frf) -> Vec<usize> {
    let lines: Vec<usize> = match frf.coherence() {
        Some(c) => (0..frf.len()).filter(|&k| c[k] >= 0.5).collect(),
        None => Vec::new(),
    };
    if lines.is_empty() {
        (0..frf.len()).collect()
    } else {
        lines
    }
}

/// Errors of a simulated output against the record.
fn time_fit(
    u: &[f64],
    y: &[f64],
    sim: &[f64],
    fs: f64,
    welch: &WelchOptions,
    measured: Option<&Frf>,
) -> TimeFit {
    let n = y.len() as f64;
    let rms = |v: &mut dyn Iterator<Item = f64>| (v.map(|x| x * x).sum::<f64>() / n).sqrt();
    let rms_time = rms(&mut y.iter().zip(sim).map(|(a, b)| a - b));
    let rms_y = rms(&mut y.iter().copied());
    let (mut rms_db, mut rms_deg) = (f64::NAN, f64::NAN);
    if let (Some(m), Ok(s)) = (measured, h1(u, sim, fs, welch)) {
        let lines = good_lines(m);
        let e: Vec<Complex64> = lines
            .iter()
            .map(|&k| (m.response()[k] / s.frf.response()[k]).ln())
            .filter(|z| z.is_finite())
            .collect();
        let c = e.len().max(1) as f64;
        rms_db = (e.iter().map(|z| z.re * z.re).sum::<f64>() / c).sqrt() * 20.0 / LN_10;
        rms_deg = (e.iter().map(|z| z.im * z.im).sum::<f64>() / c)
            .sqrt()
            .to_degrees();
    }
    TimeFit {
        rms_db,
        rms_deg,
        rms_time,
        rms_time_rel: if rms_y > 0.0 { rms_time / rms_y } else { 0.0 },
    }
}

/// Mean and minimum coherence over the lines above 0.5 and the share of
/// lines below 0.9: a nonlinearity lowers it where the noise does not.
fn coherence_evidence(frf: &Frf) -> Option<String> {
    let c = frf.coherence()?;
    let lines = good_lines(frf);
    let mean = lines.iter().map(|&k| c[k]).sum::<f64>() / lines.len() as f64;
    let low = c.iter().filter(|&&g| g < 0.9).count();
    Some(format!(
        "coherence: mean {mean:.3} over {} lines with coherence >= 0.5; {low} of {} lines below 0.9",
        lines.len(),
        c.len()
    ))
}

/// The first half's FRF against the second half's, with their input
/// levels; the difference in noise units of the coherence.
fn amplitude_evidence(u: &[f64], y: &[f64], fs: f64, opts: &WelchOptions) -> Option<String> {
    // A periodic record splits at a period boundary, so that each half is
    // made of whole periods.
    let half = match opts.period {
        Some(p) if p > 0 => u.len() / (2 * p) * p,
        _ => u.len() / 2,
    };
    let a = h1(&u[..half], &y[..half], fs, opts).ok()?;
    let b = h1(&u[half..2 * half], &y[half..2 * half], fs, opts).ok()?;
    let rms = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let (ua, ub) = (rms(&u[..half]), rms(&u[half..2 * half]));
    let (ca, cb) = (a.frf.coherence()?, b.frf.coherence()?);
    let (mut sum, mut noise, mut count) = (0.0, 0.0, 0usize);
    for k in 0..a.frf.len().min(b.frf.len()) {
        if ca[k] < 0.5 || cb[k] < 0.5 {
            continue;
        }
        let d = (a.frf.response()[k] / b.frf.response()[k]).norm().ln();
        // var ln|H| = (1 - g^2) / (2 n g^2) per estimate.
        let var = |g: f64, n: usize| (1.0 - g) / (2.0 * n as f64 * g);
        sum += d * d;
        noise += var(ca[k], a.averages) + var(cb[k], b.averages);
        count += 1;
    }
    if count == 0 {
        return None;
    }
    let db = |x: f64| (x / count as f64).sqrt() * 20.0 / LN_10;
    Some(format!(
        "amplitude dependence: input RMS {ua:.4e} (first half) vs {ub:.4e} (second half): \
         FRF magnitudes differ by {:.3} dB RMS over {count} lines, noise alone {:.3} dB",
        db(sum),
        db(noise)
    ))
}

/// For an input whose spectrum leaves lines out (a periodic multisine with
/// an integer number of periods), the output power at unexcited odd and
/// even lines relative to the excited ones: odd harmonics mark an odd
/// nonlinearity (friction, backlash), even ones an even nonlinearity.
fn harmonic_evidence(u: &[f64], y: &[f64]) -> Option<String> {
    let uf = frf::fft::fft_real(u);
    let yf = frf::fft::fft_real(y);
    let half = u.len() / 2;
    let pu: Vec<f64> = uf[1..half].iter().map(|z| z.norm_sqr()).collect();
    let top = pu.iter().cloned().fold(0.0, f64::max);
    if top == 0.0 {
        return None;
    }
    let excited: Vec<bool> = pu.iter().map(|&p| p > 1e-6 * top).collect();
    let count = excited.iter().filter(|&&e| e).count();
    let last = excited.iter().rposition(|&e| e)?;
    // Only a sparse input spectrum has lines to look at.
    if count * 2 > last + 1 || count < 3 {
        return None;
    }
    let mean = |pick: &dyn Fn(usize) -> bool| {
        let v: Vec<f64> = (0..=last)
            .filter(|&k| pick(k))
            .map(|k| yf[k + 1].norm_sqr())
            .collect();
        (v.iter().sum::<f64>() / v.len().max(1) as f64, v.len())
    };
    let (pe, _) = mean(&|k| excited[k]);
    // Line k + 1 of the record; its parity in units of the smallest
    // excited line (the multisine's fundamental).
    let base = excited.iter().position(|&e| e)? + 1;
    let parity = |k: usize| -> Option<bool> {
        let l = k + 1;
        l.is_multiple_of(base).then_some((l / base) % 2 == 1)
    };
    let (po, no) = mean(&|k| !excited[k] && parity(k) == Some(true));
    let (pv, nv) = mean(&|k| !excited[k] && parity(k) == Some(false));
    let db = |p: f64| 10.0 * (p / pe).log10();
    Some(format!(
        "harmonics: output at {no} unexcited odd lines {:.1} dB and at {nv} unexcited even lines \
         {:.1} dB relative to the excited lines",
        db(po),
        db(pv)
    ))
}
