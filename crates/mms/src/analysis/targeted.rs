//! Targeted witness search for rare generic types (issue 4, item 2).
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
use super::pole_signs::{chain_blocks, pencil};
use super::prover::{positive_full_point, substitute, Prover, Sampler, Substitution};
use crate::tf::UndampedCoefficients;
use crate::tf::OMEGA;
use crate::xorshift::XorShift;
use poly::{Int, Poly, Rat};
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
fn tf_roots(tf: &UndampedCoefficients, x: &[f64]) -> Option<(Vec<f64>, Vec<f64>, bool)> {
    let (n, d) = tf.eval(x);
    let zn = positive_roots(&n)?;
    let zd = positive_roots(&d)?;
    let nm = zn.len() < n.len() - 1;
    Some((zn, zd, nm))
}

/// Positive real roots of `sum c[k] x^k` (simple ones; a double root shows
/// once or not at all, which only matters on measure-zero sets), found by
/// bracketing between the roots of the derivative.
fn positive_roots(c: &[f64]) -> Option<Vec<f64>> {
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

fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, v| acc * x + v)
}

fn roots_in(c: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    if c.len() <= 1 {
        return Vec::new();
    }
    let derivative: Vec<f64> = c
        .iter()
        .enumerate()
        .skip(1)
        .map(|(k, v)| v * k as f64)
        .collect();
    let mut cuts = vec![lo];
    cuts.extend(roots_in(&derivative, lo, hi));
    cuts.push(hi);
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        let (mut a, mut b) = (w[0], w[1]);
        let (mut fa, fb) = (horner(c, a), horner(c, b));
        if fa == 0.0 && a > lo {
            if out.last() != Some(&a) {
                out.push(a);
            }
            continue;
        }
        if fa.signum() == fb.signum() || fb == 0.0 {
            continue;
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            let fm = horner(c, m);
            if fm.signum() == fa.signum() {
                a = m;
                fa = fm;
            } else {
                b = m;
            }
        }
        out.push(0.5 * (a + b));
    }
    out
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
    let (mut ia, mut ir) = (0, 0);
    let mut seq = Vec::with_capacity(t.tokens.len());
    for tok in &t.tokens {
        let v = match tok.feature {
            Feature::Antiresonance => {
                ia += 1;
                zn[ia - 1]
            }
            Feature::Resonance => {
                ir += 1;
                zd[ir - 1]
            }
        };
        seq.push(v.max(f64::MIN_POSITIVE).ln());
    }
    Some(
        seq.windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min),
    )
}

