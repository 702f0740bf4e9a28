//! The search for FRF types: witnesses for the possible ones, certificates
//! for the impossible ones.
//!
//! The parameter space is cut into *strata*. The top stratum is the open
//! positive orthant of the model's parameters. Its *critical polynomials*
//! are the leading and trailing coefficients and discriminants (in `Omega`)
//! of the square-free parts of `num` and `den`, and the resultants of every
//! pair of parts: off their zero sets the number, multiplicity and order of
//! the real roots cannot change (roots move continuously and can only meet,
//! leave the real axis, cross 0 or escape to infinity where one of them
//! vanishes). Each irreducible factor of a critical polynomial is either
//! certified to keep one sign on the orthant, or it is a *wall* `alpha*x =
//! beta` with `alpha, beta > 0`, whose zero set is the graph `x = beta/alpha`
//! over the orthant of the other parameters: a lower-dimensional stratum,
//! handled the same way after substituting `x`.
//!
//! A type is impossible on a stratum when it is impossible on its open part
//! (off all walls) and on every wall. The open part is handled by counting
//! (cancellations, multiplicities, Descartes' rule), by collocation
//! (interlacing), by connectedness (regions between non-crossing walls each
//! have one type, read off a sample point) or by sign conditions that the
//! type imposes on the rational roots, refuted by a positive combination
//! found by exact linear programming.

use super::configurations::Configurations;
use super::frf_type::{frf_type_at, Feature, FrfType};
use super::lp::positive_combination_in;
use super::pole_signs::{
    block_pole_sign_data, pole_sign_data, type_fits, BlockPoleSigns, BlockSignData, PoleSignData,
    PoleSigns,
};
use super::LARGEST_LISTED_FACTOR;
use crate::model::Model;
use crate::tf::OMEGA;
use crate::xorshift::XorShift;
use poly::{discriminant, factor, gcd, resultant, square_free, Poly, Rat};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::rc::Rc;

/// `var = beta / alpha`, with `alpha` and `beta` polynomials with positive
/// coefficients in the remaining parameters (so `var > 0` on their orthant).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Substitution {
    /// The parameter that is eliminated.
    pub var: String,
    /// Denominator, positive coefficients.
    pub alpha: Poly,
    /// Numerator, positive coefficients.
    pub beta: Poly,
}

/// How a factor is shown to keep one sign on the positive orthant.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum Definiteness {
    /// All coefficients have the same sign.
    NoSubtraction,
    /// `(sum of the variables [+ 1])^power * factor` has coefficients of one
    /// sign (Polya); `affine` when the `+ 1` (homogenization) is used.
    Polya {
        /// The exponent.
        power: u32,
        /// Whether the multiplier is `(1 + sum of the variables)`.
        affine: bool,
    },
    /// `sign * factor = a*x^2 + b*x + c` in `var` with `a` free of
    /// subtraction and `4ac - b^2 > 0` (by `inner`), so
    /// `4a * sign * factor = (2ax + b)^2 + (4ac - b^2) > 0`.
    CompletedSquare {
        /// The variable.
        var: String,
        /// Why `4ac - b^2 > 0`.
        inner: Box<Definiteness>,
    },
}

/// The role of a critical factor on a wall: why a type cannot occur there,
/// or the proof on the wall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FactorProof {
    /// The factor keeps the sign `sign` on the stratum.
    Definite {
        /// The factor.
        factor: Poly,
        /// +1 or -1.
        sign: i32,
        /// The definiteness argument.
        definiteness: Definiteness,
    },
    /// On the wall a pole and a zero cancel (the factor divides a resultant
    /// of a numerator part and a denominator part), but the type needs as
    /// many resonances as the stratum has: it cannot occur there.
    NeedsNoCancellation {
        /// The factor.
        factor: Poly,
    },
    /// The type needs a cancellation, and the wall gives none by itself;
    /// where it meets a cancellation wall, that wall's proof covers it.
    NeedsCancellation {
        /// The factor.
        factor: Poly,
    },
    /// The wall is a stratum of its own, with its own proof.
    Wall {
        /// The factor.
        factor: Poly,
        /// The parametrization of its zero set.
        substitution: Substitution,
        /// The proof on the wall.
        proof: Box<Proof>,
    },
}

/// A sign condition `sign(poly) > 0` (or `>= 0`) that a type forces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SignCondition {
    /// Why the type forces it.
    pub rule: ConditionRule,
    /// The condition as derived: `derived > 0` (or `>= 0`).
    pub derived: Poly,
    /// `derived = square^2 * positive * reduced` with `positive` free of
    /// subtraction, so `reduced > 0` (resp. `>= 0`) follows.
    pub square: Poly,
    /// See `square`.
    pub positive: Poly,
    /// See `square`.
    pub reduced: Poly,
    /// Strict (`> 0`) or not (`>= 0`).
    pub strict: bool,
}

/// The rule a [`SignCondition`] comes from. `part` indexes the linear
/// parts of [`OpenProof::SignConditions`]; `rho` is that part's root
/// `-b/a` of `a*Omega + b`, and `sa` the sign of `a`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum ConditionRule {
    /// The part takes a token: `rho > 0`, derived `-b*sa`.
    RootPositive {
        /// Linear part index.
        part: usize,
    },
    /// The part is off the positive axis: `rho <= 0`, derived `b*sa`.
    RootNotPositive {
        /// Linear part index.
        part: usize,
    },
    /// `rho_lower < rho_upper`: derived `sa_l*sa_u*(b_l*a_u - b_u*a_l)`.
    RootOrder {
        /// Part with the lower token.
        lower: usize,
        /// Part with the higher token.
        upper: usize,
    },
    /// The sign of the `derivative`-th derivative `q` of the part `other`
    /// (degree `d`, leading sign `sl`) at `rho`, given that `roots_above`
    /// of its roots on the positive axis lie above `rho`. Derived:
    /// `want * sa^((d-k) mod 2) * sum_j q_j (-b)^j a^(d-k-j)` with
    /// `want = sl*(-1)^roots_above` for `k = 0`, and for `k >= 1` (all roots
    /// of `other` real, `rho` below or above all of them)
    /// `want = sl*(-1)^(d-k)` below, `sl` above.
    SignAt {
        /// The part of degree >= 2 (unique for its side and multiplicity).
        other: Poly,
        /// Linear part index.
        part: usize,
        /// `k`.
        derivative: u32,
        /// Roots of `other` above `rho`.
        roots_above: u32,
    },
    /// All roots of `other` are tokens of the type, so real and simple off
    /// the walls: `disc(other) > 0`.
    RealRoots {
        /// The part.
        other: Poly,
    },
}

/// One way of assigning the rational roots to the tokens of a type, and the
/// refutation of the conditions it forces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SignCase {
    /// For each linear part (in the stratum's order), the token index it
    /// takes, or `None` for a zero off the positive axis.
    pub assignment: Vec<Option<usize>>,
    /// The conditions.
    pub conditions: Vec<SignCondition>,
    /// Multipliers with nonnegative coefficients, one per condition:
    /// `sum multipliers[i] * conditions[i].reduced` has no positive
    /// coefficient, and a multiplier of a strict condition is nonzero.
    pub multipliers: Vec<Poly>,
}

/// A sample point of a region and the type found there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionSample {
    /// The full parameter point.
    pub point: BTreeMap<String, Rat>,
    /// Its type.
    #[serde(rename = "type")]
    pub frf_type: FrfType,
}

