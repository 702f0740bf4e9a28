//! Targeted witness search for rare generic types .
//!
//! Some types fill so thin a sliver of the orthant that the prover's few
//! hundred log-uniform samples never land in it (at four masses, some show
//! up in fewer than 1 of 4000 draws). For every type still unknown after
//! the proofs, this module
//!
//! 1. samples many points in floating point, over a wider range than the
//!    exact search: each sample costs a few coefficient evaluations and a
//!    real-root count, not an exact isolation;
//! 2. for the types no sample showed, maximises the *margin* of the wanted
//!    ordering with Nelder-Mead in log-parameters: with the `k`-th wanted
//!    antiresonance taken as the `k`-th positive zero and likewise for the
//!    resonances, the margin is the smallest log-gap between tokens that
//!    should follow each other; it is positive exactly where the ordering is
//!    the wanted one;
//! 3. rounds every hit to a short rational point and accepts it only if the
//!    exact classification ([`Prover::type_at`]) gives the wanted type. f64
//!    only proposes; nothing numeric decides a verdict.
//!
//! Only generic types (simple tokens, no cancellation) are targeted here:
//! measure-zero types live on walls, which the exact search samples.

use super::frf_type::{Feature, FrfType};
use super::pole_signs::{block_ranges, run_det};
use super::prover::{positive_full_point, substitute, Prover, Sampler, Stratum, Substitution};
use crate::tf::OMEGA;
use crate::tf::{Compiled, UndampedCoefficients};
use crate::xorshift::XorShift;
use poly::{rational_roots, Int, Poly, Rat, UPoly};
use std::collections::{BTreeMap, BTreeSet};

/// Floating-point samples per model.
const SAMPLES: usize = 20_000;
/// Log-range of the samples: parameters in `[e^-R, e^R]`.
const LOG_RANGE: f64 = 5.0;
/// Nelder-Mead starts per wanted type, and evaluations per start.
const STARTS: usize = 4;
const EVALUATIONS: usize = 800;

/// Sorted positive real roots of numerator and denominator at `x`, and
/// whether the numerator has zeros off the positive axis.
pub(super) fn tf_roots(tf: &UndampedCoefficients, x: &[f64]) -> Option<(Vec<f64>, Vec<f64>, bool)> {
    let (n, d) = tf.eval(x);
    let zn = positive_roots(&n)?;
    let zd = positive_roots(&d)?;
    let nm = zn.len() < n.len() - 1;
    Some((zn, zd, nm))
}

/// Positive real roots of `sum c[k] x^k` (simple ones; a double root shows
/// once or not at all, which only matters on measure-zero sets), found by
/// bracketing between the roots of the derivative.
pub(super) fn positive_roots(c: &[f64]) -> Option<Vec<f64>> {
    let deg = c.iter().rposition(|v| *v != 0.0)?;
    if !c.iter().all(|v| v.is_finite()) {
        return None;
    }
    let c = &c[..=deg];
    if deg == 0 {
        return Some(Vec::new());
    }
    let lead = c[deg].abs();
    let bound = 1.0 + c[..deg].iter().map(|v| v.abs() / lead).fold(0.0, f64::max);
    Some(roots_in(c, 0.0, bound))
}

pub(super) fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, v| acc * x + v)
}

/// `sum |c[k]| |x|^k`, the scale of Horner's rounding error at `x`.
fn horner_abs(c: &[f64], x: f64) -> f64 {
    let x = x.abs();
    c.iter().rev().fold(0.0, |acc, v| acc * x + v.abs())
}

/// [`horner`] and [`horner_abs`] in one pass.
fn horner_with_bound(c: &[f64], x: f64) -> (f64, f64) {
    let ax = x.abs();
    c.iter().rev().fold((0.0, 0.0), |(acc, abs), v| {
        (acc * x + v, abs * ax + v.abs())
    })
}

fn roots_in(c: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let deg = c.len().saturating_sub(1);
    if deg == 0 {
        return Vec::new();
    }
    // Every derivative down to the constant one: the roots of each cut
    // the next lower one's range into monotone pieces. One buffer, the
    // derivative of order `j` (degree `deg - j`) from `start(j)` on: the
    // search calls this at every point it evaluates.
    let start = |j: usize| j * (deg + 1) - j * j.saturating_sub(1) / 2;
    let mut chain: Vec<f64> = Vec::with_capacity(start(deg) + 1);
    chain.extend_from_slice(c);
    for j in 1..=deg {
        let last = start(j - 1)..start(j);
        for k in 1..last.len() {
            let v = chain[last.start + k] * k as f64;
            chain.push(v);
        }
    }
    let level_of = |j: usize| &chain[start(j)..start(j) + deg + 1 - j];
    let mut roots: Vec<f64> = Vec::new();
    let mut cuts: Vec<f64> = Vec::with_capacity(deg + 1);
    for level in (0..deg).rev() {
        let (p, dp) = (level_of(level), level_of(level + 1));
        cuts.clear();
        cuts.push(lo);
        cuts.extend_from_slice(&roots);
        cuts.push(hi);
        roots.clear();
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let (fa, fb) = (horner(p, a), horner(p, b));
            if fa == 0.0 && a > lo {
                if roots.last() != Some(&a) {
                    roots.push(a);
                }
                continue;
            }
            if fa.signum() == fb.signum() || fb == 0.0 {
                continue;
            }
            roots.push(monotone_root(p, dp, a, b, fa));
        }
    }
    roots
}

/// The root of `c` in `(a, b)`, where `c` is monotone and changes sign
/// (`fa` its value at `a`): Newton's steps while they stay inside the
/// bracket, otherwise halving it, geometrically when it spans decades (a
/// root near zero would otherwise take a thousand halvings).
fn monotone_root(c: &[f64], derivative: &[f64], mut a: f64, mut b: f64, fa: f64) -> f64 {
    let split = |a: f64, b: f64| {
        if a > 0.0 && b > 4.0 * a {
            (a * b).sqrt()
        } else if a == 0.0 && b > 1e-300 {
            b * 0.25
        } else {
            0.5 * (a + b)
        }
    };
    if a == 0.0 && c[0] != 0.0 {
        // No positive root lies below |c0| / (|c0| + max |c_k|).
        let top = c[1..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let floor = c[0].abs() / (c[0].abs() + top);
        if floor > 0.0 && floor < b {
            a = floor;
        }
    }
    let mut x = split(a, b);
    let mut step = b - a;
    for _ in 0..200 {
        let (f, bound) = horner_with_bound(c, x);
        // Within Horner's rounding error of zero, no step can do better.
        let noise = 2.0 * c.len() as f64 * f64::EPSILON * bound;
        if f.abs() <= noise {
            return x;
        }
        if f.signum() == fa.signum() {
            a = x;
        } else {
            b = x;
        }
        // Newton's step unless it leaves the bracket or shrinks too
        // slowly (far from the root it moves by a fraction of x only).
        // A step onto an end that rounding put on the wrong side lands on
        // the root all the same.
        let tol = 8.0 * f64::EPSILON * b.abs();
        let newton = x - f / horner(derivative, x);
        let newton = if newton > b && newton <= b + tol {
            b
        } else if newton < a && newton >= a - tol {
            a
        } else {
            newton
        };
        let next = if newton >= a && newton <= b && (newton - x).abs() <= 0.5 * step {
            newton
        } else {
            split(a, b)
        };
        step = (next - x).abs();
        if next <= a || next >= b || (next - x).abs() <= 2.0 * f64::EPSILON * x.abs() {
            return next.clamp(a, b);
        }
        x = next;
    }
    x
}

/// The logarithms of the zeros and poles in the order `t` lists its
/// tokens: the `k`-th antiresonance is the `k`-th of `zeros`, likewise for
/// the resonances (both sorted, with enough entries).
fn log_sequence(t: &FrfType, zeros: &[f64], poles: &[f64]) -> Vec<f64> {
    let (mut ia, mut ir) = (0, 0);
    t.tokens
        .iter()
        .map(|tok| {
            let v = match tok.feature {
                Feature::Antiresonance => {
                    ia += 1;
                    zeros[ia - 1]
                }
                Feature::Resonance => {
                    ir += 1;
                    poles[ir - 1]
                }
            };
            v.max(f64::MIN_POSITIVE).ln()
        })
        .collect()
}

/// The log-gap margin of the wanted ordering `t` (positive iff the
/// ordering is `t`), or `None` when the root counts do not fit.
fn margin(t: &FrfType, roots: &(Vec<f64>, Vec<f64>, bool)) -> Option<f64> {
    let (zn, zd, nm) = roots;
    if *nm != t.nonminimum_phase
        || zn.len() as u32 != t.antiresonances()
        || zd.len() as u32 != t.resonances()
    {
        return None;
    }
    let seq = log_sequence(t, zn, zd);
    Some(
        seq.windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min),
    )
}

/// A short positive rational near `x` with `digits` significant decimal
/// digits.
pub(super) fn short_rational(x: f64, digits: i32) -> Option<Rat> {
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    let e = x.log10().floor() as i32 - (digits - 1);
    let m = (x / 10f64.powi(e)).round() as i64;
    if m <= 0 {
        return None;
    }
    let ten = Rat::from(10);
    Some(Rat::new(Int::from(m), Int::ONE) * ten.pow(e))
}

/// Log-uniform samples, Nelder-Mead starts and evaluations per start of
/// the violation search.
const VIOLATION_SAMPLES: usize = 2000;
const VIOLATION_STARTS: usize = 12;
const VIOLATION_EVALUATIONS: usize = 3000;
/// The log-gap the violation search asks between neighbouring tokens.
pub(super) const VIOLATION_GAP: f64 = 1e-3;

/// How far the roots at one point are from showing the simple type `t`
/// (zero exactly when it shows, with log-gaps of at least
/// [`VIOLATION_GAP`]), or `None` when the resonances do not match.
///
/// Unlike [`margin`], which needs the right number of positive zeros to say
/// anything, this sums every violated condition: the `k` zeros nearest the
/// positive axis (by angle) are the antiresonances and each adds its angle;
/// the other zeros must keep off the axis; and each pair of tokens that
/// should follow each other adds how far it falls short of the gap. So a
/// complex pair that must become two antiresonances has a slope to follow,
/// and all violations shrink together rather than the worst alone.
fn violation(t: &FrfType, num: &[f64], den: &[f64]) -> Option<f64> {
    violation_near(t, num, den, &mut Vec::new())
}

/// [`violation`] with the zeros' iteration started from `near` (the zeros
/// at a nearby point, as a descent evaluates one after another), which it
/// then holds the zeros found here.
pub(super) fn violation_near(
    t: &FrfType,
    num: &[f64],
    den: &[f64],
    near: &mut Vec<(f64, f64)>,
) -> Option<f64> {
    let poles = positive_roots(den)?;
    if poles.len() as u32 != t.resonances() {
        return None;
    }
    let k = t.antiresonances() as usize;
    let (mut cost, moduli) = zeros_near_the_axis(num, k, t.nonminimum_phase, near)?;
    let seq = log_sequence(t, &moduli, &poles);
    cost += seq
        .windows(2)
        .map(|w| (VIOLATION_GAP - (w[1] - w[0])).max(0.0))
        .sum::<f64>();
    cost.is_finite().then_some(cost)
}

/// The zeros of `num` (ascending coefficients) as the violation search
/// scores them: the `k` nearest the positive axis by angle are to be
/// antiresonances, each adding its angle, the others (there must be some
/// exactly when `nonminimum_phase`) adding how far they fall short of
/// [`VIOLATION_GAP`] off the axis. Returns that cost and the `k` zeros'
/// moduli, ascending; `None` where `num` has fewer than `k` zeros or the
/// phase cannot fit. `near` is as for [`violation_near`].
pub(super) fn zeros_near_the_axis(
    num: &[f64],
    k: usize,
    nonminimum_phase: bool,
    near: &mut Vec<(f64, f64)>,
) -> Option<(f64, Vec<f64>)> {
    let zeros = match complex_roots_near(num, near) {
        Some(z) => z,
        None => complex_roots_near(num, &[])?,
    };
    near.clone_from(&zeros);
    if zeros.len() < k || (zeros.len() > k) != nonminimum_phase {
        return None;
    }
    // A real root keeps a rounding-level imaginary part.
    let angle = |z: &(f64, f64)| {
        let a = z.1.atan2(z.0).abs();
        if a < 1e-10 {
            0.0
        } else {
            a
        }
    };
    let mut by_angle: Vec<(f64, f64)> = zeros.iter().map(|z| (angle(z), z.0.hypot(z.1))).collect();
    by_angle.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut cost = 0.0;
    for &(angle, _) in &by_angle[..k] {
        cost += angle;
    }
    for &(angle, _) in &by_angle[k..] {
        cost += (VIOLATION_GAP - angle).max(0.0);
    }
    let mut moduli: Vec<f64> = by_angle[..k].iter().map(|z| z.1).collect();
    moduli.sort_by(|a, b| a.total_cmp(b));
    Some((cost, moduli))
}

