//! Witnesses at algebraic points.
//!
//! A type with `c` root coincidences (cancelled poles, multiple zeros)
//! lives on a variety of codimension `c`. With its roots at rational
//! places, the conditions are polynomial in the parameters and linear in
//! any set no two of which share a monomial; where such a set has `c`
//! members, the root-condition searches solve it over Q. Where the
//! largest has `c - 1` or `c - 2`, the one or two parameters short of it
//! (`x`, `y`) are eliminated instead: the conditions are consistent where
//! the augmented matrix of the linear set drops rank, a polynomial in `x`
//! (one short) or two whose resultant in `y` is one (two short). Their
//! positive real roots are seldom rational; each one, isolated exactly,
//! is the generator `theta` of a real number field, over which `y` and
//! the linear set are solved exactly and the type is read by exact signs
//! ([`super::frf_type_at_algebraic`]). The point is the witness
//! ([`super::AlgebraicWitness`]).

use super::frf_type::FrfType;
use super::frf_type::{Feature, Token};
use super::prover::{Prover, Sampler};
use super::targeted::{
    integer_row, linear_sets, positive_roots, root_signature, short_rational, solve_linear,
    tf_roots, Mechanism,
};
use super::AlgebraicWitness;
use crate::tf::{UndampedCoefficients, OMEGA};
use poly::{FieldElem, FieldPoly, Poly, Rat, RealField, UPoly};
use std::collections::BTreeMap;

/// Fields of higher degree than this are not tried: their arithmetic
/// grows with the square of the degree, and a root of such a factor is
/// met again at another draw of lower degree. Two short, a draw whose
/// resultant may exceed it in `x` (Bezout's bound from the two minors) is
/// not eliminated either: its fields would be of about that degree, and
/// its cost grows faster still.
const MAX_FIELD_DEGREE: usize = 16;
/// Random draws (linear set, parameters short of it, their fixed values,
/// roots) per root signature and number of parameters short.
const ALGEBRAIC_TRIALS: usize = 60;

/// Linear sets tried per number short in the parent pass, at most.
const PARENT_SETS: usize = 3;
/// Draws of the parameters short of a set, per parent and set.
const PARENT_SHORTS: usize = 2;
/// Solves per wanted type in the parent pass, at most.
const PARENT_TRIES: usize = 48;
/// Mechanism choices per wanted type and kind of start in the mechanisms'
/// pass, at most (each tried with every number short and the first
/// linear sets).
const MECHANISM_TRIES: usize = 64;
/// Parameters short in the mechanisms' parent pass, at most.
const MECHANISM_SHORTS: usize = 1;

/// What a wanted type's coincidences are in a parent type: for each
/// cancelled pole the indices of the zero and the pole that meet, for
/// each multiple zero the indices of its zeros (in the parent's
/// ascending positive zeros and poles).
#[derive(Clone, Debug, PartialEq, Eq)]
struct MergePlan {
    cancel: Vec<(usize, usize)>,
    multiple: Vec<(usize, u32)>,
}

impl MergePlan {
    /// The roots to pose at a parent's witness with these `zeros` and
    /// `poles`: each pair's and group's geometric mean, to four digits.
    #[allow(clippy::type_complexity)]
    fn roots(&self, zeros: &[f64], poles: &[f64]) -> Option<(Vec<Rat>, Vec<(Rat, u32)>)> {
        let cancel = self
            .cancel
            .iter()
            .map(|&(z, p)| short_rational((zeros.get(z)? * poles.get(p)?).sqrt(), 4))
            .collect::<Option<Vec<Rat>>>()?;
        let multiple = self
            .multiple
            .iter()
            .map(|&(first, k)| {
                let group = zeros.get(first..first + k as usize)?;
                let mean = group.iter().map(|z| z.ln()).sum::<f64>() / f64::from(k);
                Some((short_rational(mean.exp(), 4)?, k))
            })
            .collect::<Option<Vec<_>>>()?;
        Some((cancel, multiple))
    }
}

/// Which jointly linear sets the mechanisms' pass solves in: those
/// linear in the numerator as well as the determinants, those linear in
/// the determinants alone (not the former), or both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LinearSets {
    WithNumerator,
    DeterminantsOnly,
    Both,
}

/// A start of the mechanisms' pass: a parent's witness, its own
/// cancelled poles with the mechanism kept for each, and the roots to
/// pose from it (the new cancelled poles and multiple zeros).
struct MechanismStart {
    witness: BTreeMap<String, Rat>,
    kept: Vec<(Rat, usize)>,
    fresh: Vec<Rat>,
    multiple: Vec<(Rat, u32)>,
}

/// Every choice of one of `count` mechanisms for each of `poles` poles.
fn mechanism_choices(count: usize, poles: usize) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new()];
    for _ in 0..poles {
        out = out
            .into_iter()
            .flat_map(|c| {
                (0..count).map(move |i| {
                    let mut n = c.clone();
                    n.push(i);
                    n
                })
            })
            .collect();
    }
    out
}

/// The index of the root of `roots` nearest to `r` (relatively).
fn nearest(roots: &[f64], r: f64) -> Option<usize> {
    roots
        .iter()
        .enumerate()
        .min_by(|a, b| ((a.1 - r) / r).abs().total_cmp(&((b.1 - r) / r).abs()))
        .map(|(k, _)| k)
}

