//! The configurations of the block pole-sign certificate: how the poles of
//! the chain's blocks and the eigenvalues of the blocks' principal minors
//! can lie on the positive axis, and what each order says about the
//! numerator's sign there (see [`super::pole_signs`]).
//!
//! Every block contributes its poles and the eigenvalues of the minors that
//! divide its term `n_B` (or the pseudo-remainder of `n_B` by the block's
//! pole polynomial). A minor's eigenvalues interlace the block's (Cauchy,
//! also for unions of minors no spring joins); one may sit *on* a pole,
//! which cancels it (a minor at an end of the block on at most `n - k - 1`
//! poles). The blocks share no parameter, so their sequences merge in
//! every order, two poles of different blocks possibly coinciding (a
//! shared eigenvalue: the double root of the denominator cancels once or,
//! where the terms' residues allow it, twice).
//!
//! Each configuration gives a list of *samples* in increasing order: the
//! reduced numerator's sign at `0`, at every pole that stays (unknown at a
//! shared one), at the eigenvalues of the minors of `n_B` (where `n_B`
//! vanishes, so only the other block's term is left) and at infinity. A
//! type fits a configuration if its antiresonances can be spread over the
//! gaps between samples with the parity every sign change demands, no
//! zero in a gap where all terms have one sign and at most one where all
//! are monotone one way; when the TF is one block's term and `n_B` a
//! product of minors, its zeros *are* the minors' eigenvalues and the
//! counts must match exactly.

use super::frf_type::{Feature, FrfType};
use std::collections::BTreeSet;

/// Configurations enumerated per model at most; beyond it the certificate
/// is not attempted.
const MAX_CONFIGURATIONS: usize = 400_000;

/// A minor of a block: a run of its masses whose determinant divides the
/// block's term (or its remainder).
#[derive(Clone, Debug)]
pub(crate) struct Minor {
    /// First mass of the run, in the block (0-based).
    pub start: usize,
    /// Number of masses.
    pub len: usize,
    /// Sign of the rational multiple of the run's determinant.
    pub sign: i32,
    /// Exponent in the factorization.
    pub exponent: u32,
}

/// What a block brings to the configurations.
#[derive(Clone, Debug)]
pub(crate) struct BlockEvents {
    /// Masses in the block.
    pub size: usize,
    /// A free block: its lowest eigenvalue is the rigid-body `0`.
    pub free: bool,
    /// Sign of the pole polynomial's leading coefficient in `Omega`.
    pub lead: i32,
    /// The factors are those of `n_B` itself (its zeros are the minors'
    /// eigenvalues), not of its pseudo-remainder.
    pub direct: bool,
    /// Sign of the factorization apart from the minors (at the block's
    /// poles; also elsewhere when `direct`).
    pub base: i32,
    pub minors: Vec<Minor>,
    /// `+1` when the sensor reads the block as the actuator drives it
    /// (`c_B = b_B`), `-1` for `c_B = -b_B`, else `0`: a collocated term
    /// `c_B^T P_B^-1 b_B` has the derivative `(P_B^-1 b_B)^T M_B (P_B^-1
    /// b_B)` times that sign, so it is monotone between its poles.
    pub collocated: i32,
    /// The power of `Omega` dividing `n_B`.
    pub omega_power: u32,
    /// The degree of `n_B` in `Omega`.
    pub degree: u32,
}

impl BlockEvents {
    fn first_pole(&self) -> usize {
        1 + usize::from(self.free)
    }
}

/// One sample of a configuration.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) enum Sample {
    /// A pole of the reduced TF, with the reduced numerator's sign there
    /// if it is known.
    Pole(Option<i8>),
    /// A point that is no pole, with the reduced numerator's sign.
    Point(i8),
    /// `k` zeros of the numerator at one point (exact mode only).
    Zeros(u32),
    /// The open gap between the samples before and after holds at most
    /// this many zeros (`0`: every block's term has one and the same sign
    /// there; `1`, and simple: every term is strictly monotone there, all
    /// in one direction).
    AtMost(u32),
    /// The open interval between the `from`-th and the `to`-th end (the
    /// ends are `0`, the resonances in order, and infinity) holds at most
    /// `most` zeros of the numerator, with multiplicity (Rolle, see
    /// [`rolle_spans`]). Listed after the other samples.
    Span { from: u32, to: u32, most: u32 },
}

/// All configurations of a model, as sample lists.
#[derive(Clone, Debug)]
pub(crate) struct Configurations {
    /// The zeros are exactly the `Zeros` samples (one block, `n_B` a
    /// product of minors); `nm` is then whether the numerator vanishes at
    /// `Omega = 0`.
    pub exact: Option<bool>,
    pub patterns: BTreeSet<Vec<Sample>>,
    /// Poles of the blocks together (the denominator's degree).
    pub poles: u32,
    /// The late rules: a multiple zero lies in one gap between samples.
    pub late: bool,
}

/// A token of one block's sequence.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Tok {
    /// A pole; `tied` lists the minors with an eigenvalue on it (it
    /// cancels if any), `sign` is `n_B`'s sign there when none.
    Pole { tied: Vec<usize>, sign: i32 },
    /// An eigenvalue of minor `minor` between poles.
    Eig { minor: usize },
}

/// The cell sequences of one minor's eigenvalues: cell `2j` is the block's
/// `j`-th eigenvalue (1-based), cell `2j+1` the gap above it. Eigenvalue
/// `i` of a run of `k` lies in `[lambda_i, lambda_(i+n-k)]` (Cauchy), never
/// on the block's lowest or highest eigenvalue (Perron-Frobenius, so never
/// on the rigid-body `0`); two never share a pole (the run's eigenvalues
/// are simple), and a run at an end of the block takes distinct cells
/// (with the run beyond its neighbour it is the block less one mass, whose
/// eigenvalues take one gap each).
fn minor_cells(b: &BlockEvents, m: &Minor) -> Vec<Vec<usize>> {
    let (n, k) = (b.size, m.len);
    let at_end = m.start == 0 || m.start + k == n;
    let mut out = Vec::new();
    let mut cur = Vec::with_capacity(k);
    fn grow(
        i: usize,
        n: usize,
        k: usize,
        first: usize,
        at_end: bool,
        cur: &mut Vec<usize>,
        out: &mut Vec<Vec<usize>>,
    ) {
        if i > k {
            out.push(cur.clone());
            return;
        }
        for cell in 2 * i..=2 * (i + n - k) {
            let on_pole = cell % 2 == 0;
            // Never on the rigid-body 0, and strictly inside the block's
            // extreme eigenvalues (Perron-Frobenius: a proper principal
            // submatrix of an irreducible tridiagonal matrix has its
            // extreme eigenvalues strictly inside).
            if on_pole && (cell / 2 < first.max(2) || cell / 2 == n) {
                continue;
            }
            if let Some(&last) = cur.last() {
                let strict = at_end || on_pole;
                if cell < last || (strict && cell == last) {
                    continue;
                }
            }
            cur.push(cell);
            grow(i + 1, n, k, first, at_end, cur, out);
            cur.pop();
        }
    }
    grow(1, n, k, b.first_pole(), at_end, &mut cur, &mut out);
    // An end run S shares at most n - k - 1 eigenvalues with the block:
    // split the block between S and its neighbour j, det P = det P_rest
    // det P_S - c^2 det P_(rest less j) det P_(S less its mass next to j); at a
    // common eigenvalue the last factor is nonzero (an end run of S
    // interlaces S strictly), so the eigenvalue is one of the n - k - 1 of
    // the block beyond j.
    if at_end {
        out.retain(|cells| cells.iter().filter(|c| *c % 2 == 0).count() < n - k);
    }
    out
}