/// Why a type cannot occur on the open part of a stratum.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum OpenProof {
    /// The type has more resonances than the stratum's denominator degree
    /// (this covers the walls too: they only lose poles).
    TooManyResonances {
        /// Resonances of the type, with multiplicity.
        resonances: u32,
        /// Degree of the stratum's denominator.
        degree: u32,
    },
    /// Off the walls no pole cancels, so the number of resonances is the
    /// denominator degree; the type has fewer.
    TooFewResonances {
        /// Resonances of the type, with multiplicity.
        resonances: u32,
        /// Degree of the stratum's denominator.
        degree: u32,
    },
    /// Off the walls the roots of each square-free part are simple and the
    /// parts share no root: the multiplicities of the type do not match.
    Multiplicity,
    /// Every pole of the reduced TF is simple, for every positive
    /// parameter point: `K - Omega*M` is block diagonal with one block per
    /// connected part of the chain, each an unreduced symmetric tridiagonal
    /// pencil with a positive diagonal `M` (simple eigenvalues), and the TF
    /// is a sum of one term per block, so its reduced denominator divides
    /// the product of square-free block determinants without repeats. The
    /// type has a multiple resonance. Holds on every stratum.
    SimpleResonances,
    /// Collocated actuator and sensor: the TF is a sum of modal terms with
    /// positive residues including the rigid-body pole at `Omega = 0`
    /// (the denominator excludes it), which never cancels since
    /// `numerator(0)` and `denominator(0)` have no sign change.
    /// Between consecutive poles it rises from minus to plus infinity (one
    /// simple zero), above the last it stays negative: the type is
    /// `(AR)^k`. The type is not. Holds on every stratum.
    CollocatedModes {
        /// The numerator at `Omega = 0`, of one sign on the orthant.
        num_at_zero: Poly,
        /// The denominator at `Omega = 0`, of one sign on the orthant.
        den_at_zero: Poly,
    },
    /// The numerator's sign at the poles, from its remainder by the one
    /// chain block the denominator is, leaves the type's antiresonance
    /// counts between poles the wrong parity for every placement of the
    /// block's diagonal entries among its eigenvalues (docs/analysis.md,
    /// "Pole signs"). Holds on every stratum.
    PoleSigns(PoleSigns),
    /// The numerator's sign at the poles when the denominator is the
    /// product of several blocks' pole polynomials: at a pole of one
    /// block it is fixed by how the other blocks' spectra interleave with
    /// it and where the eigenvalues of the block's principal minors lie;
    /// no configuration admits the type's antiresonances (their parities,
    /// and the gaps with none or one; docs/analysis.md, "Block pole
    /// signs"). Holds on every stratum.
    BlockPoleSigns(BlockPoleSigns),
    /// Descartes' rule of signs for the numerator part `part`, whose
    /// coefficients in `Omega` have definite signs.
    Descartes {
        /// The part.
        part: Poly,
        /// Sign changes of its coefficient sequence.
        sign_changes: u32,
        /// Positive zeros the type needs from it.
        needed: u32,
    },
    /// Off the walls the stratum falls into connected regions (between
    /// walls `var = beta_i/alpha_i` that never cross); each has one type.
    Regions {
        /// The variable the walls are graphs in (none: no walls).
        var: Option<String>,
        /// The walls in increasing order.
        walls: Vec<Substitution>,
        /// `walls[i+1] - walls[i]` cross-multiplied: positive coefficients.
        gaps: Vec<Poly>,
        /// One sample per region, in increasing `var`.
        samples: Vec<RegionSample>,
    },
    /// Every point is a limit of generic points (all roots simple, none
    /// shared), and every generic type whose roots can gather into this
    /// type is impossible (docs/analysis.md, "Limits of generic types").
    /// Premises: the leading and constant coefficients in `Omega` of the
    /// reduced numerator and denominator have one sign on the orthant (no
    /// root reaches 0 or infinity), and at `point` both are square-free
    /// and coprime. Only on the whole orthant, never on a wall.
    Limits {
        /// A point where numerator and denominator are square-free and
        /// coprime (a witness of a generic type).
        point: BTreeMap<String, Rat>,
        /// The generic types whose roots can gather into the type, each
        /// certified impossible in the same analysis.
        generic: Vec<FrfType>,
    },
    /// Every assignment of the rational roots to the type's tokens forces
    /// contradictory sign conditions.
    SignConditions {
        /// The linear parts (`Omega` degree 1): numerator first.
        linear_parts: Vec<Poly>,
        /// One case per assignment.
        cases: Vec<SignCase>,
    },
}

/// A certificate that a type cannot occur on a stratum.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Proof {
    /// The substitutions that define the stratum (empty: the whole orthant).
    pub stratum: Vec<Substitution>,
    /// The open part.
    pub open: OpenProof,
    /// Every irreducible critical factor of the stratum and its treatment
    /// (empty for [`OpenProof::TooManyResonances`]), except those that
    /// `unlisted` covers.
    pub factors: Vec<FactorProof>,
    /// Critical factors of more than [`LARGEST_LISTED_FACTOR`] terms that
    /// the proof treats by counting are not written out (at six masses they
    /// run to hundreds of megabytes, repeated in every such certificate).
    /// When set, every irreducible factor of the stratum's critical
    /// polynomials that `factors` leaves uncovered has this role.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unlisted: Option<UnlistedRole>,
}

/// The role of the critical factors a [`Proof`] leaves unlisted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnlistedRole {
    /// As [`FactorProof::NeedsCancellation`]: none of them divides a
    /// resultant of a numerator part and a denominator part, nor a leading
    /// coefficient or value at `Omega = 0`, and the type has fewer
    /// resonances than the stratum's denominator degree.
    NeedsCancellation,
}

/// One stratum with the data the proofs need.
#[derive(Clone, Debug)]
pub(crate) struct Stratum {
    pub subs: Vec<Substitution>,
    pub vars: Vec<String>,
    pub num: Poly,
    pub den: Poly,
    pub num_parts: Vec<(Poly, u32)>,
    pub den_parts: Vec<(Poly, u32)>,
    pub factors: Vec<CriticalFactor>,
}

#[derive(Clone, Debug)]
pub(crate) struct CriticalFactor {
    pub poly: Poly,
    /// Divides a resultant of a numerator part and a denominator part.
    pub cancels: bool,
    /// Divides a leading or trailing coefficient.
    pub boundary: bool,
    pub definite: Option<(i32, Definiteness)>,
    pub wall: Option<Substitution>,
}

impl Stratum {
    pub(crate) fn key(&self) -> String {
        let mut k: Vec<String> = self
            .subs
            .iter()
            .map(|s| format!("{}={}/{}", s.var, s.beta, s.alpha))
            .collect();
        k.sort();
        k.join(";")
    }

    pub(crate) fn vanishing(&self) -> impl Iterator<Item = &CriticalFactor> {
        self.factors.iter().filter(|f| f.definite.is_none())
    }

    fn den_degree(&self) -> u32 {
        self.den.degree(OMEGA)
    }
}

/// Applies `x = beta/alpha` to `p` and clears the denominator with
/// `alpha^deg_x(p)` (a positive factor).
pub(crate) fn substitute(p: &Poly, s: &Substitution) -> Poly {
    let d = p.degree(&s.var);
    let coeffs = p.coeffs_in(&s.var);
    let mut acc = Poly::zero();
    for (k, c) in coeffs.iter().enumerate() {
        if c.is_zero() {
            continue;
        }
        let term = &(c * &s.beta.pow(k as u32)) * &s.alpha.pow(d - k as u32);
        acc = &acc + &term;
    }
    acc
}

/// The full parameter point of a stratum point (undoing the substitutions),
/// if every eliminated parameter comes out positive. On walls (`alpha`,
/// `beta` free of subtraction) it always does; on the partial walls of the
/// targeted search only on part of the stratum.
pub(crate) fn positive_full_point(
    subs: &[Substitution],
    point: &BTreeMap<String, Rat>,
) -> Option<BTreeMap<String, Rat>> {
    let mut p = point.clone();
    for s in subs.iter().rev() {
        let a = s.alpha.eval(&p).ok()?;
        let b = s.beta.eval(&p).ok()?;
        if a.is_zero() {
            return None;
        }
        let v = &b / &a;
        if v.signum() <= 0 {
            return None;
        }
        p.insert(s.var.clone(), v);
    }
    Some(p)
}

