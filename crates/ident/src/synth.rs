//! Synthetic recordings from the project's own simulator, for tests and
//! benchmarks: a random structure and parameter set, its damped FRF on a
//! frequency grid that covers its features, and optional noise, together
//! with the truth (structure, parameters, the exact undamped features).
//!
//! Draws are reproducible: everything comes from one [`XorShift`].
//!
//! ```
//! use ident::synth::{synthetic, SynthOptions};
//! use mms::xorshift::XorShift;
//!
//! let mut rng = XorShift::new(1);
//! let s = synthetic(&mut rng, None, &SynthOptions::default())?;
//! assert_eq!(s.frf.len(), 2000);
//! assert_eq!(s.model.n_masses(), 3);
//! // The truth comes along: the exact undamped type and features.
//! assert_eq!(s.frf_type.resonances(), 2);
//! # Ok::<(), ident::synth::SynthError>(())
//! ```

use frf::Frf;
use mms::analysis::{Feature, FrfType};
use mms::response::{ChainResponse, Parameters, ResponseError};
use mms::xorshift::XorShift;
use mms::{Model, Output};
use num_complex::Complex64;
use poly::{interleave_roots, Rat, UPoly};
use std::f64::consts::PI;

/// How to draw a synthetic recording.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthOptions {
    /// Number of masses of a randomly drawn structure (the paper's rule (3)
    /// models of this many masses).
    pub masses: usize,
    /// Number of frequency lines.
    pub lines: usize,
    /// Log-spaced grid (else linear).
    pub log_grid: bool,
    /// Damping ratio of each spring-damper link on its own, drawn
    /// log-uniformly in this range: `d = 2 zeta sqrt(c m)` with `m` the
    /// reduced mass of the two bodies it joins (the mass itself for a link
    /// to the ground). Modes then have damping ratios of the same order,
    /// however far apart they are (stiffness-proportional damping would
    /// damp the upper modes out).
    pub damping_ratio: (f64, f64),
    /// Masses drawn log-uniformly in this range (kg).
    pub mass_range: (f64, f64),
    /// Springs drawn log-uniformly in this range (N/m).
    pub spring_range: (f64, f64),
    /// Relative complex Gaussian noise on each line (0: none).
    pub noise: f64,
    /// The measured quantity.
    pub output: Output,
    /// Redraw until distinct undamped features (antiresonances, resonances)
    /// are at least this frequency ratio apart; `1.0` accepts anything.
    pub min_separation: f64,
}

impl Default for SynthOptions {
    fn default() -> SynthOptions {
        SynthOptions {
            masses: 3,
            lines: 2000,
            log_grid: true,
            damping_ratio: (0.005, 0.03),
            mass_range: (0.01, 0.1),
            spring_range: (1e3, 1e5),
            noise: 0.0,
            output: Output::Position,
            min_separation: 1.05,
        }
    }
}

/// A synthetic recording and its truth.
#[derive(Clone, Debug, PartialEq)]
pub struct Synthetic {
    /// The generating structure.
    pub model: Model,
    /// Its parameters.
    pub parameters: Parameters,
    /// The measured quantity.
    pub output: Output,
    /// The recording.
    pub frf: Frf,
    /// The exact type of the undamped FRF.
    pub frf_type: FrfType,
    /// The undamped features in increasing frequency: kind and Hz
    /// (positive real roots of num and den, reduced by their gcd).
    pub features: Vec<(Feature, f64)>,
}

/// Why a draw failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SynthError {
    /// No structure with that many masses.
    #[error("no models of {0} masses")]
    NoModels(usize),
    /// Evaluating the response failed.
    #[error(transparent)]
    Response(#[from] ResponseError),
    /// No draw met the separation rule within the attempt limit.
    #[error("no parameter draw met the separation rule in {0} attempts")]
    Exhausted(usize),
    /// Invalid options (lines, ranges).
    #[error("invalid options: {0}")]
    Options(String),
}

const ATTEMPTS: usize = 1000;

