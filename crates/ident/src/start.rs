//! Start values from features: undamped parameters whose antiresonances,
//! resonances and static level match measured ones as closely as the
//! structure allows.
//!
//! The exact route is [`mms::backsolve`]: it finds every parameter set
//! that reproduces an undamped target exactly. Measured features of a
//! damped system are slightly off, and a structure with fewer determinable
//! parameters than features (Tab. 5: B2, C2, C4 show four numbers' worth of
//! freedom in a five-number type) has no exact solution then. This module
//! finds the nearest ones instead: a small Levenberg-Marquardt on the
//! logarithms of the feature frequencies, from several seeds.
//!
//! ```
//! use ident::start::{feature_starts, FeatureTarget};
//! use mms::Model;
//!
//! // B2 with the paper's Tab. 6 parameters has ARRA features; perturb them
//! // by 1 % (as damping and noise would): B2 cannot match exactly, but the
//! // nearest parameter set matches to within about that.
//! let b2 = Model::from_id("B2")?;
//! let truth = [0.01, 0.01, 0.01, 100.0, 200.0];
//! let t = FeatureTarget::from_model(&b2, &truth).unwrap();
//! let perturbed = FeatureTarget {
//!     antiresonances: t.antiresonances.iter().map(|z| z * 1.01).collect(),
//!     ..t.clone()
//! };
//! let starts = feature_starts(&b2, &perturbed, 8, 1);
//! assert!(!starts.is_empty());
//! assert!(starts[0].1 < 0.02); // RMS log error of the features
//! # Ok::<(), mms::ModelError>(())
//! ```

use mms::xorshift::XorShift;
use mms::Model;
use num_complex::Complex64;

/// Measured undamped features in `Omega = w^2` ((rad/s)^2), ascending, and
/// the static inertance `G_a(0)` (the rigid-body level).
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureTarget {
    /// Antiresonances, with multiplicity (a double zero appears twice).
    /// Fewer than the structure's zeros when the rest are off the positive
    /// real axis (type `(nm)`): those are then left free.
    pub antiresonances: Vec<f64>,
    /// Resonances, with multiplicity.
    pub resonances: Vec<f64>,
    /// `|G_a(0)|`, the inertance below every feature.
    pub static_inertance: f64,
}

impl FeatureTarget {
    /// The exact features of `model` at undamped parameters `values` (in
    /// the order of [`Model::undamped_parameters`]); `None` if some zero
    /// is off the positive real axis.
    pub fn from_model(model: &Model, values: &[f64]) -> Option<FeatureTarget> {
        let c = UndampedCoefficients::new(model);
        let (num, den) = c.eval(values);
        let zeros = roots(&num);
        let poles = roots(&den);
        let real = |v: Vec<Complex64>| -> Option<Vec<f64>> {
            let mut r: Vec<f64> = v
                .iter()
                .map(|z| (z.im.abs() <= 1e-9 * z.norm() && z.re > 0.0).then_some(z.re))
                .collect::<Option<_>>()?;
            r.sort_by(f64::total_cmp);
            Some(r)
        };
        Some(FeatureTarget {
            antiresonances: real(zeros)?,
            resonances: real(poles)?,
            static_inertance: (num[0] / den[0]).abs(),
        })
    }
}

pub use mms::UndampedCoefficients;

/// Roots of a real polynomial (coefficients ascending) by the Aberth-
/// Ehrlich iteration, sorted by real part. Degrees here are at most
/// `N - 1 <= 7`.
pub fn roots(coeffs: &[f64]) -> Vec<Complex64> {
    let mut c: Vec<f64> = coeffs.to_vec();
    while c.len() > 1 && c[c.len() - 1] == 0.0 {
        c.pop();
    }
    let n = c.len() - 1;
    if n == 0 {
        return Vec::new();
    }
    let lead = c[n];
    let a: Vec<f64> = c.iter().map(|x| x / lead).collect();
    // Initial guesses on a circle of the Cauchy bound's radius, rotated off
    // the real axis so conjugate pairs can separate.
    let radius = 1.0 + a[..n].iter().fold(0.0f64, |m, x| m.max(x.abs())).sqrt();
    let mut z: Vec<Complex64> = (0..n)
        .map(|k| {
            Complex64::from_polar(
                radius,
                0.4 + 2.0 * std::f64::consts::PI * k as f64 / n as f64,
            )
        })
        .collect();
    let eval = |x: Complex64| -> (Complex64, Complex64) {
        let mut p = Complex64::new(a[n], 0.0);
        let mut d = Complex64::new(0.0, 0.0);
        for &coef in a[..n].iter().rev() {
            d = d * x + p;
            p = p * x + coef;
        }
        (p, d)
    };
    for _ in 0..500 {
        let mut moved = 0.0f64;
        for i in 0..n {
            let (p, d) = eval(z[i]);
            if p.norm() == 0.0 {
                continue;
            }
            let ratio = p / d;
            let sum: Complex64 = (0..n)
                .filter(|&j| j != i)
                .map(|j| Complex64::new(1.0, 0.0) / (z[i] - z[j]))
                .sum();
            let step = ratio / (Complex64::new(1.0, 0.0) - ratio * sum);
            if step.is_finite() {
                z[i] -= step;
                moved = moved.max(step.norm() / z[i].norm().max(1e-300));
            }
        }
        if moved < 1e-15 {
            break;
        }
    }
    z.sort_by(|x, y| x.re.total_cmp(&y.re));
    z
}