/// [`positive_full_point`] on a stratum of walls, where it cannot fail.
pub(crate) fn full_point(
    subs: &[Substitution],
    point: &BTreeMap<String, Rat>,
) -> BTreeMap<String, Rat> {
    positive_full_point(subs, point).expect("walls map positive points to positive points")
}

/// Sign-definiteness on the open positive orthant: no subtraction, or
/// Polya's multiplier up to power 8.
pub(crate) fn definiteness(f: &Poly) -> Option<(i32, Definiteness)> {
    definiteness_rec(f, 2)
}

fn definiteness_rec(f: &Poly, depth: u32) -> Option<(i32, Definiteness)> {
    if let Some(d) = polya(f) {
        return Some(d);
    }
    if depth == 0 {
        return None;
    }
    // Complete the square in a variable of degree 2.
    for sign in [1, -1] {
        let g = if sign == 1 { f.clone() } else { -f.clone() };
        for x in g.vars() {
            if g.degree(x) != 2 {
                continue;
            }
            let c = g.coeffs_in(x);
            if !c[2].all_coefs_positive() {
                continue;
            }
            let inner = &(&c[2] * &c[0]).scale(&Rat::from(4)) - &(&c[1] * &c[1]);
            if let Some((1, d)) = definiteness_rec(&inner, depth - 1) {
                return Some((
                    sign,
                    Definiteness::CompletedSquare {
                        var: x.clone(),
                        inner: Box::new(d),
                    },
                ));
            }
        }
    }
    None
}

fn polya(f: &Poly) -> Option<(i32, Definiteness)> {
    if f.all_coefs_positive() {
        return Some((1, Definiteness::NoSubtraction));
    }
    if f.all_coefs_negative() {
        return Some((-1, Definiteness::NoSubtraction));
    }
    let vars = f.vars().to_vec();
    let degree = f.total_degree();
    let homogeneous = f
        .terms()
        .iter()
        .all(|t| t.exps.iter().sum::<u32>() == degree);
    let mut sum = if homogeneous {
        Poly::zero()
    } else {
        Poly::one()
    };
    for v in &vars {
        sum = &sum + &Poly::var(v);
    }
    let mut acc = f.clone();
    for power in 1..=8 {
        acc = &acc * &sum;
        if acc.num_terms() > 20_000 {
            return None;
        }
        let affine = !homogeneous;
        if acc.all_coefs_positive() {
            return Some((1, Definiteness::Polya { power, affine }));
        }
        if acc.all_coefs_negative() {
            return Some((-1, Definiteness::Polya { power, affine }));
        }
    }
    None
}

/// `f = alpha*x - beta` with `alpha, beta` free of subtraction and of one
/// sign, for the variable giving the smallest expressions.
pub(crate) fn wall_of(f: &Poly, vars: &[String]) -> Option<Substitution> {
    let mut best: Option<Substitution> = None;
    for x in vars {
        if f.degree(x) != 1 {
            continue;
        }
        let c = f.coeffs_in(x);
        let (a0, a1) = (&c[0], &c[1]);
        let sub = if a1.all_coefs_positive() && a0.all_coefs_negative() {
            Substitution {
                var: x.clone(),
                alpha: a1.clone(),
                beta: -a0.clone(),
            }
        } else if a1.all_coefs_negative() && a0.all_coefs_positive() {
            Substitution {
                var: x.clone(),
                alpha: -a1.clone(),
                beta: a0.clone(),
            }
        } else {
            continue;
        };
        let size = sub.alpha.num_terms() + sub.beta.num_terms();
        if best
            .as_ref()
            .is_none_or(|b| size < b.alpha.num_terms() + b.beta.num_terms())
        {
            best = Some(sub);
        }
    }
    best
}

fn omega_parts(p: &Poly) -> Vec<(Poly, u32)> {
    let (_, parts) = square_free(p);
    parts
        .into_iter()
        .filter(|(f, _)| f.degree(OMEGA) >= 1)
        .collect()
}

/// The discriminant of `p` in Omega, computed once per model: the strata
/// and the sign conditions of the parts' real roots ask for the same ones.
fn kept_discriminant(kept: &mut HashMap<Poly, Poly>, p: &Poly) -> Poly {
    if let Some(d) = kept.get(p) {
        return d.clone();
    }
    let d = discriminant(p, OMEGA);
    kept.insert(p.clone(), d.clone());
    d
}

/// Builds a stratum from the model's `num/den` and substitutions.
pub(crate) fn build_stratum(
    num0: &Poly,
    den0: &Poly,
    params: &[String],
    subs: Vec<Substitution>,
    discriminants: &mut HashMap<Poly, Poly>,
) -> Stratum {
    let mut num = num0.clone();
    let mut den = den0.clone();
    for s in &subs {
        num = substitute(&num, s);
        den = substitute(&den, s);
    }
    let g = gcd(&num, &den);
    if !g.is_constant() {
        num = num.div_exact(&g).expect("gcd divides");
        den = den.div_exact(&g).expect("gcd divides");
    }
    let num_parts = omega_parts(&num);
    let den_parts = omega_parts(&den);
    let eliminated: BTreeSet<&str> = subs.iter().map(|s| s.var.as_str()).collect();
    let vars: Vec<String> = params
        .iter()
        .filter(|v| !eliminated.contains(v.as_str()))
        .cloned()
        .collect();
    // Critical polynomials, with the roles of their factors.
    let mut crit: Vec<(Poly, bool, bool)> = Vec::new();
    let all: Vec<(&Poly, bool)> = num_parts
        .iter()
        .map(|(p, _)| (p, true))
        .chain(den_parts.iter().map(|(p, _)| (p, false)))
        .collect();
    for (p, _) in &all {
        crit.push((p.lead_in(OMEGA), false, true));
        crit.push((p.subs(OMEGA, &Rat::ZERO), false, true));
        if p.degree(OMEGA) >= 2 {
            // Kept: the sign conditions of a part's real roots need the
            // same discriminant (at six masses one costs a minute).
            crit.push((kept_discriminant(discriminants, p), false, false));
        }
    }
    for i in 0..all.len() {
        for j in i + 1..all.len() {
            let cancels = all[i].1 != all[j].1;
            crit.push((resultant(all[i].0, all[j].0, OMEGA), cancels, false));
        }
    }
    let mut factors: Vec<CriticalFactor> = Vec::new();
    for (c, cancels, boundary) in crit {
        for (f, _) in factor(&c).factors {
            if let Some(existing) = factors.iter_mut().find(|x| x.poly == f) {
                existing.cancels |= cancels;
                existing.boundary |= boundary;
                continue;
            }
            let definite = definiteness(&f);
            let wall = if definite.is_none() {
                wall_of(&f, &vars)
            } else {
                None
            };
            factors.push(CriticalFactor {
                poly: f,
                cancels,
                boundary,
                definite,
                wall,
            });
        }
    }
    // The keys once per factor: printing a large factor in every
    // comparison cost more than the sort.
    factors.sort_by_cached_key(|f| (f.poly.total_degree(), f.poly.to_string()));
    Stratum {
        subs,
        vars,
        num,
        den,
        num_parts,
        den_parts,
        factors,
    }
}

/// Sample points: a deterministic generator (xorshift64*).
pub(crate) struct Sampler(XorShift);

impl Sampler {
    pub(crate) fn new(seed: u64) -> Sampler {
        Sampler(XorShift::new(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1))
    }

    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A positive rational spread log-uniformly over about `[1/64, 64]`,
    /// with small numerator and denominator.
    pub(crate) fn value(&mut self) -> Rat {
        let e = (self.next() % 13) as i32 - 6;
        let m = 8 + (self.next() % 8) as i64; // 8..15
        Rat::new(m.into(), 8.into()) * Rat::from(2).pow(e)
    }