/// All roots of `sum c[k] x^k` as `(re, im)` (Aberth-Ehrlich on the
/// polynomial scaled to roots of modulus about one), roots at `0`
/// included; `None` for a zero or non-finite polynomial.
#[cfg(test)]
fn complex_roots(c: &[f64]) -> Option<Vec<(f64, f64)>> {
    complex_roots_near(c, &[])
}

/// Residual, relative to the sum of the terms' moduli, at which a root of
/// [`complex_roots_near`] counts as settled: a few units of rounding. A
/// multiple root is only found to about the square root of the rounding
/// and would otherwise be stepped on to the last iteration, as a third of
/// the calls in the violation search were.
const ROUNDING_RESIDUAL: f64 = 8.0 * f64::EPSILON;

/// [`complex_roots`] started from `near` when it holds as many roots (each
/// turned by a small angle, so that real starts can leave the real axis),
/// else from points spread on a circle.
fn complex_roots_near(c: &[f64], near: &[(f64, f64)]) -> Option<Vec<(f64, f64)>> {
    let deg = c.iter().rposition(|v| *v != 0.0)?;
    if !c.iter().all(|v| v.is_finite()) {
        return None;
    }
    let low = c.iter().position(|v| *v != 0.0)?;
    let mut out = vec![(0.0, 0.0); low];
    let c = &c[low..=deg];
    let n = c.len() - 1;
    if n == 0 {
        return Some(out);
    }
    // x = s*y with s the geometric mean of the roots' moduli.
    let s = (c[0].abs() / c[n].abs()).powf(1.0 / n as f64);
    let a: Vec<f64> = c
        .iter()
        .enumerate()
        .map(|(k, v)| v * s.powi(k as i32) / (c[n] * s.powi(n as i32)))
        .collect();
    let mul = |x: (f64, f64), y: (f64, f64)| (x.0 * y.0 - x.1 * y.1, x.0 * y.1 + x.1 * y.0);
    let div = |x: (f64, f64), y: (f64, f64)| {
        let d = y.0 * y.0 + y.1 * y.1;
        ((x.0 * y.0 + x.1 * y.1) / d, (x.1 * y.0 - x.0 * y.1) / d)
    };
    let (turn_re, turn_im) = (1e-3f64.cos(), 1e-3f64.sin());
    let mut z: Vec<(f64, f64)> = if near.len() == low + n {
        near[low..]
            .iter()
            .map(|v| {
                let (re, im) = (v.0 / s, v.1 / s);
                (re * turn_re - im * turn_im, re * turn_im + im * turn_re)
            })
            .collect()
    } else {
        (0..n)
            .map(|k| {
                let phi = 2.0 * std::f64::consts::PI * k as f64 / n as f64 + 0.4;
                (phi.cos(), phi.sin())
            })
            .collect()
    };
    // A root stops moving once its relative step is below 1e-13, or once
    // its residual is at the rounding level (see ROUNDING_RESIDUAL).
    let mut settled = vec![false; n];
    for _ in 0..200 {
        let mut moving = false;
        for i in 0..n {
            if settled[i] {
                continue;
            }
            let zi = z[i];
            // p and p' at z_i by Horner, with the bound on its rounding
            // error: where p is below it, z_i is a root of a polynomial
            // within rounding of this one and no step makes it better.
            let (mut p, mut dp) = ((1.0, 0.0), (0.0, 0.0));
            for v in a[..n].iter().rev() {
                let d = mul(dp, zi);
                dp = (d.0 + p.0, d.1 + p.1);
                p = mul(p, zi);
                p.0 += v;
            }
            let bound = horner_abs(&a, zi.0.hypot(zi.1));
            let at_rounding = p.0.hypot(p.1) <= ROUNDING_RESIDUAL * bound;
            if p == (0.0, 0.0) {
                settled[i] = true;
                continue;
            }
            let ratio = div(p, dp);
            let mut sum = (0.0, 0.0);
            for (j, zj) in z.iter().enumerate() {
                if j != i {
                    let (dr, di) = (zi.0 - zj.0, zi.1 - zj.1);
                    let m = dr * dr + di * di;
                    sum = (sum.0 + dr / m, sum.1 - di / m);
                }
            }
            let rs = mul(ratio, sum);
            let w = div(ratio, (1.0 - rs.0, -rs.1));
            if !(w.0.is_finite() && w.1.is_finite()) {
                return None;
            }
            z[i] = (zi.0 - w.0, zi.1 - w.1);
            let step = (w.0 * w.0 + w.1 * w.1) / (z[i].0 * z[i].0 + z[i].1 * z[i].1).max(1e-300);
            if step < 1e-26 || at_rounding {
                settled[i] = true;
            } else {
                moving = true;
            }
        }
        if !moving {
            break;
        }
    }
    // Near a multiple root the iteration converges slowly; the estimate is
    // still good enough to steer by.
    out.extend(z.iter().map(|v| (v.0 * s, v.1 * s)));
    Some(out)
}

/// Minimises `f` from `x0` (Nelder-Mead, standard coefficients); stops
/// early when `f` drops below `stop`.
fn nelder_mead(f: &mut dyn FnMut(&[f64]) -> f64, x0: &[f64], step: f64, stop: f64) -> Vec<f64> {
    nelder_mead_for(f, x0, step, stop, EVALUATIONS)
}