/// Residuals of the feature match at undamped parameters `x`: log ratios
/// of resonances, complex log ratios of antiresonances (real and
/// imaginary part), and the log ratio of the static level. `None` when the
/// counts differ.
fn residuals(c: &UndampedCoefficients, t: &FeatureTarget, x: &[f64]) -> Option<Vec<f64>> {
    let (num, den) = c.eval(x);
    let zeros = roots(&num);
    let poles = roots(&den);
    if zeros.len() < t.antiresonances.len() || poles.len() != t.resonances.len() {
        return None;
    }
    let mut r = Vec::with_capacity(poles.len() + 2 * t.antiresonances.len() + 1);
    for (p, &w) in poles.iter().zip(&t.resonances) {
        r.push((p.norm() / w).ln());
    }
    if zeros.len() == t.antiresonances.len() {
        for (z, &w) in zeros.iter().zip(&t.antiresonances) {
            let e = (z / w).ln();
            r.push(e.re);
            r.push(e.im);
        }
    } else {
        // More zeros than measured antiresonances (the rest are off the
        // axis, type "(nm)"): each antiresonance is matched by the zero
        // nearest to it; the others are left free.
        for &w in &t.antiresonances {
            let e = zeros
                .iter()
                .map(|z| (z / w).ln())
                .min_by(|a, b| a.norm().total_cmp(&b.norm()))?;
            r.push(e.re);
            r.push(e.im);
        }
    }
    r.push(((num[0] / den[0]).abs() / t.static_inertance).ln());
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Undamped parameter sets matching `target` as closely as possible, from
/// `seeds` pseudo-random starts (deterministic in `seed`), each with its
/// RMS log error; best first, near-duplicates removed.
pub fn feature_starts(
    model: &Model,
    target: &FeatureTarget,
    seeds: usize,
    seed: u64,
) -> Vec<(Vec<f64>, f64)> {
    let c = UndampedCoefficients::new(model);
    let n = model.n_masses();
    let n_springs = model.springs().len();
    let total = 1.0 / target.static_inertance.max(f64::MIN_POSITIVE);
    let all: Vec<f64> = target
        .resonances
        .iter()
        .chain(&target.antiresonances)
        .copied()
        .collect();
    let (w_lo, w_hi) = all
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &w| (a.min(w), b.max(w)));
    if !(w_lo.is_finite() && w_hi > 0.0) {
        return Vec::new();
    }
    let mut rng = XorShift::new(seed);
    let mut found: Vec<(Vec<f64>, f64)> = Vec::new();
    for _ in 0..seeds {
        let masses: Vec<f64> = (0..n)
            .map(|_| total / n as f64 * rng.log_uniform(0.05, 20.0))
            .collect();
        let mean = masses.iter().sum::<f64>() / n as f64;
        let mut x = masses;
        x.extend((0..n_springs).map(|_| mean * rng.log_uniform(w_lo, w_hi)));
        if let Some((x, err)) = lm(&c, target, x) {
            found.push((x, err));
        }
    }
    found.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut out: Vec<(Vec<f64>, f64)> = Vec::new();
    for (x, e) in found {
        let dup = out
            .iter()
            .any(|(y, _)| x.iter().zip(y).all(|(a, b)| ((a / b).ln()).abs() < 0.05));
        if !dup {
            out.push((x, e));
        }
    }
    out
}