    /// An index below `n` (`n > 0`).
    pub(crate) fn index(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    pub(crate) fn point(&mut self, vars: &[String]) -> BTreeMap<String, Rat> {
        vars.iter().map(|v| (v.clone(), self.value())).collect()
    }
}

/// The search state of one model.
pub(crate) struct Prover<'a> {
    pub model: &'a Model,
    pub num: Poly,
    pub den: Poly,
    pub params: Vec<String>,
    /// Shared, not copied: a stratum's factors can be large and every
    /// (stratum, type) proof attempt looks its stratum up.
    strata: HashMap<String, Rc<Stratum>>,
    pub witnesses: BTreeMap<FrfType, BTreeMap<String, Rat>>,
    /// Types shown by continuity, with their paths.
    pub paths: BTreeMap<FrfType, super::MergePath>,
    /// Types shown at points over a real number field.
    pub algebraic: BTreeMap<FrfType, super::AlgebraicWitness>,
    /// Witnesses isolated in a box, for types with none of the above.
    pub isolated: BTreeMap<FrfType, super::IsolatedWitness>,
    memo: HashMap<(String, String), Option<Proof>>,
    /// The pole-sign premise, worked out when a stratum proof first fails
    /// (outer `None`: not yet; most models never need it).
    pole_signs: Option<Option<PoleSignData>>,
    /// The same for the block-product premise.
    block_pole_signs: Option<Option<BlockSignData>>,
    /// Its configurations with the late rules (directions from paired
    /// zeros and poles, Rolle on the numerator less the shared poles).
    late_configurations: Option<Option<Configurations>>,
    /// Sign conditions recur across sign cases, types and strata.
    conditions: ConditionCache,
    /// The partial walls the witness search visited, in order.
    pub partial_walls: Vec<Vec<Substitution>>,
}

/// What the sign conditions of [`OpenProof::SignConditions`] share: the
/// reduction of a derived condition (a factorization), the discriminant of
/// a part, and a condition's signs at the sample points of a stratum's
/// parameters ([`holds_at_a_sample`]). At six masses the same
/// discriminants and their factorizations were computed for every
/// assignment of every type.
#[derive(Default)]
pub(crate) struct ConditionCache {
    reduced: HashMap<Poly, (Poly, Poly, Poly)>,
    discriminants: HashMap<Poly, Poly>,
    /// By the stratum's parameters: the sample points, and each
    /// condition's exact signs there as far as they were needed.
    signs: HashMap<Vec<String>, SampleSigns>,
    /// [`eval_at_root`] by linear part, then by polynomial.
    at_roots: HashMap<Poly, HashMap<Poly, Poly>>,
}

struct SampleSigns {
    points: Vec<BTreeMap<String, Rat>>,
    approx: Vec<BTreeMap<String, f64>>,
    signs: HashMap<Poly, ConditionSigns>,
}

/// One condition at the sample points: whether its f64 value lets it
/// hold, and its exact signs as far as they were needed.
struct ConditionSigns {
    plausible: Vec<bool>,
    exact: Vec<Option<i32>>,
}

impl ConditionCache {
    /// [`eval_at_root`]`(q, l)`, computed once.
    fn at_root(&mut self, q: &Poly, l: &Poly) -> Poly {
        if let Some(v) = self.at_roots.get(l).and_then(|m| m.get(q)) {
            return v.clone();
        }
        let v = eval_at_root(q, l);
        self.at_roots
            .entry(l.clone())
            .or_default()
            .insert(q.clone(), v.clone());
        v
    }
}

/// How far the search goes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SearchLimits {
    /// Random samples on the whole orthant.
    pub samples: usize,
    /// Random samples on each wall.
    pub wall_samples: usize,
    /// Maximal number of nested walls.
    pub max_depth: usize,
    /// Maximal multiplier degree in the sign-condition LP.
    pub multiplier_degree: u32,
    /// Nesting of the partial walls the targeted search samples for types
    /// still unknown (0: none).
    pub partial_wall_depth: usize,
}

impl Default for SearchLimits {
    fn default() -> Self {
        SearchLimits {
            samples: 300,
            wall_samples: 60,
            max_depth: 4,
            multiplier_degree: 2,
            partial_wall_depth: 2,
        }
    }
}