/// Every token sequence of block `b` (the eigenvalues of a remainder's
/// minors only act through the poles' signs and ties, so they are left
/// out).
fn block_sequences(b: &BlockEvents, budget: &mut usize) -> Option<Vec<Vec<Tok>>> {
    let per_minor: Vec<Vec<Vec<usize>>> = b.minors.iter().map(|m| minor_cells(b, m)).collect();
    let mut out: Vec<Vec<Tok>> = Vec::new();
    let mut choice = vec![0usize; b.minors.len()];
    if per_minor.iter().any(|c| c.is_empty()) {
        return Some(out);
    }
    let unions = separated_unions(&b.minors);
    loop {
        // Cells of every eigenvalue: (cell, minor).
        let mut eigs: Vec<(usize, usize)> = Vec::new();
        for (m, cells) in per_minor.iter().enumerate() {
            eigs.extend(cells[choice[m]].iter().map(|&c| (c, m)));
        }
        if unions
            .iter()
            .all(|u| union_interlaces(b.size, &b.minors, u, &eigs))
            && end_ties_pair(b, &eigs)
        {
            block_variants(b, &eigs, budget, &mut out)?;
        }
        let mut i = 0;
        loop {
            if i == choice.len() {
                return Some(out);
            }
            choice[i] += 1;
            if choice[i] < per_minor[i].len() {
                break;
            }
            choice[i] = 0;
            i += 1;
        }
    }
}

/// A pole an end run's eigenvalue sits on is an eigenvalue of the run
/// beyond the end run's neighbour (see [`minor_cells`]); when that run is
/// a minor too (the driven mass of a collocated block between them), its
/// eigenvalue sits on the same pole.
fn end_ties_pair(b: &BlockEvents, eigs: &[(usize, usize)]) -> bool {
    let n = b.size;
    b.minors.iter().enumerate().all(|(m, s)| {
        let beyond = if s.start == 0 && s.len + 1 < n {
            (s.len + 1, n - s.len - 1)
        } else if s.start > 1 && s.start + s.len == n {
            (0, s.start - 1)
        } else {
            return true;
        };
        let Some(o) = b.minors.iter().position(|x| (x.start, x.len) == beyond) else {
            return true;
        };
        eigs.iter()
            .filter(|&&(c, mm)| mm == m && c % 2 == 0)
            .all(|&(c, _)| eigs.contains(&(c, o)))
    })
}

/// Every set of two or more minors whose runs are pairwise apart (no
/// spring joins two of them): the block matrix restricted to their union
/// is block diagonal, a principal submatrix whose eigenvalues are the
/// runs' together.
fn separated_unions(minors: &[Minor]) -> Vec<Vec<usize>> {
    let apart = |a: &Minor, b: &Minor| a.start + a.len < b.start || b.start + b.len < a.start;
    let mut out = Vec::new();
    for set in 1u32..1 << minors.len() {
        let members: Vec<usize> = (0..minors.len()).filter(|&m| set >> m & 1 == 1).collect();
        let ok = members.len() >= 2
            && members.iter().enumerate().all(|(i, &a)| {
                members[i + 1..]
                    .iter()
                    .all(|&c| apart(&minors[a], &minors[c]))
            });
        if ok {
            out.push(members);
        }
    }
    out
}

/// Cauchy interlacing for the union of the runs in `union` (`k` masses of
/// a block of `n`): its `i`-th smallest eigenvalue lies in `[lambda_i,
/// lambda_(i+n-k)]`, cells `2i` to `2(i+n-k)`. Stronger than each run's
/// own interlacing: the end runs of a chain seen off its driven mass can
/// not both lie below the first pole.
fn union_interlaces(n: usize, minors: &[Minor], union: &[usize], eigs: &[(usize, usize)]) -> bool {
    let k: usize = union.iter().map(|&m| minors[m].len).sum();
    let mut cells: Vec<usize> = eigs
        .iter()
        .filter(|(_, m)| union.contains(m))
        .map(|&(c, _)| c)
        .collect();
    cells.sort_unstable();
    cells
        .iter()
        .enumerate()
        .all(|(i, &c)| 2 * (i + 1) <= c && c <= 2 * (i + 1 + n - k))
}

/// The token sequences of one choice of the minors' cells, appended to
/// `out` (without repeats).
fn block_variants(
    b: &BlockEvents,
    eigs: &[(usize, usize)],
    budget: &mut usize,
    out: &mut Vec<Vec<Tok>>,
) -> Option<()> {
    let mut seq_variants: Vec<Vec<Tok>> = vec![Vec::new()];
    for j in b.first_pole()..=b.size {
        let tied: Vec<usize> = eigs
            .iter()
            .filter(|(c, _)| *c == 2 * j)
            .map(|(_, m)| *m)
            .collect();
        let mut sign = b.base;
        for (m, minor) in b.minors.iter().enumerate() {
            if minor.exponent % 2 == 1 {
                let below = eigs.iter().filter(|(c, mm)| *mm == m && *c < 2 * j).count();
                sign *= minor.sign * if below % 2 == 1 { -1 } else { 1 };
            }
        }
        for s in seq_variants.iter_mut() {
            s.push(Tok::Pole {
                tied: tied.clone(),
                sign,
            });
        }
        if b.direct && j < b.size {
            let mut in_gap: Vec<usize> = eigs
                .iter()
                .filter(|(c, _)| *c == 2 * j + 1)
                .map(|(_, m)| *m)
                .collect();
            in_gap.sort_unstable();
            let orders = permutations(&in_gap);
            let mut grown = Vec::with_capacity(seq_variants.len() * orders.len());
            for s in &seq_variants {
                for o in &orders {
                    let mut v = s.clone();
                    v.extend(o.iter().map(|&m| Tok::Eig { minor: m }));
                    grown.push(v);
                }
            }
            seq_variants = grown;
        }
    }
    // A free block's gap above the rigid-body 0 lies below its first
    // pole: move its eigenvalues to the front.
    if b.direct && b.free {
        let below: Vec<usize> = eigs
            .iter()
            .filter(|(c, _)| *c == 3)
            .map(|(_, m)| *m)
            .collect();
        if !below.is_empty() {
            let orders = permutations(&below);
            let mut grown = Vec::new();
            for s in &seq_variants {
                for o in &orders {
                    let mut v: Vec<Tok> = o.iter().map(|&m| Tok::Eig { minor: m }).collect();
                    v.extend(s.iter().cloned());
                    grown.push(v);
                }
            }
            seq_variants = grown;
        }
    }
    *budget = budget.checked_sub(seq_variants.len())?;
    for s in seq_variants {
        if !out.contains(&s) {
            out.push(s);
        }
    }
    Some(())
}

