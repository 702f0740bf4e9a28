//! Witnesses with multiple zeros on cancellation walls.
//!
//! A double zero that must come with a cancelled pole lives on the
//! intersection of two varieties, and where its root conditions are not
//! linear in any set of parameters the root conditions of
//! [`super::targeted`] cannot build it; nor can the double root be put
//! anywhere (on the wall `c1/m1 = mu1` of N4-g1-a2.1-s4.1 the reduced
//! numerator is `Omega (Omega - mu2) + a`, whose double root must be
//! `mu2/2`). A wall here is a cancellation mechanism (two determinants
//! vanishing at one `r`, [`Prover::cancellation_mechanisms`]) with a
//! parameter solved from each: every determinant is of degree one in each
//! parameter (a mass or a spring enters the pencil as a rank-one term), so
//! the solved parameters are rational functions of the others.
//!
//! Four constructions, each exact, each hit re-classified by
//! [`Prover::record`]:
//!
//! 1. the **discriminant** of the reduced numerator on a one-parameter
//!    family, whose linear factors give rational points;
//! 2. the **wall's root conditions**: the reduced numerator's primitive
//!    part (a factor such as `m3 m4` dropped) is often linear in two
//!    parameters where the numerator is not;
//! 3. **elimination** with the cancelled root itself unknown (and, for a
//!    triple zero without cancellation, one parameter beyond a linear set);
//! 4. the **merge on the wall** from a witness of the split type.

use super::frf_type::{Feature, FrfType};
use super::prover::{Prover, Sampler};
use super::targeted::{
    linear_sets, multiple_antiresonances, short_rational, solve_linear, split_type, tf_roots,
    Mechanism, MERGE_FRACTIONS,
};
use crate::tf::{UndampedCoefficients, OMEGA};
use poly::{Int, Poly, Rat, UPoly};
use std::collections::{BTreeMap, BTreeSet};

/// Trials of the discriminant search per model; each with a cancellation
/// also poses root conditions on its wall, `WALL_ROOT_DRAWS` times.
const DISCRIMINANT_TRIALS: usize = 300;
const WALL_ROOT_DRAWS: usize = 40;
/// Trials of each elimination (tangent and triple) per model.
const ELIMINATION_TRIALS: usize = 2000;

/// A solved parameter: (name, numerator, denominator), a rational
/// function of the parameters left free.
type Solved = (String, Poly, Poly);

/// The parameters a wall may be solved for: any of the first
/// determinant's, then one of the second's the first does not contain (so
/// the first is solved independently of it); none in `used`.
pub(super) fn wall_parameters(d1: &Poly, d2: &Poly, used: &[String]) -> (Vec<String>, Vec<String>) {
    let in1 = d1.vars();
    let first = in1
        .iter()
        .filter(|v| v.as_str() != OMEGA && !used.contains(v))
        .cloned()
        .collect();
    let second = d2
        .vars()
        .iter()
        .filter(|v| v.as_str() != OMEGA && !in1.contains(v) && !used.contains(v))
        .cloned()
        .collect();
    (first, second)
}