impl<'a> Prover<'a> {
    pub(crate) fn new(model: &'a Model, num: Poly, den: Poly) -> Prover<'a> {
        let params = model.undamped_parameters();
        Prover {
            model,
            num,
            den,
            params,
            strata: HashMap::new(),
            witnesses: BTreeMap::new(),
            paths: BTreeMap::new(),
            algebraic: BTreeMap::new(),
            isolated: BTreeMap::new(),
            memo: HashMap::new(),
            pole_signs: None,
            block_pole_signs: None,
            late_configurations: None,
            conditions: ConditionCache::default(),
            partial_walls: Vec::new(),
        }
    }

    pub(crate) fn stratum(&mut self, subs: &[Substitution]) -> Rc<Stratum> {
        let probe = Stratum {
            subs: subs.to_vec(),
            vars: Vec::new(),
            num: Poly::zero(),
            den: Poly::zero(),
            num_parts: Vec::new(),
            den_parts: Vec::new(),
            factors: Vec::new(),
        };
        let key = probe.key();
        if let Some(s) = self.strata.get(&key) {
            return s.clone();
        }
        let s = Rc::new(build_stratum(
            &self.num,
            &self.den,
            &self.params,
            subs.to_vec(),
            &mut self.conditions.discriminants,
        ));
        self.strata.insert(key, s.clone());
        s
    }

    /// The type of the model at a full parameter point.
    pub(crate) fn type_at(&self, point: &BTreeMap<String, Rat>) -> Option<FrfType> {
        frf_type_at(&self.num, &self.den, OMEGA, point)
    }

    /// True when `t` has a witness of any kind: a rational point, a path,
    /// a point over a number field or one isolated in a box.
    pub(crate) fn shown(&self, t: &FrfType) -> bool {
        self.witnesses.contains_key(t)
            || self.paths.contains_key(t)
            || self.algebraic.contains_key(t)
            || self.isolated.contains_key(t)
    }

    /// Keeps the simplest witness of each type (fewest digits).
    pub(crate) fn record(&mut self, point: BTreeMap<String, Rat>) {
        if let Some(t) = self.type_at(&point) {
            self.offer(t, point);
        }
    }

    /// Keeps `point` as the witness of `t` (its exact type) if it is the
    /// simplest one yet.
    pub(super) fn offer(&mut self, t: FrfType, point: BTreeMap<String, Rat>) {
        let height =
            |p: &BTreeMap<String, Rat>| -> usize { p.values().map(|v| v.to_string().len()).sum() };
        match self.witnesses.get(&t) {
            Some(old) if height(old) <= height(&point) => {}
            _ => {
                self.witnesses.insert(t, point);
            }
        }
    }

    /// Samples the orthant and, recursively, every wall.
    pub(crate) fn search(&mut self, limits: &SearchLimits) {
        let mut visited = BTreeSet::new();
        let mut rng = Sampler::new(0x5EED);
        // The all-ones point first: simple witnesses where they exist.
        let ones: BTreeMap<String, Rat> =
            self.params.iter().map(|v| (v.clone(), Rat::ONE)).collect();
        self.record(ones);
        self.search_in(&[], limits, 0, &mut visited, &mut rng);
    }

    pub(crate) fn search_in(
        &mut self,
        subs: &[Substitution],
        limits: &SearchLimits,
        depth: usize,
        visited: &mut BTreeSet<String>,
        rng: &mut Sampler,
    ) {
        let s = self.stratum(subs);
        if !visited.insert(s.key()) {
            return;
        }
        let n = if depth == 0 {
            limits.samples
        } else {
            limits.wall_samples
        };
        let ones: BTreeMap<String, Rat> = s.vars.iter().map(|v| (v.clone(), Rat::ONE)).collect();
        self.record(full_point(subs, &ones));
        for _ in 0..n {
            let p = rng.point(&s.vars);
            self.record(full_point(subs, &p));
        }
        if depth >= limits.max_depth {
            return;
        }
        let walls: Vec<Substitution> = s.vanishing().filter_map(|f| f.wall.clone()).collect();
        for w in walls {
            let mut next = subs.to_vec();
            next.push(w);
            self.search_in(&next, limits, depth + 1, visited, rng);
        }
    }

    /// A certificate that `t` occurs nowhere on the stratum `subs`, or `None`.
    pub(crate) fn prove(
        &mut self,
        subs: &[Substitution],
        t: &FrfType,
        limits: &SearchLimits,
    ) -> Option<Proof> {
        let s = self.stratum(subs);
        let key = (s.key(), t.to_string());
        if let Some(p) = self.memo.get(&key) {
            return p.clone();
        }
        let p = self.prove_uncached(&s, t, limits);
        self.memo.insert(key, p.clone());
        p
    }

    fn prove_uncached(&mut self, s: &Stratum, t: &FrfType, limits: &SearchLimits) -> Option<Proof> {
        let r_s = s.den_degree();
        let r_t = t.resonances();
        if r_t > r_s {
            return Some(Proof {
                stratum: s.subs.clone(),
                open: OpenProof::TooManyResonances {
                    resonances: r_t,
                    degree: r_s,
                },
                factors: Vec::new(),
                unlisted: None,
            });
        }
        // Structural theorems, valid on the whole orthant and so on
        // every stratum: no factor needs a treatment.
        if t.has_multiple_resonance() {
            return Some(Proof {
                stratum: s.subs.clone(),
                open: OpenProof::SimpleResonances,
                factors: Vec::new(),
                unlisted: None,
            });
        }
        if self.model.is_collocated() && !t.is_rigid_body_interlacing() {
            let num_at_zero = self.num.subs(OMEGA, &Rat::ZERO);
            let den_at_zero = self.den.subs(OMEGA, &Rat::ZERO);
            if num_at_zero.orthant_sign().is_some() && den_at_zero.orthant_sign().is_some() {
                return Some(Proof {
                    stratum: s.subs.clone(),
                    open: OpenProof::CollocatedModes {
                        num_at_zero,
                        den_at_zero,
                    },
                    factors: Vec::new(),
                    unlisted: None,
                });
            }
        }
        // The strata first (they reproduce the paper's arguments where
        // those exist), the pole signs where the strata fail.
        if let Some(p) = self.stratum_proof(s, t, limits) {
            return Some(p);
        }
        let (model, num, den) = (self.model, &self.num, &self.den);
        let one = self
            .pole_signs
            .get_or_insert_with(|| pole_sign_data(model, num, den));
        let open = match one
            .as_ref()
            .filter(|d| t.resonances() == d.poles && !type_fits(d, t))
        {
            Some(d) => OpenProof::PoleSigns(d.certificate.clone()),
            None => {
                let d = self
                    .block_pole_signs
                    .get_or_insert_with(|| block_pole_sign_data(model, num, den))
                    .as_ref()
                    .filter(|d| !d.configurations.fits(t, d.zeros))?;
                OpenProof::BlockPoleSigns(d.certificate.clone())
            }
        };
        Some(Proof {
            stratum: s.subs.clone(),
            open,
            factors: Vec::new(),
            unlisted: None,
        })
    }

    /// The block pole-sign certificate with the late rules (each term's
    /// direction on a gap read from its zeros and poles paired across the
    /// gap, Rolle's bound on the numerator divided by the shared poles; see
    /// `configurations::monotone` and `configurations::rolle_spans`), for
    /// a type the witness searches have left unknown. It comes after them, not with the other proofs: the
    /// searches draw their random points per wanted type in turn, so a
    /// type proved before them would change what they find for others
    /// (this rule first made one witness of N5-g4-a5.1-s5.3 disappear).
    pub(crate) fn late_block_proof(&mut self, t: &FrfType) -> Option<Proof> {
        let (model, num, den) = (self.model, &self.num, &self.den);
        let d = self
            .block_pole_signs
            .get_or_insert_with(|| block_pole_sign_data(model, num, den))
            .as_ref()?;
        let late = self
            .late_configurations
            .get_or_insert_with(|| d.inputs.configurations(true))
            .as_ref()?;
        if t.has_multiple_resonance() || late.fits(t, d.zeros) {
            return None;
        }
        Some(Proof {
            stratum: Vec::new(),
            open: OpenProof::BlockPoleSigns(d.certificate.clone()),
            factors: Vec::new(),
            unlisted: None,
        })
    }

    /// A proof by the open part of `s` and the treatment of its factors.
    fn stratum_proof(&mut self, s: &Stratum, t: &FrfType, limits: &SearchLimits) -> Option<Proof> {
        let (r_s, r_t) = (s.den_degree(), t.resonances());
        let open = self.open_proof(s, t, limits)?;
        let lc_definite = s
            .factors
            .iter()
            .all(|f| !f.boundary || f.definite.is_some());
        let mut factors = Vec::new();
        let mut unlisted = None;
        for f in &s.factors {
            if let Some((sign, d)) = &f.definite {
                factors.push(FactorProof::Definite {
                    factor: f.poly.clone(),
                    sign: *sign,
                    definiteness: d.clone(),
                });
                continue;
            }
            if lc_definite && f.cancels && r_t == r_s {
                factors.push(FactorProof::NeedsNoCancellation {
                    factor: f.poly.clone(),
                });
                continue;
            }
            if lc_definite && !f.cancels && r_t < r_s {
                if f.poly.num_terms() > LARGEST_LISTED_FACTOR {
                    unlisted = Some(UnlistedRole::NeedsCancellation);
                } else {
                    factors.push(FactorProof::NeedsCancellation {
                        factor: f.poly.clone(),
                    });
                }
                continue;
            }
            let w = f.wall.clone()?;
            if s.subs.len() >= limits.max_depth {
                return None;
            }
            let mut next = s.subs.clone();
            next.push(w.clone());
            let proof = self.prove(&next, t, limits)?;
            factors.push(FactorProof::Wall {
                factor: f.poly.clone(),
                substitution: w,
                proof: Box::new(proof),
            });
        }
        Some(Proof {
            stratum: s.subs.clone(),
            open,
            factors,
            unlisted,
        })
    }

    fn open_proof(&mut self, s: &Stratum, t: &FrfType, limits: &SearchLimits) -> Option<OpenProof> {
        let r_s = s.den_degree();
        let r_t = t.resonances();
        if r_t < r_s {
            return Some(OpenProof::TooFewResonances {
                resonances: r_t,
                degree: r_s,
            });
        }
        if !multiplicities_fit(s, t) {
            return Some(OpenProof::Multiplicity);
        }
        if let Some(p) = descartes(s, t) {
            return Some(p);
        }
        if let Some((regions, types)) = self.regions(s) {
            if !types.contains(t) {
                return Some(regions);
            }
            return None;
        }
        sign_conditions(&mut self.conditions, s, t, limits)
    }

    /// The regions of the open part when the walls never cross, with their
    /// types.
    fn regions(&mut self, s: &Stratum) -> Option<(OpenProof, Vec<FrfType>)> {
        let vanishing: Vec<&CriticalFactor> = s.vanishing().collect();
        let ones: BTreeMap<String, Rat> = s.vars.iter().map(|v| (v.clone(), Rat::ONE)).collect();
        if vanishing.is_empty() {
            let point = full_point(&s.subs, &ones);
            let t = self.type_at(&point)?;
            let proof = OpenProof::Regions {
                var: None,
                walls: Vec::new(),
                gaps: Vec::new(),
                samples: vec![RegionSample {
                    point,
                    frf_type: t.clone(),
                }],
            };
            return Some((proof, vec![t]));
        }
        // All walls in one variable, pairwise ordered everywhere.
        'var: for x in &s.vars {
            let mut walls: Vec<Substitution> = Vec::new();
            for f in &vanishing {
                match wall_in(&f.poly, x) {
                    Some(w) => walls.push(w),
                    None => continue 'var,
                }
            }
            // Order by the sign of the cross difference.
            let mut order_ok = true;
            walls.sort_by(|a, b| {
                let d = &(&a.beta * &b.alpha) - &(&b.beta * &a.alpha); // sign of a - b
                if d.all_coefs_negative() {
                    std::cmp::Ordering::Less
                } else if d.all_coefs_positive() {
                    std::cmp::Ordering::Greater
                } else {
                    order_ok = false;
                    std::cmp::Ordering::Equal
                }
            });
            if !order_ok {
                continue;
            }
            let mut gaps = Vec::new();
            for w in walls.windows(2) {
                let d = &(&w[1].beta * &w[0].alpha) - &(&w[0].beta * &w[1].alpha);
                if !d.all_coefs_positive() {
                    continue 'var;
                }
                gaps.push(d);
            }
            let rest: BTreeMap<String, Rat> = ones
                .iter()
                .filter(|(k, _)| *k != x)
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect();
            let values: Vec<Rat> = walls
                .iter()
                .map(|w| Some(&w.beta.eval(&rest).ok()? / &w.alpha.eval(&rest).ok()?))
                .collect::<Option<Vec<Rat>>>()?;
            let mut xs = vec![&values[0] / &Rat::from(2)];
            for v in values.windows(2) {
                xs.push(&(&v[0] + &v[1]) / &Rat::from(2));
            }
            xs.push(&values[values.len() - 1] * &Rat::from(2));
            let mut samples = Vec::new();
            let mut types = Vec::new();
            for xv in xs {
                let mut p = rest.clone();
                p.insert(x.clone(), xv);
                let point = full_point(&s.subs, &p);
                let t = self.type_at(&point)?;
                self.witnesses
                    .entry(t.clone())
                    .or_insert_with(|| point.clone());
                types.push(t.clone());
                samples.push(RegionSample { point, frf_type: t });
            }
            let proof = OpenProof::Regions {
                var: Some(x.clone()),
                walls,
                gaps,
                samples,
            };
            return Some((proof, types));
        }
        None
    }
}