/// The distinct orders of a sorted multiset.
fn permutations(items: &[usize]) -> Vec<Vec<usize>> {
    if items.len() <= 1 {
        return vec![items.to_vec()];
    }
    let mut out = Vec::new();
    for i in 0..items.len() {
        if i > 0 && items[i] == items[i - 1] {
            continue;
        }
        let mut rest = items.to_vec();
        let x = rest.remove(i);
        for mut p in permutations(&rest) {
            p.insert(0, x);
            out.push(p);
        }
    }
    out
}

/// A token of a merged sequence.
#[derive(Clone, Debug)]
enum Merged {
    One(usize, Tok),
    /// Poles of two blocks at one point; the denominator's double root
    /// cancels once (`double == false`: a pole stays) or twice.
    Shared {
        tied: [Vec<usize>; 2],
        /// `n_B`'s sign there, per block (meaningful where untied).
        signs: [i32; 2],
        double: bool,
    },
}

/// Every merge of two blocks' sequences (`leads`: the signs of their pole
/// polynomials' leading coefficients).
///
/// Where two poles coincide, how often the double root of the
/// denominator cancels follows from the residues of the terms `T_B`
/// there: a tied pole (`n_B = 0` on it) has none, an untied one the sign
/// of `n_B` times that of `p_B'` (its leading sign, flipped once per pole
/// of the block above). Both tied: the sum has no pole, it cancels twice;
/// one tied: the other's residue stays, once; none: twice only if the
/// residues can add up to zero, of opposite signs.
fn merge(
    seqs: [&[Tok]; 2],
    leads: [i32; 2],
    pos: [usize; 2],
    cur: &mut Vec<Merged>,
    out: &mut Vec<Vec<Merged>>,
    budget: &mut usize,
) -> Option<()> {
    if pos[0] == seqs[0].len() && pos[1] == seqs[1].len() {
        *budget = budget.checked_sub(1)?;
        out.push(cur.clone());
        return Some(());
    }
    for b in 0..2 {
        if pos[b] < seqs[b].len() {
            cur.push(Merged::One(b, seqs[b][pos[b]].clone()));
            let mut next = pos;
            next[b] += 1;
            merge(seqs, leads, next, cur, out, budget)?;
            cur.pop();
        }
    }
    if let (Some(Tok::Pole { tied: t0, sign: s0 }), Some(Tok::Pole { tied: t1, sign: s1 })) =
        (seqs[0].get(pos[0]), seqs[1].get(pos[1]))
    {
        let residue = |b: usize, sign: i32| {
            let above = seqs[b][pos[b] + 1..]
                .iter()
                .filter(|t| matches!(t, Tok::Pole { .. }))
                .count();
            sign * leads[b] * if above % 2 == 1 { -1 } else { 1 }
        };
        let options: &[bool] = match (t0.is_empty(), t1.is_empty()) {
            (false, false) => &[true],
            (true, true) if residue(0, *s0) != residue(1, *s1) => &[false, true],
            _ => &[false],
        };
        for &double in options {
            cur.push(Merged::Shared {
                tied: [t0.clone(), t1.clone()],
                signs: [*s0, *s1],
                double,
            });
            merge(seqs, leads, [pos[0] + 1, pos[1] + 1], cur, out, budget)?;
            cur.pop();
        }
    }
    Some(())
}

/// What the configurations are enumerated from, kept so that they can be
/// enumerated again with the late rules without the algebra.
#[derive(Clone, Debug)]
pub(crate) struct ConfigurationInputs {
    pub blocks: Vec<BlockEvents>,
    pub scale: i32,
    pub at_zero: i32,
    pub at_inf: i32,
    pub nm_exact: bool,
}

impl ConfigurationInputs {
    /// [`configurations`] of these inputs.
    pub(crate) fn configurations(&self, late: bool) -> Option<Configurations> {
        configurations(
            &self.blocks,
            self.scale,
            self.at_zero,
            self.at_inf,
            self.nm_exact,
            late,
        )
    }
}

/// The configurations of `blocks` (one or two with a term in the TF):
/// `scale` is the sign of `-c`, `at_zero` and `at_inf` the numerator's
/// signs at `0` and infinity, `nm_exact` whether it vanishes at `0`.
/// `late`: the rules applied only to the types the witness searches leave
/// unknown (see `Prover::late_block_proof`): a term's direction on a gap
/// from its zeros and poles paired across the gap ([`monotone`]), else
/// only where all its zeros lie on one side and all its poles on the
/// other; and Rolle's bound also on the numerator divided by the shared
/// poles ([`rolle_spans`]).
fn configurations(
    blocks: &[BlockEvents],
    scale: i32,
    at_zero: i32,
    at_inf: i32,
    nm_exact: bool,
    late: bool,
) -> Option<Configurations> {
    let mut budget = MAX_CONFIGURATIONS;
    let seqs: Vec<Vec<Vec<Tok>>> = blocks
        .iter()
        .map(|b| block_sequences(b, &mut budget))
        .collect::<Option<_>>()?;
    let mut patterns = BTreeSet::new();
    let poles = blocks
        .iter()
        .map(|b| (b.size + 1 - b.first_pole()) as u32)
        .sum();
    match blocks.len() {
        1 => {
            let exact = blocks[0].direct;
            for s in &seqs[0] {
                let merged: Vec<Merged> = s.iter().map(|t| Merged::One(0, t.clone())).collect();
                patterns.insert(samples(
                    blocks, &merged, scale, at_zero, at_inf, exact, late,
                ));
            }
            Some(Configurations {
                exact: exact.then_some(nm_exact),
                patterns,
                poles,
                late,
            })
        }
        2 => {
            for a in &seqs[0] {
                for b in &seqs[1] {
                    let mut out = Vec::new();
                    let leads = [blocks[0].lead, blocks[1].lead];
                    merge(
                        [a, b],
                        leads,
                        [0, 0],
                        &mut Vec::new(),
                        &mut out,
                        &mut budget,
                    )?;
                    for m in out {
                        patterns.insert(samples(blocks, &m, scale, at_zero, at_inf, false, late));
                    }
                }
            }
            Some(Configurations {
                exact: None,
                patterns,
                poles,
                late,
            })
        }
        _ => None,
    }
}