/// A short positive rational near `x` with `digits` significant decimal
/// digits.
fn short_rational(x: f64, digits: i32) -> Option<Rat> {
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
const VIOLATION_GAP: f64 = 1e-3;

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
    let poles = positive_roots(den)?;
    if poles.len() as u32 != t.resonances() {
        return None;
    }
    let zeros = complex_roots(num)?;
    let k = t.antiresonances() as usize;
    if zeros.len() < k || (zeros.len() > k) != t.nonminimum_phase {
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
    let (mut ia, mut ir) = (0, 0);
    let mut seq = Vec::with_capacity(t.tokens.len());
    for tok in &t.tokens {
        let v = match tok.feature {
            Feature::Antiresonance => {
                ia += 1;
                moduli[ia - 1]
            }
            Feature::Resonance => {
                ir += 1;
                poles[ir - 1]
            }
        };
        seq.push(v.max(f64::MIN_POSITIVE).ln());
    }
    cost += seq
        .windows(2)
        .map(|w| (VIOLATION_GAP - (w[1] - w[0])).max(0.0))
        .sum::<f64>();
    cost.is_finite().then_some(cost)
}

/// All roots of `sum c[k] x^k` as `(re, im)` (Aberth-Ehrlich on the
/// polynomial scaled to roots of modulus about one), roots at `0`
/// included; `None` for a zero or non-finite polynomial.
fn complex_roots(c: &[f64]) -> Option<Vec<(f64, f64)>> {
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
    let mut z: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let phi = 2.0 * std::f64::consts::PI * k as f64 / n as f64 + 0.4;
            (phi.cos(), phi.sin())
        })
        .collect();
    for _ in 0..200 {
        let mut moved = 0.0f64;
        for i in 0..n {
            // p and p' at z_i by Horner.
            let (mut p, mut dp) = ((1.0, 0.0), (0.0, 0.0));
            for v in a[..n].iter().rev() {
                dp = (mul(dp, z[i]).0 + p.0, mul(dp, z[i]).1 + p.1);
                p = mul(p, z[i]);
                p.0 += v;
            }
            if p == (0.0, 0.0) {
                continue;
            }
            let ratio = div(p, dp);
            let mut sum = (0.0, 0.0);
            for (j, zj) in z.iter().enumerate() {
                if j != i {
                    let r = div((1.0, 0.0), (z[i].0 - zj.0, z[i].1 - zj.1));
                    sum = (sum.0 + r.0, sum.1 + r.1);
                }
            }
            let rs = mul(ratio, sum);
            let w = div(ratio, (1.0 - rs.0, -rs.1));
            if !(w.0.is_finite() && w.1.is_finite()) {
                return None;
            }
            z[i] = (z[i].0 - w.0, z[i].1 - w.1);
            moved = moved.max(w.0.hypot(w.1) / z[i].0.hypot(z[i].1).max(1e-300));
        }
        if moved < 1e-13 {
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
fn nelder_mead_for(
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
                if m > 0.0 && self.accept(t, &params, &x) {
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
                if ok && self.accept(t, &params, &x) {
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
            let mut f = |lx: &[f64]| cost(lx);
            let best = nelder_mead_for(&mut f, &lx0, 1.0, f64::MIN_POSITIVE, VIOLATION_EVALUATIONS);
            let x: Vec<f64> = best.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
            let ok = tf_roots(tf, &x)
                .and_then(|r| margin(t, &r))
                .is_some_and(|m| m > 0.0);
            if ok && self.accept(t, params, &x) {
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
        wanted
            .iter()
            .filter(|t| self.witnesses.contains_key(t))
            .count()
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
            next.push(w.clone());
            // The stratum's cost is factoring its critical polynomials;
            // skip substitutions that make the TF itself large.
            let size = |p: &Poly| next.iter().fold(p.clone(), |q, w| substitute(&q, w));
            // Factoring cost grows steeply with the number of variables:
            // five masses (nine) get a smaller limit than four (seven).
            let limit = if self.params.len() <= 7 {
                PARTIAL_WALL_TF_TERMS
            } else {
                PARTIAL_WALL_TF_TERMS * 5 / 8
            };
            if size(&self.num).num_terms() + size(&self.den).num_terms() > limit {
                continue;
            }
            next.pop();
            *budget -= 1;
            next.push(w);
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
            self.partial_walls(&next, wanted, depth - 1, visited, rng, budget);
        }
    }

    /// Constructs points with wanted root coincidences exactly (issue 4,
    /// item 2: parameters from wanted root positions). A type with `c`
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
        let mut signatures: BTreeSet<(u32, Vec<u32>)> = BTreeSet::new();
        for t in wanted {
            let simple_poles = t
                .tokens
                .iter()
                .all(|k| k.feature == Feature::Antiresonance || k.multiplicity == 1);
            if !simple_poles || t.resonances() > degree {
                continue;
            }
            let mults = multiple_antiresonances(t);
            let cancelled = degree - t.resonances();
            if cancelled > 0 || !mults.is_empty() {
                signatures.insert((cancelled, mults));
            }
        }
        if signatures.is_empty() {
            return 0;
        }
        let max_mult = signatures
            .iter()
            .flat_map(|(_, m)| m.iter().copied())
            .max()
            .unwrap_or(1);
        let mut derivatives = vec![self.num.clone()];
        while derivatives.len() < max_mult as usize {
            let d = derivatives[derivatives.len() - 1].derivative(OMEGA);
            derivatives.push(d);
        }
        // First, merge the zeros of a witness of the split type (A^2 as
        // AA): the root goes between them and the solved parameters stay
        // near the witness's, keeping the rest of the ordering.
        let tf = UndampedCoefficients::new(self.model);
        let params = self.params.clone();
        for t in wanted {
            let mults = multiple_antiresonances(t);
            if mults.is_empty()
                || t.resonances() != degree
                || self.witnesses.contains_key(t)
                || t.tokens
                    .iter()
                    .any(|k| k.feature == Feature::Resonance && k.multiplicity > 1)
            {
                continue;
            }
            let Some(w) = self.witnesses.get(&split_type(t)).cloned() else {
                continue;
            };
            let x: Vec<f64> = params.iter().map(|p| w[p].to_f64()).collect();
            let Some((zeros, _, _)) = tf_roots(&tf, &x) else {
                continue;
            };
            // The positive zeros in order, grouped as `t` merges them: the
            // log-range of each group.
            let mut groups: Vec<(f64, f64, u32)> = Vec::new();
            let mut next = 0;
            for k in t
                .tokens
                .iter()
                .filter(|k| k.feature == Feature::Antiresonance)
            {
                let m = k.multiplicity as usize;
                if next + m > zeros.len() {
                    break;
                }
                if m > 1 {
                    groups.push((zeros[next].ln(), zeros[next + m - 1].ln(), k.multiplicity));
                }
                next += m;
            }
            if groups.len() != mults.len() {
                continue;
            }
            let size = mults.iter().sum::<u32>() as usize;
            // Only the numerator's conditions: it alone must be linear.
            let sets = linear_sets(&[&self.num], &params, size);
            // The merged root at several places across each group, every
            // parameter set: the first that keeps the rest of the order.
            'merge: for frac in MERGE_FRACTIONS {
                let roots: Option<Vec<(Rat, u32)>> = groups
                    .iter()
                    .map(|&(a, b, k)| Some((short_rational((a + frac * (b - a)).exp(), 4)?, k)))
                    .collect();
                let Some(roots) = roots else { continue };
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
        wanted
            .iter()
            .filter(|t| self.witnesses.contains_key(t))
            .count()
    }

    /// Constructs cancellations from the chain's blocks (issue 4, item 2):
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
                    let e = point
                        .iter()
                        .filter(|(p, _)| *p != name)
                        .fold(d.subs(OMEGA, &r), |e, (p, val)| e.subs(p, val));
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
        wanted
            .iter()
            .filter(|t| self.witnesses.contains_key(t))
            .count()
    }

    /// The ways a pole cancels (see [`Self::cancellation_search`]): the
    /// determinant of a run and of its block, with the masses each may be
    /// solved for (the run's; the block's outside the run), or the
    /// determinants of two blocks with their masses.
    fn cancellation_mechanisms(&self) -> Vec<Mechanism> {
        let mass = self.model.mass_matrix();
        let stiff = self.model.stiffness_matrix();
        let det_of =
            |lo: usize, hi: usize| poly::det(&pencil(&mass, &stiff, &(lo..hi).collect::<Vec<_>>()));
        // Blocks as [first, last + 1).
        let blocks: Vec<(usize, usize)> = chain_blocks(&stiff)
            .iter()
            .map(|b| (b[0], b[b.len() - 1] + 1))
            .collect();
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

    /// Double antiresonances on a one-parameter family (issue 4, item 2).
    ///
    /// Where a double zero must come with cancelled poles, the root
    /// conditions are seldom linear, and where it sits is not free: on the
    /// wall `c1/m1 = mu1` of N4-g1-a2.1-s4.1 the reduced numerator is
    /// `Omega (Omega - mu2) + a` and its double root must be `mu2 / 2`.
    /// So: pose the cancellations as in [`Self::cancellation_search`]
    /// (each determinant condition at a rational `r` of degree one in its
    /// mass), keep one other parameter `z` free and the rest at random
    /// values; the solved masses are rational functions of `z`, the reduced
    /// numerator a polynomial in `Omega` and `z`, and its discriminant in
    /// `Omega` a polynomial in `z`. Its rational roots (the linear factors
    /// of its factorization) give exact points with a double zero, which
    /// the exact classification then names. Returns how many of `wanted`
    /// have witnesses afterwards.
    pub(crate) fn discriminant_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let degree = self.den.degree(OMEGA);
        let mut signatures: BTreeSet<u32> = BTreeSet::new();
        for t in wanted {
            if self.witnesses.contains_key(t) || t.resonances() > degree {
                continue;
            }
            let simple_poles = t
                .tokens
                .iter()
                .all(|k| k.feature == Feature::Antiresonance || k.multiplicity == 1);
            if simple_poles && multiple_antiresonances(t) == [2] {
                signatures.insert(degree - t.resonances());
            }
        }
        if signatures.is_empty() {
            return 0;
        }
        let mechanisms = self.cancellation_mechanisms();
        for t in wanted {
            let one_pole = degree == t.resonances() + 1;
            if one_pole && multiple_antiresonances(t) == [2] && !self.witnesses.contains_key(t) {
                self.wall_merge(t, &mechanisms);
            }
        }
        let signatures: Vec<u32> = signatures.into_iter().collect();
        let mut rng = Sampler::new(seed);
        for trial in 0..DISCRIMINANT_TRIALS {
            let cancelled = signatures[trial % signatures.len()] as usize;
            if cancelled > 0 && mechanisms.is_empty() {
                continue;
            }
            // The conditions: (solved parameter, equation), and the roots.
            let mut conditions: Vec<(String, Poly)> = Vec::new();
            let mut roots: Vec<Rat> = Vec::new();
            let mut used: Vec<String> = Vec::new();
            for _ in 0..cancelled {
                let (d1, _, d2, _) = &mechanisms[rng.index(mechanisms.len())];
                // Any parameter (spring or mass) of the first determinant,
                // then one of the second the first does not contain: each
                // condition is of degree one in it (multilinear).
                let in1 = d1.vars();
                let free1: Vec<&String> = in1
                    .iter()
                    .filter(|v| v.as_str() != OMEGA && !used.contains(v))
                    .collect();
                let free2: Vec<&String> = d2
                    .vars()
                    .iter()
                    .filter(|v| v.as_str() != OMEGA && !in1.contains(v) && !used.contains(v))
                    .collect();
                if free1.is_empty() || free2.is_empty() {
                    break;
                }
                let r = rng.value();
                let x = free1[rng.index(free1.len())].clone();
                let y = free2[rng.index(free2.len())].clone();
                conditions.push((x.clone(), d1.subs(OMEGA, &r)));
                conditions.push((y.clone(), d2.subs(OMEGA, &r)));
                used.extend([x, y]);
                roots.push(r);
            }
            if roots.len() != cancelled {
                continue;
            }
            let open: Vec<&String> = self
                .params
                .iter()
                .filter(|p| conditions.iter().all(|(v, _)| v != *p))
                .collect();
            let z = open[rng.index(open.len())].clone();
            let fixed: BTreeMap<String, Rat> = self
                .params
                .iter()
                .filter(|p| **p != z && conditions.iter().all(|(v, _)| v != *p))
                .map(|p| (p.clone(), rng.value()))
                .collect();
            if let Some(points) = double_zero_points(&self.num, &fixed, &conditions, &roots, &z) {
                for point in points {
                    self.record(point);
                }
            }
            // The same wall with every other parameter free: the double
            // root's conditions at a chosen rational root are often linear
            // in two parameters there even where they are not before the
            // cancellation (a factor free of Omega, such as m3*m4, dropped).
            if cancelled > 0 {
                self.wall_root_conditions(&conditions, &roots, &mut rng);
            }
        }
        wanted
            .iter()
            .filter(|t| self.witnesses.contains_key(t))
            .count()
    }

    /// Multiple zeros by elimination (issue 4, item 2), where no set of
    /// parameters makes all the root conditions linear.
    ///
    /// A double zero at a chosen rational `sigma` next to a cancelled pole
    /// at `r`: with `r` symbolic (here written `Omega`), the wall's two
    /// conditions solved for a parameter each (rational in `r` and one
    /// more parameter `w`), `num(sigma) = num'(sigma) = 0` are two
    /// polynomials in `r` and `w`; their resultant in `w` is a polynomial
    /// in `r` whose rational roots (linear factors) give exact points.
    /// For N4-g2-a3.2-s4.2 (`S = r1/(l1 - W) + r2/(l2 - W) - b/W` on the
    /// wall) the condition on `r` is linear. A triple zero at `sigma`
    /// without cancellation: two of its three conditions solved in a linear
    /// set `{w1, w2}` (rational in one more parameter `z`), the third is a
    /// polynomial in `z`, with the same use of its linear factors.
    /// Returns how many of `wanted` have witnesses afterwards.
    pub(crate) fn elimination_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let degree = self.den.degree(OMEGA);
        let (mut tangent, mut triple) = (false, false);
        for t in wanted {
            if self.witnesses.contains_key(t)
                || t.resonances() > degree
                || t.tokens
                    .iter()
                    .any(|k| k.feature == Feature::Resonance && k.multiplicity > 1)
            {
                continue;
            }
            match (
                degree - t.resonances(),
                multiple_antiresonances(t).as_slice(),
            ) {
                (1, [2]) => tangent = true,
                (0, [3]) => triple = true,
                _ => {}
            }
        }
        let mut rng = Sampler::new(seed);
        let dn = self.num.derivative(OMEGA);
        let ddn = dn.derivative(OMEGA);
        if tangent {
            let mechanisms = self.cancellation_mechanisms();
            for _ in 0..(ELIMINATION_TRIALS * usize::from(!mechanisms.is_empty())) {
                let (d1, _, d2, _) = &mechanisms[rng.index(mechanisms.len())];
                let in1: Vec<&String> = d1.vars().iter().filter(|v| v.as_str() != OMEGA).collect();
                let in2: Vec<&String> = d2
                    .vars()
                    .iter()
                    .filter(|v| v.as_str() != OMEGA && !in1.contains(v))
                    .collect();
                if in1.is_empty() || in2.is_empty() {
                    continue;
                }
                let x = in1[rng.index(in1.len())].clone();
                let y = in2[rng.index(in2.len())].clone();
                let open: Vec<&String> = self
                    .params
                    .iter()
                    .filter(|p| **p != x && **p != y)
                    .collect();
                let w = open[rng.index(open.len())].clone();
                let fixed: BTreeMap<String, Rat> = open
                    .iter()
                    .filter(|p| ***p != w)
                    .map(|p| ((*p).clone(), rng.value()))
                    .collect();
                let sigma = rng.value();
                let conditions = [(x, d1.clone()), (y, d2.clone())];
                for point in tangent_points(&self.num, &dn, &fixed, &conditions, &w, &sigma) {
                    self.record(point);
                }
            }
        }
        if triple {
            let sets = linear_sets(&[&self.num], &self.params, 2);
            for _ in 0..(ELIMINATION_TRIALS * usize::from(!sets.is_empty())) {
                let vars = &sets[rng.index(sets.len())];
                let open: Vec<&String> = self.params.iter().filter(|p| !vars.contains(p)).collect();
                let z = open[rng.index(open.len())].clone();
                let fixed: BTreeMap<String, Rat> = open
                    .iter()
                    .filter(|p| ***p != z)
                    .map(|p| ((*p).clone(), rng.value()))
                    .collect();
                let sigma = rng.value();
                let eqs: Vec<Poly> = [&self.num, &dn, &ddn]
                    .iter()
                    .map(|e| {
                        fixed
                            .iter()
                            .fold(e.subs(OMEGA, &sigma), |e, (p, v)| e.subs(p, v))
                    })
                    .collect();
                for point in triple_points(&eqs, vars, &z, &fixed) {
                    self.record(point);
                }
            }
        }
        wanted
            .iter()
            .filter(|t| self.witnesses.contains_key(t))
            .count()
    }

    /// A double zero next to a cancelled pole, merged from a witness of
    /// the split type on the same wall: its cancelled root `r` (a rational
    /// common root of its numerator and denominator), every mechanism whose
    /// two determinants vanish there, the double root placed between the
    /// two zeros to merge and solved in a linear set of the wall's reduced
    /// numerator, every other parameter kept. Where the double zero needs
    /// a thin region (N4-g2-a3.1-s4.1 `A^2RR`: the spring-mass impedance's
    /// pole just above the cancelled one), the split witness is already in
    /// it.
    fn wall_merge(&mut self, t: &FrfType, mechanisms: &[Mechanism]) {
        let Some(w) = self.witnesses.get(&split_type(t)).cloned() else {
            return;
        };
        let at_w = |e: &Poly| w.iter().fold(e.clone(), |e, (p, v)| e.subs(p, v));
        let common = poly::gcd(&at_w(&self.num), &at_w(&self.den));
        let cancelled = rational_roots(&common, OMEGA);
        let [r] = cancelled.as_slice() else {
            return;
        };
        // The reduced zeros of the witness, in order, and where t merges.
        let x: Vec<f64> = self.params.iter().map(|p| w[p].to_f64()).collect();
        let tf = UndampedCoefficients::new(self.model);
        let Some((mut zeros, _, _)) = tf_roots(&tf, &x) else {
            return;
        };
        let Some(at_r) = zeros
            .iter()
            .enumerate()
            .min_by(|a, b| {
                (a.1 - r.to_f64())
                    .abs()
                    .total_cmp(&(b.1 - r.to_f64()).abs())
            })
            .map(|(i, _)| i)
        else {
            return;
        };
        zeros.remove(at_r);
        let mut next = 0;
        let mut pair = None;
        for k in t
            .tokens
            .iter()
            .filter(|k| k.feature == Feature::Antiresonance)
        {
            let m = k.multiplicity as usize;
            if m == 2 && next + 1 < zeros.len() {
                pair = Some((zeros[next].ln(), zeros[next + 1].ln()));
            }
            next += m;
        }
        let Some((lo, hi)) = pair else { return };
        for (d1, _, d2, _) in mechanisms {
            let at_r = |d: &Poly| at_w(&d.subs(OMEGA, r)).is_zero();
            if !(at_r(d1) && at_r(d2)) {
                continue;
            }
            let in1: Vec<&String> = d1.vars().iter().filter(|v| v.as_str() != OMEGA).collect();
            for x in &in1 {
                for y in d2
                    .vars()
                    .iter()
                    .filter(|v| v.as_str() != OMEGA && !in1.contains(v))
                {
                    let conditions = [
                        ((*x).clone(), d1.subs(OMEGA, r)),
                        (y.clone(), d2.subs(OMEGA, r)),
                    ];
                    let Some((solved, n)) = wall_numerator(
                        &self.num,
                        &BTreeMap::new(),
                        &conditions,
                        std::slice::from_ref(r),
                    ) else {
                        continue;
                    };
                    let n = poly::primitive_part_in(&n, OMEGA);
                    let dn = n.derivative(OMEGA);
                    let open: Vec<String> = self
                        .params
                        .iter()
                        .filter(|p| solved.iter().all(|(v, _, _)| v != *p))
                        .cloned()
                        .collect();
                    for vars in linear_sets(&[&n], &open, 2) {
                        let fixed: BTreeMap<String, Rat> = open
                            .iter()
                            .filter(|p| !vars.contains(p))
                            .map(|p| (p.clone(), w[p].clone()))
                            .collect();
                        for frac in MERGE_FRACTIONS {
                            let Some(sigma) = short_rational((lo + frac * (hi - lo)).exp(), 4)
                            else {
                                continue;
                            };
                            let equations: Vec<Poly> = [&n, &dn]
                                .iter()
                                .map(|e| {
                                    fixed
                                        .iter()
                                        .fold(e.subs(OMEGA, &sigma), |e, (p, v)| e.subs(p, v))
                                })
                                .collect();
                            let Some(values) = solve_linear(&equations, &vars) else {
                                continue;
                            };
                            if values.iter().any(|v| v.signum() <= 0) {
                                continue;
                            }
                            let mut point = fixed.clone();
                            point.extend(vars.iter().cloned().zip(values));
                            if let Some(point) = with_solved(point, &solved) {
                                self.record(point);
                                if self.witnesses.contains_key(t) {
                                    return;
                                }
                            }
                        }
                    }
                    // No linear set: the cancelled root itself as the
                    // unknown (see `tangent_points`), one parameter freed.
                    let dnum = self.num.derivative(OMEGA);
                    let conditions = [((*x).clone(), d1.clone()), (y.clone(), d2.clone())];
                    for free in &open {
                        let fixed: BTreeMap<String, Rat> = open
                            .iter()
                            .filter(|p| *p != free)
                            .map(|p| (p.clone(), w[p].clone()))
                            .collect();
                        for frac in MERGE_FRACTIONS {
                            let Some(sigma) = short_rational((lo + frac * (hi - lo)).exp(), 4)
                            else {
                                continue;
                            };
                            for point in
                                tangent_points(&self.num, &dnum, &fixed, &conditions, free, &sigma)
                            {
                                self.record(point);
                                if self.witnesses.contains_key(t) {
                                    return;
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// Double zeros at random rational roots on the cancellation wall of
    /// `conditions`, solved exactly in the sets of two parameters the
    /// reduced numerator's primitive part is jointly linear in.
    fn wall_root_conditions(
        &mut self,
        conditions: &[(String, Poly)],
        roots: &[Rat],
        rng: &mut Sampler,
    ) {
        let Some((solved, n)) = wall_numerator(&self.num, &BTreeMap::new(), conditions, roots)
        else {
            return;
        };
        let n = poly::primitive_part_in(&n, OMEGA);
        if n.degree(OMEGA) < 2 {
            return;
        }
        let open: Vec<String> = self
            .params
            .iter()
            .filter(|p| solved.iter().all(|(v, _, _)| v != *p))
            .cloned()
            .collect();
        let sets = linear_sets(&[&n], &open, 2);
        if sets.is_empty() {
            return;
        }
        let dn = n.derivative(OMEGA);
        for draw in 0..WALL_ROOT_DRAWS {
            let vars = &sets[rng.index(sets.len())];
            let fixed: BTreeMap<String, Rat> = open
                .iter()
                .filter(|p| !vars.contains(p))
                .map(|p| (p.clone(), rng.value()))
                .collect();
            // Every other root near the cancelled one: a double zero next
            // to a pole is where the terms' residues leave room for it.
            let sigma = if draw % 2 == 0 {
                rng.value()
            } else {
                &roots[0] * &Rat::new(Int::from(1 + rng.index(15) as i64), Int::from(8))
            };
            let equations: Vec<Poly> = [&n, &dn]
                .iter()
                .map(|e| {
                    fixed
                        .iter()
                        .fold(e.subs(OMEGA, &sigma), |e, (p, v)| e.subs(p, v))
                })
                .collect();
            let Some(values) = solve_linear(&equations, vars) else {
                continue;
            };
            if values.iter().any(|v| v.signum() <= 0) {
                continue;
            }
            let mut point = fixed;
            point.extend(vars.iter().cloned().zip(values));
            if let Some(point) = with_solved(point, &solved) {
                self.record(point);
            }
        }
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
        let mut equations: Vec<Poly> = Vec::new();
        for r in cancel {
            equations.push(self.num.subs(OMEGA, r));
            equations.push(self.den.subs(OMEGA, r));
        }
        for (r, k) in multiple {
            equations.extend(derivatives[..*k as usize].iter().map(|d| d.subs(OMEGA, r)));
        }
        let equations: Vec<Poly> = equations
            .into_iter()
            .map(|e| fixed.iter().fold(e, |e, (p, v)| e.subs(p, v)))
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
    fn accept(&mut self, t: &FrfType, params: &[String], x: &[f64]) -> bool {
        for digits in [2, 3, 4, 6, 9] {
            let point: Option<BTreeMap<String, Rat>> = params
                .iter()
                .zip(x)
                .map(|(p, v)| Some((p.clone(), short_rational(*v, digits)?)))
                .collect();
            let Some(point) = point else { return false };
            if self.type_at(&point).as_ref() == Some(t) {
                self.witnesses.insert(t.clone(), point);
                return true;
            }
        }
        false
    }
}

/// A cancellation mechanism: (first determinant, the masses it may be
/// solved for; second determinant, its masses).
type Mechanism = (Poly, Vec<usize>, Poly, Vec<usize>);

/// Trials of the discriminant search per model; each with a cancellation
/// also poses root conditions on its wall, `WALL_ROOT_DRAWS` times.
const DISCRIMINANT_TRIALS: usize = 300;
const WALL_ROOT_DRAWS: usize = 40;

/// `e`, of degree at most one in `var`, with `var = p/q` substituted and
/// the denominator cleared: `q e(0) + p de/dvar`.
fn clear_into(e: &Poly, var: &str, p: &Poly, q: &Poly) -> Option<Poly> {
    match e.degree(var) {
        0 => Some(e.clone()),
        1 => Some(&(q * &e.subs(var, &Rat::ZERO)) + &(p * &e.derivative(var))),
        _ => None,
    }
}

/// A solved parameter: (name, numerator, denominator), a rational
/// function of the parameters left free.
type Solved = (String, Poly, Poly);

/// The numerator on a cancellation wall: with `fixed` substituted, each
/// condition (of degree one in its parameter) solved in turn as a rational
/// function of the parameters left, the numerator cleared of their
/// denominators and divided by `Omega - r` for each cancelled root `r`.
fn wall_numerator(
    num: &Poly,
    fixed: &BTreeMap<String, Rat>,
    conditions: &[(String, Poly)],
    roots: &[Rat],
) -> Option<(Vec<Solved>, Poly)> {
    let at_fixed = |e: &Poly| fixed.iter().fold(e.clone(), |e, (p, v)| e.subs(p, v));
    let mut solved: Vec<Solved> = Vec::new();
    for (var, eq) in conditions {
        let mut e = at_fixed(eq);
        for (name, p, q) in &solved {
            e = clear_into(&e, name, p, q)?;
        }
        if e.degree(var) != 1 {
            return None;
        }
        let alpha = e.derivative(var);
        let beta = e.subs(var, &Rat::ZERO);
        solved.push((var.clone(), -beta, alpha));
    }
    let mut n = at_fixed(num);
    for (name, p, q) in &solved {
        n = clear_into(&n, name, p, q)?;
    }
    let om = Poly::var(OMEGA);
    for r in roots {
        n = n.div_exact(&(&om - &Poly::constant(r.clone())))?;
    }
    Some((solved, n))
}

/// Completes `point` with the solved parameters, in order; `None` unless
/// each is defined and positive.
fn with_solved(
    mut point: BTreeMap<String, Rat>,
    solved: &[Solved],
) -> Option<BTreeMap<String, Rat>> {
    for (name, p, q) in solved {
        let at = |f: &Poly| {
            point
                .iter()
                .fold(f.clone(), |f, (k, v)| f.subs(k, v))
                .as_constant()
        };
        let (a, b) = (at(p)?, at(q)?);
        if b.signum() == 0 || (a.clone() / b.clone()).signum() <= 0 {
            return None;
        }
        point.insert(name.clone(), a / b);
    }
    Some(point)
}

/// The points of the one-parameter family of [`Prover::discriminant_search`]
/// where the reduced numerator has a multiple root: `fixed` holds every
/// parameter but `z` and the solved ones; each condition, of degree one in
/// its parameter, is solved in turn (a rational function of `z`), and the
/// numerator, cleared of denominators and divided by `Omega - r` for each
/// cancelled root, has a discriminant in `Omega` whose linear factors in
/// `z` give the points (every parameter positive).
fn double_zero_points(
    num: &Poly,
    fixed: &BTreeMap<String, Rat>,
    conditions: &[(String, Poly)],
    roots: &[Rat],
    z: &str,
) -> Option<Vec<BTreeMap<String, Rat>>> {
    let (solved, n) = wall_numerator(num, fixed, conditions, roots)?;
    if n.degree(OMEGA) < 2 {
        return None;
    }
    let d = poly::discriminant(&n, OMEGA);
    if d.is_zero() || d.vars().iter().any(|v| v != z) {
        return None;
    }
    let mut points = Vec::new();
    for (g, _) in poly::factor(&d).factors {
        if g.degree(z) != 1 {
            continue;
        }
        let value = -(g.subs(z, &Rat::ZERO).as_constant()? / g.derivative(z).as_constant()?);
        if value.signum() <= 0 {
            continue;
        }
        let mut point = fixed.clone();
        point.insert(z.to_string(), value);
        points.extend(with_solved(point, &solved));
    }
    Some(points)
}

/// Trials of each elimination (tangent and triple) per model.
const ELIMINATION_TRIALS: usize = 2000;

/// The positive rational roots of `p`, a polynomial in `var` alone: from
/// its linear factors.
fn rational_roots(p: &Poly, var: &str) -> Vec<Rat> {
    if p.is_zero() || p.vars().iter().any(|v| v != var) {
        return Vec::new();
    }
    poly::factor(p)
        .factors
        .iter()
        .filter(|(g, _)| g.degree(var) == 1)
        .filter_map(|(g, _)| {
            let v = -(g.subs(var, &Rat::ZERO).as_constant()? / g.derivative(var).as_constant()?);
            (v.signum() > 0).then_some(v)
        })
        .collect()
}

/// Points of [`Prover::elimination_search`] with a double zero at `sigma`
/// and a pole cancelled at a rational `r`: `conditions` are the wall's
/// determinants (in `Omega`, which stands for `r`), each solved for its
/// parameter; `w` is the one other free parameter.
fn tangent_points(
    num: &Poly,
    dnum: &Poly,
    fixed: &BTreeMap<String, Rat>,
    conditions: &[(String, Poly)],
    w: &str,
    sigma: &Rat,
) -> Vec<BTreeMap<String, Rat>> {
    let at_fixed = |e: &Poly| fixed.iter().fold(e.clone(), |e, (p, v)| e.subs(p, v));
    let mut solved: Vec<Solved> = Vec::new();
    for (var, eq) in conditions {
        let mut e = at_fixed(eq);
        for (name, p, q) in &solved {
            let Some(c) = clear_into(&e, name, p, q) else {
                return Vec::new();
            };
            e = c;
        }
        if e.degree(var) != 1 {
            return Vec::new();
        }
        solved.push((var.clone(), -e.subs(var, &Rat::ZERO), e.derivative(var)));
    }
    // num(sigma) and num'(sigma), in r (as Omega) and w.
    let mut eqs = Vec::new();
    for f in [num, dnum] {
        let mut e = at_fixed(&f.subs(OMEGA, sigma));
        for (name, p, q) in &solved {
            let Some(c) = clear_into(&e, name, p, q) else {
                return Vec::new();
            };
            e = c;
        }
        eqs.push(e);
    }
    let res = poly::resultant(&eqs[0], &eqs[1], w);
    let mut points = Vec::new();
    for r in rational_roots(&res, OMEGA) {
        if &r == sigma {
            continue;
        }
        let e = eqs[0].subs(OMEGA, &r);
        for wv in rational_roots(&e, w) {
            if !eqs[1].subs(OMEGA, &r).subs(w, &wv).is_zero() {
                continue;
            }
            let mut point = fixed.clone();
            point.insert(w.to_string(), wv);
            // The solved parameters are rational in r too: evaluate there.
            let solved_at: Vec<Solved> = solved
                .iter()
                .map(|(n, p, q)| (n.clone(), p.subs(OMEGA, &r), q.subs(OMEGA, &r)))
                .collect();
            points.extend(with_solved(point, &solved_at));
        }
    }
    points
}

/// Points of [`Prover::elimination_search`] with a triple zero: `eqs` are
/// the numerator and its first two derivatives at the root, linear in the
/// two `vars` (solved from the first two by Cramer's rule, rational in
/// `z`), the third's linear factors in `z` give `z`.
fn triple_points(
    eqs: &[Poly],
    vars: &[String],
    z: &str,
    fixed: &BTreeMap<String, Rat>,
) -> Vec<BTreeMap<String, Rat>> {
    let (a, b) = (&vars[0], &vars[1]);
    // e = c0 + ca a + cb b, the coefficients polynomials in z.
    let split = |e: &Poly| -> Option<(Poly, Poly, Poly)> {
        if e.degree(a) > 1 || e.degree(b) > 1 {
            return None;
        }
        let ca = e.derivative(a);
        let cb = e.derivative(b);
        if ca.degree(b) > 0 || cb.degree(a) > 0 {
            return None;
        }
        Some((e.subs(a, &Rat::ZERO).subs(b, &Rat::ZERO), ca, cb))
    };
    let parts: Option<Vec<(Poly, Poly, Poly)>> = eqs.iter().map(split).collect();
    let Some(parts) = parts else {
        return Vec::new();
    };
    let (e1, e2, e3) = (&parts[0], &parts[1], &parts[2]);
    let det = &(&e1.1 * &e2.2) - &(&e1.2 * &e2.1);
    // a = (-c0_1 cb_2 + c0_2 cb_1) / det, b = (-ca_1 c0_2 + ca_2 c0_1) / det.
    let na = &(&e2.0 * &e1.2) - &(&e1.0 * &e2.2);
    let nb = &(&e2.1 * &e1.0) - &(&e1.1 * &e2.0);
    let third = &(&(&e3.0 * &det) + &(&e3.1 * &na)) + &(&e3.2 * &nb);
    let mut points = Vec::new();
    for zv in rational_roots(&third, z) {
        let d = det.subs(z, &zv).as_constant();
        let (Some(d), Some(va), Some(vb)) = (
            d,
            na.subs(z, &zv).as_constant(),
            nb.subs(z, &zv).as_constant(),
        ) else {
            continue;
        };
        if d.signum() == 0 {
            continue;
        }
        let (va, vb) = (va / d.clone(), vb / d);
        if va.signum() <= 0 || vb.signum() <= 0 {
            continue;
        }
        let mut point = fixed.clone();
        point.insert(z.to_string(), zv);
        point.insert(a.clone(), va);
        point.insert(b.clone(), vb);
        points.push(point);
    }
    points
}

/// `t` with every multiple token split into simple ones (`AA` for `A^2`).
fn split_type(t: &FrfType) -> FrfType {
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
fn multiple_antiresonances(t: &FrfType) -> Vec<u32> {
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
const MERGE_FRACTIONS: [f64; 5] = [0.5, 0.25, 0.75, 0.1, 0.9];
/// Parameter sets tried per merged root, at most.
const MERGE_SETS: usize = 24;
/// Trials per root-coincidence signature in the root-condition search.
const ROOT_TRIALS: usize = 2000;
/// Candidate parameter sets kept for the root-condition search, at most.
const MAX_LINEAR_SETS: usize = 64;

/// Sets of `size` parameters each of degree at most one in every `polys`
/// and no two of them in one monomial: the polys are jointly linear in
/// them (the first `MAX_LINEAR_SETS` in lexicographic order).
fn linear_sets(polys: &[&Poly], params: &[String], size: usize) -> Vec<Vec<String>> {
    let single: Vec<&String> = params
        .iter()
        .filter(|x| polys.iter().all(|p| p.degree(x) <= 1))
        .collect();
    let apart = |x: &String, y: &String| {
        polys.iter().all(|p| {
            let c = p.coeffs_in(x);
            c.len() < 2 || c[1].degree(y) == 0
        })
    };
    let mut out = Vec::new();
    let mut cur: Vec<usize> = Vec::new();
    fn grow(
        from: usize,
        size: usize,
        single: &[&String],
        apart: &dyn Fn(&String, &String) -> bool,
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
            if cur.iter().all(|&j| apart(single[j], single[i])) {
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
fn solve_linear(equations: &[Poly], vars: &[String]) -> Option<Vec<Rat>> {
    let n = vars.len();
    if equations.len() != n {
        return None;
    }
    // Rows [a_1 .. a_n | -b] of a.x + b = 0.
    let mut rows: Vec<Vec<Rat>> = Vec::with_capacity(n);
    for e in equations {
        let mut row = Vec::with_capacity(n + 1);
        let mut rest = e.clone();
        for x in vars {
            let c = rest.coeffs_in(x);
            row.push(c.get(1).map_or(Some(Rat::ZERO), |a| a.as_constant())?);
            rest = c.first().cloned().unwrap_or_else(Poly::zero);
        }
        row.push(-rest.as_constant()?);
        rows.push(row);
    }
    for col in 0..n {
        let pivot = (col..n).find(|&r| !rows[r][col].is_zero())?;
        rows.swap(col, pivot);
        let inv = rows[col][col].recip();
        for v in rows[col].iter_mut() {
            *v = &*v * &inv;
        }
        let pivot_row = rows[col].clone();
        for (r, row) in rows.iter_mut().enumerate() {
            if r != col && !row[col].is_zero() {
                let f = row[col].clone();
                for (x, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                    let d = &f * p;
                    *x = &*x - &d;
                }
            }
        }
    }
    Some(rows.into_iter().map(|r| r[n].clone()).collect())
}

/// Samples per partial wall.
const PARTIAL_WALL_SAMPLES: usize = 40;
/// Partial-wall strata built per model at most.
const PARTIAL_WALL_BUDGET: usize = 40;
/// Terms of `alpha` and `beta` together, at most, for a partial wall.
const PARTIAL_WALL_TERMS: usize = 24;
/// Terms of the substituted numerator and denominator together, at most
/// (up to seven parameters; five eighths of it beyond).
const PARTIAL_WALL_TF_TERMS: usize = 400;

/// `f = alpha*x - beta` for the parameter `x` of degree one with the
/// smallest `alpha` and `beta` (any signs).
fn linear_solution(f: &Poly, vars: &[String]) -> Option<Substitution> {
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
    fn rational_roots_come_from_linear_factors() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        // (2z - 3)(z^2 + 1)(z + 5): only 3/2 is rational and positive.
        let f = p("(2*z - 3)*(z^2 + 1)*(z + 5)");
        assert_eq!(rational_roots(&f, "z"), vec![Rat::new(3.into(), 2.into())]);
        // Another variable left: none.
        assert!(rational_roots(&p("z - y"), "z").is_empty());
    }

    #[test]
    fn triple_roots_by_elimination() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        // Omega^3 - a Omega^2 + b Omega - z has the triple root 2 exactly
        // for (Omega - 2)^3: a = 6, b = 12, z = 8.
        let num = p("Omega^3 - a*Omega^2 + b*Omega - z");
        let two = Rat::from(2);
        let d1 = num.derivative(OMEGA);
        let d2 = d1.derivative(OMEGA);
        let eqs: Vec<Poly> = [&num, &d1, &d2]
            .iter()
            .map(|e| e.subs(OMEGA, &two))
            .collect();
        let vars = ["a".to_string(), "b".to_string()];
        let points = triple_points(&eqs, &vars, "z", &BTreeMap::new());
        assert_eq!(points.len(), 1);
        let want: BTreeMap<String, Rat> = [("a", 6), ("b", 12), ("z", 8)]
            .iter()
            .map(|(k, v)| (k.to_string(), Rat::from(*v)))
            .collect();
        assert_eq!(points[0], want);
    }

    #[test]
    fn tangent_points_solve_for_the_cancelled_root() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        // num = (Omega - x)(Omega^2 - 2 w Omega + y) on the wall x = r,
        // y = 2r: the quadratic has the double root sigma = w exactly when
        // w^2 = 2r, so for sigma = 3: r = 9/2, x = 9/2, y = 9, w = 3.
        let num = p("(Omega - x)*(Omega^2 - 2*w*Omega + y)");
        let dnum = num.derivative(OMEGA);
        let conditions = [
            ("x".to_string(), p("x - Omega")),
            ("y".to_string(), p("y - 2*Omega")),
        ];
        let points = tangent_points(
            &num,
            &dnum,
            &BTreeMap::new(),
            &conditions,
            "w",
            &Rat::from(3),
        );
        let want: BTreeMap<String, Rat> = [("w", "3"), ("x", "9/2"), ("y", "9")]
            .iter()
            .map(|(k, v)| (k.to_string(), v.parse().unwrap()))
            .collect();
        assert_eq!(points, vec![want]);
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

    #[test]
    fn short_rationals() {
        assert_eq!(
            short_rational(0.012345, 3).unwrap(),
            "123/10000".parse().unwrap()
        );
        assert_eq!(short_rational(98765.0, 2).unwrap(), Rat::from(99000));
    }
}