/// `f = alpha*x - beta` in the given variable with `alpha, beta` free of
/// subtraction and of one sign.
fn wall_in(f: &Poly, x: &str) -> Option<Substitution> {
    wall_of(f, &[x.to_string()])
}

/// Whether the multiplicities of `t` can be those of the open part of `s`.
fn multiplicities_fit(s: &Stratum, t: &FrfType) -> bool {
    let mut den_need: Vec<u32> = s
        .den_parts
        .iter()
        .flat_map(|(p, m)| std::iter::repeat_n(*m, p.degree(OMEGA) as usize))
        .collect();
    let mut den_have: Vec<u32> = t
        .tokens
        .iter()
        .filter(|k| k.feature == Feature::Resonance)
        .map(|k| k.multiplicity)
        .collect();
    den_need.sort();
    den_have.sort();
    if den_need != den_have {
        return false;
    }
    let mut num_avail: Vec<u32> = s
        .num_parts
        .iter()
        .flat_map(|(p, m)| std::iter::repeat_n(*m, p.degree(OMEGA) as usize))
        .collect();
    let total_avail = num_avail.len();
    let mut used = 0;
    for k in t
        .tokens
        .iter()
        .filter(|k| k.feature == Feature::Antiresonance)
    {
        match num_avail.iter().position(|m| *m == k.multiplicity) {
            Some(i) => {
                num_avail.remove(i);
                used += 1;
            }
            None => return false,
        }
    }
    // Without (nm) every zero is an antiresonance; with it, some is not.
    if t.nonminimum_phase {
        used < total_avail
    } else {
        used == total_avail
    }
}

/// Descartes' rule for a numerator part that alone supplies the type's
/// antiresonances of its multiplicity.
fn descartes(s: &Stratum, t: &FrfType) -> Option<OpenProof> {
    for (p, m) in &s.num_parts {
        if s.num_parts.iter().filter(|(_, k)| k == m).count() != 1 {
            continue;
        }
        let mut signs = Vec::new();
        for c in p.coeffs_in(OMEGA).iter().rev() {
            if c.is_zero() {
                continue;
            }
            if c.all_coefs_positive() {
                signs.push(1);
            } else if c.all_coefs_negative() {
                signs.push(-1);
            } else {
                signs.clear();
                break;
            }
        }
        if signs.is_empty() {
            continue;
        }
        let v = signs.windows(2).filter(|w| w[0] != w[1]).count() as u32;
        let needed = t.tokens.iter().filter(|k| k.is_zero_of(*m)).count() as u32;
        if needed > v || (v - needed) % 2 == 1 {
            return Some(OpenProof::Descartes {
                part: p.clone(),
                sign_changes: v,
                needed,
            });
        }
    }
    None
}

/// Writes `c` as `square^2 * positive * reduced` dropping factors whose
/// sign is known (even powers, subtraction-free factors).
pub(crate) fn reduce_condition(c: &Poly) -> (Poly, Poly, Poly) {
    let f = factor(c);
    let mut square = Poly::one();
    let mut positive = Poly::constant(f.unit.abs());
    let mut reduced = Poly::constant(Rat::from(f.unit.signum() as i64));
    for (g, e) in &f.factors {
        let half = e / 2;
        if half > 0 {
            square = &square * &g.pow(half);
        }
        if e % 2 == 1 {
            if g.all_coefs_positive() {
                positive = &positive * g;
            } else if g.all_coefs_negative() {
                positive = &positive * &(-g.clone());
                reduced = -reduced;
            } else {
                reduced = &reduced * g;
            }
        }
    }
    (square, positive, reduced)
}

struct LinearPart {
    poly: Poly,
    numerator: bool,
    multiplicity: u32,
}

/// Sign conditions from the rational roots, refuted per assignment.
fn sign_conditions(
    cache: &mut ConditionCache,
    s: &Stratum,
    t: &FrfType,
    limits: &SearchLimits,
) -> Option<OpenProof> {
    let linear: Vec<LinearPart> = s
        .num_parts
        .iter()
        .map(|(p, m)| (p, m, true))
        .chain(s.den_parts.iter().map(|(p, m)| (p, m, false)))
        .filter(|(p, _, _)| p.degree(OMEGA) == 1)
        .map(|(p, m, n)| LinearPart {
            poly: p.clone(),
            numerator: n,
            multiplicity: *m,
        })
        .collect();
    if linear.is_empty() {
        return None;
    }
    let feature = |n: bool| {
        if n {
            Feature::Antiresonance
        } else {
            Feature::Resonance
        }
    };
    // Enumerate assignments: each linear part to a token of its side and
    // multiplicity (distinct), or to "off the positive axis" (numerator, nm).
    let mut assignments: Vec<Vec<Option<usize>>> = vec![Vec::new()];
    for l in &linear {
        let mut next = Vec::new();
        for a in &assignments {
            for (i, k) in t.tokens.iter().enumerate() {
                if k.feature == feature(l.numerator)
                    && k.multiplicity == l.multiplicity
                    && !a.contains(&Some(i))
                {
                    let mut b = a.clone();
                    b.push(Some(i));
                    next.push(b);
                }
            }
            if l.numerator && t.nonminimum_phase {
                let mut b = a.clone();
                b.push(None);
                next.push(b);
            }
        }
        assignments = next;
    }
    let mut cases = Vec::new();
    for a in assignments {
        let conditions = conditions_for(cache, s, t, &linear, &a)?;
        let reduced: Vec<(Poly, bool)> = conditions
            .iter()
            .map(|c| (c.reduced.clone(), c.strict))
            .collect();
        if holds_at_a_sample(cache, &reduced, &s.vars) {
            return None;
        }
        // Constant multipliers settle most cases at little cost; before
        // the higher degrees, which fail slowly, a descent may show that no
        // combination exists.
        let multipliers = match positive_combination_in(&reduced, &s.vars, 0..=0) {
            Some(m) => m,
            None if limits.multiplier_degree == 0 => return None,
            None if holds_where_a_descent_ends(&reduced, &s.vars) => return None,
            None => positive_combination_in(&reduced, &s.vars, 1..=limits.multiplier_degree)?,
        };
        cases.push(SignCase {
            assignment: a,
            conditions,
            multipliers,
        });
    }
    Some(OpenProof::SignConditions {
        linear_parts: linear.iter().map(|l| l.poly.clone()).collect(),
        cases,
    })
}