/// Where the mechanisms' pass starts for `t`, from `witnesses`: each
/// parent with `fresh` cancellations fewer ([`parents`]) that has a
/// rational witness, the
/// roots to pose from it, and the parent's own cancelled poles (its
/// shared rational roots, as many as `t` has cancellations beyond
/// `fresh`), each with a mechanism whose determinants vanish there.
fn mechanism_starts(
    prover: &Prover<'_>,
    witnesses: &BTreeMap<FrfType, BTreeMap<String, Rat>>,
    t: &FrfType,
    fresh: u32,
    tf: &UndampedCoefficients,
    mechanisms: &[Mechanism],
) -> Vec<MechanismStart> {
    let Some((total, _)) = root_signature(t, prover.den.degree(OMEGA)) else {
        return Vec::new();
    };
    if fresh > total {
        return Vec::new();
    }
    let mut out = Vec::new();
    for (parent, plan) in parents(t, fresh) {
        let Some(w) = witnesses.get(&parent) else {
            continue;
        };
        let x: Vec<f64> = prover.params.iter().map(|p| w[p].to_f64()).collect();
        let Some((mut zeros, mut poles, _)) = tf_roots(tf, &x) else {
            continue;
        };
        let mut kept = Vec::new();
        if total > fresh {
            let at = |p: &Poly| UPoly::from_poly(&p.subs_point(w), OMEGA).map(|(_, u)| u);
            let (Some(n), Some(d)) = (at(&prover.num), at(&prover.den)) else {
                continue;
            };
            let shared: Vec<Rat> = poly::rational_roots(&n.gcd(&d))
                .into_iter()
                .filter(|r| r.signum() > 0)
                .collect();
            if shared.len() != (total - fresh) as usize {
                continue;
            }
            for r in shared {
                let holds = |q: &Poly| q.subs(OMEGA, &r).subs_point(w).is_zero();
                let Some(i) = mechanisms
                    .iter()
                    .position(|(d1, _, d2, _)| holds(d1) && holds(d2))
                else {
                    break;
                };
                // The kept root is not one of the parent type's tokens.
                let rf = r.to_f64();
                for roots in [&mut zeros, &mut poles] {
                    if let Some(k) = nearest(roots, rf) {
                        roots.remove(k);
                    }
                }
                kept.push((r, i));
            }
            if kept.len() != (total - fresh) as usize {
                continue;
            }
        }
        let Some((fresh_roots, multiple)) = plan.roots(&zeros, &poles) else {
            continue;
        };
        out.push(MechanismStart {
            witness: w.clone(),
            kept,
            fresh: fresh_roots,
            multiple,
        });
    }
    out
}

/// One root of a parent type in the making: a zero or a pole, plain, of
/// a multiple zero (its group), or of a cancelled pair (its pair).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Item {
    Zero(Option<usize>, Option<usize>),
    Pole(Option<usize>),
}

/// The parents of `t` with `cancelled` cancelled poles: `t` with each
/// multiple zero split into simple ones and, for each cancelled pole, a
/// zero and a pole inserted side by side (in either order, at any
/// place), each with its [`MergePlan`]; at most two cancellations.
fn parents(t: &FrfType, cancelled: u32) -> Vec<(FrfType, MergePlan)> {
    if cancelled > 2 {
        return Vec::new();
    }
    let mut base = Vec::new();
    let mut group = 0;
    for k in &t.tokens {
        match k.feature {
            Feature::Antiresonance if k.multiplicity > 1 => {
                base.extend(std::iter::repeat_n(
                    Item::Zero(Some(group), None),
                    k.multiplicity as usize,
                ));
                group += 1;
            }
            Feature::Antiresonance => base.push(Item::Zero(None, None)),
            Feature::Resonance => base.push(Item::Pole(None)),
        }
    }
    let mut seqs = vec![base];
    for pair in 0..cancelled as usize {
        let mut next = Vec::new();
        for s in &seqs {
            for at in 0..=s.len() {
                for zero_first in [true, false] {
                    let (a, b) = if zero_first {
                        (Item::Zero(None, Some(pair)), Item::Pole(Some(pair)))
                    } else {
                        (Item::Pole(Some(pair)), Item::Zero(None, Some(pair)))
                    };
                    let mut n = s.clone();
                    n.splice(at..at, [a, b]);
                    if !next.contains(&n) {
                        next.push(n);
                    }
                }
            }
        }
        seqs = next;
    }
    let mut out: Vec<(FrfType, MergePlan)> = Vec::new();
    for s in seqs {
        let mut tokens = Vec::new();
        let (mut nz, mut np) = (0, 0);
        let mut cancel = vec![(0, 0); cancelled as usize];
        let mut multiple: Vec<(usize, u32)> = Vec::new();
        for item in &s {
            match *item {
                Item::Zero(g, c) => {
                    if let Some(g) = g {
                        if multiple.len() <= g {
                            multiple.push((nz, 0));
                        }
                        multiple[g].1 += 1;
                    }
                    if let Some(c) = c {
                        cancel[c].0 = nz;
                    }
                    nz += 1;
                    tokens.push(Token {
                        feature: Feature::Antiresonance,
                        multiplicity: 1,
                    });
                }
                Item::Pole(c) => {
                    if let Some(c) = c {
                        cancel[c].1 = np;
                    }
                    np += 1;
                    tokens.push(Token {
                        feature: Feature::Resonance,
                        multiplicity: 1,
                    });
                }
            }
        }
        let parent = FrfType {
            tokens,
            nonminimum_phase: t.nonminimum_phase,
        };
        let plan = MergePlan { cancel, multiple };
        if !out.contains(&(parent.clone(), plan.clone())) {
            out.push((parent, plan));
        }
    }
    out
}

/// A point over a real number field.
pub(super) type FieldPoint = (RealField, BTreeMap<String, FieldElem>);