/// [`nelder_mead`] with `evaluations` evaluations at most.
pub(super) fn nelder_mead_for(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    stop: f64,
    evaluations: usize,
) -> Vec<f64> {
    let n = x0.len();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    simplex.push((x0.to_vec(), f(x0)));
    for i in 0..n {
        let mut x = x0.to_vec();
        x[i] += step;
        let v = f(&x);
        simplex.push((x, v));
    }
    let mut evals = n + 1;
    while evals < evaluations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if simplex[0].1 < stop {
            break;
        }
        // A simplex shrunk to 1e-9 of its coordinates (logarithms of the
        // parameters, whose witnesses are rounded to 9 digits at most)
        // has found what it will find: the rest of the budget would be
        // spent in place. The 5-mass table is the same to the byte.
        let base = &simplex[0].0;
        let collapsed = simplex[1..].iter().all(|(x, _)| {
            x.iter()
                .zip(base)
                .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + b.abs()))
        });
        if collapsed {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|s| s.0[j]).sum::<f64>() / n as f64)
            .collect();
        let worst = simplex[n].clone();
        let along = |t: f64| -> Vec<f64> {
            centroid
                .iter()
                .zip(&worst.0)
                .map(|(c, w)| c + t * (c - w))
                .collect()
        };
        let xr = along(1.0);
        let fr = f(&xr);
        evals += 1;
        if fr < simplex[0].1 {
            let xe = along(2.0);
            let fe = f(&xe);
            evals += 1;
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = along(-0.5);
            let fc = f(&xc);
            evals += 1;
            if fc < worst.1 {
                simplex[n] = (xc, fc);
            } else {
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    s.0 = best
                        .iter()
                        .zip(&s.0)
                        .map(|(b, x)| b + 0.5 * (x - b))
                        .collect();
                    s.1 = f(&s.0);
                    evals += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex.swap_remove(0).0
}

/// A stratum's reduced transfer function compiled to f64 over the model's
/// parameters: a point of the stratum is given by the logarithms of its
/// free variables, and the eliminated parameters follow from the
/// substitutions (a point where one is not positive is off the orthant).
pub(super) struct StratumCoefficients {
    num: Vec<Compiled>,
    den: Vec<Compiled>,
    free: Vec<usize>,
    subs: Vec<(usize, Compiled, Compiled)>,
    params: usize,
}

impl StratumCoefficients {
    /// `None` if a variable of the stratum is not among `names`.
    pub(super) fn new(s: &Stratum, names: &[String]) -> Option<StratumCoefficients> {
        StratumCoefficients::of(&s.num, &s.den, &s.vars, &s.subs, names)
    }

    /// The same for `num` and `den` (in `Omega` and the free variables
    /// `vars`) on the chart where `subs` give the other variables of
    /// `names`.
    pub(super) fn of(
        num: &Poly,
        den: &Poly,
        vars: &[String],
        subs: &[Substitution],
        names: &[String],
    ) -> Option<StratumCoefficients> {
        let index = |v: &str| names.iter().position(|n| n == v);
        let compile = |p: &Poly| -> Vec<Compiled> {
            p.coeffs_in(OMEGA)
                .iter()
                .map(|c| Compiled::new(c, names))
                .collect()
        };
        let free = vars
            .iter()
            .map(|v| index(v))
            .collect::<Option<Vec<usize>>>()?;
        let subs = subs
            .iter()
            .map(|w| {
                Some((
                    index(&w.var)?,
                    Compiled::new(&w.alpha, names),
                    Compiled::new(&w.beta, names),
                ))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(StratumCoefficients {
            num: compile(num),
            den: compile(den),
            free,
            subs,
            params: names.len(),
        })
    }

    /// The full point of a log-point of the stratum, if on the orthant.
    pub(super) fn full(&self, lx: &[f64]) -> Option<Vec<f64>> {
        let mut x = vec![0.0; self.params];
        for (&i, v) in self.free.iter().zip(lx) {
            x[i] = v.clamp(-30.0, 30.0).exp();
        }
        for (i, alpha, beta) in self.subs.iter().rev() {
            let v = beta.eval(&x) / alpha.eval(&x);
            if !(v.is_finite() && v > 0.0) {
                return None;
            }
            x[*i] = v;
        }
        Some(x)
    }

    /// The reduced numerator's and denominator's coefficients in `Omega`
    /// at a log-point of the stratum.
    pub(super) fn at(&self, lx: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let x = self.full(lx)?;
        Some((
            self.num.iter().map(|c| c.eval(&x)).collect(),
            self.den.iter().map(|c| c.eval(&x)).collect(),
        ))
    }
}

impl Prover<'_> {
    /// Looks for witnesses of the generic types in `wanted`; records every
    /// one it finds (exactly checked) and returns how many.
    pub(crate) fn targeted_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let wanted: Vec<&FrfType> = wanted
            .iter()
            .filter(|t| t.tokens.iter().all(|k| k.multiplicity == 1))
            .collect();
        if wanted.is_empty() {
            return 0;
        }
        // The prover's parameters are the model's undamped ones, in order.
        let params = self.params.clone();
        let tf = UndampedCoefficients::new(self.model);
        let mut rng = XorShift::new(seed | 1);
        // The best starts per wanted type: (margin, log-point).
        let mut starts: Vec<Vec<(f64, Vec<f64>)>> = vec![Vec::new(); wanted.len()];
        let mut found = vec![false; wanted.len()];
        for _ in 0..SAMPLES {
            let lx: Vec<f64> = params
                .iter()
                .map(|_| LOG_RANGE * (2.0 * rng.uniform() - 1.0))
                .collect();
            let x: Vec<f64> = lx.iter().map(|v| v.exp()).collect();
            let Some(roots) = tf_roots(&tf, &x) else {
                continue;
            };
            for (i, t) in wanted.iter().enumerate() {
                if found[i] {
                    continue;
                }
                let Some(m) = margin(t, &roots) else { continue };
                if m > 0.0 && self.accept(t, &[], &params, &x) {
                    found[i] = true;
                    continue;
                }
                let s = &mut starts[i];
                if s.len() < STARTS || m > s[s.len() - 1].0 {
                    s.push((m, lx.clone()));
                    s.sort_by(|a, b| b.0.total_cmp(&a.0));
                    s.truncate(STARTS);
                }
            }
        }
        for (i, t) in wanted.iter().enumerate() {
            if found[i] {
                continue;
            }
            for (_, lx0) in starts[i].clone() {
                let mut cost = |lx: &[f64]| -> f64 {
                    let x: Vec<f64> = lx.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
                    match tf_roots(&tf, &x).and_then(|r| margin(t, &r)) {
                        Some(m) => -m,
                        None => 1e3,
                    }
                };
                let best = nelder_mead(&mut cost, &lx0, 0.5, -0.05);
                let x: Vec<f64> = best.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
                let ok = tf_roots(&tf, &x)
                    .and_then(|r| margin(t, &r))
                    .is_some_and(|m| m > 0.0);
                if ok && self.accept(t, &[], &params, &x) {
                    found[i] = true;
                    break;
                }
            }
        }
        // What neither found: the violation search, from its own best
        // samples.
        let missing: Vec<&FrfType> = wanted
            .iter()
            .zip(&found)
            .filter(|(_, f)| !**f)
            .map(|(t, _)| *t)
            .collect();
        let mut extra = 0;
        for t in missing {
            if self.violation_search(t, &tf, &params, &mut rng) {
                extra += 1;
            }
        }
        found.iter().filter(|f| **f).count() + extra
    }

    /// Minimises the total [`violation`] of `t` with Nelder-Mead from the
    /// best of [`VIOLATION_SAMPLES`] log-uniform points, then from random
    /// ones; accepts the first point the exact classification confirms.
    fn violation_search(
        &mut self,
        t: &FrfType,
        tf: &UndampedCoefficients,
        params: &[String],
        rng: &mut XorShift,
    ) -> bool {
        let cost = |lx: &[f64]| -> f64 {
            let x: Vec<f64> = lx.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
            let (n, d) = tf.eval(&x);
            violation(t, &n, &d).unwrap_or(f64::INFINITY)
        };
        let mut pool: Vec<(f64, Vec<f64>)> = Vec::new();
        for _ in 0..VIOLATION_SAMPLES {
            let lx: Vec<f64> = params
                .iter()
                .map(|_| LOG_RANGE * (2.0 * rng.uniform() - 1.0))
                .collect();
            let v = cost(&lx);
            if v.is_finite() {
                pool.push((v, lx));
            }
        }
        pool.sort_by(|a, b| a.0.total_cmp(&b.0));
        pool.truncate(VIOLATION_STARTS);
        for (_, lx0) in pool {
            let mut near = Vec::new();
            let mut f = |lx: &[f64]| -> f64 {
                let x: Vec<f64> = lx.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
                let (n, d) = tf.eval(&x);
                violation_near(t, &n, &d, &mut near).unwrap_or(f64::INFINITY)
            };
            let best = nelder_mead_for(&mut f, &lx0, 1.0, f64::MIN_POSITIVE, VIOLATION_EVALUATIONS);
            let x: Vec<f64> = best.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
            let ok = tf_roots(tf, &x)
                .and_then(|r| margin(t, &r))
                .is_some_and(|m| m > 0.0);
            if ok && self.accept(t, &[], params, &x) {
                return true;
            }
        }
        false
    }

    /// Samples the *partial walls*: critical factors linear in a parameter
    /// `x` whose solution `x = beta/alpha` is positive only on part of the
    /// orthant (so they are no walls for the proofs), nested up to
    /// `depth`. Measure-zero types (cancellations, double zeros) that need
    /// such a variety live there, and a point on it is exact. Returns how
    /// many of `wanted` it found.
    pub(crate) fn partial_wall_search(&mut self, wanted: &[FrfType], depth: usize) -> usize {
        let mut rng = Sampler::new(0x0A27_1A1E);
        let mut visited = BTreeSet::new();
        let mut budget = PARTIAL_WALL_BUDGET;
        self.partial_walls(&[], wanted, depth, &mut visited, &mut rng, &mut budget);
        self.witnessed(wanted)
    }

    fn partial_walls(
        &mut self,
        subs: &[Substitution],
        wanted: &[FrfType],
        depth: usize,
        visited: &mut BTreeSet<String>,
        rng: &mut Sampler,
        budget: &mut usize,
    ) {
        if depth == 0 || wanted.iter().all(|t| self.witnesses.contains_key(t)) {
            return;
        }
        let s = self.stratum(subs);
        let walls: Vec<Substitution> = s
            .vanishing()
            .filter_map(|f| linear_solution(&f.poly, &s.vars))
            .filter(|w| w.alpha.num_terms() + w.beta.num_terms() <= PARTIAL_WALL_TERMS)
            .collect();
        for w in walls {
            // Each stratum costs gcds and resultants of the substituted
            // TF: a fixed budget (not a clock) keeps five masses in bounds
            // and the output deterministic.
            if *budget == 0 {
                return;
            }
            let mut next = subs.to_vec();
            next.push(w);
            if self.partial_wall_too_large(&next) {
                continue;
            }
            *budget -= 1;
            let s = self.stratum(&next);
            if !visited.insert(s.key()) {
                continue;
            }
            for _ in 0..PARTIAL_WALL_SAMPLES {
                let p = rng.point(&s.vars);
                if let Some(point) = positive_full_point(&next, &p) {
                    self.record(point);
                }
            }
            self.partial_walls.push(next.clone());
            self.partial_walls(&next, wanted, depth - 1, visited, rng, budget);
        }
    }

    /// Whether the numerator and denominator with the substitutions
    /// `subs` made hold too many terms for a stratum: its cost is factoring
    /// its critical polynomials, which grows steeply with the number of
    /// variables, so five masses (nine) get a smaller limit than four
    /// (seven).
    pub(super) fn partial_wall_too_large(&self, subs: &[Substitution]) -> bool {
        let limit = if self.params.len() <= 7 {
            PARTIAL_WALL_TF_TERMS
        } else {
            PARTIAL_WALL_TF_TERMS * 5 / 8
        };
        let size = |p: &Poly| {
            subs.iter()
                .fold(p.clone(), |q, w| substitute(&q, w))
                .num_terms()
        };
        size(&self.num) + size(&self.den) > limit
    }

    /// For a type still unknown whose only multiple tokens are
    /// antiresonances and which keeps all `degree` poles: the
    /// multiplicities of those and the witness of its split type, if any.
    fn split_witness(&self, t: &FrfType, degree: u32) -> Option<(Vec<u32>, BTreeMap<String, Rat>)> {
        let mults = multiple_antiresonances(t);
        if mults.is_empty()
            || t.resonances() != degree
            || self.witnesses.contains_key(t)
            || t.tokens
                .iter()
                .any(|k| k.feature == Feature::Resonance && k.multiplicity > 1)
        {
            return None;
        }
        let w = self.witnesses.get(&split_type(t))?.clone();
        Some((mults, w))
    }

    /// Multiple antiresonances from a witness of the split type whose
    /// zeros lie too far apart for the merge of
    /// [`Self::root_condition_search`]: the zeros are first drawn
    /// together in floating point, keeping the split order
    /// ([`pull_together`]); near the merge the solved parameters move
    /// little, so they stay positive and the rest of the order holds.
    /// Runs after the other searches, so that what they find does not
    /// depend on it. Returns how many of `wanted` are witnessed.
    pub(crate) fn close_merge_search(&mut self, wanted: &[FrfType]) -> usize {
        let degree = self.den.degree(OMEGA);
        let tf = UndampedCoefficients::new(self.model);
        let params = self.params.clone();
        for t in wanted {
            let Some((mults, w)) = self.split_witness(t, degree) else {
                continue;
            };
            let x: Vec<f64> = params.iter().map(|p| w[p].to_f64()).collect();
            let close = pull_together(&tf, t, &x);
            let Some(groups) = merged_groups(&tf, t, &close) else {
                continue;
            };
            if groups.len() != mults.len() {
                continue;
            }
            let Some(roots) = merged_roots(&groups, 0.5, 6) else {
                continue;
            };
            let derivatives = self.numerator_derivatives(mults.iter().copied().max().unwrap_or(1));
            let size = mults.iter().sum::<u32>() as usize;
            for vars in linear_sets(&[&self.num], &params, size)
                .iter()
                .take(MERGE_SETS)
            {
                let fixed: Option<BTreeMap<String, Rat>> = params
                    .iter()
                    .zip(&close)
                    .filter(|(p, _)| !vars.contains(p))
                    .map(|(p, v)| Some((p.clone(), short_rational(*v, 9)?)))
                    .collect();
                let Some(fixed) = fixed else { break };
                self.solve_root_conditions(vars, fixed, &[], &roots, &derivatives);
                if self.witnesses.contains_key(t) {
                    break;
                }
            }
        }
        self.witnessed(wanted)
    }

    /// Generic types from the witnesses of their neighbours: a type one
    /// swap of adjacent tokens away (an antiresonance and a resonance
    /// trading places) shares a boundary with the wanted one, where that
    /// zero crosses that pole, so a thin region the samples miss may lie
    /// next to a witness already found. The margin of the wanted order is
    /// maximised by Nelder-Mead from each neighbour's witness. Runs after
    /// the other searches (see [`Self::close_merge_search`]). Returns how
    /// many of `wanted` are witnessed.
    pub(crate) fn neighbour_search(&mut self, wanted: &[FrfType]) -> usize {
        // A type found here is a neighbour of others: again, until a pass
        // finds none.
        let tf = UndampedCoefficients::new(self.model);
        let mut found = self.witnessed(wanted);
        loop {
            self.neighbour_pass(wanted, &tf);
            let now = self.witnessed(wanted);
            if now == found {
                return now;
            }
            found = now;
        }
    }

    fn neighbour_pass(&mut self, wanted: &[FrfType], tf: &UndampedCoefficients) {
        let params = self.params.clone();
        let zeros = self.num.degree(OMEGA);
        for t in wanted {
            if self.witnesses.contains_key(t) || t.tokens.iter().any(|k| k.multiplicity > 1) {
                continue;
            }
            'neighbours: for (neighbour, complex) in neighbours(t, zeros) {
                let Some(w) = self.witnesses.get(&neighbour) else {
                    continue;
                };
                let lx0: Vec<f64> = params.iter().map(|p| w[p].to_f64().ln()).collect();
                // Across a swap the margin has a slope; across a pair of
                // zeros leaving the axis only the violation has one.
                let mut near = Vec::new();
                let mut cost = |lx: &[f64]| -> f64 {
                    let x: Vec<f64> = lx.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
                    if complex {
                        let (n, d) = tf.eval(&x);
                        return violation_near(t, &n, &d, &mut near).unwrap_or(1e3);
                    }
                    match tf_roots(tf, &x).and_then(|r| margin(t, &r)) {
                        Some(m) => -m,
                        None => 1e3,
                    }
                };
                let stop = if complex { f64::MIN_POSITIVE } else { -0.05 };
                for step in [0.5, 0.1] {
                    let best = nelder_mead_for(&mut cost, &lx0, step, stop, NEIGHBOUR_EVALUATIONS);
                    let x: Vec<f64> = best.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
                    let shows = tf_roots(tf, &x)
                        .and_then(|r| margin(t, &r))
                        .is_some_and(|m| m > 0.0);
                    if shows && self.accept(t, &[], &params, &x) {
                        break 'neighbours;
                    }
                }
            }
        }
    }

    /// [`Self::stratum_targeted_search`] on every partial wall the
    /// search visited, after the other searches (see
    /// [`Self::close_merge_search`]). Returns how many of `wanted` are
    /// witnessed.
    pub(crate) fn wall_targeted_search(&mut self, wanted: &[FrfType]) -> usize {
        for (i, subs) in self.partial_walls.clone().iter().enumerate() {
            if wanted.iter().all(|t| self.witnesses.contains_key(t)) {
                break;
            }
            let s = self.stratum(subs);
            self.stratum_targeted_search(&s, wanted, i as u64 + 1);
        }
        self.witnessed(wanted)
    }

    /// The targeted search within a stratum: there the types with as many
    /// resonances as its reduced denominator has poles are generic, and
    /// some fill only a thin part of it, which its few exact samples miss.
    /// The reduced TF is compiled to f64 over the stratum's variables, the
    /// eliminated parameters follow from the substitutions (a point where
    /// one is not positive is off the orthant), and the margin of each
    /// wanted ordering is maximised as on the orthant. A hit is rounded
    /// to a short rational point of the stratum, mapped to its exact full
    /// point and accepted only if the exact classification agrees.
    fn stratum_targeted_search(&mut self, s: &Stratum, wanted: &[FrfType], seed: u64) {
        let degree = s.den.degree(OMEGA);
        let goals: Vec<&FrfType> = wanted
            .iter()
            .filter(|t| {
                !self.witnesses.contains_key(t)
                    && t.resonances() == degree
                    && t.tokens.iter().all(|k| k.multiplicity == 1)
            })
            .collect();
        if goals.is_empty() || s.vars.is_empty() {
            return;
        }
        let Some(coefficients) = StratumCoefficients::new(s, &self.params) else {
            return;
        };
        let roots = |lx: &[f64]| -> Option<(Vec<f64>, Vec<f64>, bool)> {
            let (n, d) = coefficients.at(lx)?;
            let zn = positive_roots(&n)?;
            let zd = positive_roots(&d)?;
            let nm = zn.len() < n.len() - 1;
            Some((zn, zd, nm))
        };
        let free = &s.vars;
        let mut rng = XorShift::new(seed.wrapping_mul(0x9E37_79B9) | 1);
        let mut starts: Vec<Vec<(f64, Vec<f64>)>> = vec![Vec::new(); goals.len()];
        for _ in 0..STRATUM_SAMPLES {
            let lx: Vec<f64> = free
                .iter()
                .map(|_| LOG_RANGE * (2.0 * rng.uniform() - 1.0))
                .collect();
            let Some(r) = roots(&lx) else { continue };
            for (i, t) in goals.iter().enumerate() {
                let Some(m) = margin(t, &r) else { continue };
                let best = &mut starts[i];
                if best.len() < STRATUM_STARTS || m > best[best.len() - 1].0 {
                    best.push((m, lx.clone()));
                    best.sort_by(|a, b| b.0.total_cmp(&a.0));
                    best.truncate(STRATUM_STARTS);
                }
            }
        }
        for (i, t) in goals.iter().enumerate() {
            for (m, lx0) in starts[i].clone() {
                if self.witnesses.contains_key(*t) {
                    break;
                }
                let best = if m > 0.0 {
                    lx0
                } else {
                    let mut cost = |lx: &[f64]| match roots(lx).and_then(|r| margin(t, &r)) {
                        Some(m) => -m,
                        None => 1e3,
                    };
                    nelder_mead_for(&mut cost, &lx0, 0.5, -0.05, STRATUM_EVALUATIONS)
                };
                if !roots(&best)
                    .and_then(|r| margin(t, &r))
                    .is_some_and(|m| m > 0.0)
                {
                    continue;
                }
                let x: Vec<f64> = best.iter().map(|v| v.exp()).collect();
                self.accept(t, &s.subs, &s.vars, &x);
            }
        }
    }

    /// Constructs points with wanted root coincidences exactly
    /// (parameters from wanted root positions). A type with `c`
    /// cancelled poles and multiple antiresonances of multiplicities
    /// `k_1, k_2, ...` lives where `num(r) = den(r) = 0` at `c` points and
    /// `num` and its first `k_j - 1` derivatives vanish at one point each.
    /// The TF is multilinear in the parameters (every mass and spring
    /// enters the determinants to the first power), so for rational roots
    /// `r`, rational values of all but a set of parameters no two of which
    /// share a monomial, these conditions are a linear system in that set:
    /// its exact solution, when positive, is a point on the wanted variety,
    /// whose type is then classified exactly. Returns how many of `wanted`
    /// it found.
    pub(crate) fn root_condition_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let degree = self.den.degree(OMEGA);
        let signatures: BTreeSet<(u32, Vec<u32>)> = wanted
            .iter()
            .filter_map(|t| root_signature(t, degree))
            .collect();
        if signatures.is_empty() {
            return 0;
        }
        let max_mult = signatures
            .iter()
            .flat_map(|(_, m)| m.iter().copied())
            .max()
            .unwrap_or(1);
        let derivatives = self.numerator_derivatives(max_mult);
        // First, merge the zeros of a witness of the split type (A^2 as
        // AA): the root goes between them and the solved parameters stay
        // near the witness's, keeping the rest of the ordering.
        let tf = UndampedCoefficients::new(self.model);
        let params = self.params.clone();
        for t in wanted {
            let Some((mults, w)) = self.split_witness(t, degree) else {
                continue;
            };
            let x: Vec<f64> = params.iter().map(|p| w[p].to_f64()).collect();
            let Some(groups) = merged_groups(&tf, t, &x) else {
                continue;
            };
            if groups.len() != mults.len() {
                continue;
            }
            let size = mults.iter().sum::<u32>() as usize;
            // Only the numerator's conditions: it alone must be linear.
            let sets = linear_sets(&[&self.num], &params, size);
            // The merged root at several places across each group, every
            // parameter set: the first that keeps the rest of the order.
            'merge: for frac in MERGE_FRACTIONS {
                let Some(roots) = merged_roots(&groups, frac, 4) else {
                    continue;
                };
                for vars in sets.iter().take(MERGE_SETS) {
                    let fixed: BTreeMap<String, Rat> = w
                        .iter()
                        .filter(|(p, _)| !vars.contains(p))
                        .map(|(p, v)| (p.clone(), v.clone()))
                        .collect();
                    self.solve_root_conditions(vars, fixed, &[], &roots, &derivatives);
                    if self.witnesses.contains_key(t) {
                        break 'merge;
                    }
                }
            }
        }
        // Then random roots and parameters.
        let mut rng = Sampler::new(seed);
        for (cancelled, mults) in signatures {
            let size = 2 * cancelled as usize + mults.iter().sum::<u32>() as usize;
            let polys: Vec<&Poly> = if cancelled == 0 {
                vec![&self.num]
            } else {
                vec![&self.num, &self.den]
            };
            let sets = linear_sets(&polys, &self.params, size);
            if sets.is_empty() {
                continue;
            }
            for _ in 0..ROOT_TRIALS {
                let vars = sets[rng.index(sets.len())].clone();
                let fixed: BTreeMap<String, Rat> = self
                    .params
                    .iter()
                    .filter(|p| !vars.contains(p))
                    .map(|p| (p.clone(), rng.value()))
                    .collect();
                let cancel: Vec<Rat> = (0..cancelled).map(|_| rng.value()).collect();
                let multiple: Vec<(Rat, u32)> = mults.iter().map(|&k| (rng.value(), k)).collect();
                self.solve_root_conditions(&vars, fixed, &cancel, &multiple, &derivatives);
            }
        }
        self.witnessed(wanted)
    }

    /// [`Self::root_condition_search`] where no parameter set holds the
    /// conditions linearly, one parameter short of it: with a jointly
    /// linear set `vars` of one fewer than the conditions and one more
    /// parameter `x`, and the rest at random values, the conditions are
    /// linear in `vars` with coefficients polynomial in `x`. They have a
    /// common solution where the determinant of that system (with its
    /// constant column) vanishes, a polynomial in `x` alone; each positive
    /// rational root gives an exact point on the wanted variety. A
    /// quadruple zero of a numerator linear in only three parameters at a
    /// time is found so. Runs last, on what the other searches leave, so
    /// that their draws do not change. Three passes, in this order: the
    /// zeros of split witnesses merged, the walk along the variety from
    /// witnesses on it, random roots and parameters. Returns how many of
    /// `wanted` have a witness afterwards.
    pub(crate) fn root_condition_pencil_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        self.pencil_merge_search(wanted);
        self.variety_walk_search(wanted);
        self.pencil_random_search(wanted, seed);
        self.witnessed(wanted)
    }

    /// The types of `wanted` that are neither witnessed nor proven
    /// impossible, by root signature, and the numerator derivatives their
    /// multiple zeros need.
    #[allow(clippy::type_complexity)]
    pub(super) fn pencil_signatures(
        &self,
        wanted: &[FrfType],
    ) -> (BTreeMap<(u32, Vec<u32>), Vec<FrfType>>, Vec<Poly>) {
        let degree = self.den.degree(OMEGA);
        let mut signatures: BTreeMap<(u32, Vec<u32>), Vec<FrfType>> = BTreeMap::new();
        for t in wanted {
            if self.shown(t) {
                continue;
            }
            if let Some(s) = root_signature(t, degree) {
                signatures.entry(s).or_default().push(t.clone());
            }
        }
        let max_mult = signatures
            .keys()
            .flat_map(|(_, m)| m.iter().copied())
            .max()
            .unwrap_or(1);
        let derivatives = self.numerator_derivatives(max_mult);
        (signatures, derivatives)
    }

    /// The first pass of [`Self::root_condition_pencil_search`]: the zeros
    /// of a witness of the split type merged (A^4 from AAAA), at several
    /// places across them, from the witness and from the point with its
    /// zeros pulled together.
    fn pencil_merge_search(&mut self, wanted: &[FrfType]) {
        let degree = self.den.degree(OMEGA);
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let tf = UndampedCoefficients::new(self.model);
        let params = self.params.clone();
        for t in signatures.values().flatten() {
            let Some((mults, w)) = self.split_witness(t, degree) else {
                continue;
            };
            let size = mults.iter().sum::<u32>() as usize;
            if size < 2 || !linear_sets(&[&self.num], &params, size).is_empty() {
                continue;
            }
            let mut sets = linear_sets(&[&self.num], &params, size - 1);
            sets.truncate(PENCIL_SETS);
            let x: Vec<f64> = params.iter().map(|p| w[p].to_f64()).collect();
            let close = pull_together(&tf, t, &x);
            'bases: for base in [x, close] {
                let Some(groups) = merged_groups(&tf, t, &base) else {
                    continue;
                };
                if groups.len() != mults.len() {
                    continue;
                }
                for frac in PENCIL_FRACTIONS {
                    let Some(roots) = merged_roots(&groups, frac, 4) else {
                        continue;
                    };
                    let equations = self.root_equations(&[], &roots, &derivatives);
                    for vars in &sets {
                        for x in params.iter().filter(|p| !vars.contains(p)) {
                            let fixed: Option<BTreeMap<String, Rat>> = params
                                .iter()
                                .zip(&base)
                                .filter(|(p, _)| !vars.contains(p) && *p != x)
                                .map(|(p, v)| Some((p.clone(), short_rational(*v, 6)?)))
                                .collect();
                            let Some(fixed) = fixed else { continue 'bases };
                            for point in pencil_points(&equations, vars, x, fixed) {
                                self.record(point);
                            }
                            if self.witnesses.contains_key(t) {
                                break 'bases;
                            }
                        }
                    }
                }
            }
        }
    }

    /// The second pass of [`Self::root_condition_pencil_search`]: along
    /// the variety from every witness on it (the same multiple zeros,
    /// every pole), each multiple zero moved by factors up to 64 either
    /// way, or one other parameter by 2 to 8, the conditions solved again.
    /// Where the zeros fall between other poles the type changes, which no
    /// merge from a split witness reaches when that split type has no
    /// witness.
    fn variety_walk_search(&mut self, wanted: &[FrfType]) {
        let degree = self.den.degree(OMEGA);
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let params = self.params.clone();
        let steps: Vec<i32> = (-24..=24).filter(|k| *k != 0).collect();
        for ((cancelled, mults), types) in &signatures {
            let size = mults.iter().sum::<u32>() as usize;
            if *cancelled > 0 || size < 2 {
                continue;
            }
            if !linear_sets(&[&self.num], &params, size).is_empty() {
                continue;
            }
            let mut sets = linear_sets(&[&self.num], &params, size - 1);
            sets.truncate(PENCIL_SETS);
            'walk: for (roots, w) in self.walk_starts(mults, degree) {
                let at: Vec<Rat> = roots.iter().map(|r| r.0.clone()).collect();
                let moves: Vec<(MultipleZeros, Option<(String, Rat)>)> =
                    walk_moves(&at, &w, &params, &steps)
                        .into_iter()
                        .map(|(at, moved)| {
                            let r = at.into_iter().zip(roots.iter().map(|r| r.1)).collect();
                            (r, moved)
                        })
                        .collect();
                for vars in &sets {
                    for x in params.iter().filter(|p| !vars.contains(p)) {
                        for (r, moved) in &moves {
                            if types.iter().all(|t| self.witnesses.contains_key(t)) {
                                break 'walk;
                            }
                            self.walk_step(&w, r, moved.as_ref(), vars, x, &derivatives);
                        }
                    }
                }
            }
        }
    }

    /// The walk of [`Self::variety_walk_search`] where one set of
    /// parameters holds every condition of the multiple zeros linearly:
    /// from each of the first [`WALK_STARTS`] witnesses with the wanted
    /// multiple zeros and every pole, each zero is moved in turn, nearest
    /// first, or one other parameter, and the conditions solved again
    /// exactly. A double zero moved past a pole, or past a simple zero, is
    /// reached so where no merge of a split witness keeps the rest of the
    /// order. Runs after the other searches. Returns how many of `wanted`
    /// have a witness afterwards.
    pub(crate) fn root_walk_search(&mut self, wanted: &[FrfType]) -> usize {
        let degree = self.den.degree(OMEGA);
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let params = self.params.clone();
        let steps: Vec<i32> = (1..=12).flat_map(|k| [k, -k]).collect();
        for ((cancelled, mults), types) in &signatures {
            let size = mults.iter().sum::<u32>() as usize;
            if *cancelled > 0 || size < 2 {
                continue;
            }
            let mut sets = linear_sets(&[&self.num], &params, size);
            sets.truncate(PENCIL_SETS);
            let mut starts = self.walk_starts(mults, degree);
            starts.truncate(WALK_STARTS);
            'walk: for (roots, w) in starts {
                let at: Vec<Rat> = roots.iter().map(|r| r.0.clone()).collect();
                for (at, moved) in walk_moves(&at, &w, &params, &steps) {
                    let multiple: MultipleZeros =
                        at.into_iter().zip(roots.iter().map(|r| r.1)).collect();
                    for vars in &sets {
                        if types.iter().all(|t| self.witnesses.contains_key(t)) {
                            break 'walk;
                        }
                        if moved.as_ref().is_some_and(|(p, _)| vars.contains(p)) {
                            continue;
                        }
                        let fixed = kept_point(&w, moved.as_ref(), |p| !vars.contains(p));
                        self.solve_root_conditions(vars, fixed, &[], &multiple, &derivatives);
                    }
                }
            }
        }
        self.witnessed(wanted)
    }

    /// The witnesses a walk starts from: those of types with the multiple
    /// zeros `mults` and every pole, with their rational multiple zeros,
    /// in the witnesses' order.
    fn walk_starts(
        &self,
        mults: &[u32],
        degree: u32,
    ) -> Vec<(MultipleZeros, BTreeMap<String, Rat>)> {
        let signature = Some((0, mults.to_vec()));
        self.witnesses
            .iter()
            .filter(|(t, _)| root_signature(t, degree) == signature)
            .filter_map(|(_, w)| Some((multiple_zeros(&self.num.subs_point(w))?, w.clone())))
            .filter(|(roots, _)| same_multiplicities(roots, mults))
            .collect()
    }

    /// One step of [`Self::variety_walk_search`] from the witness `w`: its
    /// multiple zeros at `roots` (moved or not) and the parameter `moved`
    /// at its new value, if any; the conditions solved for `vars` and the
    /// roots of their determinant in `x`, the other parameters kept.
    fn walk_step(
        &mut self,
        w: &BTreeMap<String, Rat>,
        roots: &[(Rat, u32)],
        moved: Option<&(String, Rat)>,
        vars: &[String],
        x: &str,
        derivatives: &[Poly],
    ) {
        if moved.is_some_and(|(p, _)| vars.contains(p) || p == x) {
            return;
        }
        let fixed = kept_point(w, moved, |p| !vars.contains(p) && p.as_str() != x);
        let equations = self.root_equations(&[], roots, derivatives);
        for point in pencil_points(&equations, vars, x, fixed) {
            self.record(point);
        }
    }

    /// The last pass of [`Self::root_condition_pencil_search`]: random
    /// roots and parameters.
    fn pencil_random_search(&mut self, wanted: &[FrfType], seed: u64) {
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let mut rng = Sampler::new(seed);
        for ((cancelled, mults), types) in signatures {
            let size = 2 * cancelled as usize + mults.iter().sum::<u32>() as usize;
            let polys: Vec<&Poly> = if cancelled == 0 {
                vec![&self.num]
            } else {
                vec![&self.num, &self.den]
            };
            if size < 2 || !linear_sets(&polys, &self.params, size).is_empty() {
                continue;
            }
            let sets = linear_sets(&polys, &self.params, size - 1);
            if sets.is_empty() {
                continue;
            }
            for _ in 0..PENCIL_TRIALS {
                if types.iter().all(|t| self.witnesses.contains_key(t)) {
                    break;
                }
                let vars = sets[rng.index(sets.len())].clone();
                let others: Vec<String> = self
                    .params
                    .iter()
                    .filter(|p| !vars.contains(p))
                    .cloned()
                    .collect();
                let x = others[rng.index(others.len())].clone();
                let fixed: BTreeMap<String, Rat> = others
                    .iter()
                    .filter(|p| **p != x)
                    .map(|p| (p.clone(), rng.value()))
                    .collect();
                let cancel: Vec<Rat> = (0..cancelled).map(|_| rng.value()).collect();
                let multiple: Vec<(Rat, u32)> = mults.iter().map(|&k| (rng.value(), k)).collect();
                let equations = self.root_equations(&cancel, &multiple, &derivatives);
                for point in pencil_points(&equations, &vars, &x, fixed) {
                    self.record(point);
                }
            }
        }
    }

    /// The numerator and its first `count - 1` derivatives in `Omega`: the
    /// conditions of a zero of multiplicity `count`.
    fn numerator_derivatives(&self, count: u32) -> Vec<Poly> {
        let mut out = vec![self.num.clone()];
        while out.len() < count as usize {
            let d = out[out.len() - 1].derivative(OMEGA);
            out.push(d);
        }
        out
    }

    /// `num(r) = den(r) = 0` for every `r` of `cancel` and `num^(i)(r) =
    /// 0`, `i < k`, for every `(r, k)` of `multiple`.
    pub(super) fn root_equations(
        &self,
        cancel: &[Rat],
        multiple: &[(Rat, u32)],
        derivatives: &[Poly],
    ) -> Vec<Poly> {
        let mut equations: Vec<Poly> = Vec::new();
        for r in cancel {
            equations.push(self.num.subs(OMEGA, r));
            equations.push(self.den.subs(OMEGA, r));
        }
        for (r, k) in multiple {
            equations.extend(derivatives[..*k as usize].iter().map(|d| d.subs(OMEGA, r)));
        }
        equations
    }

    /// Constructs cancellations from the chain's blocks:
    /// a pole of a block cancels where the eigenvalue of a run of the
    /// block's masses falls on it, or where another block has the same
    /// eigenvalue. Both are two determinant conditions at a chosen `r`,
    /// `det(K_S - r M_S) = 0` and `det(K_B - r M_B) = 0`, each of degree
    /// one in a mass the other does not contain (a mass of the run, then
    /// one of the block outside it; or one of each block): solved one
    /// after the other, exactly. Where the denominator shares a monomial
    /// with every pair of parameters (five masses) the root conditions
    /// cannot pose a cancellation as a linear system; this can. Returns
    /// how many of `wanted` it found.
    pub(crate) fn cancellation_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let degree = self.den.degree(OMEGA);
        let counts: BTreeSet<u32> = wanted
            .iter()
            .filter(|t| {
                t.resonances() < degree
                    && t.tokens.iter().all(|k| k.multiplicity == 1)
                    && !self.witnesses.contains_key(t)
            })
            .map(|t| degree - t.resonances())
            .collect();
        if counts.is_empty() {
            return 0;
        }
        let names = self.model.masses();
        let mechanisms = self.cancellation_mechanisms();
        if mechanisms.is_empty() {
            return 0;
        }
        let mut rng = Sampler::new(seed);
        // Every number of cancellations in turn, not just the wanted ones:
        // the trials stay the same when other verdicts change.
        let counts: Vec<u32> = (1..degree.max(1) + 1).collect();
        for trial in 0..CANCEL_TRIALS {
            let c = counts[trial % counts.len()] as usize;
            let mut point: BTreeMap<String, Rat> = self
                .params
                .iter()
                .map(|p| (p.clone(), rng.value()))
                .collect();
            let mut used: Vec<usize> = Vec::new();
            let mut ok = true;
            for _ in 0..c {
                let (d1, m1, d2, m2) = &mechanisms[rng.index(mechanisms.len())];
                let r = rng.value();
                let free1: Vec<usize> = m1.iter().copied().filter(|i| !used.contains(i)).collect();
                let free2: Vec<usize> = m2.iter().copied().filter(|i| !used.contains(i)).collect();
                if free1.is_empty() || free2.is_empty() {
                    ok = false;
                    break;
                }
                let x = free1[rng.index(free1.len())];
                let y = free2[rng.index(free2.len())];
                for (d, v) in [(d1, x), (d2, y)] {
                    let name = &names[v];
                    let mut known = point.clone();
                    known.remove(name);
                    known.insert(OMEGA.to_string(), r.clone());
                    let e = d.subs_point(&known);
                    match solve_linear(&[e], std::slice::from_ref(name)) {
                        Some(sol) if sol[0].signum() > 0 => {
                            point.insert(name.clone(), sol[0].clone());
                        }
                        _ => ok = false,
                    }
                }
                used.extend([x, y]);
                if !ok {
                    break;
                }
            }
            if ok {
                self.record(point);
            }
        }
        self.witnessed(wanted)
    }

    /// The ways a pole cancels (see [`Self::cancellation_search`]): the
    /// determinant of a run and of its block, with the masses each may be
    /// solved for (the run's; the block's outside the run), or the
    /// determinants of two blocks with their masses.
    pub(super) fn cancellation_mechanisms(&self) -> Vec<Mechanism> {
        let mass = self.model.mass_matrix();
        let stiff = self.model.stiffness_matrix();
        let det_of = |lo: usize, hi: usize| run_det(&mass, &stiff, lo, hi);
        let blocks = block_ranges(&stiff);
        let mut mechanisms: Vec<Mechanism> = Vec::new();
        for (k, &(lo, hi)) in blocks.iter().enumerate() {
            let whole = det_of(lo, hi);
            for a in lo..hi {
                for z in a + 1..=hi {
                    if z - a < hi - lo {
                        let outside: Vec<usize> = (lo..hi).filter(|i| *i < a || *i >= z).collect();
                        mechanisms.push((det_of(a, z), (a..z).collect(), whole.clone(), outside));
                    }
                }
            }
            for &(lo2, hi2) in &blocks[k + 1..] {
                mechanisms.push((
                    whole.clone(),
                    (lo..hi).collect(),
                    det_of(lo2, hi2),
                    (lo2..hi2).collect(),
                ));
            }
        }
        mechanisms
    }

    /// Solves `num(r) = den(r) = 0` for every `r` of `cancel` and
    /// `num^(i)(r) = 0`, `i < k`, for every `(r, k)` of `multiple`, in
    /// `vars` with the other parameters at `fixed`; records the point if
    /// the solution is unique and positive.
    fn solve_root_conditions(
        &mut self,
        vars: &[String],
        mut fixed: BTreeMap<String, Rat>,
        cancel: &[Rat],
        multiple: &[(Rat, u32)],
        derivatives: &[Poly],
    ) {
        let equations: Vec<Poly> = self
            .root_equations(cancel, multiple, derivatives)
            .into_iter()
            .map(|e| e.subs_point(&fixed))
            .collect();
        let Some(solution) = solve_linear(&equations, vars) else {
            return;
        };
        if solution.iter().all(|v| v.signum() > 0) {
            fixed.extend(vars.iter().cloned().zip(solution));
            self.record(fixed);
        }
    }

    /// Rounds `x` to ever longer rationals until the exact type is `t`;
    /// records the witness if so.
    /// `x` is a point of the stratum of `subs` in its variables `params`
    /// (of the orthant when `subs` is empty), mapped to its full point.
    fn accept(&mut self, t: &FrfType, subs: &[Substitution], params: &[String], x: &[f64]) -> bool {
        for digits in [2, 3, 4, 6, 9] {
            let point: Option<BTreeMap<String, Rat>> = params
                .iter()
                .zip(x)
                .map(|(p, v)| Some((p.clone(), short_rational(*v, digits)?)))
                .collect();
            let Some(point) = point else { return false };
            let Some(point) = positive_full_point(subs, &point) else {
                continue;
            };
            if self.type_at(&point).as_ref() == Some(t) {
                self.witnesses.insert(t.clone(), point);
                return true;
            }
        }
        false
    }
}