/// Points tried before a linear program is set up for a sign case.
const CASE_SAMPLES: usize = 32;

/// Whether every condition (`> 0` when strict, else `>= 0`) holds at one
/// of a few sample points of the orthant, checked exactly. Then no positive
/// combination exists at any multiplier degree: it would be positive at
/// that point and yet have no positive coefficient. So the linear program,
/// which costs seconds at five masses, is known to fail without running it.
fn holds_at_a_sample(
    cache: &mut ConditionCache,
    conditions: &[(Poly, bool)],
    vars: &[String],
) -> bool {
    let known = cache.signs.entry(vars.to_vec()).or_insert_with(|| {
        let points = sample_points(vars);
        let approx = points
            .iter()
            .map(|p| p.iter().map(|(k, v)| (k.clone(), v.to_f64())).collect())
            .collect();
        SampleSigns {
            points,
            approx,
            signs: HashMap::new(),
        }
    });
    // f64 first, to skip the exact evaluation where it plainly fails: each
    // condition's values at all the points once per model, since the sign
    // cases of a model repeat the same conditions many times over.
    let n = known.points.len();
    let mut plausible = vec![true; n];
    for (g, _) in conditions {
        if !known.signs.contains_key(g) {
            let at = ConditionSigns {
                plausible: known
                    .approx
                    .iter()
                    .map(|x| g.eval_f64(x).is_ok_and(|v| v > -1e-9 * (1.0 + v.abs())))
                    .collect(),
                exact: vec![None; n],
            };
            known.signs.insert(g.clone(), at);
        }
        let at = &known.signs[g];
        for (p, q) in plausible.iter_mut().zip(&at.plausible) {
            *p &= *q;
        }
    }
    for j in (0..n).filter(|&j| plausible[j]) {
        let mut all = true;
        for (g, strict) in conditions {
            let slot = &mut known.signs.get_mut(g).expect("stored above").exact[j];
            let sign =
                *slot.get_or_insert_with(|| g.eval(&known.points[j]).map_or(-1, |v| v.signum()));
            if !(sign > 0 || (!strict && sign == 0)) {
                all = false;
                break;
            }
        }
        if all {
            return true;
        }
    }
    false
}

/// Log-uniform starts, Nelder-Mead descents and evaluations per descent of
/// [`holds_where_a_descent_ends`].
const DESCENT_SAMPLES: usize = 64;
const DESCENTS: usize = 2;
const DESCENT_EVALUATIONS: usize = 300;
/// Terms of all conditions together above which the descent is not tried:
/// on larger ones (the gap-0 chains at five masses, tens of thousands of
/// terms) it failed where it was tried and cost more than the simplices
/// it was meant to spare.
const DESCENT_TERMS: usize = 5000;

/// Like [`holds_at_a_sample`], at a point found by a descent instead: in
/// f64, Nelder-Mead raises the smallest of the conditions' relative values
/// (each divided by the sum of its terms' moduli) from the best of a few
/// log-uniform points; where it ends above zero, the point is rounded to
/// short rationals and every condition checked there exactly. A point
/// where all hold proves that no positive combination exists, so the
/// linear program, which fails at a cost of a quarter second at five
/// masses, is skipped; any other outcome leaves the decision to it.
fn holds_where_a_descent_ends(conditions: &[(Poly, bool)], vars: &[String]) -> bool {
    use super::targeted::{nelder_mead_for, short_rational};
    use crate::tf::Compiled;
    if conditions.iter().map(|(g, _)| g.num_terms()).sum::<usize>() > DESCENT_TERMS {
        return false;
    }
    let compiled: Vec<Compiled> = conditions
        .iter()
        .map(|(g, _)| Compiled::new(g, vars))
        .collect();
    let lowest = |lx: &[f64]| -> f64 {
        let x: Vec<f64> = lx.iter().map(|v| v.clamp(-30.0, 30.0).exp()).collect();
        compiled
            .iter()
            .map(|c| c.relative(&x))
            .fold(f64::INFINITY, f64::min)
    };
    let mut rng = XorShift::new(0x5165_1A7E);
    let mut starts: Vec<(f64, Vec<f64>)> = (0..DESCENT_SAMPLES)
        .map(|_| {
            let lx: Vec<f64> = vars
                .iter()
                .map(|_| 3.0 * (2.0 * rng.uniform() - 1.0))
                .collect();
            (lowest(&lx), lx)
        })
        .collect();
    starts.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, lx0) in starts.into_iter().take(DESCENTS) {
        let mut cost = |lx: &[f64]| -lowest(lx);
        let best = nelder_mead_for(&mut cost, &lx0, 1.0, -1e-3, DESCENT_EVALUATIONS);
        if lowest(&best) <= 1e-9 {
            continue;
        }
        let point: Option<BTreeMap<String, Rat>> = vars
            .iter()
            .zip(&best)
            .map(|(v, lx)| Some((v.clone(), short_rational(lx.clamp(-30.0, 30.0).exp(), 8)?)))
            .collect();
        let Some(point) = point else { continue };
        let holds = conditions.iter().all(|(g, strict)| {
            g.eval(&point)
                .is_ok_and(|v| v.signum() > 0 || (!strict && v.is_zero()))
        });
        if holds {
            return true;
        }
    }
    false
}

/// The points of [`holds_at_a_sample`]: all ones, then [`CASE_SAMPLES`]
/// drawn with a fixed seed.
fn sample_points(vars: &[String]) -> Vec<BTreeMap<String, Rat>> {
    let mut rng = Sampler::new(0xCA5E);
    let ones: BTreeMap<String, Rat> = vars.iter().map(|v| (v.clone(), Rat::ONE)).collect();
    let mut points = vec![ones];
    points.extend((0..CASE_SAMPLES).map(|_| rng.point(vars)));
    points
}

fn condition(
    cache: &mut ConditionCache,
    rule: ConditionRule,
    derived: Poly,
    strict: bool,
) -> SignCondition {
    let (square, positive, reduced) = match cache.reduced.get(&derived) {
        Some(r) => r.clone(),
        None => {
            let r = reduce_condition(&derived);
            cache.reduced.insert(derived.clone(), r.clone());
            r
        }
    };
    SignCondition {
        rule,
        derived,
        square,
        positive,
        reduced,
        strict,
    }
}

/// `q(rho) * a^deg(q)` for the root `rho = -b/a` of `l = a*Omega + b`.
pub(crate) fn eval_at_root(q: &Poly, l: &Poly) -> Poly {
    let c = l.coeffs_in(OMEGA);
    let (b, a) = (&c[0], &c[1]);
    let d = q.degree(OMEGA);
    let mut acc = Poly::zero();
    for (k, qk) in q.coeffs_in(OMEGA).iter().enumerate() {
        if qk.is_zero() {
            continue;
        }
        let term = &(qk * &(-b.clone()).pow(k as u32)) * &a.pow(d - k as u32);
        acc = &acc + &term;
    }
    acc
}