impl Prover<'_> {
    /// The parameters not among `solved`, in order.
    fn unsolved(&self, solved: &[Solved]) -> Vec<String> {
        self.params
            .iter()
            .filter(|p| solved.iter().all(|(v, _, _)| v != *p))
            .cloned()
            .collect()
    }

    /// How many of `wanted` have witnesses.
    pub(super) fn witnessed(&self, wanted: &[FrfType]) -> usize {
        wanted
            .iter()
            .filter(|t| self.witnesses.contains_key(t))
            .count()
    }

    /// Double antiresonances on a one-parameter family: pose the
    /// cancellations at rational roots `r`, keep one other parameter `z`
    /// free and the rest at random values; the solved parameters are
    /// rational functions of `z`, the reduced numerator a polynomial in
    /// `Omega` and `z`, and its discriminant in `Omega` a polynomial in `z`
    /// whose linear factors give exact points with a double zero. Each
    /// trial with a cancellation also poses the double root's conditions
    /// on its wall ([`Self::wall_root_conditions`]); first, every wanted
    /// type with one cancelled pole is merged from its split witness
    /// ([`Self::wall_merge`]). Returns how many of `wanted` have witnesses
    /// afterwards.
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
                let (free1, free2) = wall_parameters(d1, d2, &used);
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
            let (z, fixed) = one_free(&open, &mut rng);
            let wall = wall_numerator(&self.num, &fixed, &conditions, &roots);
            if let Some(points) = wall.and_then(|w| double_zero_points(w, &fixed, &z)) {
                for point in points {
                    self.record(point);
                }
            }
            // The same wall with every other parameter free.
            if cancelled > 0 {
                self.wall_root_conditions(&conditions, &roots, &mut rng);
            }
        }
        self.witnessed(wanted)
    }

    /// Multiple zeros by elimination, where no set of parameters makes all
    /// the root conditions linear.
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
                let (in1, in2) = wall_parameters(d1, d2, &[]);
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
                let (w, fixed) = one_free(&open, &mut rng);
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
                let (z, fixed) = one_free(&open, &mut rng);
                let sigma = rng.value();
                let eqs: Vec<Poly> = [&self.num, &dn, &ddn]
                    .iter()
                    .map(|e| at_omega(e, &sigma, &fixed))
                    .collect();
                for point in triple_points(&eqs, vars, &z, &fixed) {
                    self.record(point);
                }
            }
        }
        self.witnessed(wanted)
    }

    /// A double zero next to a cancelled pole, merged from a witness of
    /// the split type on the same wall: its cancelled root `r` (a rational
    /// common root of its numerator and denominator), every mechanism whose
    /// two determinants vanish there, the double root placed between the
    /// two zeros to merge and solved in a linear set of the wall's reduced
    /// numerator (or, with none, by [`tangent_points`] with `r` unknown),
    /// every other parameter kept. Where the double zero needs a thin
    /// region (N4-g2-a3.1-s4.1 `A^2RR`: the spring-mass impedance's pole
    /// just above the cancelled one), the split witness is already in it.
    fn wall_merge(&mut self, t: &FrfType, mechanisms: &[Mechanism]) {
        let Some(w) = self.witnesses.get(&split_type(t)).cloned() else {
            return;
        };
        let common = poly::gcd(&at(&self.num, &w), &at(&self.den, &w));
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
        let sigmas: Vec<Rat> = MERGE_FRACTIONS
            .iter()
            .filter_map(|f| short_rational((lo + f * (hi - lo)).exp(), 4))
            .collect();
        let dnum = self.num.derivative(OMEGA);
        for (d1, _, d2, _) in mechanisms {
            let vanishes = |d: &Poly| at_omega(d, r, &w).is_zero();
            if !(vanishes(d1) && vanishes(d2)) {
                continue;
            }
            let (in1, in2) = wall_parameters(d1, d2, &[]);
            for x in &in1 {
                for y in &in2 {
                    let conditions = [
                        (x.clone(), d1.subs(OMEGA, r)),
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
                    let open = self.unsolved(&solved);
                    let kept = |skip: &dyn Fn(&String) -> bool| -> BTreeMap<String, Rat> {
                        open.iter()
                            .filter(|p| !skip(p))
                            .map(|p| (p.clone(), w[p].clone()))
                            .collect()
                    };
                    for vars in linear_sets(&[&n], &open, 2) {
                        let fixed = kept(&|p| vars.contains(p));
                        for sigma in &sigmas {
                            if self.solve_double_root([&n, &dn], &fixed, &vars, sigma, &solved)
                                && self.witnesses.contains_key(t)
                            {
                                return;
                            }
                        }
                    }
                    // No linear set: the cancelled root itself as the
                    // unknown, one parameter freed.
                    let conditions = [(x.clone(), d1.clone()), (y.clone(), d2.clone())];
                    for free in &open {
                        let fixed = kept(&|p| p == free);
                        for sigma in &sigmas {
                            for point in
                                tangent_points(&self.num, &dnum, &fixed, &conditions, free, sigma)
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
    /// reduced numerator's primitive part is jointly linear in (often
    /// there where the numerator is not: a factor free of `Omega`, such as
    /// `m3 m4`, dropped).
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
        let open = self.unsolved(&solved);
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
            self.solve_double_root([&n, &dn], &fixed, vars, &sigma, &solved);
        }
    }

    /// Solves `n(sigma) = n'(sigma) = 0` in `vars` with `fixed` elsewhere,
    /// completes the point with the `solved` parameters and records it if
    /// every value is positive; whether it recorded one.
    fn solve_double_root(
        &mut self,
        n_and_derivative: [&Poly; 2],
        fixed: &BTreeMap<String, Rat>,
        vars: &[String],
        sigma: &Rat,
        solved: &[Solved],
    ) -> bool {
        let equations: Vec<Poly> = n_and_derivative
            .iter()
            .map(|e| at_omega(e, sigma, fixed))
            .collect();
        let Some(values) = solve_linear(&equations, vars) else {
            return false;
        };
        if values.iter().any(|v| v.signum() <= 0) {
            return false;
        }
        let mut point = fixed.clone();
        point.extend(vars.iter().cloned().zip(values));
        match with_solved(point, solved) {
            Some(point) => {
                self.record(point);
                true
            }
            None => false,
        }
    }
}

/// One of `open` left free (drawn first), random values for the others,
/// in order.
fn one_free(open: &[&String], rng: &mut Sampler) -> (String, BTreeMap<String, Rat>) {
    let free = open[rng.index(open.len())].clone();
    let fixed = open
        .iter()
        .filter(|p| ***p != free)
        .map(|p| ((*p).clone(), rng.value()))
        .collect();
    (free, fixed)
}

/// `e` with the values of `point` substituted.
fn at(e: &Poly, point: &BTreeMap<String, Rat>) -> Poly {
    e.subs_point(point)
}

/// [`at`] with `Omega = omega` substituted too.
fn at_omega(e: &Poly, omega: &Rat, point: &BTreeMap<String, Rat>) -> Poly {
    let mut point = point.clone();
    point.insert(OMEGA.to_string(), omega.clone());
    e.subs_point(&point)
}

/// `e`, of degree at most one in `var`, with `var = p/q` substituted and
/// the denominator cleared: `q e(0) + p de/dvar`.
fn clear_into(e: &Poly, var: &str, p: &Poly, q: &Poly) -> Option<Poly> {
    match e.degree(var) {
        0 => Some(e.clone()),
        1 => Some(&(q * &e.subs(var, &Rat::ZERO)) + &(p * &e.derivative(var))),
        _ => None,
    }
}

/// `e` with every solved parameter substituted, denominators cleared.
fn clear_all(e: &Poly, solved: &[Solved]) -> Option<Poly> {
    solved
        .iter()
        .try_fold(e.clone(), |e, (name, p, q)| clear_into(&e, name, p, q))
}

/// Each condition (of degree one in its parameter, after the earlier ones
/// are substituted) solved in turn, with `fixed` substituted first.
pub(super) fn solve_in_turn(
    fixed: &BTreeMap<String, Rat>,
    conditions: &[(String, Poly)],
) -> Option<Vec<Solved>> {
    let mut solved: Vec<Solved> = Vec::new();
    for (var, eq) in conditions {
        let e = clear_all(&at(eq, fixed), &solved)?;
        if e.degree(var) != 1 {
            return None;
        }
        solved.push((var.clone(), -e.subs(var, &Rat::ZERO), e.derivative(var)));
    }
    Some(solved)
}

/// The numerator on a cancellation wall: with `fixed` substituted, the
/// conditions solved in turn ([`solve_in_turn`]), the numerator cleared of
/// their denominators and divided by `Omega - r` for each cancelled root
/// `r`.
fn wall_numerator(
    num: &Poly,
    fixed: &BTreeMap<String, Rat>,
    conditions: &[(String, Poly)],
    roots: &[Rat],
) -> Option<(Vec<Solved>, Poly)> {
    let solved = solve_in_turn(fixed, conditions)?;
    let mut n = clear_all(&at(num, fixed), &solved)?;
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
        let (a, b) = (at(p, &point).as_constant()?, at(q, &point).as_constant()?);
        if b.signum() == 0 || (a.clone() / b.clone()).signum() <= 0 {
            return None;
        }
        point.insert(name.clone(), a / b);
    }
    Some(point)
}

/// The points of the one-parameter family of [`Prover::discriminant_search`]
/// where the reduced numerator has a multiple root: `fixed` holds every
/// parameter but `z` and the solved ones (`wall`, from [`wall_numerator`]);
/// the discriminant in `Omega` of the wall's numerator has linear factors
/// in `z` that give the points (every parameter positive).
fn double_zero_points(
    (solved, n): (Vec<Solved>, Poly),
    fixed: &BTreeMap<String, Rat>,
    z: &str,
) -> Option<Vec<BTreeMap<String, Rat>>> {
    if n.degree(OMEGA) < 2 {
        return None;
    }
    let d = poly::discriminant(&n, OMEGA);
    let mut points = Vec::new();
    for value in rational_roots(&d, z) {
        let mut point = fixed.clone();
        point.insert(z.to_string(), value);
        points.extend(with_solved(point, &solved));
    }
    Some(points)
}

/// The positive rational roots of `p`, a polynomial in `var` alone, in
/// increasing order.
fn rational_roots(p: &Poly, var: &str) -> Vec<Rat> {
    let Some((_, u)) = UPoly::from_poly(p, var) else {
        return Vec::new();
    };
    poly::rational_roots(&u)
        .into_iter()
        .filter(|r| r.signum() > 0)
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
    let Some(solved) = solve_in_turn(fixed, conditions) else {
        return Vec::new();
    };
    // num(sigma) and num'(sigma), in r (as Omega) and w.
    let eqs: Option<Vec<Poly>> = [num, dnum]
        .iter()
        .map(|f| clear_all(&at_omega(f, sigma, fixed), &solved))
        .collect();
    let Some(eqs) = eqs else {
        return Vec::new();
    };
    // Only its roots are used: the primitive parts' resultant spares
    // rescaling the whole polynomial by the contents' powers.
    let res = poly::resultant(&eqs[0].primitive_part(), &eqs[1].primitive_part(), w);
    let mut points = Vec::new();
    for r in rational_roots(&res, OMEGA) {
        if &r == sigma {
            continue;
        }
        for wv in rational_roots(&eqs[0].subs(OMEGA, &r), w) {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