/// Levenberg-Marquardt on the feature residuals in log-parameters, with a
/// forward-difference Jacobian (the residuals are cheap).
fn lm(c: &UndampedCoefficients, t: &FeatureTarget, x0: Vec<f64>) -> Option<(Vec<f64>, f64)> {
    let np = x0.len();
    let mut y: Vec<f64> = x0.iter().map(|v| v.ln()).collect();
    let exp = |y: &[f64]| y.iter().map(|v| v.exp()).collect::<Vec<f64>>();
    let mut r = residuals(c, t, &exp(&y))?;
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut cur = cost(&r);
    let mut lambda = 1e-2;
    for _ in 0..200 {
        let h = 1e-7;
        // Row-major Jacobian, one row per residual.
        let mut jac = vec![0.0; r.len() * np];
        for k in 0..np {
            let mut yk = y.clone();
            yk[k] += h;
            let rk = residuals(c, t, &exp(&yk))?;
            for (row, (a, b)) in rk.iter().zip(&r).enumerate() {
                jac[row * np + k] = (a - b) / h;
            }
        }
        let (a, g) = crate::fit::normal_equations(&jac, &r, np);
        let mut improved = false;
        while lambda < 1e12 {
            let mut m = a.clone();
            for i in 0..np {
                m[i * np + i] += lambda * (a[i * np + i] + 1e-12);
            }
            let Some(step) = solve(&m, &g, np) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = y
                .iter()
                .zip(&step)
                .map(|(v, s)| v - s.clamp(-2.0, 2.0))
                .collect();
            match residuals(c, t, &exp(&trial)) {
                Some(tr) if cost(&tr) < cur => {
                    let done = (cur - cost(&tr)) < 1e-14 * (1.0 + cur);
                    y = trial;
                    cur = cost(&tr);
                    r = tr;
                    lambda = (lambda / 3.0).max(1e-12);
                    improved = !done;
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        if !improved || cur < 1e-26 {
            break;
        }
    }
    Some((exp(&y), (cur / r.len() as f64).sqrt()))
}

/// Gaussian elimination with partial pivoting on a small dense system.
fn solve(m: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut a = m.to_vec();
    let mut x = b.to_vec();
    for k in 0..n {
        let p = (k..n).max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))?;
        if a[p * n + k].abs() < 1e-300 {
            return None;
        }
        if p != k {
            for c in 0..n {
                a.swap(p * n + c, k * n + c);
            }
            x.swap(p, k);
        }
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for c in k..n {
                a[i * n + c] -= f * a[k * n + c];
            }
            x[i] -= f * x[k];
        }
    }
    for i in (0..n).rev() {
        for c in i + 1..n {
            x[i] -= a[i * n + c] * x[c];
        }
        x[i] /= a[i * n + i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Roots against polynomials built from known roots.
    #[test]
    fn aberth_finds_known_roots() {
        // (x - 1)(x - 4)(x^2 + 2x + 5) = x^4 - 3x^3 - x^2 - 17x + 20:
        // roots 1, 4, -1 +- 2j.
        let p = [20.0, -17.0, -1.0, -3.0, 1.0];
        let mut r = roots(&p);
        r.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        let want = [
            Complex64::new(-1.0, -2.0),
            Complex64::new(-1.0, 2.0),
            Complex64::new(1.0, 0.0),
            Complex64::new(4.0, 0.0),
        ];
        for (a, b) in r.iter().zip(want) {
            assert!((a - b).norm() < 1e-12, "{a} vs {b}");
        }
        // Widely spread roots, as feature frequencies squared are:
        // (x - 1e2)(x - 1e6).
        let r = roots(&[1e8, -1_000_100.0, 1.0]);
        assert!((r[0].re / 1e2 - 1.0).abs() < 1e-12 && (r[1].re / 1e6 - 1.0).abs() < 1e-12);
    }

    /// The compiled coefficients agree with exact evaluation of the
    /// symbolic TF.
    #[test]
    fn compiled_coefficients_match_exact_evaluation() {
        for m in mms::rule3_models(3).unwrap() {
            let names = m.undamped_parameters();
            let x: Vec<f64> = (0..names.len()).map(|i| 1.0 + i as f64 * 0.7).collect();
            let (num, _) = UndampedCoefficients::new(&m).eval(&x);
            let point: std::collections::BTreeMap<String, poly::Rat> = names
                .iter()
                .zip(&x)
                .map(|(n, v)| (n.clone(), poly::Rat::from_f64(*v).unwrap()))
                .collect();
            let exact = m.undamped_tf().num.coeffs_in(mms::OMEGA);
            for (a, p) in num.iter().zip(exact) {
                let e = p.eval(&point).unwrap().to_f64();
                assert!((a - e).abs() <= 1e-12 * e.abs().max(1.0), "{m}: {a} vs {e}");
            }
        }
    }
}
