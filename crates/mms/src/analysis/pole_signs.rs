//! The sign of the numerator at the poles, a certificate on the whole
//! orthant for models whose denominator is one chain block.
//!
//! When the denominator's `Omega`-dependence is the determinant `P` of one
//! unreduced tridiagonal block of `K - Omega*M` (a free block divided by
//! `Omega`), its roots `lambda_1 < ... < lambda_n` are real, simple and
//! positive. The pseudo-remainder `R` of the numerator by `P`
//! (`lc(P)^e * num = q*P + R`) has the numerator's sign at every pole, and
//! for the chains here it often factors into factors of one sign, powers
//! of `Omega`, and *anchors* `K_jj - Omega*M_jj`: a diagonal entry of the
//! block, whose ratio `rho_j = K_jj/M_jj` lies strictly between the
//! block's extreme eigenvalues (a Rayleigh quotient of an unreduced
//! tridiagonal matrix; `0` is the lowest eigenvalue of a free block). For
//! every placement of the anchors among the poles that allows, the signs
//! of the numerator at `0`, at each pole and at infinity fix the parity of
//! the number of antiresonances in every interval between poles; a type
//! with all `n` resonances (none cancelled: a pole where the numerator
//! vanishes cancels) that matches no placement cannot occur anywhere.
//!
//! At four masses this settles the models with the gap before the last
//! mass and the grounded ones with both ports at the ends, where the other
//! methods leave dozens of orderings undecided.

use super::frf_type::{Feature, FrfType};
use crate::model::Model;
use crate::tf::OMEGA;
use poly::{det, factor, Poly};
use serde::Serialize;

/// The data of a pole-sign certificate (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoleSigns {
    /// `R` as `unit * prod factor^exponent`.
    #[serde(serialize_with = "super::prover::ser_display")]
    pub remainder_unit: poly::Rat,
    /// The factors of `R` with their exponents.
    pub remainder_factors: Vec<RemainderFactor>,
}

/// One factor of the remainder.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RemainderFactor {
    /// The factor.
    #[serde(serialize_with = "super::prover::ser_display")]
    pub factor: Poly,
    /// Its exponent.
    pub exponent: u32,
}

/// What the prover keeps per model: the certificate data and the parity
/// patterns of every allowed anchor placement.
#[derive(Clone, Debug)]
pub(crate) struct PoleSignData {
    pub certificate: PoleSigns,
    /// Resonances (roots of the block's determinant on the positive axis).
    pub poles: u32,
    /// Degree of the numerator in `Omega`.
    pub zeros: u32,
    /// For every allowed placement: whether the number of antiresonances
    /// in interval `i` (below the first pole, between poles, above the
    /// last) is odd.
    pub parities: Vec<Vec<bool>>,
}

/// `(R, e)` with `lc(b)^e * a = q*b + R`, `deg R < deg b` in `x`.
pub(crate) fn pseudo_remainder(a: &Poly, b: &Poly, x: &str) -> (Poly, u32) {
    let n = b.degree(x);
    let lb = b.coeffs_in(x)[n as usize].clone();
    let mut r = a.clone();
    let mut e = 0;
    let xv = Poly::var(x);
    while !r.is_zero() && r.degree(x) >= n {
        let d = r.degree(x);
        let lr = r.coeffs_in(x)[d as usize].clone();
        r = &(&lb * &r) - &(&(&lr * &xv.pow(d - n)) * b);
        e += 1;
    }
    (r, e)
}

/// The premise and the placements for `model`'s `num/den`, if they hold.
pub(crate) fn pole_sign_data(model: &Model, num: &Poly, den: &Poly) -> Option<PoleSignData> {
    let mass = model.mass_matrix();
    let stiff = model.stiffness_matrix();
    let om = Poly::var(OMEGA);
    // The blocks: maximal runs linked by nonzero off-diagonal entries.
    let n = mass.len();
    let mut blocks: Vec<Vec<usize>> = vec![vec![0]];
    for i in 1..n {
        if stiff[i - 1][i].is_zero() {
            blocks.push(vec![i]);
        } else {
            blocks.last_mut().expect("a block").push(i);
        }
    }
    for b in &blocks {
        if b.len() < 2 {
            continue;
        }
        let pencil: Vec<Vec<Poly>> = b
            .iter()
            .map(|&i| {
                b.iter()
                    .map(|&j| &stiff[i][j] - &(&om * &mass[i][j]))
                    .collect()
            })
            .collect();
        let d = det(&pencil);
        let free = d.subs(OMEGA, &poly::Rat::ZERO).is_zero();
        let p = if free { d.div_exact(&om)? } else { d };
        let q = den.div_exact(&p)?;
        if q.degree(OMEGA) != 0 {
            continue;
        }
        return placements(b, free, num, &p, &mass, &stiff);
    }
    None
}