/// The positive zeros at `x` in order, grouped as `t` merges them: the
/// log-range of each group of a multiple antiresonance, with its
/// multiplicity.
fn merged_groups(
    tf: &UndampedCoefficients,
    t: &FrfType,
    x: &[f64],
) -> Option<Vec<(f64, f64, u32)>> {
    let (zeros, _, _) = tf_roots(tf, x)?;
    Some(zero_groups(t, &zeros).0)
}

/// `zeros` (increasing) grouped as `t`'s antiresonances merge them: the
/// log-range and multiplicity of each multiple one, up to the first token
/// the zeros left do not fill; and whether they filled every token and
/// were all used.
pub(super) fn zero_groups(t: &FrfType, zeros: &[f64]) -> (Vec<(f64, f64, u32)>, bool) {
    let mut groups = Vec::new();
    let mut next = 0;
    for k in t
        .tokens
        .iter()
        .filter(|k| k.feature == Feature::Antiresonance)
    {
        let m = k.multiplicity as usize;
        if next + m > zeros.len() {
            return (groups, false);
        }
        if m > 1 {
            groups.push((zeros[next].ln(), zeros[next + m - 1].ln(), k.multiplicity));
        }
        next += m;
    }
    (groups, next == zeros.len())
}

/// The merged roots of `groups` (see [`merged_groups`]), each at `frac`
/// of its group's log-range, as rationals of `digits` significant digits,
/// with their multiplicities.
fn merged_roots(groups: &[(f64, f64, u32)], frac: f64, digits: i32) -> Option<MultipleZeros> {
    groups
        .iter()
        .map(|&(a, b, k)| Some((short_rational((a + frac * (b - a)).exp(), digits)?, k)))
        .collect()
}