/// The samples of one merged sequence.
#[allow(clippy::too_many_arguments)]
fn samples(
    blocks: &[BlockEvents],
    seq: &[Merged],
    scale: i32,
    at_zero: i32,
    at_inf: i32,
    exact: bool,
    late: bool,
) -> Vec<Sample> {
    let flip = |k: usize| if k % 2 == 1 { -1 } else { 1 };
    let is_pole = |t: &Merged, b: usize| match t {
        Merged::One(x, Tok::Pole { .. }) => *x == b,
        Merged::Shared { .. } => true,
        _ => false,
    };
    // Eigenvalues of minor `m` of block `b` strictly before position `p`.
    let eigs_before = |p: usize, b: usize, m: usize| -> usize {
        seq[..p]
            .iter()
            .map(|t| match t {
                Merged::One(x, Tok::Eig { minor }) if *x == b && *minor == m => 1,
                Merged::One(x, Tok::Pole { tied, .. }) if *x == b => {
                    tied.iter().filter(|&&y| y == m).count()
                }
                Merged::Shared { tied, .. } => tied[b].iter().filter(|&&y| y == m).count(),
                _ => 0,
            })
            .sum()
    };
    // The sign of n_B at a point that is none of its poles or zeros.
    let n_sign = |p: usize, b: usize| -> Option<i32> {
        let blk = &blocks[b];
        if !blk.direct {
            return None;
        }
        let mut s = blk.base;
        for (m, minor) in blk.minors.iter().enumerate() {
            if minor.exponent % 2 == 1 {
                s *= minor.sign * flip(eigs_before(p, b, m));
            }
        }
        Some(s)
    };
    let poles_after = |p: usize, b: usize| seq[p + 1..].iter().filter(|t| is_pole(t, b)).count();
    // Points where the reduced TF divides out a factor (Omega - lambda):
    // (position, times).
    let mut divided: Vec<(usize, u32)> = Vec::new();
    for (p, t) in seq.iter().enumerate() {
        match t {
            Merged::One(_, Tok::Pole { tied, .. }) if !tied.is_empty() => divided.push((p, 1)),
            Merged::Shared { double, .. } => divided.push((p, if *double { 2 } else { 1 })),
            _ => {}
        }
    }
    let reduce = |p: usize, s: i32| -> i32 {
        divided
            .iter()
            .filter(|(q, k)| *q > p && k % 2 == 1)
            .fold(s, |s, _| -s)
    };
    let odd_divisions = divided.iter().filter(|(_, k)| k % 2 == 1).count();
    // The numerator's sign at a pole of block `b` where `n_B` has the sign
    // `sign`, before the reduction: `-c n_B p_B'` with `p_B'` the other
    // block's pole polynomial, of its leading sign flipped once per pole
    // of it above.
    let pole_sign = |p: usize, b: usize, sign: i32| -> i32 {
        let mut s = scale * sign;
        for (o, blk) in blocks.iter().enumerate() {
            if o != b {
                s *= blk.lead * flip(poles_after(p, o));
            }
        }
        s
    };
    // The sign of block `b`'s residue at a pole of it where `n_B` has the
    // sign `sign` (as in [`merge`]).
    let residue =
        |p: usize, b: usize, sign: i32| -> i32 { sign * blocks[b].lead * flip(poles_after(p, b)) };
    // On the open gap below `seq[g]` (above the last token when `g` is
    // the length) the TF's zeros are those of `S = sum_B T_B`, `T_B = n_B /
    // d_B` (`d_B = Omega^free p_B`). If every term has one sign there, the
    // same, `S` has no zero there; if every term is strictly monotone in
    // one direction, `S` has at most one, simple. A term's sign needs all
    // of `n_B`'s zeros in the sequence (a direct block); its direction
    // comes from collocation, or from `d/dOmega log|T_B| = sum over the
    // zeros z of n_B of 1/(Omega - z) - sum over the roots r of d_B of
    // 1/(Omega - r)`, of one sign when all of `n_B`'s zeros (and `0` as
    // often as `Omega` divides it) lie on one side of the gap and all of
    // `d_B`'s on the other.
    // The sign of block `b`'s term on the gap below `seq[g]`.
    let term_sign = |g: usize, b: usize| -> Option<i32> {
        let poles_above = seq[g..].iter().filter(|t| is_pole(t, b)).count();
        Some(n_sign(g, b)? * blocks[b].lead * flip(poles_above))
    };
    let direction = |g: usize, b: usize| -> Option<i32> {
        let blk = &blocks[b];
        if blk.collocated != 0 {
            return Some(blk.collocated);
        }
        let sign = term_sign(g, b)?;
        if !late {
            let poles_below = seq[..g].iter().filter(|t| is_pole(t, b)).count();
            let poles = blk.size + 1 - blk.first_pole();
            let eigs: Vec<(usize, usize)> = (0..blk.minors.len())
                .map(|m| (eigs_before(g, b, m), blk.minors[m].len))
                .collect();
            let free = u32::from(blk.free);
            // n_B's zeros below, d_B's above (0 as often as in n_B at least).
            let rising = blk.omega_power >= free
                && eigs.iter().all(|&(below, all)| below == all)
                && poles_below == 0;
            // n_B's zeros above, d_B's below (0 as often as in n_B at most).
            let falling = blk.omega_power <= free
                && eigs.iter().all(|&(below, _)| below == 0)
                && poles_below == poles;
            return match (rising, falling) {
                (true, false) => Some(sign),
                (false, true) => Some(-sign),
                _ => None,
            };
        }
        // n_B's zeros less d_B's roots at each place (0 first), a
        // zero on a pole cancelling it.
        let mut net: Vec<i64> = vec![i64::from(blk.omega_power) - i64::from(blk.free)];
        for t in seq {
            let exp = |m: &usize| i64::from(blk.minors[*m].exponent);
            net.push(match t {
                Merged::One(x, Tok::Pole { tied, .. }) if *x == b => {
                    tied.iter().map(exp).sum::<i64>() - 1
                }
                Merged::Shared { tied, .. } => tied[b].iter().map(exp).sum::<i64>() - 1,
                Merged::One(x, Tok::Eig { minor }) if *x == b => exp(minor),
                Merged::One(..) => 0,
            });
        }
        let (below, above) = net.split_at(g + 1);
        match monotone(below, above) {
            Some(true) => Some(sign),
            Some(false) => Some(-sign),
            None => None,
        }
    };
    // The open interval from the gap below `seq[from]` to the gap below
    // `seq[to]`, across the tokens between them that give no sample
    // (`skipped`: eigenvalues of minors and poles a minor's eigenvalue
    // cancels, where no term has a pole, so each term is continuous
    // there). If every term has one sign on every gap of it, the same, and
    // one term has no token inside (so no zero either), `S` has no zero;
    // if every term is strictly monotone in one direction on every gap,
    // `S` is on the whole interval, with at most one zero, and a simple
    // one when one term's derivative has no zero inside: a collocated
    // term's never has, another's not where it has no token.
    let cap = |from: usize, to: usize, skipped: &[usize]| -> Option<u32> {
        let untouched = |b: usize| {
            !skipped
                .iter()
                .any(|&p| matches!(&seq[p], Merged::One(x, _) if *x == b))
        };
        let gaps = from..=to;
        if blocks.len() >= 2 && (0..blocks.len()).any(untouched) {
            let first = term_sign(from, 0);
            let same = |g: usize| (0..blocks.len()).all(|b| term_sign(g, b) == first);
            if first.is_some() && gaps.clone().all(same) {
                return Some(0);
            }
        }
        if !(0..blocks.len()).any(|b| blocks[b].collocated != 0 || untouched(b)) {
            return None;
        }
        let mut dirs = gaps.flat_map(|g| (0..blocks.len()).map(move |b| (g, b)));
        let first = dirs.next().and_then(|(g, b)| direction(g, b))?;
        dirs.all(|(g, b)| direction(g, b) == Some(first))
            .then_some(1)
    };
    let mut out = Vec::with_capacity(seq.len() + 2);
    // Positions of the poles that stay: the type's resonances.
    let mut resonances: Vec<usize> = Vec::new();
    // The gap index just past the last sample pushed, and the tokens
    // since then that gave none: the open interval from that sample to
    // the next is bounded only if no term has a pole inside it (a double
    // cancellation is two poles whose sum is regular).
    let mut next_gap: Option<usize> = None;
    let mut skipped: Vec<usize> = Vec::new();
    let mut broken = false;
    if !exact {
        out.push(Sample::Point((at_zero * flip(odd_divisions)) as i8));
        next_gap = Some(0);
    }
    for (p, t) in seq.iter().enumerate() {
        let len = out.len();
        match t {
            Merged::One(b, Tok::Pole { tied, sign }) => {
                if exact {
                    if tied.is_empty() {
                        out.push(Sample::Pole(None));
                    } else {
                        let k: u32 = tied.iter().map(|&m| blocks[*b].minors[m].exponent).sum();
                        if k > 1 {
                            out.push(Sample::Zeros(k - 1));
                        }
                    }
                    continue;
                }
                // A cancelled pole is an unknown point, where no term has
                // a pole.
                if tied.is_empty() {
                    out.push(Sample::Pole(Some(reduce(p, pole_sign(p, *b, *sign)) as i8)));
                    resonances.push(p);
                }
            }
            Merged::Shared {
                tied,
                signs,
                double,
            } => {
                if !double {
                    // The reduced numerator there is `num'` there: with
                    // two blocks `-c (n_B p_B'' + n_B' p_B)` up to positive
                    // factors, `p` the blocks' pole polynomials, whose terms
                    // have the signs of the blocks' residues times `p_B'
                    // p_B''`: known where those agree, or where one block's
                    // term has no pole (tied).
                    let from = match (tied[0].is_empty(), tied[1].is_empty()) {
                        (true, true) if residue(p, 0, signs[0]) == residue(p, 1, signs[1]) => {
                            Some(0)
                        }
                        (true, false) => Some(0),
                        (false, true) => Some(1),
                        _ => None,
                    };
                    let s = from.map(|b| reduce(p, pole_sign(p, b, signs[b])) as i8);
                    out.push(Sample::Pole(s));
                    resonances.push(p);
                }
            }
            Merged::One(b, Tok::Eig { minor }) => {
                if exact {
                    out.push(Sample::Zeros(blocks[*b].minors[*minor].exponent));
                    continue;
                }
                // n_B vanishes: num = -c * p_B * n_B' up to powers of Omega.
                let o = 1 - *b;
                // The first token on each side past this block's own
                // eigenvalues: if it is the other block's eigenvalue or a
                // cancelled pole of it (or a shared pole), all of them may
                // sit at one point, where the numerator vanishes to an
                // order the formula cannot see; the sample is dropped.
                let vanishing = |t: &Merged| match t {
                    Merged::One(x, Tok::Eig { .. }) => *x == o,
                    Merged::One(x, Tok::Pole { tied, .. }) => *x == o && !tied.is_empty(),
                    Merged::Shared { .. } => true,
                };
                let own_eig =
                    |t: &&Merged| matches!(t, Merged::One(x, Tok::Eig { .. }) if *x == *b);
                let right = seq[p + 1..].iter().find(|t| !own_eig(t));
                let left = seq[..p].iter().rev().find(|t| !own_eig(t));
                if !(right.is_some_and(vanishing) || left.is_some_and(vanishing)) {
                    if let Some(other) = n_sign(p, o) {
                        let s = scale * blocks[*b].lead * flip(poles_after(p, *b)) * other;
                        out.push(Sample::Point(reduce(p, s) as i8));
                    }
                }
            }
        }
        if out.len() > len {
            let at_most = match next_gap {
                Some(g) if !broken => cap(g, p, &skipped),
                _ => None,
            };
            if let Some(k) = at_most {
                out.insert(len, Sample::AtMost(k));
            }
            next_gap = Some(p + 1);
            skipped.clear();
            broken = false;
        } else {
            skipped.push(p);
            broken |= matches!(t, Merged::Shared { .. });
        }
    }
    if !exact {
        if let (Some(g), false) = (next_gap, broken) {
            if let Some(k) = cap(g, seq.len(), &skipped) {
                out.push(Sample::AtMost(k));
            }
        }
        out.push(Sample::Point(at_inf as i8));
        if blocks.len() == 2 {
            out.extend(rolle_spans(blocks, seq, &resonances, late));
        }
    }
    out
}

