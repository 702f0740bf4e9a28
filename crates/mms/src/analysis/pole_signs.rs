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
//!
//! [`BlockPoleSigns`] extends the argument to a denominator that is the
//! product of several blocks' pole polynomials `p_B` (both sides of the
//! gap carry springs). The TF is `-Omega * sum_B n_B / d_B`, one term per
//! block, so at a pole of block `B` the numerator has the sign of `n_B`
//! times the other blocks' `p_B'`: those contribute how their spectra
//! interleave with the pole (the blocks share no parameter, so every
//! interleaving is enumerated), and `n_B`, or its pseudo-remainder by
//! `p_B`, factors into signs, `Omega` and determinants of runs of the
//! block's masses (principal minors, the anchors being runs of one),
//! whose eigenvalues interlace the block's (Cauchy). A run at an end of
//! the block is, with the run beyond its neighbour, the block less one
//! mass, whose eigenvalues take one gap between the block's each: the
//! run's own eigenvalues then lie in distinct gaps.

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

/// The data of a pole-sign certificate for a denominator that is the
/// product of several blocks' determinants (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlockPoleSigns {
    /// Every block whose term the TF has, in chain order.
    pub blocks: Vec<BlockSign>,
}

/// One block `B` of a [`BlockPoleSigns`] certificate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlockSign {
    /// The block's masses (1-based, consecutive).
    pub masses: Vec<usize>,
    /// `n_B = c_B^T adj(K_B - Omega*M_B) b_B`, the block's term of the
    /// receptance over its determinant.
    #[serde(serialize_with = "super::prover::ser_display")]
    pub numerator: Poly,
    /// Whether the factors below are those of the pseudo-remainder of
    /// `n_B` by the block's pole polynomial (else of `n_B` itself).
    pub remainder: bool,
    /// The factorization: `unit * prod factor^exponent`.
    #[serde(serialize_with = "super::prover::ser_display")]
    pub unit: poly::Rat,
    /// Its factors: of one sign, `Omega`, or a multiple of the
    /// determinant of a run of the block's masses (a principal minor).
    pub factors: Vec<RemainderFactor>,
}

/// Which certificate a [`PoleSignData`] carries.
#[derive(Clone, Debug)]
pub(crate) enum PoleSignCertificate {
    OneBlock(PoleSigns),
    Blocks(BlockPoleSigns),
}