/// From `x`, where the split type of `t` shows, a point where the zeros
/// `t` merges lie close together (the sum of the groups' log-ranges
/// minimised by Nelder-Mead in log-parameters) and the split type still
/// shows.
fn pull_together(tf: &UndampedCoefficients, t: &FrfType, x: &[f64]) -> Vec<f64> {
    let split = split_type(t);
    let spread = |lx: &[f64]| -> Option<f64> {
        let x: Vec<f64> = lx.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
        let roots = tf_roots(tf, &x)?;
        if margin(&split, &roots)? <= 0.0 {
            return None;
        }
        let groups = merged_groups(tf, t, &x)?;
        Some(groups.iter().map(|(a, b, _)| b - a).sum())
    };
    let lx0: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let start = spread(&lx0).unwrap_or(f64::INFINITY);
    let mut cost = |lx: &[f64]| spread(lx).unwrap_or(1e3);
    let best = nelder_mead_for(&mut cost, &lx0, 0.1, 1e-4, PULL_EVALUATIONS);
    if spread(&best).is_some_and(|v| v < start) {
        best.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect()
    } else {
        x.to_vec()
    }
}

/// f64 samples, Nelder-Mead starts and evaluations per start of the
/// targeted search within a stratum.
const STRATUM_SAMPLES: usize = 1000;
const STRATUM_STARTS: usize = 2;
const STRATUM_EVALUATIONS: usize = 1500;