/// Draws a synthetic recording of `model` (or of a random rule (3) model of
/// `options.masses` masses).
pub fn synthetic(
    rng: &mut XorShift,
    model: Option<Model>,
    options: &SynthOptions,
) -> Result<Synthetic, SynthError> {
    if options.lines < 2 {
        return Err(SynthError::Options(format!("{} lines", options.lines)));
    }
    let model = match model {
        Some(m) => m,
        None => {
            let models = mms::rule3_models(options.masses)
                .map_err(|_| SynthError::NoModels(options.masses))?;
            if models.is_empty() {
                return Err(SynthError::NoModels(options.masses));
            }
            models[(rng.next_u64() % models.len() as u64) as usize]
        }
    };
    let tf = model.undamped_tf();
    let n = model.n_masses();
    let springs = model.springs();
    for _ in 0..ATTEMPTS {
        let masses: Vec<f64> = (0..n)
            .map(|_| rng.log_uniform(options.mass_range.0, options.mass_range.1))
            .collect();
        let stiff: Vec<f64> = springs
            .iter()
            .map(|_| rng.log_uniform(options.spring_range.0, options.spring_range.1))
            .collect();
        let mut point = std::collections::BTreeMap::new();
        for (name, v) in model
            .masses()
            .iter()
            .zip(&masses)
            .chain(springs.iter().zip(&stiff))
        {
            point.insert(name.clone(), Rat::from_f64(*v).expect("finite"));
        }
        let Some((frf_type, features)) = undamped_features(&tf.num, &tf.den, &point) else {
            continue;
        };
        let separated = features
            .windows(2)
            .all(|w| w[1].1 >= w[0].1 * options.min_separation);
        if !separated || features.is_empty() {
            continue;
        }
        let dampers: Vec<f64> = (0..n)
            .filter(|&i| model.has_link(i))
            .zip(&stiff)
            .map(|(i, c)| {
                let m = if i == 0 {
                    masses[0]
                } else {
                    masses[i - 1] * masses[i] / (masses[i - 1] + masses[i])
                };
                let zeta = rng.log_uniform(options.damping_ratio.0, options.damping_ratio.1);
                2.0 * zeta * (c * m).sqrt()
            })
            .collect();
        let mut values = masses;
        values.extend(&stiff);
        values.extend(&dampers);
        let parameters = Parameters::from_values(&model, values)?;
        let lo = features[0].1 / 3.0;
        let hi = features[features.len() - 1].1 * 3.0;
        let freq: Vec<f64> = (0..options.lines)
            .map(|k| {
                let t = k as f64 / (options.lines - 1) as f64;
                if options.log_grid {
                    lo * (hi / lo).powf(t)
                } else {
                    lo + (hi - lo) * t
                }
            })
            .collect();
        let g = ChainResponse::new(&model, options.output);
        let mut h = g.eval_many(parameters.values(), &freq)?;
        if options.noise > 0.0 {
            for z in &mut h {
                let e = Complex64::new(rng.normal(), rng.normal()) * (options.noise / 2f64.sqrt());
                *z *= Complex64::new(1.0, 0.0) + e;
            }
        }
        let frf = Frf::new(freq, h, None).map_err(|e| SynthError::Options(e.to_string()))?;
        return Ok(Synthetic {
            model,
            parameters,
            output: options.output,
            frf,
            frf_type,
            features,
        });
    }
    Err(SynthError::Exhausted(ATTEMPTS))
}

/// The exact undamped type and feature frequencies (Hz) at `point`.
fn undamped_features(
    num: &poly::Poly,
    den: &poly::Poly,
    point: &std::collections::BTreeMap<String, Rat>,
) -> Option<(FrfType, Vec<(Feature, f64)>)> {
    let (mut n, mut d) = (num.clone(), den.clone());
    for (name, v) in point {
        n = n.subs(name, v);
        d = d.subs(name, v);
    }
    let (_, n) = UPoly::from_poly(&n, mms::OMEGA)?;
    let (_, d) = UPoly::from_poly(&d, mms::OMEGA)?;
    let frf_type = mms::analysis::frf_type_of(&n, &d)?;
    let g = n.gcd(&d);
    let (n, d) = (n.div_exact(&g)?, d.div_exact(&g)?);
    let polys = [n, d];
    let mut roots = interleave_roots(&polys);
    let mut features = Vec::new();
    for r in roots.iter_mut().filter(|r| r.is_positive()) {
        // Isolating intervals are coarse; refine to ~1e-12 relative.
        let width = Rat::from_f64(r.to_f64().abs() * 1e-12).filter(|w| w.signum() > 0)?;
        r.refine(&polys, &width).ok()?;
        let kind = if r.multiplicities[0] > 0 {
            Feature::Antiresonance
        } else {
            Feature::Resonance
        };
        features.push((kind, r.to_f64().sqrt() / (2.0 * PI)));
    }
    Some((frf_type, features))
}