/// What the prover keeps per model: the certificate data and the parity
/// patterns of every allowed anchor placement.
#[derive(Clone, Debug)]
pub(crate) struct PoleSignData {
    pub certificate: PoleSignCertificate,
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
                    certificate: PoleSignCertificate::OneBlock(PoleSigns {
                        remainder_unit: f.unit.clone(),
                        remainder_factors: f
                            .factors
                            .iter()
                            .map(|(g, k)| RemainderFactor {
                                factor: g.clone(),
                                exponent: *k,
                            })
                            .collect(),
                    }),
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

/// The chain's blocks: maximal runs of masses joined by springs (0-based).
fn chain_blocks(stiff: &[Vec<Poly>]) -> Vec<Vec<usize>> {
    let mut blocks: Vec<Vec<usize>> = Vec::new();
    for i in 0..stiff.len() {
        match blocks.last_mut() {
            Some(b) if !stiff[i - 1][i].is_zero() => b.push(i),
            _ => blocks.push(vec![i]),
        }
    }
    blocks
}

/// Cap on the configurations (interleavings times minor placements) the
/// block certificate enumerates; beyond it the prover gives up.
const MAX_CONFIGURATIONS: usize = 200_000;

/// One block's contribution to the signs at its own poles.
struct BlockSignInfo {
    /// Positive eigenvalues: the degree of the pole polynomial.
    poles: usize,
    /// Sign of the pole polynomial's leading coefficient in `Omega`.
    lead: i32,
    /// Every sign pattern `n_B` can have at the block's poles, over all
    /// placements of its minors' eigenvalues.
    patterns: Vec<Vec<i32>>,
}

/// The premise and the placements for a denominator that is a product of
/// block pole polynomials (see [`BlockPoleSigns`]), if they hold.
///
/// The TF is `-Omega * sum_B n_B / d_B` with `d_B` the determinant of
/// block `B` and `p_B` its pole polynomial (`d_B`, or `d_B/Omega` for a
/// free block). If `den = c * Omega^delta * prod_B p_B` with `c` free of
/// `Omega` and of one sign, then at a root `lambda` of `p_B` (simple,
/// positive, a root of no other `p_B'` unless a pole cancels)
/// `num(lambda) = -c lambda^(1+delta-f_B) n_B(lambda) prod_B' p_B'(lambda)`:
/// the other blocks contribute the sign of how their spectra interleave
/// with `lambda`, and `n_B(lambda)` that of where the eigenvalues of the
/// block's principal minors lie (Cauchy interlacing).
pub(crate) fn block_pole_sign_data(model: &Model, num: &Poly, den: &Poly) -> Option<PoleSignData> {
    let mass = model.mass_matrix();
    let stiff = model.stiffness_matrix();
    let (b, c) = (model.input_vector(), model.output_vector());
    let om = Poly::var(OMEGA);
    let pencil_of = |idx: &[usize]| -> Vec<Vec<Poly>> {
        idx.iter()
            .map(|&i| {
                idx.iter()
                    .map(|&j| &stiff[i][j] - &(&om * &mass[i][j]))
                    .collect()
            })
            .collect()
    };
    // (indices, d_B, p_B, free, n_B) of every block the TF has a term of.
    let mut parts = Vec::new();
    for blk in chain_blocks(&stiff) {
        let pencil = pencil_of(&blk);
        let adj = poly::adjugate(&pencil);
        let mut n_b = Poly::zero();
        for (ii, &i) in blk.iter().enumerate() {
            for (jj, &j) in blk.iter().enumerate() {
                if c[i] != 0 && b[j] != 0 {
                    n_b = &n_b + &adj[ii][jj].scale(&poly::Rat::from(c[i] * b[j]));
                }
            }
        }
        if n_b.is_zero() {
            continue;
        }
        let d = det(&pencil);
        let free = d.subs(OMEGA, &poly::Rat::ZERO).is_zero();
        let p = if free { d.div_exact(&om)? } else { d.clone() };
        parts.push((blk, d, p, free, n_b));
    }
    if parts.is_empty() {
        return None;
    }
    let prod_p = parts.iter().fold(Poly::one(), |acc, q| &acc * &q.2);
    let rest = den.div_exact(&prod_p)?.coeffs_in(OMEGA);
    let delta = rest.len() - 1;
    if rest[..delta].iter().any(|x| !x.is_zero()) {
        return None;
    }
    let c_sign = rest[delta].orthant_sign()?;
    // The identity num * prod d_B = -Omega * den * sum_B n_B prod_{B' != B} d_B'.
    let prod_d = parts.iter().fold(Poly::one(), |acc, q| &acc * &q.1);
    let mut sum = Poly::zero();
    for (k, q) in parts.iter().enumerate() {
        let others = parts
            .iter()
            .enumerate()
            .filter(|(l, _)| *l != k)
            .fold(Poly::one(), |acc, (_, r)| &acc * &r.1);
        sum = &sum + &(&q.4 * &others);
    }
    if num * &prod_d != -(&(&om * den) * &sum) {
        return None;
    }
    let num_at_zero = num.subs(OMEGA, &poly::Rat::ZERO).orthant_sign()?;
    let zeros = num.degree(OMEGA);
    let num_at_inf = num.coeffs_in(OMEGA)[zeros as usize].orthant_sign()?;
    let mut infos = Vec::new();
    let mut blocks = Vec::new();
    for (blk, _, p, free, n_b) in &parts {
        let poles = p.degree(OMEGA) as usize;
        let lead = p.coeffs_in(OMEGA)[poles].orthant_sign()?;
        let mut sign = BlockSign {
            masses: blk.iter().map(|i| i + 1).collect(),
            numerator: n_b.clone(),
            remainder: false,
            unit: poly::Rat::ONE,
            factors: Vec::new(),
        };
        if poles == 0 {
            blocks.push(sign);
            infos.push(BlockSignInfo {
                poles,
                lead,
                patterns: vec![Vec::new()],
            });
            continue;
        }
        // The determinants of the block's proper runs (principal minors).
        let mut minors = Vec::new();
        for start in 0..blk.len() {
            for end in start + 1..=blk.len() {
                if end - start < blk.len() {
                    minors.push((start, end - start, det(&pencil_of(&blk[start..end]))));
                }
            }
        }
        let direct = signed_factors(n_b, &minors);
        let (f, split, remainder) = match direct {
            Some(x) => (factor(n_b), x, false),
            None => {
                let (r, e) = pseudo_remainder(n_b, p, OMEGA);
                if r.is_zero() {
                    return None;
                }
                let (s, m) = signed_factors(&r, &minors)?;
                (factor(&r), (s * lead.pow(e), m), true)
            }
        };
        sign.remainder = remainder;
        sign.unit = f.unit.clone();
        sign.factors = f
            .factors
            .iter()
            .map(|(g, k)| RemainderFactor {
                factor: g.clone(),
                exponent: *k,
            })
            .collect();
        blocks.push(sign);
        let (base, odd_minors) = split;
        infos.push(BlockSignInfo {
            poles,
            lead,
            patterns: minor_patterns(blk.len(), *free, base, &odd_minors)?,
        });
    }
    let parities = interleaved_parities(&infos, -c_sign, num_at_zero, num_at_inf)?;
    Some(PoleSignData {
        certificate: PoleSignCertificate::Blocks(BlockPoleSigns { blocks }),
        poles: infos.iter().map(|i| i.poles as u32).sum(),
        zeros,
        parities,
    })
}

/// A minor with an odd exponent: `(first mass in the block, size, sign
/// of the multiple)`.
type OddMinor = (usize, usize, i32);

/// `p`'s factorization read as signs: the sign of everything but the
/// minors, and the minors with an odd exponent. `None` if a factor is
/// none of: of one sign, `Omega`, a rational multiple of a minor.
fn signed_factors(p: &Poly, minors: &[(usize, usize, Poly)]) -> Option<(i32, Vec<OddMinor>)> {
    let f = factor(p);
    let mut sign = f.unit.signum();
    let mut odd = Vec::new();
    let om = Poly::var(OMEGA);
    for (g, k) in &f.factors {
        if g.degree(OMEGA) == 0 {
            sign *= g.orthant_sign()?.pow(*k);
        } else if *g != om {
            let (start, len, s) = minors
                .iter()
                .find_map(|(st, l, m)| ratio_sign(g, m).map(|s| (*st, *l, s)))?;
            if k % 2 == 1 {
                odd.push((start, len, s));
            }
        }
    }
    Some((sign, odd))
}

/// The sign patterns of `n_B` at the block's poles: `base` times, for
/// each minor, its multiple's sign and `(-1)^(eigenvalues of the minor
/// below the pole)`, over every placement Cauchy's interlacing allows
/// (the `i`-th of `k` eigenvalues of a minor of a size-`n` block lies
/// strictly between the block's eigenvalues `i` and `i+n-k`, 1-based;
/// strictly, since an eigenvalue on a pole would cancel it).
fn minor_patterns(
    size: usize,
    free: bool,
    base: i32,
    minors: &[OddMinor],
) -> Option<Vec<Vec<i32>>> {
    let first = usize::from(free) + 1;
    let mut patterns: Vec<Vec<i32>> = vec![vec![base; size + 1 - first]];
    for &(start, k, s) in minors {
        // Slots: eigenvalue i lies between block eigenvalues j and j+1. A
        // run at an end of the block is, with the run beyond the mass next
        // to it, the block with one mass removed, whose eigenvalues
        // interlace the block's one per slot: its own take distinct slots.
        let distinct = start == 0 || start + k == size;
        let mut slots: Vec<Vec<usize>> = Vec::new();
        let mut cur = Vec::with_capacity(k);
        fill_slots(size, k, 1, 1, &mut cur, &mut slots);
        if distinct {
            slots.retain(|sl| sl.windows(2).all(|w| w[0] < w[1]));
        }
        let mut next = Vec::new();
        for pat in &patterns {
            for sl in &slots {
                let v: Vec<i32> = pat
                    .iter()
                    .enumerate()
                    .map(|(q, x)| {
                        let m = first + q;
                        let below = sl.iter().filter(|&&j| j < m).count();
                        x * s * if below % 2 == 1 { -1 } else { 1 }
                    })
                    .collect();
                if !next.contains(&v) {
                    next.push(v);
                }
            }
        }
        if next.len() > MAX_CONFIGURATIONS {
            return None;
        }
        patterns = next;
    }
    Some(patterns)
}

/// Every nondecreasing `j_i` in `[i, i+n-k-1]` for `i = from..=k`.
fn fill_slots(
    n: usize,
    k: usize,
    i: usize,
    lo: usize,
    cur: &mut Vec<usize>,
    out: &mut Vec<Vec<usize>>,
) {
    if i > k {
        out.push(cur.clone());
        return;
    }
    for j in lo.max(i)..=(i + n - k - 1) {
        cur.push(j);
        fill_slots(n, k, i + 1, j, cur, out);
        cur.pop();
    }
}

/// The parity patterns over every interleaving of the blocks' poles and
/// every sign pattern of each block; `scale` is the sign of `-c`.
fn interleaved_parities(
    infos: &[BlockSignInfo],
    scale: i32,
    at_zero: i32,
    at_inf: i32,
) -> Option<Vec<Vec<bool>>> {
    let total: usize = infos.iter().map(|i| i.poles).sum();
    if total == 0 {
        return None;
    }
    let mut orders: Vec<Vec<usize>> = Vec::new();
    let mut left: Vec<usize> = infos.iter().map(|i| i.poles).collect();
    interleavings(&mut left, &mut Vec::new(), &mut orders);
    let combos: usize = orders.len() * infos.iter().map(|i| i.patterns.len()).product::<usize>();
    if combos > MAX_CONFIGURATIONS {
        return None;
    }
    let mut parities: Vec<Vec<bool>> = Vec::new();
    for order in &orders {
        let mut choice = vec![0usize; infos.len()];
        loop {
            let mut signs = vec![at_zero];
            let mut seen = vec![0usize; infos.len()];
            for &blk in order {
                let mut v = scale * infos[blk].patterns[choice[blk]][seen[blk]];
                seen[blk] += 1;
                for (other, info) in infos.iter().enumerate() {
                    if other != blk && info.poles > 0 {
                        let above = info.poles - seen[other];
                        v *= info.lead * if above % 2 == 1 { -1 } else { 1 };
                    }
                }
                signs.push(v);
            }
            signs.push(at_inf);
            let par: Vec<bool> = signs.windows(2).map(|w| w[0] != w[1]).collect();
            if !parities.contains(&par) {
                parities.push(par);
            }
            // Next choice (odometer).
            let mut i = 0;
            loop {
                if i == infos.len() {
                    break;
                }
                choice[i] += 1;
                if choice[i] < infos[i].patterns.len() {
                    break;
                }
                choice[i] = 0;
                i += 1;
            }
            if i == infos.len() {
                break;
            }
        }
    }
    parities.sort();
    Some(parities)
}

/// Every sequence of block labels with `left[b]` copies of `b`.
fn interleavings(left: &mut [usize], cur: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    if left.iter().all(|&l| l == 0) {
        out.push(cur.clone());
        return;
    }
    for b in 0..left.len() {
        if left[b] > 0 {
            left[b] -= 1;
            cur.push(b);
            interleavings(left, cur, out);
            cur.pop();
            left[b] += 1;
        }
    }
}