impl Prover<'_> {
    /// The root conditions of the unknown types of `wanted` solved over
    /// real number fields, one or two parameters short of a linear set
    /// (see the module docs), in three passes: from the parents' witnesses
    /// with cancellations posed by the chain's mechanisms, then by
    /// numerator and denominator, then at random roots and parameters.
    /// Runs after every other search, on what they leave. Returns how many
    /// of `wanted` have a witness of any kind afterwards.
    pub(crate) fn algebraic_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        self.mechanism_parent_search(wanted, seed);
        self.algebraic_parent_search(wanted, seed);
        self.algebraic_random_search(wanted, seed);
        wanted.iter().filter(|t| self.shown(t)).count()
    }

    /// The first pass of [`Self::algebraic_search`], for types with one to
    /// three cancelled poles: as the second, but each cancellation posed by a
    /// mechanism of the chain ([`Self::cancellation_mechanisms`]: a run's
    /// determinant and its block's, or two blocks') at the pole instead of
    /// by numerator and denominator. The determinants of sub-chains share
    /// few monomials, so with the multiple zeros' conditions they are
    /// jointly linear in more parameters than the denominator allows: at
    /// times in all of them (solved over Q), else one short (a field of
    /// degree at most the eliminant's). It runs first: its points are
    /// cheap, and each type it shows spares the other two passes. Two
    /// parameters short showed 3 more types at 5 masses for a third more
    /// time, so the pass stops at one.
    fn mechanism_parent_search(&mut self, wanted: &[FrfType], seed: u64) {
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let mechanisms = self.cancellation_mechanisms();
        if mechanisms.is_empty() {
            return;
        }
        let tf = UndampedCoefficients::new(self.model);
        let params = self.params.clone();
        let num = self.num.clone();
        let mut rng = Sampler::new(seed ^ 0x00E0_C4A2);
        // Round one: parents without cancellations, sets linear in the
        // numerator too. Round two, on what is left: parents with one
        // cancellation fewer (theirs kept), and the sets linear in the
        // determinants alone. Each round takes its starts from the
        // witnesses as it found them.
        for round in 0..2 {
            let witnesses = self.witnesses.clone();
            for ((cancelled, _), types) in &signatures {
                let cancelled = *cancelled;
                if !(1..=3).contains(&cancelled) {
                    continue;
                }
                for t in types {
                    let mut groups = Vec::new();
                    if round == 0 && cancelled <= 2 {
                        let starts =
                            mechanism_starts(self, &witnesses, t, cancelled, &tf, &mechanisms);
                        groups.push((starts, LinearSets::WithNumerator));
                    }
                    if round == 1 && cancelled >= 2 {
                        let starts = mechanism_starts(self, &witnesses, t, 1, &tf, &mechanisms);
                        groups.push((starts, LinearSets::Both));
                    }
                    if round == 1 && cancelled <= 2 {
                        let starts =
                            mechanism_starts(self, &witnesses, t, cancelled, &tf, &mechanisms);
                        groups.push((starts, LinearSets::DeterminantsOnly));
                    }
                    for (starts, kind) in groups {
                        let mut tries = 0;
                        'starts: for start in starts {
                            if kind == LinearSets::DeterminantsOnly && !start.multiple.is_empty() {
                                continue;
                            }
                            for choice in mechanism_choices(mechanisms.len(), start.fresh.len()) {
                                if self.shown(t) || tries >= MECHANISM_TRIES {
                                    break 'starts;
                                }
                                tries += 1;
                                let mut equations = Vec::new();
                                let mut polys = vec![num.clone()];
                                let posed =
                                    start.kept.iter().cloned().chain(
                                        start.fresh.iter().cloned().zip(choice.iter().copied()),
                                    );
                                let mut cancel = Vec::new();
                                for (r, i) in posed {
                                    let (d1, _, d2, _) = &mechanisms[i];
                                    equations.push(d1.subs(OMEGA, &r));
                                    equations.push(d2.subs(OMEGA, &r));
                                    polys.extend([d1.clone(), d2.clone()]);
                                    cancel.push(r);
                                }
                                for (r, k) in &start.multiple {
                                    equations.extend(
                                        derivatives[..*k as usize].iter().map(|d| d.subs(OMEGA, r)),
                                    );
                                }
                                self.solve_posed(
                                    t,
                                    types,
                                    &start.witness,
                                    (&equations, &polys, kind),
                                    (&cancel, &start.multiple),
                                    &params,
                                    &mut rng,
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// Solves `equations` (built of `polys`, the numerator first) in the
    /// first jointly linear sets (of the kind asked for), the other
    /// parameters at `witness`: over Q in as many parameters as equations,
    /// or one short over a number field, and records what the points show.
    #[allow(clippy::too_many_arguments)]
    fn solve_posed(
        &mut self,
        t: &FrfType,
        types: &[FrfType],
        witness: &BTreeMap<String, Rat>,
        (equations, polys, kind): (&[Poly], &[Poly], LinearSets),
        (cancel, multiple): (&[Rat], &[(Rat, u32)]),
        params: &[String],
        rng: &mut Sampler,
    ) {
        let refs: Vec<&Poly> = polys.iter().collect();
        let size = equations.len();
        for short in 0..=MECHANISM_SHORTS.min(size) {
            let mut sets = linear_sets(&refs, params, size - short);
            sets.truncate(PARENT_SETS);
            // Without multiple zeros no condition is the numerator's, so
            // the sets linear in the determinants alone (often larger)
            // hold the conditions as well.
            if kind != LinearSets::WithNumerator && multiple.is_empty() {
                let mut more = linear_sets(&refs[1..], params, size - short);
                more.retain(|v| !sets.contains(v));
                more.truncate(PARENT_SETS);
                if kind == LinearSets::DeterminantsOnly {
                    sets.clear();
                }
                sets.extend(more);
            }
            for vars in &sets {
                let others: Vec<&String> = params.iter().filter(|p| !vars.contains(p)).collect();
                if others.len() < short {
                    continue;
                }
                let mut pool = others.clone();
                let mut xs = Vec::new();
                for _ in 0..short {
                    xs.push(pool.remove(rng.index(pool.len())).clone());
                }
                let fixed: BTreeMap<String, Rat> = pool
                    .iter()
                    .map(|p| ((*p).clone(), witness[*p].clone()))
                    .collect();
                let eqs: Vec<Poly> = equations.iter().map(|e| e.subs_point(&fixed)).collect();
                if short == 0 {
                    if let Some(sol) = solve_linear(&eqs, vars) {
                        if sol.iter().all(|v| v.signum() > 0) {
                            let mut point = fixed.clone();
                            point.extend(vars.iter().cloned().zip(sol));
                            self.record(point);
                        }
                    }
                    continue;
                }
                for (field, point) in algebraic_points(&eqs, vars, &xs) {
                    self.record_algebraic(types, &fixed, (cancel, multiple), field, point);
                }
            }
            if self.shown(t) {
                break;
            }
        }
    }

    /// The second pass of [`Self::algebraic_search`]: from a witness of a
    /// parent of each wanted type (its coincident roots apart: `AA` for
    /// `A^2`, a zero and a pole side by side for a cancelled pole), the
    /// roots to merge placed at their geometric mean and the other
    /// parameters kept at the witness's values, so that the solutions
    /// include the one near the witness, where the rest of the order holds.
    fn algebraic_parent_search(&mut self, wanted: &[FrfType], seed: u64) {
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let tf = UndampedCoefficients::new(self.model);
        let params = self.params.clone();
        let mut rng = Sampler::new(seed ^ 0x009A_2E17);
        for ((cancelled, mults), types) in signatures {
            let size = 2 * cancelled as usize + mults.iter().sum::<u32>() as usize;
            let (num, den) = (self.num.clone(), self.den.clone());
            let polys: Vec<&Poly> = if cancelled == 0 {
                vec![&num]
            } else {
                vec![&num, &den]
            };
            if size == 0 || !linear_sets(&polys, &params, size).is_empty() {
                continue;
            }
            let sets: Vec<(usize, Vec<Vec<String>>)> = (1..=2usize.min(size))
                .map(|short| {
                    let mut s = linear_sets(&polys, &params, size - short);
                    s.truncate(PARENT_SETS);
                    (short, s)
                })
                .filter(|(_, s)| !s.is_empty())
                .collect();
            if sets.is_empty() {
                continue;
            }
            for t in &types {
                let mut tries = 0;
                'parents: for (parent, plan) in parents(t, cancelled) {
                    let Some(w) = self.witnesses.get(&parent).cloned() else {
                        continue;
                    };
                    let x: Vec<f64> = params.iter().map(|p| w[p].to_f64()).collect();
                    let Some((zeros, poles, _)) = tf_roots(&tf, &x) else {
                        continue;
                    };
                    let Some((cancel, multiple)) = plan.roots(&zeros, &poles) else {
                        continue;
                    };
                    let equations = self.root_equations(&cancel, &multiple, &derivatives);
                    for (short, sets) in &sets {
                        for vars in sets {
                            let others: Vec<&String> =
                                params.iter().filter(|p| !vars.contains(p)).collect();
                            if others.len() < *short {
                                continue;
                            }
                            for _ in 0..PARENT_SHORTS {
                                if self.shown(t) || tries >= PARENT_TRIES {
                                    break 'parents;
                                }
                                tries += 1;
                                let mut pool = others.clone();
                                let mut xs = Vec::new();
                                for _ in 0..*short {
                                    xs.push(pool.remove(rng.index(pool.len())).clone());
                                }
                                let fixed: BTreeMap<String, Rat> =
                                    pool.iter().map(|p| ((*p).clone(), w[*p].clone())).collect();
                                let eqs: Vec<Poly> =
                                    equations.iter().map(|e| e.subs_point(&fixed)).collect();
                                for (field, point) in algebraic_points(&eqs, vars, &xs) {
                                    self.record_algebraic(
                                        &types,
                                        &fixed,
                                        (&cancel, &multiple),
                                        field,
                                        point,
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// The third pass of [`Self::algebraic_search`]: random roots, sets
    /// and parameters.
    fn algebraic_random_search(&mut self, wanted: &[FrfType], seed: u64) {
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let mut rng = Sampler::new(seed);
        for ((cancelled, mults), types) in signatures {
            let size = 2 * cancelled as usize + mults.iter().sum::<u32>() as usize;
            let (num, den) = (self.num.clone(), self.den.clone());
            let polys: Vec<&Poly> = if cancelled == 0 {
                vec![&num]
            } else {
                vec![&num, &den]
            };
            if size == 0 || !linear_sets(&polys, &self.params, size).is_empty() {
                continue;
            }
            for short in 1..=2usize.min(size) {
                let sets = linear_sets(&polys, &self.params, size - short);
                if sets.is_empty() {
                    continue;
                }
                for _ in 0..ALGEBRAIC_TRIALS {
                    if types.iter().all(|t| self.shown(t)) {
                        break;
                    }
                    let vars = sets[rng.index(sets.len())].clone();
                    let mut others: Vec<String> = self
                        .params
                        .iter()
                        .filter(|p| !vars.contains(p))
                        .cloned()
                        .collect();
                    if others.len() < short {
                        break;
                    }
                    let mut xs = Vec::new();
                    for _ in 0..short {
                        xs.push(others.remove(rng.index(others.len())));
                    }
                    let fixed: BTreeMap<String, Rat> =
                        others.iter().map(|p| (p.clone(), rng.value())).collect();
                    let cancel: Vec<Rat> = (0..cancelled).map(|_| rng.value()).collect();
                    let multiple: Vec<(Rat, u32)> =
                        mults.iter().map(|&k| (rng.value(), k)).collect();
                    let equations: Vec<Poly> = self
                        .root_equations(&cancel, &multiple, &derivatives)
                        .iter()
                        .map(|e| e.subs_point(&fixed))
                        .collect();
                    for (field, point) in algebraic_points(&equations, &vars, &xs) {
                        self.record_algebraic(&types, &fixed, (&cancel, &multiple), field, point);
                    }
                }
            }
        }
    }

    /// Classifies the point `fixed` and `point` over `field` exactly and
    /// keeps it as the witness of its type if that is one of `types` and
    /// has no witness yet. A point of degree one is a rational point.
    /// The posed coincidences `(cancel, multiple)` are divided out exactly
    /// first and the rest read in `f64`: only a point whose type so
    /// predicted is wanted is classified exactly, which costs far more.
    pub(super) fn record_algebraic(
        &mut self,
        types: &[FrfType],
        fixed: &BTreeMap<String, Rat>,
        (cancel, multiple): (&[Rat], &[(Rat, u32)]),
        field: RealField,
        point: BTreeMap<String, FieldElem>,
    ) {
        if field.degree() == 1 {
            let mut p = fixed.clone();
            for (k, v) in &point {
                match v.as_rat() {
                    Some(r) => p.insert(k.clone(), r),
                    None => return,
                };
            }
            self.record(p);
            return;
        }
        let num = self.num.subs_point(fixed);
        let den = self.den.subs_point(fixed);
        match predicted_type(&field, &num, &den, &point, cancel, multiple) {
            Some(p) if types.contains(&p) && !self.shown(&p) => {}
            _ => return,
        }
        let Some(t) = posed_type(&field, &num, &den, &point, cancel, multiple) else {
            return;
        };
        if !types.contains(&t) || self.shown(&t) {
            return;
        }
        let mut full = point;
        for (k, v) in fixed {
            full.insert(k.clone(), field.from_rat(v));
        }
        self.algebraic
            .insert(t, AlgebraicWitness::new(&field, &full, cancel, multiple));
    }
}

/// `f` divided by `(x - r)` for each `r` of `roots`, exactly; `None`
/// where one does not divide.
fn divided(field: &RealField, f: &FieldPoly, roots: &[&Rat]) -> Option<FieldPoly> {
    let mut f = f.clone();
    for r in roots {
        let linear = FieldPoly::new(vec![field.from_rat(&-*r), field.one()]);
        f = field.poly_div_exact(&f, &linear)?;
    }
    Some(f)
}

/// The posed roots of `cancel` and `multiple` divided out of `num` and
/// `den` at `point` over `field`: the numerator's rest `Q` and the
/// denominator's rest `P`.
fn posed_rests(
    field: &RealField,
    num: &Poly,
    den: &Poly,
    point: &BTreeMap<String, FieldElem>,
    cancel: &[Rat],
    multiple: &[(Rat, u32)],
) -> Option<(FieldPoly, FieldPoly)> {
    let n = field.univariate(num, OMEGA, point).ok()?;
    let d = field.univariate(den, OMEGA, point).ok()?;
    let mut zeros: Vec<&Rat> = cancel.iter().collect();
    for (r, k) in multiple {
        zeros.extend(std::iter::repeat_n(r, *k as usize));
    }
    let poles: Vec<&Rat> = cancel.iter().collect();
    Some((divided(field, &n, &zeros)?, divided(field, &d, &poles)?))
}

/// The exact type at `point` over `field` of `num/den` built with the
/// cancelled poles `cancel` and the multiple zeros `multiple`: these
/// divided out exactly, every positive root of the rests `Q` (of the
/// numerator) and `P` (of the denominator) isolated together by
/// Descartes' rule over the field, each simple, so that `Q` and `P` share
/// none; the multiple zeros, roots of neither, put back in their places.
/// `None` where the point does not have that structure: a posed root that
/// does not divide, a multiple zero met again by the rests, a multiple
/// root of `Q P`, or a pole off the positive axis. A cancelled pole that
/// stays a simple pole of `P` (a double root of the denominator cancelled
/// once) is a resonance.
pub(super) fn posed_type(
    field: &RealField,
    num: &Poly,
    den: &Poly,
    point: &BTreeMap<String, FieldElem>,
    cancel: &[Rat],
    multiple: &[(Rat, u32)],
) -> Option<FrfType> {
    let (q, p) = posed_rests(field, num, den, point, cancel, multiple)?;
    // A cancelled pole may stay a pole of the rest: two blocks' poles on
    // one point, cancelled once. It is then read as a resonance; were it a
    // zero of the rest too, the product's root there would not be simple.
    if multiple
        .iter()
        .any(|(r, _)| field.sign_at(&q, r) == 0 || field.sign_at(&p, r) == 0)
    {
        return None;
    }
    let product = field.poly_mul(&q, &p);
    let mut roots: Vec<(Rat, Rat, Token)> = Vec::new();
    let mut poles = 0;
    let mut zeros = 0;
    for (lo, hi) in field.positive_simple_roots(&product)? {
        let of_q = if lo == hi {
            field.sign_at(&q, &lo) == 0
        } else {
            field.sign_at(&q, &lo) * field.sign_at(&q, &hi) < 0
        };
        let feature = if of_q {
            zeros += 1;
            Feature::Antiresonance
        } else {
            poles += 1;
            Feature::Resonance
        };
        roots.push((
            lo,
            hi,
            Token {
                feature,
                multiplicity: 1,
            },
        ));
    }
    if poles != p.degree().unwrap_or(0) {
        return None;
    }
    for (r, k) in multiple {
        // Cut an interval holding the zero at it: the root is on the side
        // where the product changes sign.
        if let Some(i) = roots.iter().position(|(lo, hi, _)| lo < r && r < hi) {
            let (lo, hi, tok) = roots[i].clone();
            roots[i] = if field.sign_at(&product, &lo) * field.sign_at(&product, r) < 0 {
                (lo, r.clone(), tok)
            } else {
                (r.clone(), hi, tok)
            };
        }
        let tok = Token {
            feature: Feature::Antiresonance,
            multiplicity: *k,
        };
        roots.push((r.clone(), r.clone(), tok));
    }
    roots.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
    Some(FrfType {
        tokens: roots.into_iter().map(|r| r.2).collect(),
        nonminimum_phase: zeros < q.degree().unwrap_or(0),
    })
}

/// The type at `point` over `field` as floating point reads it once the
/// posed coincidences are divided out exactly: each cancelled root `r`
/// from numerator and denominator, each multiple zero `(r, k)` `k` times
/// from the numerator; the rest read as simple roots in `f64`, with the
/// posed zeros put back at their places. `None` where a posed root does
/// not divide.
fn predicted_type(
    field: &RealField,
    num: &Poly,
    den: &Poly,
    point: &BTreeMap<String, FieldElem>,
    cancel: &[Rat],
    multiple: &[(Rat, u32)],
) -> Option<FrfType> {
    let (n, d) = posed_rests(field, num, den, point, cancel, multiple)?;
    let approx =
        |f: &FieldPoly| -> Vec<f64> { f.coeffs().iter().map(|c| field.to_f64(c)).collect() };
    let zeros = positive_roots(&approx(&n))?;
    let poles = positive_roots(&approx(&d))?;
    let mut roots: Vec<(f64, Token)> = Vec::new();
    let simple = |feature| Token {
        feature,
        multiplicity: 1,
    };
    roots.extend(zeros.iter().map(|z| (*z, simple(Feature::Antiresonance))));
    roots.extend(poles.iter().map(|p| (*p, simple(Feature::Resonance))));
    roots.extend(multiple.iter().map(|(r, k)| {
        (
            r.to_f64(),
            Token {
                feature: Feature::Antiresonance,
                multiplicity: *k,
            },
        )
    }));
    roots.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(FrfType {
        tokens: roots.into_iter().map(|r| r.1).collect(),
        nonminimum_phase: zeros.len() < n.degree().unwrap_or(0),
    })
}

/// The positive points where `equations` (polynomials in `vars` and `xs`
/// only, jointly linear in `vars`; one or two `xs`, as many equations as
/// `vars` and `xs` together) hold at once, each over the real number field
/// of its `x`: see the module docs. A point whose `x` is rational comes in
/// a field of degree one.
pub(super) fn algebraic_points(
    equations: &[Poly],
    vars: &[String],
    xs: &[String],
) -> Vec<FieldPoint> {
    algebraic_points_up_to(equations, vars, xs, MAX_FIELD_DEGREE)
}

/// [`algebraic_points`] with fields, and two short eliminants, of degree
/// up to `max_degree`.
pub(super) fn algebraic_points_up_to(
    equations: &[Poly],
    vars: &[String],
    xs: &[String],
    max_degree: usize,
) -> Vec<FieldPoint> {
    if equations.len() != vars.len() + xs.len() || xs.is_empty() || xs.len() > 2 {
        return Vec::new();
    }
    let at_zero: BTreeMap<String, Rat> = vars.iter().map(|v| (v.clone(), Rat::ZERO)).collect();
    // Rows [d e / d v_1 .. d e / d v_n, e at v = 0], polynomials in `xs`.
    let rows: Vec<Vec<Poly>> = equations
        .iter()
        .map(|e| {
            let mut row: Vec<Poly> = vars.iter().map(|v| e.derivative(v)).collect();
            row.push(e.subs_point(&at_zero));
            row
        })
        .collect();
    let x = &xs[0];
    // With two short parameters: the two minors whose common root in the
    // second gives it, and their first subresultant in it.
    let mut pair: Option<(Poly, Poly, Option<Poly>)> = None;
    let eliminated: Option<UPoly> = if xs.len() == 1 {
        let Some(int_rows) = rows
            .iter()
            .map(|r| integer_row(r, x))
            .collect::<Option<Vec<_>>>()
        else {
            return Vec::new();
        };
        poly::det_univariate(&int_rows).ok()
    } else {
        // Two maximal minors (leaving out the last row, then the one
        // before): both vanish at every solution.
        let n = rows.len();
        let minor = |skip: usize| -> Poly {
            let m: Vec<Vec<Poly>> = rows
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != skip)
                .map(|(_, r)| r.clone())
                .collect();
            poly::det(&m)
        };
        let (a, b) = (minor(n - 1), minor(n - 2));
        let (y, dx) = (&xs[1], |p: &Poly| p.degree(x));
        if (dx(&a) * b.degree(y) + a.degree(y) * dx(&b)) as usize > max_degree {
            return Vec::new();
        }
        let r = poly::resultant(&a, &b, y);
        let first = poly::subresultant_chain(&a, &b, y).get(1).cloned();
        pair = Some((a, b, first));
        UPoly::from_poly(&r, x).map(|(_, u)| u)
    };
    let Some(u) = eliminated else {
        return Vec::new();
    };
    if u.is_zero() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for field in RealField::real_roots_of(&u) {
        let (lo, _) = field.interval();
        if lo.signum() < 0 || field.degree() > max_degree || field.sign(&field.generator()) <= 0 {
            continue;
        }
        if let Some(point) = complete(&field, &rows, pair.as_ref(), equations, vars, xs) {
            out.push((field, point));
        }
    }
    out
}

/// At `x = theta` of `field`: `y` (if any) the common root of the two
/// minors of `pair` (see [`common_root`]), then the linear set from all
/// but the last equations, kept if every equation holds exactly and every
/// coordinate is positive.
fn complete(
    field: &RealField,
    rows: &[Vec<Poly>],
    pair: Option<&(Poly, Poly, Option<Poly>)>,
    equations: &[Poly],
    vars: &[String],
    xs: &[String],
) -> Option<BTreeMap<String, FieldElem>> {
    let mut at: BTreeMap<String, FieldElem> = BTreeMap::from([(xs[0].clone(), field.generator())]);
    if let Some(y) = xs.get(1) {
        // The two left-out minors' common root in y; one of them would do
        // on its own only where it is linear.
        let (a, b, first) = pair?;
        let y0 = common_root(field, a, b, first.as_ref(), y, &at)?;
        if field.sign(&y0) <= 0 {
            return None;
        }
        at.insert(y.clone(), y0);
    }
    let k = vars.len();
    let value = |p: &Poly| field.eval(p, &at).ok();
    let mut a: Vec<Vec<FieldElem>> = Vec::with_capacity(k);
    let mut b: Vec<FieldElem> = Vec::with_capacity(k);
    for row in rows.iter().take(k) {
        let mut r = Vec::with_capacity(k);
        for p in &row[..k] {
            r.push(value(p)?);
        }
        a.push(r);
        b.push(field.neg(&value(&row[k])?));
    }
    let solution = if k == 0 {
        Vec::new()
    } else {
        field.solve(&a, &b)?
    };
    for (v, s) in vars.iter().zip(solution) {
        if field.sign(&s) <= 0 {
            return None;
        }
        at.insert(v.clone(), s);
    }
    for e in equations {
        if !field.eval(e, &at).ok()?.is_zero() {
            return None;
        }
    }
    Some(at)
}

/// The one common root in `y` of `a` and `b` (polynomials in `y` and the
/// variables of `at`, whose resultant in `y` vanishes at `at`) over
/// `field`, if their gcd there is of degree one.
///
/// By their first subresultant `S_1` (`first`, over the integers), where
/// neither leading coefficient in `y` vanishes at `at` and both are of
/// degree two or more in `y`: `S_1` then specializes to the first
/// subresultant of the specialized pair, which is of degree one exactly
/// when their gcd is (its leading coefficient is the first principal
/// subresultant coefficient, the resultant being zero), and is then a
/// multiple of the gcd. Otherwise by Euclid's algorithm over the field,
/// whose remainders' coefficients grow in height so fast in fields of
/// degree 20 or more that one gcd took minutes.
fn common_root(
    field: &RealField,
    a: &Poly,
    b: &Poly,
    first: Option<&Poly>,
    y: &str,
    at: &BTreeMap<String, FieldElem>,
) -> Option<FieldElem> {
    let kept = |p: &Poly| {
        p.degree(y) >= 2
            && p.coeffs_in(y)
                .last()
                .and_then(|lc| field.eval(lc, at).ok())
                .is_some_and(|v| !v.is_zero())
    };
    if let Some(s) = first.filter(|_| kept(a) && kept(b)) {
        let s = field.univariate(s, y, at).ok()?;
        if s.degree() != Some(1) {
            return None;
        }
        let c = s.coeffs();
        return Some(field.neg(&field.div(&c[0], &c[1])?));
    }
    let g = field.poly_gcd(
        &field.univariate(a, y, at).ok()?,
        &field.univariate(b, y, at).ok()?,
    );
    if g.degree() != Some(1) {
        return None;
    }
    Some(field.neg(&g.coeffs()[0]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_subresultant_gives_the_common_root_as_euclid_does() {
        // theta = sqrt(2) for x. Pairs with a gcd in y of degree one (the
        // root x, and 1/x), of degree two (none), and with a leading
        // coefficient that vanishes at theta (Euclid's route alone).
        let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
        let at = BTreeMap::from([("x".to_string(), k.generator())]);
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let cases = [
            (
                "(y - x)*(y + 2)",
                "(y - x)*(y - 3*x)*(y + 1)",
                Some(2f64.sqrt()),
            ),
            (
                "(x*y - 1)*(y^2 + 1)",
                "(x*y - 1)*(y + x)",
                Some(0.5f64.sqrt()),
            ),
            (
                "(y - x)*(y - 2*x)*(y + 1)",
                "(y - x)*(y - 2*x)*(y + 5)",
                None,
            ),
            (
                "(x^2 - 2)*y^3 + (y - x)*(y + 1)",
                "(y - x)*(y - 7)",
                Some(2f64.sqrt()),
            ),
        ];
        for (a, b, want) in cases {
            let (a, b) = (p(a), p(b));
            let first = poly::subresultant_chain(&a, &b, "y").get(1).cloned();
            let by_subresultant = common_root(k, &a, &b, first.as_ref(), "y", &at);
            let by_euclid = common_root(k, &a, &b, None, "y", &at);
            assert_eq!(by_subresultant, by_euclid);
            match want {
                Some(v) => assert!((k.to_f64(&by_euclid.unwrap()) - v).abs() < 1e-12),
                None => assert!(by_euclid.is_none()),
            }
        }
    }

    #[test]
    fn one_short_points_solve_every_equation() {
        // x*y - 2 = 0 and y - x = 0 in the linear set {y} with x short:
        // x = y = sqrt(2), a point no rational draw reaches.
        let e: Vec<Poly> = ["x*y - 2", "y - x"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let points = algebraic_points(&e, &["y".to_string()], &["x".to_string()]);
        assert_eq!(points.len(), 1);
        let (k, p) = &points[0];
        assert_eq!(k.degree(), 2);
        assert!((k.to_f64(&p["x"]) - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(p["x"], p["y"]);
    }

    /// The quadruple zeros of N5-g2-a3.2-s4.2 at 544/625, the draw of
    /// the 5-mass table (engine 29): its numerator is jointly linear in
    /// pairs only, so `m3` and `m5` are eliminated and `theta` is of degree
    /// four. A point's type is read by two routes (Descartes' rule with
    /// the posed zero divided out, and the general gcd and Sturm reading
    /// over the field), and at each the fifth derivative condition fails,
    /// so the zero is of multiplicity four exactly.
    #[test]
    fn quadruple_zeros_two_parameters_short() {
        let model = crate::Model::from_id("N5-g2-a3.2-s4.2").unwrap();
        let tf = model.undamped_tf();
        let q = |s: &str| -> Rat { s.parse().unwrap() };
        let sigma = q("544/625");
        let fixed: BTreeMap<String, Rat> = [
            ("c12", "133/5"),
            ("c34", "21/1000"),
            ("c45", "14/625"),
            ("m2", "421/10"),
            ("m4", "223/100"),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), q(v)))
        .collect();
        let mut derivatives = vec![tf.num.clone()];
        for _ in 0..4 {
            let d = derivatives[derivatives.len() - 1].derivative(OMEGA);
            derivatives.push(d);
        }
        let at = |p: &Poly| p.subs(OMEGA, &sigma).subs_point(&fixed);
        let equations: Vec<Poly> = derivatives[..4].iter().map(at).collect();
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let points = algebraic_points(&equations, &names(&["c1", "m1"]), &names(&["m3", "m5"]));
        let num = tf.num.subs_point(&fixed);
        let den = tf.den.subs_point(&fixed);
        let mut types = Vec::new();
        for (k, p) in &points {
            assert!(k.degree() > 1);
            let posed = posed_type(k, &num, &den, p, &[], &[(sigma.clone(), 4)]).unwrap();
            // The general reading costs seconds per point: once is enough.
            if types.is_empty() {
                let general = super::super::frf_type_at_algebraic(&num, &den, OMEGA, k, p).unwrap();
                assert_eq!(posed, general);
            }
            let fifth = k.eval(&at(&derivatives[4]), p).unwrap();
            assert_ne!(k.sign(&fifth), 0);
            types.push(posed.to_string());
        }
        types.sort();
        assert!(types.contains(&"RRA^4RR".to_string()), "{types:?}");
        assert!(types.contains(&"RRRA^4R".to_string()), "{types:?}");
    }

    #[test]
    fn two_short_points_solve_every_equation() {
        // Three equations, linear in v alone, with x and y short:
        // v = x + y, x*y = 1, v^2 = 5: x + y = sqrt 5 and x y = 1, so x and y
        // are (sqrt 5 +- 1)/2. Every positive solution is found and holds.
        let e: Vec<Poly> = ["v - x - y", "x*y - 1", "v*x + v*y - 5"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let points = algebraic_points(&e, &["v".to_string()], &["x".to_string(), "y".to_string()]);
        assert_eq!(points.len(), 2);
        let golden = (5f64.sqrt() + 1.0) / 2.0;
        for (k, p) in &points {
            let (x, y, v) = (k.to_f64(&p["x"]), k.to_f64(&p["y"]), k.to_f64(&p["v"]));
            assert!((x * y - 1.0).abs() < 1e-12 && (v - 5f64.sqrt()).abs() < 1e-12);
            assert!((x - golden).abs() < 1e-12 || (y - golden).abs() < 1e-12);
            for q in &e {
                assert!(k.eval(q, p).unwrap().is_zero());
            }
        }
    }

    /// The mechanisms' pass on N5-g2-a3.1-s5.2: from the table's witness
    /// of `RRAARRA`, posing a cancellation by a mechanism of the chain
    /// (not by numerator and denominator) solves it over Q in all the
    /// parameters it needs and shows `RRAAR`, which no earlier search
    /// reached. Checked by another route: the rational roots of the
    /// numerator and of the denominator at the point (the rational root
    /// test) share exactly one, `rho`; divided out, the quadratic's zeros
    /// (its formula) and the cubic's poles (bisection on its f64 values)
    /// are in the order R R A A with the last pole above them.
    #[test]
    fn a_mechanism_poses_a_cancelled_pole() {
        let (tf, w) = mechanism_pass_from(
            "RRAARRA",
            &[
                ("c1", "13/2"),
                ("c12", "5/256"),
                ("c34", "3/128"),
                ("c45", "4"),
                ("m1", "4"),
                ("m2", "9/4"),
                ("m3", "6"),
                ("m4", "16"),
                ("m5", "11/64"),
            ],
            "RRAAR",
            7,
        );
        let (shared, nr, dr) = shared_and_rest(&tf, &w);
        assert_eq!(shared.len(), 1);
        assert_eq!((nr.len(), dr.len()), (3, 4));
        let disc = nr[1] * nr[1] - 4.0 * nr[2] * nr[0];
        assert!(disc > 0.0);
        let mut z = [
            (-nr[1] - disc.sqrt()) / (2.0 * nr[2]),
            (-nr[1] + disc.sqrt()) / (2.0 * nr[2]),
        ];
        z.sort_by(f64::total_cmp);
        let f = |x: f64| dr[0] + x * (dr[1] + x * (dr[2] + x * dr[3]));
        let mut poles = Vec::new();
        let grid: Vec<f64> = (0..=4000)
            .map(|i| 10f64.powf(-10.0 + i as f64 * 0.005))
            .collect();
        for g in grid.windows(2) {
            let (mut a, mut b) = (g[0], g[1]);
            if f(a).signum() != f(b).signum() {
                for _ in 0..200 {
                    let m = 0.5 * (a + b);
                    if f(m).signum() == f(a).signum() {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                poles.push(a);
            }
        }
        assert_eq!(poles.len(), 3);
        assert!(z[0] > 0.0 && poles[1] < z[0] && z[1] < poles[2]);
    }

    /// The mechanisms' pass on N5-g2-a3.1-s5.2 for `wanted` with `parent`'s
    /// witness `at` (checked to show it) as the only witness: the transfer
    /// function and the witness found.
    fn mechanism_pass_from(
        parent: &str,
        at: &[(&str, &str)],
        wanted: &str,
        seed: u64,
    ) -> (crate::tf::UndampedTf, BTreeMap<String, Rat>) {
        let model = crate::Model::from_id("N5-g2-a3.1-s5.2").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let point: BTreeMap<String, Rat> = at
            .iter()
            .map(|(k, v)| (k.to_string(), v.parse().unwrap()))
            .collect();
        let parent: FrfType = parent.parse().unwrap();
        assert_eq!(prover.type_at(&point), Some(parent.clone()));
        prover.witnesses.insert(parent, point);
        let wanted: FrfType = wanted.parse().unwrap();
        prover.mechanism_parent_search(std::slice::from_ref(&wanted), seed);
        let w = prover.witnesses[&wanted].clone();
        (tf, w)
    }

    /// The shared positive rational roots of numerator and denominator of
    /// `tf` at `w` by the rational root test on each (not their gcd), and
    /// the rest of each in f64 with those roots divided out, lowest
    /// coefficient first.
    fn shared_and_rest(
        tf: &crate::tf::UndampedTf,
        w: &BTreeMap<String, Rat>,
    ) -> (Vec<Rat>, Vec<f64>, Vec<f64>) {
        let upoly = |p: &Poly| UPoly::from_poly(&p.subs_point(w), OMEGA).unwrap().1;
        let (n, d) = (upoly(&tf.num), upoly(&tf.den));
        let zeros = poly::rational_roots(&n);
        let shared: Vec<Rat> = poly::rational_roots(&d)
            .into_iter()
            .filter(|r| r.signum() > 0 && zeros.contains(r))
            .collect();
        let deflate = |p: &UPoly| -> Vec<f64> {
            let mut c: Vec<f64> = p.coeffs().iter().map(|c| c.to_f64()).collect();
            for r in &shared {
                let r = r.to_f64();
                let mut out = vec![0.0; c.len() - 1];
                let mut carry = 0.0;
                for k in (1..c.len()).rev() {
                    carry = c[k] + carry * r;
                    out[k - 1] = carry;
                }
                c = out;
            }
            c
        };
        let (nr, dr) = (deflate(&n), deflate(&d));
        (shared, nr, dr)
    }

    /// The mechanisms' second round on N5-g2-a3.1-s5.2: from the table's
    /// witness of `RAARR`, which has a cancelled pole of its own, that pole
    /// is kept by the mechanism that holds it and a second one posed by
    /// another, one parameter short (the draw of seed 3; a field of degree
    /// one), which shows `RAR` (two cancelled poles). Checked by another
    /// route: numerator and denominator at the point share exactly two
    /// positive rational roots (the rational root test on each), one of
    /// them the parent's; divided out, the zero left (linear) lies between
    /// the two poles left (the quadratic formula).
    #[test]
    fn a_mechanism_keeps_a_cancelled_pole_and_poses_another() {
        let parent = [
            ("c1", "9/2"),
            ("c12", "15"),
            ("c34", "64"),
            ("c45", "1"),
            ("m1", "6/185"),
            ("m2", "11/4"),
            ("m3", "5/8"),
            ("m4", "1"),
            ("m5", "13212/8423"),
        ];
        let (tf, w) = mechanism_pass_from("RAARR", &parent, "RAR", 3);
        let at: BTreeMap<String, Rat> = parent
            .iter()
            .map(|(k, v)| (k.to_string(), v.parse().unwrap()))
            .collect();
        let (kept, _, _) = shared_and_rest(&tf, &at);
        assert_eq!(kept.len(), 1);
        let (shared, nr, dr) = shared_and_rest(&tf, &w);
        assert_eq!(shared.len(), 2);
        assert!(shared.contains(&kept[0]));
        assert_eq!((nr.len(), dr.len()), (2, 3));
        let zero = -nr[0] / nr[1];
        let disc = dr[1] * dr[1] - 4.0 * dr[2] * dr[0];
        assert!(disc > 0.0);
        let mut poles = [
            (-dr[1] - disc.sqrt()) / (2.0 * dr[2]),
            (-dr[1] + disc.sqrt()) / (2.0 * dr[2]),
        ];
        poles.sort_by(f64::total_cmp);
        assert!(poles[0] > 0.0 && poles[0] < zero && zero < poles[1]);
    }
}