/// Bounds on the zeros between two resonances (or `0`, or infinity) by
/// Rolle's theorem: the numerator's positive zeros are those of `E = n_1
/// d_2 + n_2 d_1`. Where `A = n_a d_o` has degree below `k`, `E^(k) =
/// B^(k)` with `B = n_o d_a`, whose roots `x_1 <= ... <= x_D` all lie in
/// the sequence (the poles of block `a`, `0` for a free one, and the
/// eigenvalues of the minors of a direct `n_o`, `0` as often as `Omega`
/// divides it). The `i`-th root of `B^(k)` lies in `[x_i, x_(i+k)]`, and
/// `E` has at most `k` zeros more than `E^(k)` in an open interval. The
/// bound spans poles, which the gap rules cannot: for the grounded mass
/// beside a free chain seen end to end, `k = 2` and no four zeros fit
/// below the first resonance. One order lower, `E^(k-1)` is `B^(k-1)`
/// plus a constant of `A`'s leading sign, and where `B^(k-1)` has that
/// sign throughout, `E` has at most `k - 1` zeros; both bounds also for
/// `u^D E(1/u)`, whose zeros are the inverses.
///
/// With `late`, also on `E` divided by `Omega - lambda` for every pole
/// `lambda` the two blocks share: both products keep a factor of it (each
/// has one block's `d` as a factor), so `A`'s degree, and `k`, drop by
/// the number of shared poles, and `B`'s roots lose one copy of each. A
/// pole cancelled twice stays a zero of the quotient, not of the reduced
/// numerator, and is taken off the bound of the intervals it lies in. For
/// the grounded mass beside a free chain seen end to end, with the mass's
/// pole on the chain's `i`-th, the quotient is a constant plus `Omega`
/// times the chain's other two pole factors: no zero between those two.
fn rolle_spans(
    blocks: &[BlockEvents],
    seq: &[Merged],
    resonances: &[usize],
    late: bool,
) -> Vec<Sample> {
    let shared = seq
        .iter()
        .filter(|t| matches!(t, Merged::Shared { .. }))
        .count();
    let mut most = rolle_bounds(blocks, seq, resonances, false);
    if late && shared > 0 {
        let reduced = rolle_bounds(blocks, seq, resonances, true);
        for (row, other) in most.iter_mut().zip(reduced) {
            for (m, r) in row.iter_mut().zip(other) {
                *m = (*m).min(r);
            }
        }
    }
    let mut out = Vec::new();
    for (i, row) in most.iter().enumerate() {
        for (j, &m) in row.iter().enumerate() {
            if m != u32::MAX {
                out.push(Sample::Span {
                    from: i as u32,
                    to: j as u32,
                    most: m,
                });
            }
        }
    }
    out
}