/// The generic types next to `t` (simple tokens, `zeros` the numerator's
/// degree), with whether the boundary between them is a pair of zeros
/// leaving the positive axis: two adjacent tokens swapped (a zero crossing
/// a pole), two adjacent antiresonances merged into a complex pair, or,
/// for a type with zeros off the axis, a complex pair reaching it as two
/// adjacent antiresonances anywhere.
fn neighbours(t: &FrfType, zeros: u32) -> Vec<(FrfType, bool)> {
    let zero = super::frf_type::Token {
        feature: Feature::Antiresonance,
        multiplicity: 1,
    };
    let mut out = Vec::new();
    for i in 1..t.tokens.len() {
        if t.tokens[i - 1].feature != t.tokens[i].feature {
            let mut n = t.clone();
            n.tokens.swap(i - 1, i);
            out.push((n, false));
        }
    }
    for i in 1..t.tokens.len() {
        if t.tokens[i - 1] == zero && t.tokens[i] == zero {
            let mut n = t.clone();
            n.tokens.drain(i - 1..=i);
            n.nonminimum_phase = true;
            out.push((n, true));
        }
    }
    if t.nonminimum_phase && t.antiresonances() + 2 <= zeros {
        for i in 0..=t.tokens.len() {
            let mut n = t.clone();
            n.tokens.splice(i..i, [zero, zero]);
            n.nonminimum_phase = t.antiresonances() + 2 < zeros;
            if !out.contains(&(n.clone(), true)) {
                out.push((n, true));
            }
        }
    }
    out
}

/// Evaluations per start of the search from a neighbour's witness.
const NEIGHBOUR_EVALUATIONS: usize = 3000;

/// Evaluations of the search that draws a split witness's zeros together.
const PULL_EVALUATIONS: usize = 3000;

/// A cancellation mechanism: (first determinant, the masses it may be
/// solved for; second determinant, its masses).
pub(super) type Mechanism = (Poly, Vec<usize>, Poly, Vec<usize>);

/// `t` with every multiple token split into simple ones (`AA` for `A^2`).
pub(super) fn split_type(t: &FrfType) -> FrfType {
    FrfType {
        tokens: t
            .tokens
            .iter()
            .flat_map(|k| {
                std::iter::repeat_n(
                    super::frf_type::Token {
                        feature: k.feature,
                        multiplicity: 1,
                    },
                    k.multiplicity as usize,
                )
            })
            .collect(),
        nonminimum_phase: t.nonminimum_phase,
    }
}

/// The multiplicities of `t`'s multiple antiresonances, in order.
/// The root coincidences a type of a model with `degree` poles needs: its
/// number of cancelled poles and the multiplicities of its multiple
/// antiresonances; `None` for a type with none, or with a multiple pole.
pub(super) fn root_signature(t: &FrfType, degree: u32) -> Option<(u32, Vec<u32>)> {
    let simple_poles = t
        .tokens
        .iter()
        .all(|k| k.feature == Feature::Antiresonance || k.multiplicity == 1);
    if !simple_poles || t.resonances() > degree {
        return None;
    }
    let mults = multiple_antiresonances(t);
    let cancelled = degree - t.resonances();
    (cancelled > 0 || !mults.is_empty()).then_some((cancelled, mults))
}

/// The points where `equations` (jointly linear in `vars`, and in `x`
/// too once `fixed` is substituted) hold at once: the positive rational
/// roots `x0` of the determinant of the rows `[d e / d v_1 .. d e / d v_n,
/// e at v = 0]`, each completed by solving all but one equation for
/// `vars` (the first choice that is unique and positive) and kept if the
/// left-out one holds too.
fn pencil_points(
    equations: &[Poly],
    vars: &[String],
    x: &str,
    fixed: BTreeMap<String, Rat>,
) -> Vec<BTreeMap<String, Rat>> {
    let equations: Vec<Poly> = equations.iter().map(|e| e.subs_point(&fixed)).collect();
    if equations.len() != vars.len() + 1 {
        return Vec::new();
    }
    let at_zero: BTreeMap<String, Rat> = vars.iter().map(|v| (v.clone(), Rat::ZERO)).collect();
    // Each row scaled to integer coefficients: the determinant changes by
    // a non-zero factor only, so its roots stay; over Z[x] it is formed
    // without the rational gcds that dominated this search's time. A row
    // in another variable than `x` leaves no pencil in `x`.
    let Some(rows) = equations
        .iter()
        .map(|e| {
            let mut row: Vec<Poly> = vars.iter().map(|v| e.derivative(v)).collect();
            row.push(e.subs_point(&at_zero));
            integer_row(&row, x)
        })
        .collect::<Option<Vec<Vec<UPoly>>>>()
    else {
        return Vec::new();
    };
    let Ok(u) = poly::det_univariate(&rows) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for x0 in rational_roots(&u).into_iter().filter(|r| r.signum() > 0) {
        let at_x: BTreeMap<String, Rat> = [(x.to_string(), x0.clone())].into();
        let eqs: Vec<Poly> = equations.iter().map(|e| e.subs_point(&at_x)).collect();
        for left_out in (0..eqs.len()).rev() {
            let rest: Vec<Poly> = eqs
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != left_out)
                .map(|(_, e)| e.clone())
                .collect();
            let Some(sol) = solve_linear(&rest, vars) else {
                continue;
            };
            if sol.iter().any(|v| v.signum() <= 0) {
                continue;
            }
            let mut point = fixed.clone();
            point.insert(x.to_string(), x0.clone());
            point.extend(vars.iter().cloned().zip(sol));
            if eqs[left_out].eval(&point).is_ok_and(|v| v.is_zero()) {
                out.push(point);
            }
            break;
        }
    }
    out
}

/// The polynomials of `row`, in `x` alone, times one positive integer
/// that clears every denominator; `None` if one has another variable.
pub(super) fn integer_row(row: &[Poly], x: &str) -> Option<Vec<UPoly>> {
    let parts: Vec<(Rat, UPoly)> = row
        .iter()
        .map(|p| UPoly::from_poly(p, x))
        .collect::<Option<_>>()?;
    let mut den = Int::ONE;
    for (c, _) in &parts {
        den = den.lcm(c.denom());
    }
    Some(
        parts
            .iter()
            .map(|(c, u)| u.scale(&(c.numer() * &den.div_exact(c.denom()))))
            .collect(),
    )
}

/// Multiple zeros, each with its multiplicity.
type MultipleZeros = Vec<(Rat, u32)>;

/// The positive rational multiple zeros of a numerator with rational
/// coefficients in `Omega`, in increasing order, with their
/// multiplicities; `None` if it is not such a polynomial.
fn multiple_zeros(n: &Poly) -> Option<MultipleZeros> {
    let (_, u) = UPoly::from_poly(n, OMEGA)?;
    let mut out = Vec::new();
    for r in rational_roots(&u).into_iter().filter(|r| r.signum() > 0) {
        let mut k = 0;
        let mut d = u.clone();
        while !d.is_zero() && d.eval(&r).is_zero() {
            k += 1;
            d = d.derivative();
        }
        if k > 1 {
            out.push((r, k));
        }
    }
    Some(out)
}

/// `w` without the parameters `keep` rejects, and with `moved` at its new
/// value, if any: the fixed values of a walk's step.
fn kept_point(
    w: &BTreeMap<String, Rat>,
    moved: Option<&(String, Rat)>,
    keep: impl Fn(&String) -> bool,
) -> BTreeMap<String, Rat> {
    let mut fixed: BTreeMap<String, Rat> = w
        .iter()
        .filter(|(p, _)| keep(p))
        .map(|(p, v)| (p.clone(), v.clone()))
        .collect();
    if let Some((p, v)) = moved {
        fixed.insert(p.clone(), v.clone());
    }
    fixed
}

/// Whether `roots` have the multiplicities `mults`, in any order.
fn same_multiplicities(roots: &[(Rat, u32)], mults: &[u32]) -> bool {
    let mut have: Vec<u32> = roots.iter().map(|r| r.1).collect();
    let mut want = mults.to_vec();
    have.sort_unstable();
    want.sort_unstable();
    have == want
}

/// The moves of a walk along a variety from the witness `w` with its
/// coincident roots `at`: each root in turn scaled by `2^(k/4)` for `k` in
/// `steps` (rounded to four digits), then each parameter of `params` scaled
/// by 2 to 8 either way, given with its new value.
#[allow(clippy::type_complexity)]
fn walk_moves(
    at: &[Rat],
    w: &BTreeMap<String, Rat>,
    params: &[String],
    steps: &[i32],
) -> Vec<(Vec<Rat>, Option<(String, Rat)>)> {
    let mut moves = Vec::new();
    for i in 0..at.len() {
        for k in steps {
            let Some(z) = short_rational(at[i].to_f64() * 2f64.powf(f64::from(*k) / 4.0), 4) else {
                continue;
            };
            let mut a = at.to_vec();
            a[i] = z;
            moves.push((a, None));
        }
    }
    for p in params {
        for k in [-3, -2, -1, 1, 2, 3] {
            moves.push((at.to_vec(), Some((p.clone(), &w[p] * &Rat::from(2).pow(k)))));
        }
    }
    moves
}

pub(super) fn multiple_antiresonances(t: &FrfType) -> Vec<u32> {
    t.tokens
        .iter()
        .filter(|k| k.feature == Feature::Antiresonance && k.multiplicity > 1)
        .map(|k| k.multiplicity)
        .collect()
}

/// Trials of the block cancellation construction per model.
const CANCEL_TRIALS: usize = 10_000;
/// Where between the zeros of a split witness the merged root goes (as a
/// fraction of their log-distance), in the order tried.
pub(super) const MERGE_FRACTIONS: [f64; 5] = [0.5, 0.25, 0.75, 0.1, 0.9];
/// Parameter sets tried per merged root, at most.
const MERGE_SETS: usize = 24;
/// Trials per root-coincidence signature in the root-condition search.
const ROOT_TRIALS: usize = 2000;
/// Trials per root-coincidence signature in the search one parameter short
/// of a linear set.
const PENCIL_TRIALS: usize = 500;
/// Parameter sets (in lexicographic order) that the search one parameter
/// short of a linear set merges and walks in: each is tried with every
/// other parameter as the one short, at every place and move.
const PENCIL_SETS: usize = 3;
/// Witnesses a walk of [`Prover::root_walk_search`] starts from, per root
/// signature.
const WALK_STARTS: usize = 2;
/// Where between the zeros of a split witness the merged root goes in the
/// search one parameter short of a linear set, in the order tried: the
/// solved parameters move far, so more places than [`MERGE_FRACTIONS`].
const PENCIL_FRACTIONS: [f64; 11] = [0.5, 0.25, 0.75, 0.1, 0.9, 0.05, 0.95, 0.35, 0.65, 0.8, 0.2];
/// Candidate parameter sets kept for the root-condition search, at most.
const MAX_LINEAR_SETS: usize = 64;

/// Sets of `size` parameters each of degree at most one in every `polys`
/// and no two of them in one monomial: the polys are jointly linear in
/// them (the first `MAX_LINEAR_SETS` in lexicographic order).
pub(super) fn linear_sets(polys: &[&Poly], params: &[String], size: usize) -> Vec<Vec<String>> {
    let single: Vec<&String> = params
        .iter()
        .filter(|x| polys.iter().all(|p| p.degree(x) <= 1))
        .collect();
    // apart[i][j]: the coefficient of `single[i]` in every polynomial is
    // free of `single[j]`. Taken once per pair, not at every step of the
    // enumeration: the coefficients of large numerators and determinants
    // were most of the number-field searches' time at six masses.
    let apart: Vec<Vec<bool>> = single
        .iter()
        .map(|x| {
            let slopes: Vec<Poly> = polys
                .iter()
                .filter_map(|p| p.coeffs_in(x).into_iter().nth(1))
                .collect();
            single
                .iter()
                .map(|y| slopes.iter().all(|c| c.degree(y) == 0))
                .collect()
        })
        .collect();
    let mut out = Vec::new();
    let mut cur: Vec<usize> = Vec::new();
    fn grow(
        from: usize,
        size: usize,
        single: &[&String],
        apart: &[Vec<bool>],
        cur: &mut Vec<usize>,
        out: &mut Vec<Vec<String>>,
    ) {
        if out.len() >= MAX_LINEAR_SETS {
            return;
        }
        if cur.len() == size {
            out.push(cur.iter().map(|&i| single[i].clone()).collect());
            return;
        }
        for i in from..single.len() {
            if cur.iter().all(|&j| apart[j][i]) {
                cur.push(i);
                grow(i + 1, size, single, apart, cur, out);
                cur.pop();
            }
        }
    }
    if size > 0 {
        grow(0, size, &single, &apart, &mut cur, &mut out);
    }
    out
}