/// The conditions one assignment forces; `None` when the assignment is
/// inconsistent with the parts (then it needs no refutation... but we only
/// skip what the counting already excludes, so it is treated as unprovable).
fn conditions_for(
    cache: &mut ConditionCache,
    s: &Stratum,
    t: &FrfType,
    linear: &[LinearPart],
    a: &[Option<usize>],
) -> Option<Vec<SignCondition>> {
    let mut out = Vec::new();
    let lead = |l: &LinearPart| l.poly.coeffs_in(OMEGA)[1].orthant_sign();
    for (i, l) in linear.iter().enumerate() {
        let sa = lead(l)?;
        let b = l.poly.coeffs_in(OMEGA)[0].clone();
        match a[i] {
            Some(_) => {
                // rho = -b/a > 0
                let derived = (-b).scale(&Rat::from(sa as i64));
                out.push(condition(
                    cache,
                    ConditionRule::RootPositive { part: i },
                    derived,
                    true,
                ));
            }
            None => {
                let derived = b.scale(&Rat::from(sa as i64));
                out.push(condition(
                    cache,
                    ConditionRule::RootNotPositive { part: i },
                    derived,
                    false,
                ));
            }
        }
    }
    // Order between assigned linear parts.
    for i in 0..linear.len() {
        for j in 0..linear.len() {
            let (Some(ti), Some(tj)) = (a[i], a[j]) else {
                continue;
            };
            if ti >= tj {
                continue;
            }
            let (ci, cj) = (
                linear[i].poly.coeffs_in(OMEGA),
                linear[j].poly.coeffs_in(OMEGA),
            );
            // rho_j - rho_i = (b_i a_j - b_j a_i) / (a_i a_j)
            let d = &(&ci[0] * &cj[1]) - &(&cj[0] * &ci[1]);
            let sign = lead(&linear[i])? * lead(&linear[j])?;
            out.push(condition(
                cache,
                ConditionRule::RootOrder { lower: i, upper: j },
                d.scale(&Rat::from(sign as i64)),
                true,
            ));
        }
    }
    // Position of each assigned linear root relative to the one nonlinear
    // part of each side and multiplicity.
    let groups: Vec<(&Poly, bool, u32)> = s
        .num_parts
        .iter()
        .map(|(p, m)| (p, true, *m))
        .chain(s.den_parts.iter().map(|(p, m)| (p, false, *m)))
        .filter(|(p, _, _)| p.degree(OMEGA) >= 2)
        .collect();
    for (o, numerator, m) in &groups {
        if groups
            .iter()
            .filter(|(_, n2, m2)| n2 == numerator && m2 == m)
            .count()
            != 1
        {
            continue;
        }
        let feat = if *numerator {
            Feature::Antiresonance
        } else {
            Feature::Resonance
        };
        // The tokens of o: those of its side and multiplicity not taken by
        // linear parts.
        let taken: BTreeSet<usize> = a.iter().flatten().copied().collect();
        let slots: Vec<usize> = t
            .tokens
            .iter()
            .enumerate()
            .filter(|(i, k)| k.feature == feat && k.multiplicity == *m && !taken.contains(i))
            .map(|(i, _)| i)
            .collect();
        let d = o.degree(OMEGA);
        if slots.len() as u32 > d {
            return None;
        }
        let real_rooted = slots.len() as u32 == d;
        if real_rooted {
            // d real simple roots (off the walls): positive discriminant.
            let disc = kept_discriminant(&mut cache.discriminants, o);
            out.push(condition(
                cache,
                ConditionRule::RealRoots {
                    other: (*o).clone(),
                },
                disc,
                true,
            ));
        }
        let Some(slc) = o.lead_in(OMEGA).orthant_sign() else {
            continue;
        };
        for (i, l) in linear.iter().enumerate() {
            let Some(ti) = a[i] else { continue };
            let above = slots.iter().filter(|&&k| k > ti).count() as u32;
            let sa = lead(l)?;
            let sgn = slc
                * if above.is_multiple_of(2) { 1 } else { -1 }
                * if d.is_multiple_of(2) { 1 } else { sa };
            let derived = cache.at_root(o, &l.poly).scale(&Rat::from(sgn as i64));
            out.push(condition(
                cache,
                ConditionRule::SignAt {
                    other: (*o).clone(),
                    part: i,
                    derivative: 0,
                    roots_above: above,
                },
                derived,
                true,
            ));
            if real_rooted && (above == d || above == 0) {
                let mut q = (*o).clone();
                for k in 1..d {
                    q = q.derivative(OMEGA);
                    let dk = d - k;
                    let want = slc * if above == d && dk % 2 == 1 { -1 } else { 1 };
                    let sgn = want * if dk % 2 == 0 { 1 } else { sa };
                    let derived = cache.at_root(&q, &l.poly).scale(&Rat::from(sgn as i64));
                    out.push(condition(
                        cache,
                        ConditionRule::SignAt {
                            other: (*o).clone(),
                            part: i,
                            derivative: k,
                            roots_above: above,
                        },
                        derived,
                        true,
                    ));
                }
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::lp::positive_combination;
    use crate::xorshift::XorShift;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    /// The shortcut claims a point where every condition holds: the linear
    /// program, run by itself, must then find no combination at any degree.
    /// Random systems of two or three conditions, some satisfiable, some
    /// not.
    #[test]
    fn a_sample_where_the_conditions_hold_means_no_combination_exists() {
        let vars: Vec<String> = ["x", "y", "z"].map(String::from).to_vec();
        let monos = ["x", "y", "z", "x*y", "y*z", "x*z", "x^2", "1"];
        let mut rng = XorShift::new(7);
        let (mut shortcut, mut refuted) = (0, 0);
        for _ in 0..200 {
            let k = 2 + (rng.next_u64() % 2) as usize;
            let conditions: Vec<(Poly, bool)> = (0..k)
                .map(|_| {
                    let terms: Vec<String> = (0..3)
                        .map(|_| {
                            let c = (rng.next_u64() % 7) as i64 - 3;
                            format!("({c})*{}", monos[(rng.next_u64() % 8) as usize])
                        })
                        .collect();
                    (p(&terms.join(" + ")), !rng.next_u64().is_multiple_of(3))
                })
                .filter(|(g, _)| !g.is_zero())
                .collect();
            let combination = positive_combination(&conditions, &vars, 2);
            if holds_at_a_sample(&mut ConditionCache::default(), &conditions, &vars) {
                shortcut += 1;
                assert!(combination.is_none(), "{conditions:?}");
            } else if combination.is_some() {
                refuted += 1;
            }
        }
        // Both sides occur, so the assertion above was exercised.
        assert!(shortcut > 20 && refuted > 20, "{shortcut} {refuted}");
    }

    /// A thin wedge `y < x < 1.001 y` that the fixed samples miss: the
    /// descent finds a point in it, and the linear program, run all the
    /// same, confirms that no combination exists. The A2 pair, which
    /// contradicts itself, gives the descent no point.
    #[test]
    fn a_descent_into_a_thin_region_means_no_combination_exists() {
        let vars: Vec<String> = ["x", "y"].map(String::from).to_vec();
        let wedge = [(p("x - y"), true), (p("1001*y - 1000*x"), true)];
        assert!(!holds_at_a_sample(
            &mut ConditionCache::default(),
            &wedge,
            &vars
        ));
        assert!(holds_where_a_descent_ends(&wedge, &vars));
        assert!(positive_combination(&wedge, &vars, 2).is_none());
        let vars: Vec<String> = ["c12", "c23", "m1", "m2", "m3"].map(String::from).to_vec();
        let a2 = [
            (p("c12*m3 - c23*m1"), true),
            (p("c23*m1*(m2 - m3) - c12*m3*(m1 + m2)"), true),
        ];
        assert!(!holds_where_a_descent_ends(&a2, &vars));
        assert!(positive_combination(&a2, &vars, 1).is_some());
    }

    /// The design note's A2 pair contradicts itself: no point satisfies it
    /// (the combination exists), so the shortcut must not claim one.
    #[test]
    fn contradictory_conditions_hold_at_no_sample() {
        let vars: Vec<String> = ["c12", "c23", "m1", "m2", "m3"].map(String::from).to_vec();
        let conditions = [
            (p("c12*m3 - c23*m1"), true),
            (p("c23*m1*(m2 - m3) - c12*m3*(m1 + m2)"), true),
        ];
        assert!(!holds_at_a_sample(
            &mut ConditionCache::default(),
            &conditions,
            &vars
        ));
        assert!(holds_at_a_sample(
            &mut ConditionCache::default(),
            &conditions[..1],
            &vars
        ));
    }
}