/// The bounds of [`rolle_spans`] between every two ends (`u32::MAX`:
/// none), on `E` itself or, `reduced`, on `E` divided by the shared poles'
/// factors.
fn rolle_bounds(
    blocks: &[BlockEvents],
    seq: &[Merged],
    resonances: &[usize],
    reduced: bool,
) -> Vec<Vec<u32>> {
    let flip = |k: usize| if k % 2 == 1 { -1 } else { 1 };
    // The signs of `n_B`'s leading and lowest coefficients in `Omega`, when
    // its factors are its own: a run's determinant leads with `(-1)^len`
    // and is positive at `0` (a proper run is held by a spring).
    let n_signs = |b: &BlockEvents| -> Option<(i32, i32)> {
        b.direct.then(|| {
            b.minors.iter().fold((b.base, b.base), |(lead, low), m| {
                let run_lead = m.sign * flip(m.len);
                (
                    lead * run_lead.pow(m.exponent),
                    low * m.sign.pow(m.exponent),
                )
            })
        })
    };
    // The sign of `d_B` at `0+`: `p_B` has all its roots above `0`.
    let at_zero = |b: &BlockEvents| b.lead * flip(b.size - usize::from(b.free));
    // Positions on the sequence, shifted by one: `0` is the root at
    // `Omega = 0`, `seq.len() + 1` stands for infinity.
    let mut ends: Vec<usize> = vec![0];
    ends.extend(resonances.iter().map(|p| p + 1));
    ends.push(seq.len() + 1);
    let mut most: Vec<Vec<u32>> = vec![vec![u32::MAX; ends.len()]; ends.len()];
    // The shared poles divided out, and the places of those cancelled
    // twice (the quotient's own zeros there).
    let mut divided = 0;
    let mut doubles: Vec<usize> = Vec::new();
    if reduced {
        for (p, t) in seq.iter().enumerate() {
            if let Merged::Shared { double, .. } = t {
                divided += 1;
                if *double {
                    doubles.push(p + 1);
                }
            }
        }
    }
    for a in 0..2 {
        let o = 1 - a;
        let (ba, bo) = (&blocks[a], &blocks[o]);
        if !bo.direct {
            continue;
        }
        let Some(k) = ((ba.degree + bo.size as u32 + 1) as usize).checked_sub(divided) else {
            continue;
        };
        let mut roots: Vec<usize> = vec![0; usize::from(ba.free) + bo.omega_power as usize];
        let exp = |m: usize| bo.minors[m].exponent as usize;
        for (p, t) in seq.iter().enumerate() {
            let at = p + 1;
            match t {
                Merged::One(x, Tok::Pole { tied, .. }) => {
                    if *x == a {
                        roots.push(at);
                    } else {
                        tied.iter().for_each(|&m| roots.extend(vec![at; exp(m)]));
                    }
                }
                Merged::One(x, Tok::Eig { minor }) if *x == o => {
                    roots.extend(vec![at; exp(*minor)]);
                }
                Merged::One(..) => {}
                Merged::Shared { tied, .. } => {
                    if !reduced {
                        roots.push(at);
                    }
                    tied[o].iter().for_each(|&m| roots.extend(vec![at; exp(m)]));
                }
            }
        }
        let d = roots.len();
        if d + divided != bo.degree as usize + ba.size || k == 0 || k > d {
            continue;
        }
        roots.sort_unstable();
        let mut bound = |i: usize, j: usize, b: usize| {
            if b < d {
                // The quotient's zeros at poles cancelled twice inside.
                let (lo, hi) = (ends[i], ends[j]);
                let own = doubles.iter().filter(|&&at| lo < at && at < hi).count();
                let b = b.saturating_sub(own);
                most[i][j] = most[i][j].min(b as u32);
            }
        };
        for i in 0..ends.len() {
            for j in i + 1..ends.len() {
                let inside = (0..d - k)
                    .filter(|&t| roots[t] < ends[j] && roots[t + k] > ends[i])
                    .count();
                bound(i, j, k + inside);
            }
        }
        // One order lower, `E^(k-1) = B^(k-1) + (k-1)! lc(A)`: on an
        // interval no root of `B^(k-1)` reaches into, `B^(k-1)` has the sign
        // of `lc(B)` flipped once per root above; where that is the sign of
        // `lc(A)`, `E^(k-1)` has no zero there, so `E` has at most `k - 1`.
        // The same for `u^d E(1/u)` (the zeros `1/Omega`), whose `A` part
        // has the lower degree `d - z_A` when `A` has more roots at `0`
        // than `B` (`z_A > z_B`); its leading signs are `A`'s and `B`'s
        // at `0+`, and the roots of its `B` part are `1/x` for `B`'s
        // nonzero roots `x`.
        let (Some(na), Some(no)) = (n_signs(ba), n_signs(bo)) else {
            continue;
        };
        let k0 = k - 1;
        let (a_lead, b_lead) = (na.0 * bo.lead, no.0 * ba.lead);
        let za = ba.omega_power as usize + usize::from(bo.free);
        let ys: Vec<usize> = roots.iter().rev().filter(|&&r| r > 0).copied().collect();
        // The reversed A's degree, where it is below the reversed B's.
        let kt = (za + ys.len() > d).then(|| d - za);
        let (a_low, b_low) = (na.1 * at_zero(bo), no.1 * at_zero(ba));
        for i in 0..ends.len() {
            for j in i + 1..ends.len() {
                let (lo, hi) = (ends[i], ends[j]);
                if (0..d - k0).all(|t| roots[t + k0] <= lo || roots[t] >= hi) {
                    let above = (0..d - k0).filter(|&t| roots[t] >= hi).count();
                    if b_lead * flip(above) == a_lead {
                        bound(i, j, k0);
                    }
                }
                let Some(kt) = kt else { continue };
                if (0..ys.len() - kt).all(|t| ys[t] <= lo || ys[t + kt] >= hi) {
                    let below = (0..ys.len() - kt).filter(|&t| ys[t] <= lo).count();
                    if b_low * flip(below) == a_low {
                        bound(i, j, kt);
                    }
                }
                let inside = (0..ys.len().saturating_sub(kt + 1))
                    .filter(|&t| ys[t] > lo && ys[t + kt + 1] < hi)
                    .count();
                bound(i, j, kt + 1 + inside);
            }
        }
    }
    most
}