fn placements(
    block: &[usize],
    free: bool,
    num: &Poly,
    p: &Poly,
    mass: &[Vec<Poly>],
    stiff: &[Vec<Poly>],
) -> Option<PoleSignData> {
    let poles = p.degree(OMEGA);
    let zeros = num.degree(OMEGA);
    let lc_p = p.coeffs_in(OMEGA)[poles as usize].orthant_sign()?;
    let num_at_zero = num.subs(OMEGA, &poly::Rat::ZERO).orthant_sign()?;
    let num_at_inf = num.coeffs_in(OMEGA)[zeros as usize].orthant_sign()?;
    let (r, e) = pseudo_remainder(num, p, OMEGA);
    if r.is_zero() {
        return None;
    }
    let f = factor(&r);
    // Sign of R at a pole, as a constant times the anchors' signs.
    let mut sign = f.unit.signum();
    // Each anchor: the sign of the factor is `s * sign(rho - lambda)`.
    let mut anchors: Vec<i32> = Vec::new();
    for (g, k) in &f.factors {
        let d = g.degree(OMEGA);
        if d == 0 {
            let s = g.orthant_sign()?;
            sign *= s.pow(*k);
        } else if *g == Poly::var(OMEGA) {
            // Positive at every pole.
        } else if d == 1 && *k == 1 {
            let s = block.iter().find_map(|&j| {
                let diag = &stiff[j][j] - &(&Poly::var(OMEGA) * &mass[j][j]);
                ratio_sign(g, &diag)
            })?;
            anchors.push(s);
        } else {
            return None;
        }
    }
    let at_pole = sign * lc_p.pow(e);
    // Anchor placements: the number of poles below rho.
    let lowest = if free { 0 } else { 1 };
    if poles < 1 || (!anchors.is_empty() && lowest > poles - 1) {
        return None;
    }
    let mut parities: Vec<Vec<bool>> = Vec::new();
    let mut pos = vec![lowest; anchors.len()];
    loop {
        let mut ends = vec![num_at_zero];
        for i in 0..poles {
            let mut v = at_pole;
            for (s, k) in anchors.iter().zip(&pos) {
                // lambda_i lies above rho iff i >= k.
                v *= s * if i >= *k { -1 } else { 1 };
            }
            ends.push(v);
        }
        ends.push(num_at_inf);
        let par: Vec<bool> = ends.windows(2).map(|w| w[0] != w[1]).collect();
        if !parities.contains(&par) {
            parities.push(par);
        }
        // Next placement (odometer over lowest..poles).
        let mut i = 0;
        loop {
            if i == pos.len() {
                parities.sort();
                return Some(PoleSignData {
                    certificate: PoleSigns {
                        remainder_unit: f.unit.clone(),
                        remainder_factors: f
                            .factors
                            .iter()
                            .map(|(g, k)| RemainderFactor {
                                factor: g.clone(),
                                exponent: *k,
                            })
                            .collect(),
                    },
                    poles,
                    zeros,
                    parities,
                });
            }
            pos[i] += 1;
            if pos[i] < poles {
                break;
            }
            pos[i] = lowest;
            i += 1;
        }
    }
}

/// `g = c * h` with `c` a nonzero rational: the sign of `c`.
fn ratio_sign(g: &Poly, h: &Poly) -> Option<i32> {
    let (a, b) = (g.terms().first()?, h.terms().first()?);
    let c = &a.coef / &b.coef;
    (h.scale(&c) == *g).then(|| c.signum())
}

/// Whether `t` (all `poles` resonances, simple) matches one of the
/// placements: the antiresonance count in every interval has the parity
/// the signs force, and the positive zeros are all the numerator's zeros
/// exactly when `t` is not `(nm)`.
pub(crate) fn type_fits(data: &PoleSignData, t: &FrfType) -> bool {
    let mut counts = vec![0u32; data.poles as usize + 1];
    let mut j = 0;
    for tok in &t.tokens {
        match tok.feature {
            Feature::Resonance => j += 1,
            Feature::Antiresonance => counts[j.min(data.poles as usize)] += tok.multiplicity,
        }
    }
    let total: u32 = counts.iter().sum();
    if total > data.zeros || (total == data.zeros) == t.nonminimum_phase {
        return false;
    }
    data.parities
        .iter()
        .any(|par| par.iter().zip(&counts).all(|(odd, c)| *odd == (c % 2 == 1)))
}