/// The exact solution of the square linear system `equations = 0` in
/// `vars` (each equation of degree one in them), if it is unique.
pub(super) fn solve_linear(equations: &[Poly], vars: &[String]) -> Option<Vec<Rat>> {
    let n = vars.len();
    if equations.len() != n {
        return None;
    }
    // a.x = -b for a.x + b = 0.
    let mut a: Vec<Vec<Rat>> = Vec::with_capacity(n);
    let mut b: Vec<Rat> = Vec::with_capacity(n);
    for e in equations {
        let mut row = Vec::with_capacity(n);
        let mut rest = e.clone();
        for x in vars {
            let c = rest.coeffs_in(x);
            row.push(c.get(1).map_or(Some(Rat::ZERO), |a| a.as_constant())?);
            rest = c.first().cloned().unwrap_or_else(Poly::zero);
        }
        b.push(-rest.as_constant()?);
        a.push(row);
    }
    poly::solve_rat(&a, &b)
}

/// Samples per partial wall.
const PARTIAL_WALL_SAMPLES: usize = 40;
/// Partial-wall strata built per model at most.
const PARTIAL_WALL_BUDGET: usize = 40;
/// Terms of `alpha` and `beta` together, at most, for a partial wall.
pub(super) const PARTIAL_WALL_TERMS: usize = 24;
/// Terms of the substituted numerator and denominator together, at most
/// (up to seven parameters; five eighths of it beyond).
const PARTIAL_WALL_TF_TERMS: usize = 400;