/// Whether a term `T = n / d` rises (`Some(true)`) or falls on an open
/// interval, from its zeros less its poles at each place below the
/// interval (`below`, in increasing order) and above it: `d/dOmega log|T|
/// = sum_z 1/(Omega - z) - sum_r 1/(Omega - r)`. Above the interval a pole
/// `r` and a zero `z >= r` together add `1/(r - Omega) - 1/(z - Omega) >=
/// 0`, and a pole alone adds more; below it a zero `z` and a pole `r <= z`
/// add `1/(Omega - z) - 1/(Omega - r) >= 0`, and a zero alone more. So
/// the term rises if, going up from the interval, the poles never fall
/// behind the zeros, and going down, the zeros never fall behind the
/// poles (each is matched to one nearer the interval); it falls in the
/// mirror case. Strictly, when any root is left: each pair at two places
/// adds a positive amount.
fn monotone(below: &[i64], above: &[i64]) -> Option<bool> {
    // Whether the running sum of `sign * n` over `places` stays >= 0.
    fn ahead<'a>(places: impl Iterator<Item = &'a i64>, sign: i64) -> bool {
        let mut lead = 0;
        places.into_iter().all(|n| {
            lead += sign * n;
            lead >= 0
        })
    }
    if below.iter().chain(above).all(|&n| n == 0) {
        return None;
    }
    let rising = ahead(above.iter(), -1) && ahead(below.iter().rev(), 1);
    let falling = ahead(above.iter(), 1) && ahead(below.iter().rev(), -1);
    match (rising, falling) {
        (true, false) => Some(true),
        (false, true) => Some(false),
        _ => None,
    }
}

impl Configurations {
    /// Whether `t` (simple resonances) fits some configuration; `zeros` is
    /// the numerator's degree.
    pub(crate) fn fits(&self, t: &FrfType, zeros: u32) -> bool {
        let mut counts = vec![0u32];
        // The zeros of each interval as they must lie together: one point
        // per token with the late rules (a multiple zero is in one gap),
        // else each zero on its own.
        let mut zero_points: Vec<Vec<u32>> = vec![Vec::new()];
        for tok in &t.tokens {
            match tok.feature {
                Feature::Resonance => {
                    if tok.multiplicity > 1 {
                        return true; // not this certificate's business
                    }
                    counts.push(0);
                    zero_points.push(Vec::new());
                }
                Feature::Antiresonance => {
                    *counts.last_mut().expect("one") += tok.multiplicity;
                    let points = zero_points.last_mut().expect("one");
                    if self.late {
                        points.push(tok.multiplicity);
                    } else {
                        points.extend(std::iter::repeat_n(1, tok.multiplicity as usize));
                    }
                }
            }
        }
        // Every cancelled pole divides out a zero: the reduced numerator
        // has degree `zeros - (poles - resonances)`, and the type is (nm)
        // exactly when it has fewer positive zeros.
        let resonances = counts.len() as u32 - 1;
        let Some(degree) = (zeros + resonances).checked_sub(self.poles) else {
            return false;
        };
        let total: u32 = counts.iter().sum();
        if resonances > self.poles || total > degree || (total < degree) != t.nonminimum_phase {
            return false;
        }
        if let Some(nm) = self.exact {
            return t.nonminimum_phase == nm && self.patterns.iter().any(|p| exact_fit(p, &counts));
        }
        self.patterns
            .iter()
            .any(|p| spans_fit(p, &counts) && parity_fit(p, &zero_points))
    }
}

/// Whether the antiresonances between every two ends the pattern bounds
/// are within the bound.
fn spans_fit(samples: &[Sample], counts: &[u32]) -> bool {
    samples.iter().all(|s| match *s {
        Sample::Span { from, to, most } => {
            let (from, to) = (from as usize, (to as usize).min(counts.len()));
            from >= to || counts[from..to].iter().sum::<u32>() <= most
        }
        _ => true,
    })
}

fn exact_fit(samples: &[Sample], counts: &[u32]) -> bool {
    let mut got = vec![0u32];
    for s in samples {
        match s {
            Sample::Pole(_) => got.push(0),
            Sample::Zeros(k) => *got.last_mut().expect("one") += k,
            Sample::Point(_) | Sample::AtMost(_) | Sample::Span { .. } => {}
        }
    }
    got == counts
}

