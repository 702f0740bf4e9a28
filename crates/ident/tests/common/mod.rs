//! Random chains shared by the diagnosis tests.

use mms::xorshift::XorShift;
use mms::Model;
use std::f64::consts::PI;

/// Log-uniform in `[lo, hi]`.
pub fn log_uniform(rng: &mut XorShift, lo: f64, hi: f64) -> f64 {
    lo * (hi / lo).powf(rng.uniform())
}

/// Parameters for `model`: masses 0.5-2, each link tuned to a mode in
/// `modes_hz` with its reduced mass, 2-8 % damping per link (drawn in
/// this order, so that a seed gives the same chain everywhere).
pub fn chain_parameters(rng: &mut XorShift, model: &Model, modes_hz: (f64, f64)) -> Vec<f64> {
    let n = model.n_masses();
    let masses: Vec<f64> = (0..n).map(|_| log_uniform(rng, 0.5, 2.0)).collect();
    let mut values = masses.clone();
    let mut dampers = Vec::new();
    for i in (0..n).filter(|&i| model.has_link(i)) {
        let reduced = if i == 0 {
            masses[0]
        } else {
            masses[i - 1] * masses[i] / (masses[i - 1] + masses[i])
        };
        let w = 2.0 * PI * log_uniform(rng, modes_hz.0, modes_hz.1);
        let c = reduced * w * w;
        values.push(c);
        dampers.push(2.0 * log_uniform(rng, 0.02, 0.08) * (c * reduced).sqrt());
    }
    values.extend(dampers);
    values
}

/// A model file of `model` with `values`, unit gain, no effects.
pub fn model_file(
    model: Model,
    output: mms::Output,
    values: Vec<f64>,
) -> mms::model_file::ModelFile {
    mms::model_file::ModelFile {
        model,
        output,
        parameters: mms::response::Parameters::from_values(&model, values).unwrap(),
        gain: 1.0,
        motion: mms::model_file::Motion::Translational,
        effects: mms::response::Effects::default(),
    }
}