/// `f = alpha*x - beta` for the parameter `x` of degree one with the
/// smallest `alpha` and `beta` (any signs).
pub(super) fn linear_solution(f: &Poly, vars: &[String]) -> Option<Substitution> {
    vars.iter()
        .filter(|x| f.degree(x) == 1)
        .map(|x| {
            let c = f.coeffs_in(x);
            Substitution {
                var: x.clone(),
                alpha: c[1].clone(),
                beta: -c[0].clone(),
            }
        })
        .min_by_key(|s| s.alpha.num_terms() + s.beta.num_terms())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Model;

    /// The rows scaled to integers give the determinant over `Q` times a
    /// positive constant (Laplace's expansion of the rational rows is the
    /// other route), so the same rational roots; a row in another variable
    /// is refused.
    #[test]
    fn integer_rows_keep_the_determinants_roots() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let rows = vec![
            vec![p("x/3 - 1/2"), p("2/7"), p("0")],
            vec![p("5/4"), p("x - 3/5"), p("-1/6")],
            vec![p("1"), p("0"), p("2*x/9 + 4/11")],
        ];
        let over_q = poly::det_laplace(&rows).unwrap();
        let ints: Vec<Vec<UPoly>> = rows.iter().map(|r| integer_row(r, "x").unwrap()).collect();
        let over_z = poly::det_univariate(&ints).unwrap().to_poly("x");
        let (cq, uq) = UPoly::from_poly(&over_q, "x").unwrap();
        let (cz, uz) = UPoly::from_poly(&over_z, "x").unwrap();
        assert_eq!(uq, uz);
        assert_eq!(cq.signum(), cz.signum());
        assert_eq!(rational_roots(&uq), rational_roots(&uz));
        // (x/3 - 1/2) * (5/4 - x): the roots 5/4 and 3/2, by hand.
        let triangular = [vec![p("x/3 - 1/2"), p("2/7")], vec![p("0"), p("5/4 - x")]];
        let ints: Vec<Vec<UPoly>> = triangular
            .iter()
            .map(|r| integer_row(r, "x").unwrap())
            .collect();
        let roots = rational_roots(&poly::det_univariate(&ints).unwrap());
        assert_eq!(roots, vec!["5/4".parse().unwrap(), "3/2".parse().unwrap()]);
        assert!(integer_row(&[p("x"), p("y")], "x").is_none());
    }

    /// A parameter point written `"c1=25 m1=36 ..."`.
    fn point(text: &str) -> BTreeMap<String, Rat> {
        text.split_whitespace()
            .map(|kv| {
                let (k, v) = kv.split_once('=').unwrap();
                (k.to_string(), v.parse().unwrap())
            })
            .collect()
    }

    /// The numerator at a parameter point, a polynomial in `Omega` alone.
    fn num_at(p: &Poly, w: &BTreeMap<String, Rat>) -> Poly {
        w.iter().fold(p.clone(), |q, (k, v)| q.subs(k, v))
    }

    /// A witness of `AARRAARR` of N5-g2-a3.2-s4.2 whose second pair of
    /// zeros lies a factor 1.8 apart (194 and 351, the latter just below
    /// the third pole): merged where they are, the solved parameters leave
    /// the orthant or the order (engine 15 left `AARRA^2RR` unknown from
    /// this very witness). Drawn together first,
    /// the double zero is a small step away. Checked by a second route:
    /// the numerator and its derivative share a root there (their gcd),
    /// and the exact type is the wanted one.
    #[test]
    fn close_merge_reaches_a_double_zero() {
        let m = Model::from_id("N5-g2-a3.2-s4.2").unwrap();
        let tf = m.undamped_tf();
        let mut prover = Prover::new(&m, tf.num.clone(), tf.den.clone());
        let split: FrfType = "AARRAARR".parse().unwrap();
        let t: FrfType = "AARRA^2RR".parse().unwrap();
        let w =
            point("c1=21/50 c12=77/10 c34=25 c45=1/4 m1=21/500 m2=1/100 m3=34 m4=9/125 m5=11/50");
        assert_eq!(prover.type_at(&w).as_ref(), Some(&split));
        prover.witnesses.insert(split, w);
        assert_eq!(prover.close_merge_search(std::slice::from_ref(&t)), 1);
        let found = &prover.witnesses[&t];
        assert!(found.values().all(|v| v.signum() > 0));
        let n = num_at(&tf.num, found);
        let common = poly::gcd(&n, &n.derivative(OMEGA));
        assert_eq!(common.degree(OMEGA), 1, "{common}");
        let tf_at = crate::analysis::frf_type_at(&tf.num, &tf.den, OMEGA, found).unwrap();
        assert_eq!(tf_at, t);
    }

    /// The neighbours' ascent in model `id` from the witnesses `starts`
    /// (type, point; each checked to show its type) finds `wanted`, and
    /// the crate's exact classifier agrees at the point found.
    fn neighbours_reach(id: &str, wanted: &str, starts: &[(&str, &str)]) {
        let m = Model::from_id(id).unwrap();
        let tf = m.undamped_tf();
        let mut prover = Prover::new(&m, tf.num.clone(), tf.den.clone());
        let t: FrfType = wanted.parse().unwrap();
        for (n, w) in starts {
            let n: FrfType = n.parse().unwrap();
            let w = point(w);
            assert_eq!(prover.type_at(&w).as_ref(), Some(&n));
            prover.witnesses.insert(n, w);
        }
        assert_eq!(prover.neighbour_search(std::slice::from_ref(&t)), 1);
        let found = &prover.witnesses[&t];
        let tf_at = crate::analysis::frf_type_at(&tf.num, &tf.den, OMEGA, found).unwrap();
        assert_eq!(tf_at, t);
    }

    /// `RARARRAA` of N5-g1-a3.1-s4.1 fills about 1.4e-5 of the box
    /// `[e^-6, e^6]` (14 of 10^6 numpy samples, scripts/sample_unknown_types.py)
    /// and none of `[e^-3, e^3]`: the targeted search's samples and starts
    /// miss it. Its neighbour `ARRARRAA` (the first two tokens swapped)
    /// has a witness, from which the margin's ascent reaches it.
    #[test]
    fn neighbour_search_reaches_a_thin_region() {
        neighbours_reach(
            "N5-g1-a3.1-s4.1",
            "RARARRAA",
            &[(
                "ARRARRAA",
                "c1=25 c23=37/100 c34=49/1000 c45=6/625 m1=36 m2=81/100 m3=5/2 m4=9/50 m5=51/10",
            )],
        );
    }

    /// `AARRRRAA` of N5-g1-a2.1-s5.1 (two zeros below the first pole and
    /// two above the last, each at Rolle's bound there, three and two)
    /// showed at none of 2 x 10^6 numpy samples, and both of its swap
    /// neighbours are impossible. Its other neighbours have a pair of
    /// zeros off the axis instead (`RRRRAA (nm)`, `AARRRR (nm)`); from
    /// their witnesses the violation, which has a slope toward the axis,
    /// leads to it.
    #[test]
    fn neighbour_search_crosses_a_complex_pair() {
        neighbours_reach(
            "N5-g1-a2.1-s5.1",
            "AARRRRAA",
            &[
                (
                    "RRRRAA (nm)",
                    "c1=140 c23=7/2 c34=9/100 c45=4/25 m1=30 m2=3/2 m3=21/10 m4=3/25 m5=13/200",
                ),
                (
                    "AARRRR (nm)",
                    "c1=15/2 c23=7/8 c34=52 c45=7 m1=15/512 m2=14/201 m3=6 m4=56 m5=7/13",
                ),
            ],
        );
    }

    /// `RRARAA` of N5-g2-a3.2-s4.2 (a pole cancelled, the rest in an
    /// order the wall's exact samples miss) is found by the targeted search
    /// within the partial walls, from no witness at all; the exact type at
    /// the point, by the crate's classifier, is the wanted one, and a pole
    /// cancels there (the numerator and denominator share a root).
    #[test]
    fn targeted_search_within_partial_walls() {
        let m = Model::from_id("N5-g2-a3.2-s4.2").unwrap();
        let tf = m.undamped_tf();
        let mut prover = Prover::new(&m, tf.num.clone(), tf.den.clone());
        let t: FrfType = "RRARAA".parse().unwrap();
        let wanted = std::slice::from_ref(&t);
        let _ = prover.partial_wall_search(wanted, 2);
        assert!(!prover.witnesses.contains_key(&t));
        assert_eq!(prover.wall_targeted_search(wanted), 1);
        let found = &prover.witnesses[&t];
        let common = poly::gcd(&num_at(&tf.num, found), &num_at(&tf.den, found));
        assert!(common.degree(OMEGA) >= 1, "{common}");
        let tf_at = crate::analysis::frf_type_at(&tf.num, &tf.den, OMEGA, found).unwrap();
        assert_eq!(tf_at, t);
    }

    #[test]
    fn a_collapsed_simplex_ends_the_descent() {
        // A smooth bowl with its minimum at (1, -2): the descent gets there
        // and stops once the simplex has shrunk to nothing, long before the
        // budget, which a target value below any cost never ends.
        let mut evaluations = 0;
        let mut bowl = |x: &[f64]| {
            evaluations += 1;
            (x[0] - 1.0).powi(2) + 3.0 * (x[1] + 2.0).powi(2)
        };
        let best = nelder_mead_for(&mut bowl, &[4.0, 5.0], 0.5, f64::MIN_POSITIVE, 1_000_000);
        assert!(
            (best[0] - 1.0).abs() < 1e-6 && (best[1] + 2.0).abs() < 1e-6,
            "{best:?}"
        );
        assert!(evaluations < 5_000, "{evaluations} evaluations");
    }

    #[test]
    fn positive_roots_of_a_product() {
        // (x - 1)(x - 3)(x + 2)(x - 1/2) = x^4 - 2.5x^3 - 4x^2 + 8.5x - 3
        let mut r = positive_roots(&[-3.0, 8.5, -4.0, -2.5, 1.0]).unwrap();
        r.sort_by(f64::total_cmp);
        assert_eq!(r.len(), 3);
        for (got, want) in r.iter().zip([0.5, 1.0, 3.0]) {
            assert!((got - want).abs() < 1e-9, "{r:?}");
        }
        // x^2 + 1: none.
        assert!(positive_roots(&[1.0, 0.0, 1.0]).unwrap().is_empty());
    }

    #[test]
    fn margin_is_positive_only_for_the_ordering() {
        let t: FrfType = "ARRA".parse().unwrap();
        let good = (vec![1.0, 5.0], vec![2.0, 3.0], false);
        let bad = (vec![1.0, 2.5], vec![2.0, 3.0], false);
        assert!(margin(&t, &good).unwrap() > 0.0);
        assert!(margin(&t, &bad).unwrap() < 0.0);
        assert!(margin(&t, &(vec![1.0], vec![2.0, 3.0], true)).is_none());
    }

    #[test]
    fn complex_roots_of_a_product() {
        // x (x - 1e-3)(x^2 + 2x + 5) = x^4 + 1.999x^3 + 4.998x^2 - 0.005x:
        // roots 0, 1e-3, -1 +- 2i, over three decades.
        let mut r = complex_roots(&[0.0, -0.005, 4.998, 1.999, 1.0]).unwrap();
        r.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let want = [(-1.0, -2.0), (-1.0, 2.0), (0.0, 0.0), (1e-3, 0.0)];
        assert_eq!(r.len(), 4);
        for (got, w) in r.iter().zip(want) {
            assert!((got.0 - w.0).hypot(got.1 - w.1) < 1e-12, "{r:?}");
        }
        // A double root converges slowly but is still located.
        let r = complex_roots(&[4.0, -4.0, 1.0]).unwrap();
        assert!(r.iter().all(|z| (z.0 - 2.0).hypot(z.1) < 1e-6), "{r:?}");
        // (x - 1)^3 (x + 3) = x^4 - 6x^2 + 8x - 3: settling the triple root
        // at the rounding level keeps it to the cube root of the rounding
        // and leaves the simple root exact.
        let mut r = complex_roots(&[-3.0, 8.0, -6.0, 0.0, 1.0]).unwrap();
        r.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!((r[0].0 + 3.0).hypot(r[0].1) < 1e-12, "{r:?}");
        assert!(
            r[1..].iter().all(|z| (z.0 - 1.0).hypot(z.1) < 1e-4),
            "{r:?}"
        );
    }

    #[test]
    fn violation_vanishes_only_for_the_ordering() {
        let t: FrfType = "AARR".parse().unwrap();
        // Poles 2 and 3: (x - 2)(x - 3) = x^2 - 5x + 6.
        let den = [6.0, -5.0, 1.0];
        // Zeros 1/2 and 1: the ordering, with room to spare.
        assert_eq!(violation(&t, &[0.5, -1.5, 1.0], &den), Some(0.0));
        // Zeros 1 +- i/2: the angles are the distance to go, and the two
        // moduli, equal, lack the gap.
        let v = violation(&t, &[1.25, -2.0, 1.0], &den).unwrap();
        assert!((v - (2.0 * 0.5f64.atan() + 1e-3)).abs() < 1e-9, "{v}");
        // Zeros 1/2 and 5/2: the second must move below the first pole.
        let v = violation(&t, &[1.25, -3.0, 1.0], &den).unwrap();
        assert!((v - (1e-3 + (2.5f64 / 2.0).ln())).abs() < 1e-9, "{v}");
        // Three resonances wanted, two present.
        let r: FrfType = "ARRR".parse().unwrap();
        assert_eq!(violation(&r, &[-1.0, 1.0], &den), None);
    }

    #[test]
    fn linear_systems_are_solved_exactly() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let vars = ["x".to_string(), "y".to_string()];
        // 2x + y = 5/2, x - 3y = -2: x = 11/14, y = 13/14.
        let sol = solve_linear(&[p("2*x + y - 5/2"), p("x - 3*y + 2")], &vars).unwrap();
        assert_eq!(
            sol,
            vec![
                Rat::new(11.into(), 14.into()),
                Rat::new(13.into(), 14.into())
            ]
        );
        // Singular: no unique solution.
        assert!(solve_linear(&[p("x + y - 1"), p("2*x + 2*y - 3")], &vars).is_none());
        // Not linear in the unknowns.
        assert!(solve_linear(&[p("x*y - 1"), p("x - 1")], &vars).is_none());
    }

    #[test]
    fn linear_sets_avoid_shared_monomials() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let params: Vec<String> = ["a", "b", "c", "d"].iter().map(|s| s.to_string()).collect();
        // a*b shares a monomial, c appears squared.
        let f = p("a*b + c^2 + a*d + b + 1");
        let sets = linear_sets(&[&f], &params, 2);
        assert_eq!(sets, vec![vec!["b".to_string(), "d".to_string()]]);
    }

    /// N5-g1-a2.1-s4.1's numerator is linear in `c1, m1, m2` jointly and
    /// in no four parameters; a quadruple zero at `Omega = 1/2` is found
    /// with `c23` as the parameter one short. The point is the one sympy
    /// finds by solving the first three conditions and then the fourth
    /// for `c23` (scripts/quadruple_zero_point.py), and the numerator
    /// there is a multiple of `(Omega - 1/2)^4`.
    #[test]
    fn a_quadruple_zero_one_parameter_short_of_a_linear_set() {
        let model = Model::from_id("N5-g1-a2.1-s4.1").unwrap();
        let num = model.undamped_tf().num;
        let vars: Vec<String> = ["c1", "m1", "m2"].iter().map(|s| s.to_string()).collect();
        assert!(linear_sets(&[&num], &model.undamped_parameters(), 4).is_empty());
        assert!(linear_sets(&[&num], &model.undamped_parameters(), 3)
            .iter()
            .any(|set| set.len() == 3 && vars.iter().all(|v| set.contains(v))));
        let z: Rat = "1/2".parse().unwrap();
        let mut equations = Vec::new();
        let mut d = num.clone();
        for _ in 0..4 {
            equations.push(d.subs(OMEGA, &z));
            d = d.derivative(OMEGA);
        }
        let fixed = point(
            "c34=247281/25000 c45=29163/200000 m3=169783/10000 m4=470593/5000 m5=128607/500000",
        );
        let found = pencil_points(&equations, &vars, "c23", fixed.clone());
        let mut expected = fixed;
        expected.extend(point(
            "c1=7270684179057141808752772005997609/285730712504365797240669548262500 \
             c23=1033510567014063014454693381790319765999/1386143327576619880510221603777403200000 \
             m1=89771175462149219173064936996625358234223/1940488702445149526116503916506081500000 \
             m2=1033510567014063014454693381790319765999/970244351222574763058251958253040750000",
        ));
        assert_eq!(found, vec![expected.clone()]);
        let n = num.subs_point(&expected);
        let lead = n.coeffs_in(OMEGA)[4].clone();
        let quartic = (&Poly::var(OMEGA) - &Poly::constant(z)).pow(4);
        assert_eq!(n, &lead * &quartic);
    }

    /// The walk along the variety: from the quadruple zero below every
    /// pole (the point of the test above, `A^4RRRR`), moving the zero
    /// and the other parameters reaches `RA^4RRR`, the zero between the
    /// first and the second pole, which no split witness is given for.
    /// Checked by another route: the numerator at the point is a multiple
    /// of `(Omega - z)^4`, and Descartes' rule on the denominator's
    /// Taylor coefficients at `z` finds one pole below `z` and three above
    /// it.
    #[test]
    fn the_walk_moves_a_quadruple_zero_past_a_pole() {
        let m = Model::from_id("N5-g1-a2.1-s4.1").unwrap();
        let tf = m.undamped_tf();
        let mut prover = Prover::new(&m, tf.num.clone(), tf.den.clone());
        let start = point(
            "c1=7270684179057141808752772005997609/285730712504365797240669548262500 \
             c23=1033510567014063014454693381790319765999/1386143327576619880510221603777403200000 \
             c34=247281/25000 c45=29163/200000 \
             m1=89771175462149219173064936996625358234223/1940488702445149526116503916506081500000 \
             m2=1033510567014063014454693381790319765999/970244351222574763058251958253040750000 \
             m3=169783/10000 m4=470593/5000 m5=128607/500000",
        );
        let below: FrfType = "A^4RRRR".parse().unwrap();
        assert_eq!(prover.type_at(&start), Some(below.clone()));
        prover.witnesses.insert(below, start);
        let wanted: FrfType = "RA^4RRR".parse().unwrap();
        prover.variety_walk_search(std::slice::from_ref(&wanted));
        let w = &prover.witnesses[&wanted];
        let n = tf.num.subs_point(w);
        let c = n.coeffs_in(OMEGA);
        let z = -(&c[3].as_constant().unwrap() / &c[4].as_constant().unwrap()) / Rat::from(4);
        let quartic = (&Poly::var(OMEGA) - &Poly::constant(z.clone())).pow(4);
        assert_eq!(n, &c[4] * &quartic);
        // The denominator is real-rooted (a symmetric definite eigenvalue
        // problem), so Descartes' rule is exact: the sign changes of the
        // Taylor coefficients at `z`, `d^(k)(z)`, count the poles above
        // `z`, those of `(-1)^k d^(k)(z)` the ones below.
        let d = tf.den.subs_point(w);
        assert_eq!(d.degree(OMEGA), 4);
        let mut signs = Vec::new();
        let mut dk = d.clone();
        for _ in 0..=4 {
            signs.push(dk.subs(OMEGA, &z).as_constant().unwrap().signum());
            dk = dk.derivative(OMEGA);
        }
        let changes = |s: &[i32]| s.windows(2).filter(|p| p[0] * p[1] < 0).count();
        let alternated: Vec<i32> = signs
            .iter()
            .enumerate()
            .map(|(k, s)| if k % 2 == 0 { *s } else { -s })
            .collect();
        assert!(signs.iter().all(|s| *s != 0));
        assert_eq!((changes(&alternated), changes(&signs)), (1, 3));
    }

    /// The walk with a linear set: from the double zero above two simple
    /// zeros (`AAA^2RRRR`, a witness of the table), moving it down
    /// reaches `A^2AARRRR`, below them. Checked by another route: the
    /// numerator at the point is `(Omega - z)^2 q` with `q` of degree two;
    /// `q` has a positive discriminant and the denominator is real-rooted, so
    /// Descartes' rule on Taylor coefficients counts their roots above a
    /// point exactly: `q` has both roots above `z`, and a point found by
    /// bisection has both of them below it and all four poles above it.
    #[test]
    fn the_walk_moves_a_double_zero_below_two_simple_ones() {
        let m = Model::from_id("N5-g1-a2.1-s4.1").unwrap();
        let tf = m.undamped_tf();
        let mut prover = Prover::new(&m, tf.num.clone(), tf.den.clone());
        let start = point(
            "c1=41241939/2500000 c23=490183917/10000000000 c34=989123767/100000000 \
             c45=3645383/25000000 m2=161916331/2000000000 m3=169796483/10000000 \
             m5=257592441/1000000000 \
             m1=106029178452472125087705383978392214208949519860526731386910799126239249310723/\
             3747618510086243398469434062977857866318920011641761151370265095750000000000 \
             m4=7038595450818191697400488495434563383672093835191063/\
             74202222446526633461545836819499827183123898232800",
        );
        let above: FrfType = "AAA^2RRRR".parse().unwrap();
        assert_eq!(prover.type_at(&start), Some(above.clone()));
        prover.witnesses.insert(above, start);
        let wanted: FrfType = "A^2AARRRR".parse().unwrap();
        assert_eq!(prover.root_walk_search(std::slice::from_ref(&wanted)), 1);
        let w = &prover.witnesses[&wanted];
        let n = UPoly::from_poly(&tf.num.subs_point(w), OMEGA).unwrap().1;
        let d = UPoly::from_poly(&tf.den.subs_point(w), OMEGA).unwrap().1;
        let doubles: Vec<Rat> = rational_roots(&n)
            .into_iter()
            .filter(|r| n.derivative().eval(r).is_zero())
            .collect();
        assert_eq!(doubles.len(), 1);
        let z = &doubles[0];
        let square = UPoly::linear_root(z).pow(2);
        let q = n
            .div_exact(&square)
            .expect("(Omega - z)^2 divides the numerator");
        assert_eq!((q.degree(), d.degree()), (Some(2), Some(4)));
        let c = q.coeffs();
        assert!(&c[1] * &c[1] - &(&c[0] * &c[2]) * &Int::from(4) > Int::from(0));
        let roots_above = |p: &UPoly, b: &Rat| {
            let mut signs = Vec::new();
            let mut pk = p.clone();
            while !pk.is_zero() {
                signs.push(pk.sign_at(b));
                pk = pk.derivative();
            }
            assert!(signs.iter().all(|s| *s != 0));
            signs.windows(2).filter(|s| s[0] * s[1] < 0).count()
        };
        assert_eq!(roots_above(&q, z), 2);
        // Bisection for a point just above the larger zero of `q`.
        let (mut lo, mut hi) = (z.clone(), z * &Rat::from(1i64 << 40));
        assert_eq!(roots_above(&q, &hi), 0);
        for _ in 0..200 {
            let mid = (&lo + &hi) / Rat::from(2);
            if roots_above(&q, &mid) == 0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        assert_eq!(roots_above(&d, &hi), 4);
    }

    #[test]
    fn short_rationals() {
        assert_eq!(
            short_rational(0.012345, 3).unwrap(),
            "123/10000".parse().unwrap()
        );
        assert_eq!(short_rational(98765.0, 2).unwrap(), Rat::from(99000));
    }
}