/// Whether the antiresonances between the `i`-th and `(i+1)`-th pole,
/// `points[i]` (the multiplicity of each zero, in order), can be placed in
/// the gaps between samples, each zero in one gap, so that every gap
/// between two samples of known sign holds an odd number (with
/// multiplicity) exactly where the sign changes.
fn parity_fit(samples: &[Sample], points: &[Vec<u32>]) -> bool {
    let poles = samples
        .iter()
        .filter(|s| matches!(s, Sample::Pole(_)))
        .count();
    if poles + 1 != points.len() {
        return false;
    }
    // States: (interval, zeros of it placed, parity since the last known
    // sign, that sign).
    let first = match samples.first() {
        Some(Sample::Point(s)) => *s,
        _ => return false,
    };
    let mut states: BTreeSet<(usize, u32, u32, i8)> = BTreeSet::new();
    states.insert((0, 0, 0, first));
    let mut cap = None;
    for s in &samples[1..] {
        if let Sample::AtMost(k) = s {
            cap = Some(*k);
            continue;
        }
        if let Sample::Span { .. } = s {
            continue;
        }
        // Zeros in the gap before `s`.
        let mut next = BTreeSet::new();
        for &(i, used, par, last) in &states {
            let rest = &points[i][used as usize..];
            // Taking the next `j` zeros into this gap: their multiplicities.
            let takes = (0..=rest.len()).map(|j| (j as u32, rest[..j].iter().sum::<u32>()));
            for (j, z) in takes.take_while(|&(_, z)| cap.is_none_or(|k| z <= k)) {
                let (used, par) = (used + j, (par + z) % 2);
                let known = match s {
                    Sample::Point(x) | Sample::Pole(Some(x)) => Some(*x),
                    _ => None,
                };
                let (par, last) = match known {
                    Some(x) => {
                        if (x != last) != (par == 1) {
                            continue;
                        }
                        (0, x)
                    }
                    None => (par, last),
                };
                match s {
                    Sample::Pole(_) => {
                        if used as usize == points[i].len() {
                            next.insert((i + 1, 0, par, last));
                        }
                    }
                    _ => {
                        next.insert((i, used, par, last));
                    }
                }
            }
        }
        states = next;
        cap = None;
        if states.is_empty() {
            return false;
        }
    }
    states
        .iter()
        .any(|&(i, used, _, _)| i + 1 == points.len() && used as usize == points[i].len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parities_between_samples() {
        use Sample::*;
        // + at 0, pole with +, a point with -, pole with -, + at infinity.
        let p = vec![Point(1), Pole(Some(1)), Point(-1), Pole(Some(-1)), Point(1)];
        // Each interval's zeros, one point per token.
        let counts = |s: &str| {
            let t: FrfType = s.parse().unwrap();
            let mut c: Vec<Vec<u32>> = vec![Vec::new()];
            for k in &t.tokens {
                match k.feature {
                    Feature::Resonance => c.push(Vec::new()),
                    Feature::Antiresonance => c.last_mut().unwrap().push(k.multiplicity),
                }
            }
            c
        };
        // Between the poles the sign goes + -> - -> -: one zero at least.
        // ... and above the last pole from - to +: one more.
        assert!(!parity_fit(&p, &counts("RAR")));
        assert!(!parity_fit(&p, &counts("RR")));
        assert!(!parity_fit(&p, &counts("RRA")));
        assert!(parity_fit(&p, &counts("RARA")));
        assert!(parity_fit(&p, &counts("RAAARA")));
        assert!(!parity_fit(&p, &counts("RAARA")));
        // An unknown pole merges the parities of its two sides.
        let q = vec![Point(1), Pole(None), Point(-1)];
        assert!(parity_fit(&q, &counts("AR")));
        assert!(parity_fit(&q, &counts("RA")));
        assert!(!parity_fit(&q, &counts("R")));
        assert!(!parity_fit(&q, &counts("ARA")));
        // Two sign changes between the poles need a zero in each of two
        // gaps: two simple zeros fit, a double zero (in one gap) does not,
        // nor a double beside a simple one (three in all, odd) -- but a
        // triple zero and a simple one do.
        let r = vec![
            Point(1),
            Pole(Some(1)),
            Point(-1),
            Point(1),
            Pole(Some(1)),
            Point(1),
        ];
        assert!(parity_fit(&r, &counts("RAAR")));
        assert!(!parity_fit(&r, &counts("RA^2R")));
        assert!(!parity_fit(&r, &counts("RA^2AR")));
        assert!(parity_fit(&r, &counts("RA^3AR")));
        assert!(parity_fit(&r, &counts("RAA^3R")));
        // A cap of one zero in a gap keeps a double zero out of it.
        let capped = vec![Point(1), AtMost(1), Pole(Some(1)), Point(1)];
        assert!(parity_fit(&capped, &counts("R")));
        assert!(!parity_fit(&capped, &counts("A^2R")));
    }

    #[test]
    fn cells_follow_cauchy() {
        // A grounded block of 3, the run of its last two masses: the
        // eigenvalues lie in [l1, l2] and [l2, l3], in distinct cells.
        let b = BlockEvents {
            size: 3,
            free: false,
            lead: 1,
            direct: true,
            base: 1,
            minors: vec![],
            collocated: 0,
            omega_power: 0,
            degree: 0,
        };
        let m = Minor {
            start: 1,
            len: 2,
            sign: 1,
            exponent: 1,
        };
        let cells = minor_cells(&b, &m);
        // Cauchy: cells 2..=4 and 4..=6; strictly inside the extreme
        // eigenvalues (cells 2 and 6); increasing, not both on pole 2;
        // and never on pole 2 at all: an end run shares n - k - 1 = 0
        // eigenvalues with its block (the classic strict interlacing of a
        // Jacobi matrix less an end row).
        assert_eq!(cells, vec![vec![3, 5]]);
        // The run of the middle mass alone: anywhere strictly inside.
        let middle = Minor {
            start: 1,
            len: 1,
            sign: 1,
            exponent: 1,
        };
        assert_eq!(minor_cells(&b, &middle), vec![vec![3], vec![4], vec![5]]);
        // The first mass of a block of 4: up to n - k - 1 = 2 shared
        // eigenvalues, so its one eigenvalue may sit on pole 2 or 3 or in
        // any gap strictly inside.
        let b4 = BlockEvents { size: 4, ..b };
        let first = Minor {
            start: 0,
            len: 1,
            sign: 1,
            exponent: 1,
        };
        assert_eq!(
            minor_cells(&b4, &first),
            vec![vec![3], vec![4], vec![5], vec![6], vec![7]]
        );
    }

    #[test]
    fn end_run_ties_need_the_run_beyond() {
        // The free chain of 4 driven and seen at m2: n_B = det(m1) *
        // det(m3-m4). An eigenvalue of m3-m4 on a pole needs m1's there too.
        let b = BlockEvents {
            size: 4,
            free: true,
            lead: 1,
            direct: true,
            base: 1,
            minors: vec![
                Minor {
                    start: 0,
                    len: 1,
                    sign: 1,
                    exponent: 1,
                },
                Minor {
                    start: 2,
                    len: 2,
                    sign: 1,
                    exponent: 1,
                },
            ],
            collocated: 1,
            omega_power: 0,
            degree: 0,
        };
        // m3-m4 on pole 3 (cell 6) and m1 on it too: fine; m1 in a gap: not.
        assert!(end_ties_pair(&b, &[(6, 0), (5, 1), (6, 1)]));
        assert!(!end_ties_pair(&b, &[(5, 0), (5, 1), (6, 1)]));
        // m1 on a pole alone is fine as far as m3-m4 go, but m1 is an end
        // run too, and the run beyond its neighbour is m3-m4: not there.
        assert!(!end_ties_pair(&b, &[(6, 0), (5, 1), (7, 1)]));
        // Nobody on a pole.
        assert!(end_ties_pair(&b, &[(5, 0), (5, 1), (7, 1)]));
    }
}
