//! Inverse-dynamics identification (IDIM-LS) of a rigid body driven by a
//! measured force: the standard method of robot identification (Gautier
//! 1997; Janot, Gautier and Brunot, "Data Set and Reference Models of
//! EMPS", 2019), used by the time-domain diagnosis as a second method
//! independent of any simulation.
//!
//! The inverse dynamic model of one body with viscous and Coulomb friction
//! and a force offset is linear in its parameters:
//!
//! ```text
//! F(t) = M q''(t) + F_v q'(t) + F_c sign(q'(t)) + offset
//! ```
//!
//! 1. **Derivatives.** The measured position is low-pass filtered by a
//!    Butterworth filter run forward and backward (zero phase, so no lag
//!    enters the regressors), then differentiated by central differences.
//! 2. **Decimation.** Every column (the force and each regressor) is
//!    filtered by the same zero-phase low-pass at `0.8 fs / (2 d)` and one
//!    sample in `d` is kept: the force carries ripples the controller
//!    rejects and that the model does not explain.
//! 3. **Least squares** (normal equations with column scaling); standard
//!    deviations from the residual variance.
//! 4. **Selection.** The base model is the chain's own terms (`M q''` and,
//!    by default, `F_v q'`). Coulomb friction (`sign q'`, kind `friction`,
//!    parameter `coulomb_n`) and the offset (a constant, kind `offset`,
//!    parameter `force_n`) are added by forward selection: each must lower
//!    the force residual by the BIC price `ln n + margin` (`n ln(RSS_0 /
//!    RSS_1)`) and remove at least `min_share` of the residual energy.
//!
//! ```
//! use ident::diagnose::EffectKind;
//! use ident::idim::{idim_ls, IdimOptions};
//! // A 2 kg body with 3 N s/m viscous and 0.5 N Coulomb friction, moved
//! // along q(t) = sin(2 pi t) + 0.3 sin(6 pi t); the force is what the
//! // model needs.
//! let fs = 1000.0;
//! let w = 2.0 * std::f64::consts::PI;
//! let (mut q, mut f) = (Vec::new(), Vec::new());
//! for k in 0..4000 {
//!     let t = k as f64 / fs;
//!     let (x, v, a) = (
//!         (w * t).sin() + 0.3 * (3.0 * w * t).sin(),
//!         w * (w * t).cos() + 0.9 * w * (3.0 * w * t).cos(),
//!         -w * w * (w * t).sin() - 2.7 * w * w * (3.0 * w * t).sin(),
//!     );
//!     q.push(x);
//!     f.push(2.0 * a + 3.0 * v + 0.5 * v.signum());
//! }
//! let id = idim_ls(&f, &q, fs, &IdimOptions::default())?;
//! assert_eq!(id.effects[0].kind, EffectKind::CoulombFriction);
//! assert!((id.value("m").unwrap() / 2.0 - 1.0).abs() < 0.01);
//! assert!((id.value("coulomb_n").unwrap() / 0.5 - 1.0).abs() < 0.05);
//! # Ok::<(), ident::idim::IdimError>(())
//! ```

use crate::diagnose::{EffectKind, EffectVerdict};
use crate::evidence::{Evidence, RegressionEvidence};
use crate::fit::solve_spd;
use crate::selection::{forward_select, none, Trial};
use serde::Serialize;
use std::collections::BTreeMap;

/// Options of [`idim_ls`].
#[derive(Clone, Debug, PartialEq)]
pub struct IdimOptions {
    /// Corner of the zero-phase Butterworth filter of the position before
    /// differentiation, Hz; `None`: `fs / 10` (the authors' rule of thumb
    /// is at least 5 times the closed-loop bandwidth, 20 Hz for EMPS).
    pub cutoff_hz: Option<f64>,
    /// Order of the Butterworth filters (even).
    pub order: usize,
    /// Decimation factor `d` of the parallel filtering.
    pub decimation: usize,
    /// Fit a viscous friction term in the base model.
    pub viscous: bool,
    /// What an effect must gain beyond the BIC price of its parameter.
    pub margin: f64,
    /// The share of the residual energy an effect must remove as well.
    pub min_share: f64,
}

impl Default for IdimOptions {
    fn default() -> IdimOptions {
        IdimOptions {
            cutoff_hz: None,
            order: 4,
            decimation: 10,
            viscous: true,
            margin: 10.0,
            min_share: 0.05,
        }
    }
}

/// Why an inverse-dynamics identification cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IdimError {
    /// Bad samples or options.
    #[error("{0}")]
    Input(String),
    /// The regressors do not determine the parameters (no motion, no
    /// acceleration, or a velocity of one sign where the offset and the
    /// Coulomb force cannot be told apart).
    #[error("the inverse-dynamics regressors are singular: {0}")]
    Singular(String),
}

/// One estimated parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// `m` (mass or inertia), `viscous_ns_per_m`, `coulomb_n`, or
    /// `offset_n`.
    pub name: String,
    /// Least-squares value.
    pub value: f64,
    /// Its standard deviation (from the residual variance).
    pub std: f64,
}

/// The result of [`idim_ls`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InverseDynamics {
    /// Parameters of the selected model, in regressor order.
    pub estimates: Vec<Estimate>,
    /// Effects kept by the selection, in the order kept; `[none]` if the
    /// base model explains the force.
    pub effects: Vec<EffectVerdict>,
    /// Effects that did not earn their parameter.
    pub rejected: Vec<EffectVerdict>,
    /// Relative force error `|F - F_model| / |F|` of the base model.
    pub rel_err_before: f64,
    /// The same for the selected model.
    pub rel_err: f64,
    /// Samples after decimation.
    pub samples: usize,
    /// Position filter corner, Hz.
    pub cutoff_hz: f64,
    /// Decimation factor.
    pub decimation: usize,
    /// Order of the Butterworth filters.
    pub order: usize,
    /// Condition number of the scaled observation matrix.
    pub condition: f64,
}

impl InverseDynamics {
    /// The estimate called `name`, if the selected model has it.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.estimates
            .iter()
            .find(|e| e.name == name)
            .map(|e| e.value)
    }

    /// Relative force error of this model on another record (cross-test
    /// validation), with the same filters.
    pub fn validate(&self, force: &[f64], q: &[f64], fs: f64) -> Result<f64, IdimError> {
        let names: Vec<&str> = self.estimates.iter().map(|e| e.name.as_str()).collect();
        let (cols, y) = regressors(
            force,
            q,
            fs,
            self.cutoff_hz,
            self.order,
            self.decimation,
            &names,
        )?;
        let theta: Vec<f64> = self.estimates.iter().map(|e| e.value).collect();
        let pred: Vec<f64> = (0..y.len())
            .map(|k| cols.iter().zip(&theta).map(|(c, t)| c[k] * t).sum())
            .collect();
        Ok(rel_err(&y, &pred))
    }
}

/// Second-order sections `(b0, b1, b2, a1, a2)` of a low-pass
/// Butterworth filter of even `order` with corner `fc` at rate `fs`
/// (bilinear transform with a prewarped corner).
pub(crate) fn butterworth(order: usize, fc: f64, fs: f64) -> Vec<[f64; 5]> {
    let k = (std::f64::consts::PI * fc / fs).tan();
    (1..=order / 2)
        .map(|i| {
            // 2 zeta of the pole pair i of the analogue prototype.
            let two_zeta =
                2.0 * (std::f64::consts::PI * (2 * i - 1) as f64 / (2 * order) as f64).sin();
            let a0 = 1.0 + two_zeta * k + k * k;
            let b = k * k / a0;
            [
                b,
                2.0 * b,
                b,
                (2.0 * k * k - 2.0) / a0,
                (1.0 - two_zeta * k + k * k) / a0,
            ]
        })
        .collect()
}

/// One section over `x` in the order given (direct form II transposed),
/// started in the steady state of its first input (unit DC gain): the
/// serial pass the tests hold the chunked one against.
#[cfg(test)]
fn section<'a>(&[b0, b1, b2, a1, a2]: &[f64; 5], x: impl Iterator<Item = &'a mut f64>) {
    let mut x = x.peekable();
    let Some(x0) = x.peek().map(|v| **v) else {
        return;
    };
    let mut z2 = (b2 - a2) * x0;
    let mut z1 = (b1 - a1) * x0 + z2;
    for v in x {
        let u = *v;
        let y = b0 * u + z1;
        z1 = b1 * u - a1 * y + z2;
        z2 = b2 * u - a2 * y;
        *v = y;
    }
}

/// [`section`] forward over `x`, in chunks that run side by side: the
/// recursion is a chain of dependent operations per sample, so one chain
/// leaves the processor idle most of the time. Each chunk after the first
/// runs from a zero state; its output is then corrected by the free
/// response to its true start state (the previous chunk's end), which is
/// what superposition gives for a linear recursion. Equal to the serial
/// pass up to rounding.
fn section_chunked(coefficients: &[f64; 5], x: &mut [f64]) {
    let Some(&x0) = x.first() else {
        return;
    };
    section_chunked_from(coefficients, x, steady_state(coefficients, x0));
}

/// The state of a section in the steady state of a constant input `x0`
/// (unit DC gain): where a pass starts.
fn steady_state(&[_, b1, b2, a1, a2]: &[f64; 5], x0: f64) -> (f64, f64) {
    let z2 = (b2 - a2) * x0;
    ((b1 - a1) * x0 + z2, z2)
}

/// One sample of a section (direct form II transposed): the output for
/// input `u`, the state `z` moved on.
#[inline(always)]
fn step(&[b0, b1, b2, a1, a2]: &[f64; 5], (z1, z2): &mut (f64, f64), u: f64) -> f64 {
    let y = b0 * u + *z1;
    *z1 = b1 * u - a1 * y + *z2;
    *z2 = b2 * u - a2 * y;
    y
}

/// [`section_chunked`] from the state `start`; returns the state after
/// the last sample.
fn section_chunked_from(coefficients: &[f64; 5], x: &mut [f64], start: (f64, f64)) -> (f64, f64) {
    let n = x.len();
    let &[_, b1, b2, a1, a2] = coefficients;
    if n < 1024 {
        let mut z = start;
        for v in x.iter_mut() {
            *v = step(coefficients, &mut z, *v);
        }
        return z;
    }
    // The end state from the last two inputs and outputs.
    let (u1, u2) = (x[n - 2], x[n - 1]);
    // Four chunks, the last one taking the remainder.
    let len = n / 4;
    let longest = n - 3 * len;
    let step = |z: &mut (f64, f64), v: &mut f64| *v = step(coefficients, z, *v);
    // The free response `g` to a unit first state, a fifth chain beside
    // the chunks: `g[k]` is the output `k` samples on. A unit second state
    // moves into a unit first state in one sample, so its response is `g`
    // one sample late.
    let mut g = Vec::with_capacity(longest);
    let mut free = (1.0, 0.0);
    let mut next = |g: &mut Vec<f64>| {
        g.push(free.0);
        free = (free.1 - a1 * free.0, -a2 * free.0);
        free
    };
    // The first chunk starts from `start`, the others at zero.
    let mut z = [start, (0.0, 0.0), (0.0, 0.0), (0.0, 0.0)];
    let mut after_one_chunk = (1.0, 0.0);
    {
        let (c0, rest) = x.split_at_mut(len);
        let (c1, rest) = rest.split_at_mut(len);
        let (c2, c3) = rest.split_at_mut(len);
        let [z0, z1, z2, z3] = &mut z;
        for (((v0, v1), v2), v3) in c0
            .iter_mut()
            .zip(c1.iter_mut())
            .zip(c2.iter_mut())
            .zip(c3.iter_mut())
        {
            step(z0, v0);
            step(z1, v1);
            step(z2, v2);
            step(z3, v3);
            after_one_chunk = next(&mut g);
        }
        for v in &mut c3[len..] {
            step(z3, v);
            next(&mut g);
        }
    }
    // The states a unit first and second state reach after one chunk.
    let (p11, p21) = after_one_chunk;
    let (p12, p22) = (g[len - 1], -a2 * g[len - 2]);
    let (mut s1, mut s2) = z[0];
    for (c, &(e1, e2)) in z.iter().enumerate().skip(1) {
        // Each chunk's own samples only: the later chunks get the free
        // response through their own start states.
        let end = if c == 3 { n } else { (c + 1) * len };
        let chunk = &mut x[c * len..end];
        chunk[0] += s1;
        for ((v, a), b) in chunk[1..].iter_mut().zip(&g[1..]).zip(&g) {
            *v += a * s1 + b * s2;
        }
        (s1, s2) = (e1 + p11 * s1 + p12 * s2, e2 + p21 * s1 + p22 * s2);
    }
    let (y1, y2) = (x[n - 2], x[n - 1]);
    (b1 * u2 - a1 * y2 + b2 * u1 - a2 * y1, b2 * u2 - a2 * y2)
}

/// Zero-phase filtering: forward and backward, with `pad` samples of odd
/// reflection at each end so the ends carry no transient.
pub(crate) fn filtfilt(sections: &[[f64; 5]], x: &[f64], pad: usize) -> Vec<f64> {
    let n = x.len();
    let pad = pad.min(n - 1);
    let mut v = Vec::with_capacity(n + 2 * pad);
    v.extend((1..=pad).rev().map(|i| 2.0 * x[0] - x[i]));
    v.extend_from_slice(x);
    v.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
    for s in sections {
        section_chunked(s, &mut v);
    }
    // Backward: the reversed record, up to the last kept sample (the
    // leading padding's outputs are dropped), copied reversed at once.
    let mut w: Vec<f64> = v[pad..].iter().rev().copied().collect();
    for s in sections {
        section_chunked(s, &mut w);
    }
    w[pad..].iter().rev().copied().collect()
}

/// [`filtfilt`] by one section, for records of one length, with the
/// padding's share precomputed. Both passes are linear, so what the
/// padding contributes is a fixed linear function of the samples it
/// reflects: the forward pass's state at the record's start is a weighted
/// sum of the leading padding, and the backward pass's state at the
/// record's end is a linear map of the forward state there plus a
/// weighted sum of the trailing padding. Each filtering then runs the
/// section over the record only, twice, where [`filtfilt`] runs it over
/// the record and both paddings forward and over the record and one
/// padding backward (five times the record for a padding as long as it).
/// Equal to [`filtfilt`] up to rounding.
pub(crate) struct ZeroPhase {
    section: [f64; 5],
    /// The record length it is built for, and the padding.
    n: usize,
    pad: usize,
    /// `lead[k]`: the weight of the `k`-th padded sample before the record
    /// in the forward state at its start.
    lead: Vec<[f64; 2]>,
    /// The backward state at the record's end: `q` times the forward state
    /// there, plus `tail[i]` times the `i`-th padded sample after it.
    q: [[f64; 2]; 2],
    tail: Vec<[f64; 2]>,
}

impl ZeroPhase {
    /// The zero-phase filter of `section` for records of `n` samples with
    /// `pad` samples of odd reflection at each end (at most `n - 1`, as
    /// [`filtfilt`] takes).
    pub(crate) fn new(section: [f64; 5], n: usize, pad: usize) -> ZeroPhase {
        let pad = pad.min(n.saturating_sub(1));
        let [b0, b1, b2, a1, a2] = section;
        // The section as a state-space model on (z1, z2): z' = A z + B u,
        // y = z1 + b0 u; started in the steady state of its first input
        // u0, z = E u0.
        let a = |g: [f64; 2]| [-a1 * g[0] + g[1], -a2 * g[0]];
        let b = [b1 - a1 * b0, b2 - a2 * b0];
        let e = [(b1 - a1) + (b2 - a2), b2 - a2];
        // Powers of A applied to B, and A^pad E.
        let mut a_b = Vec::with_capacity(pad);
        let mut g = b;
        for _ in 0..pad {
            a_b.push(g);
            g = a(g);
        }
        let mut a_e = e;
        for _ in 0..pad {
            a_e = a(a_e);
        }
        let add = |x: [f64; 2], y: [f64; 2]| [x[0] + y[0], x[1] + y[1]];
        // Forward over the leading padding v_0 .. v_(pad-1), from E v_0:
        // z = A^pad E v_0 + sum_k A^(pad-1-k) B v_k.
        let mut lead: Vec<[f64; 2]> = (0..pad).map(|k| a_b[pad - 1 - k]).collect();
        if pad > 0 {
            lead[0] = add(lead[0], a_e);
        }
        // Backward over the forward outputs w_j of the trailing padding,
        // last first, from E w_(pad-1): z = sum_j M_j w_j with M_j = A^j B
        // (and A^pad E added to the last).
        let mut m = a_b;
        if pad > 0 {
            m[pad - 1] = add(m[pad - 1], a_e);
        }
        // w_j = C A^j z_end + sum_(i<=j) h_(j-i) t_i, with C = (1, 0) and h
        // the section's impulse response: q = sum_j M_j (C A^j), and
        // tail_i = sum_(j>=i) M_j h_(j-i), the section run backward in
        // time (from rest) over each component of M.
        let mut q = [[0.0; 2]; 2];
        let mut row = [1.0, 0.0];
        for mj in &m {
            for r in 0..2 {
                q[r][0] += mj[r] * row[0];
                q[r][1] += mj[r] * row[1];
            }
            row = [-a1 * row[0] - a2 * row[1], row[0]];
        }
        let mut tail = vec![[0.0; 2]; pad];
        for r in 0..2 {
            let mut z = (0.0, 0.0);
            for i in (0..pad).rev() {
                tail[i][r] = step(&section, &mut z, m[i][r]);
            }
        }
        ZeroPhase {
            section,
            n,
            pad,
            lead,
            q,
            tail,
        }
    }

    /// The zero-phase low-pass of `x` ([`filtfilt`] with this section and
    /// padding); a record of another length than the filter was built for
    /// is filtered by [`filtfilt`] itself.
    pub(crate) fn apply(&self, x: &[f64]) -> Vec<f64> {
        let (n, pad) = (self.n, self.pad);
        if x.len() != n || pad == 0 {
            return filtfilt(&[self.section], x, pad);
        }
        // The forward state at the record's start: v_k = 2 x_0 - x_(pad-k).
        let x0 = 2.0 * x[0];
        let mut start = (0.0, 0.0);
        for (k, w) in self.lead.iter().enumerate() {
            let v = x0 - x[pad - k];
            start.0 += w[0] * v;
            start.1 += w[1] * v;
        }
        let mut y = x.to_vec();
        let end = section_chunked_from(&self.section, &mut y, start);
        // The backward state at the record's end: t_i = 2 x_(n-1) - x_(n-2-i).
        let xn = 2.0 * x[n - 1];
        let mut back = (
            self.q[0][0] * end.0 + self.q[0][1] * end.1,
            self.q[1][0] * end.0 + self.q[1][1] * end.1,
        );
        for (i, w) in self.tail.iter().enumerate() {
            let t = xn - x[n - 2 - i];
            back.0 += w[0] * t;
            back.1 += w[1] * t;
        }
        y.reverse();
        section_chunked_from(&self.section, &mut y, back);
        y.reverse();
        y
    }
}

/// The decimated regressor columns named in `names` and the decimated
/// force.
fn regressors(
    force: &[f64],
    q: &[f64],
    fs: f64,
    cutoff_hz: f64,
    order: usize,
    decimation: usize,
    names: &[&str],
) -> Result<(Vec<Vec<f64>>, Vec<f64>), IdimError> {
    let bad = |s: String| Err(IdimError::Input(s));
    let n = q.len();
    if force.len() != n {
        return bad(format!("force has {} samples, position {n}", force.len()));
    }
    if !(fs.is_finite() && fs > 0.0) {
        return bad(format!("sample rate {fs} Hz must be positive and finite"));
    }
    if !(cutoff_hz > 0.0 && cutoff_hz < 0.5 * fs) {
        return bad(format!(
            "position filter corner {cutoff_hz} Hz must lie between 0 and fs/2 = {} Hz",
            0.5 * fs
        ));
    }
    if decimation == 0 || order == 0 || order % 2 == 1 {
        return bad("the decimation must be at least 1 and the order even".into());
    }
    if n < 20 * decimation.max(10) {
        return bad(format!("{n} samples are too few"));
    }
    if let Some(k) = q.iter().chain(force).position(|v| !v.is_finite()) {
        return bad(format!("sample {} is not finite", k % n));
    }
    // Long enough for the filters' transients (a few time constants).
    let pad = |fc: f64| ((3.0 * fs / fc).ceil() as usize).max(3 * order);
    let qf = filtfilt(&butterworth(order, cutoff_hz, fs), q, pad(cutoff_hz));
    let dt = 1.0 / fs;
    let mut qd = vec![0.0; n];
    let mut qdd = vec![0.0; n];
    for k in 1..n - 1 {
        qd[k] = (qf[k + 1] - qf[k - 1]) / (2.0 * dt);
        qdd[k] = (qf[k + 1] - 2.0 * qf[k] + qf[k - 1]) / (dt * dt);
    }
    // The end samples have one-sided differences only: copy the neighbours.
    qd[0] = qd[1];
    qd[n - 1] = qd[n - 2];
    qdd[0] = qdd[1];
    qdd[n - 1] = qdd[n - 2];
    let mut cols = Vec::with_capacity(names.len());
    for name in names {
        cols.push(match *name {
            "m" => qdd.clone(),
            "viscous_ns_per_m" => qd.clone(),
            "coulomb_n" => qd.iter().map(|v| sign(*v)).collect(),
            "offset_n" => vec![1.0; n],
            other => return bad(format!("unknown regressor '{other}'")),
        });
    }
    // Parallel filtering and decimation of every column and the force.
    let fd = 0.8 * fs / (2.0 * decimation as f64);
    let (sections, p) = (butterworth(order, fd, fs), pad(fd));
    let decimate = |x: &[f64]| -> Vec<f64> {
        let y = if decimation > 1 {
            filtfilt(&sections, x, p)
        } else {
            x.to_vec()
        };
        // Drop the ends where the differences and filters are one-sided.
        let skip = 2 * decimation;
        y[skip..n - skip]
            .iter()
            .step_by(decimation)
            .copied()
            .collect()
    };
    let cols = cols.iter().map(|c| decimate(c)).collect();
    Ok((cols, decimate(force)))
}

/// `sign` with 0 at 0.
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `|y - p| / |y|`.
fn rel_err(y: &[f64], p: &[f64]) -> f64 {
    let e: f64 = y.iter().zip(p).map(|(a, b)| (a - b) * (a - b)).sum();
    let s: f64 = y.iter().map(|a| a * a).sum();
    if s > 0.0 {
        (e / s).sqrt()
    } else {
        0.0
    }
}

/// Least squares of `y` on `cols`: parameters, standard deviations, RSS,
/// condition number of the column-scaled normal matrix (its square root).
fn least_squares(cols: &[&Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, Vec<f64>, f64, f64)> {
    let p = cols.len();
    let n = y.len();
    // Column scaling makes the normal equations well conditioned enough
    // for a handful of regressors of very different sizes.
    let scale: Vec<f64> = cols
        .iter()
        .map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt())
        .collect();
    if scale.iter().any(|&s| s.is_nan() || s <= 0.0) || n <= p {
        return None;
    }
    let mut a = vec![0.0; p * p];
    let mut g = vec![0.0; p];
    for i in 0..p {
        for j in 0..=i {
            let s: f64 = cols[i].iter().zip(cols[j]).map(|(a, b)| a * b).sum::<f64>()
                / (scale[i] * scale[j]);
            a[i * p + j] = s;
            a[j * p + i] = s;
        }
        g[i] = cols[i].iter().zip(y).map(|(a, b)| a * b).sum::<f64>() / scale[i];
    }
    let z = solve_spd(&a, &g, p)?;
    let theta: Vec<f64> = z.iter().zip(&scale).map(|(z, s)| z / s).collect();
    let rss: f64 = (0..n)
        .map(|k| {
            let e = y[k] - cols.iter().zip(&theta).map(|(c, t)| c[k] * t).sum::<f64>();
            e * e
        })
        .sum();
    // Diagonal of the inverse normal matrix, one column at a time.
    let var = rss / (n - p) as f64;
    let mut std = Vec::with_capacity(p);
    let mut cond_inv_max: f64 = 0.0;
    for i in 0..p {
        let mut e = vec![0.0; p];
        e[i] = 1.0;
        let col = solve_spd(&a, &e, p)?;
        std.push((var * col[i]).sqrt() / scale[i]);
        cond_inv_max = cond_inv_max.max(col.iter().map(|v| v.abs()).sum());
    }
    // ||A||_1 ||A^-1||_1 bounds the 2-norm condition number of the scaled
    // normal matrix; its square root is that of the observation matrix.
    let norm_a = (0..p)
        .map(|j| (0..p).map(|i| a[i * p + j].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    Some((theta, std, rss, (norm_a * cond_inv_max).sqrt()))
}

/// IDIM-LS of a rigid body: force `force[k]` (N, or N m) and position
/// `q[k]` (m, or rad) at rate `fs`; see the module documentation.
pub fn idim_ls(
    force: &[f64],
    q: &[f64],
    fs: f64,
    o: &IdimOptions,
) -> Result<InverseDynamics, IdimError> {
    if !(o.margin.is_finite() && (0.0..1.0).contains(&o.min_share)) {
        return Err(IdimError::Input(
            "the margin must be finite and the share in [0, 1)".into(),
        ));
    }
    let cutoff_hz = o.cutoff_hz.unwrap_or(0.1 * fs);
    let all = ["m", "viscous_ns_per_m", "coulomb_n", "offset_n"];
    let (cols, y) = regressors(force, q, fs, cutoff_hz, o.order, o.decimation, &all)?;
    let n = y.len();
    let chosen: Vec<usize> = if o.viscous { vec![0, 1] } else { vec![0] };
    let fit = |idx: &[usize]| {
        let c: Vec<&Vec<f64>> = idx.iter().map(|&i| &cols[i]).collect();
        least_squares(&c, &y)
    };
    let singular = |what: &str| IdimError::Singular(what.to_string());
    let (_, _, rss0, _) = fit(&chosen).ok_or_else(|| singular("no acceleration or velocity"))?;
    let y_energy: f64 = y.iter().map(|v| v * v).sum();
    let rel_err_before = (rss0 / y_energy).sqrt();
    let price = (n as f64).ln() + o.margin;
    let candidates = [(2, EffectKind::CoulombFriction), (3, EffectKind::Offset)];
    // Forward selection: the state is the chosen columns and their RSS.
    let selected = forward_select((chosen, rss0), |(chosen, rss_base), _, step| {
        // Each remaining effect added to the kept ones, refitted jointly.
        Ok::<_, IdimError>(
            candidates
                .iter()
                .filter(|(col, _)| !chosen.contains(col))
                .filter_map(|&(col, kind)| {
                    let mut idx = chosen.clone();
                    idx.push(col);
                    let (theta, _, rss, _) = fit(&idx)?;
                    let gain = n as f64 * (rss_base / rss).ln();
                    let share = 1.0 - rss / rss_base;
                    let score = if share >= o.min_share {
                        gain - price
                    } else {
                        (gain - price).min(-1.0)
                    };
                    let mut parameters = BTreeMap::new();
                    parameters.insert(
                        kind.parameter_name().unwrap_or("value").to_string(),
                        theta[idx.len() - 1],
                    );
                    Some(Trial {
                        verdict: EffectVerdict {
                            kind,
                            parameters,
                            evidence: Evidence::InverseDynamics(RegressionEvidence {
                                residual_before: (rss_base / y_energy).sqrt(),
                                residual_after: (rss / y_energy).sqrt(),
                                share,
                                bic_gain: gain,
                                price,
                            }),
                            score,
                            step,
                            unresolved: None,
                            standard_errors: Default::default(),
                        },
                        state: (idx, rss),
                    })
                })
                .collect(),
        )
    })?;
    let chosen = selected.state.0.clone();
    let rejected = selected.rejected.clone();
    let mut effects = selected.kept;
    let (theta, std, rss, condition) =
        fit(&chosen).ok_or_else(|| singular("the selected regressors are dependent"))?;
    // Effect parameters from the final joint fit.
    for e in &mut effects {
        let col = if e.kind == EffectKind::CoulombFriction {
            2
        } else {
            3
        };
        let at = chosen.iter().position(|&c| c == col).unwrap_or(0);
        for v in e.parameters.values_mut() {
            *v = theta[at];
        }
    }
    if effects.is_empty() {
        effects.push(none(&rejected));
    }
    let estimates = chosen
        .iter()
        .zip(theta.iter().zip(&std))
        .map(|(&c, (&value, &std))| Estimate {
            name: all[c].to_string(),
            value,
            std,
        })
        .collect();
    Ok(InverseDynamics {
        estimates,
        effects,
        rejected,
        rel_err_before,
        rel_err: (rss / y_energy).sqrt(),
        samples: n,
        cutoff_hz,
        decimation: o.decimation,
        order: o.order,
        condition,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform noise in [-0.5, 0.5) from a linear congruential generator.
    fn noise(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    fn largest(x: &[f64]) -> f64 {
        x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
    }

    /// The precomputed padding against [`filtfilt`] itself: equal up to
    /// rounding, with a padding shorter than the record and one cut to it,
    /// a corner whose response outlasts the record, and records long and
    /// short enough for the chunked and serial passes.
    #[test]
    fn zero_phase_equals_filtfilt() {
        let mut noise = noise(11);
        for (n, fc, offset) in [
            (4096, 0.122, 0.0),
            (4096, 0.122, 30.0),
            (4096, 8.0, 0.0),
            (5001, 25.0, -3.0),
            (700, 3.0, 1.0),
            (2, 10.0, 0.0),
        ] {
            let x: Vec<f64> = (0..n)
                .map(|k| offset + (k as f64 * 0.01).sin() + 0.1 * noise() + 1e-4 * k as f64)
                .collect();
            let sections = butterworth(2, fc, 4000.0);
            let pad = (3.0 * 4000.0 / fc) as usize;
            let z = ZeroPhase::new(sections[0], n, pad);
            let (a, b) = (z.apply(&x), filtfilt(&sections, &x, pad));
            let (scale, worst) = (largest(&x), worst_difference(&a, &b));
            assert_eq!(a.len(), n);
            // At the lowest corner the poles lie within 2e-4 of 1 and any
            // pass rounds at 1e-9 of the scale (the serial pass on the
            // record and on the record less its mean differ by that much).
            assert!(worst < 3e-9 * scale, "n {n}, fc {fc}: {worst:e}");
        }
    }

    /// The chunked passes against one serial pass each way over the whole
    /// padded record: equal up to rounding, for records shorter and
    /// longer than the chunking starts at, a large offset (the steady
    /// start), the fourth order (two sections in a row), and a corner so
    /// low that the free response outlasts a chunk (padding of the whole
    /// record, chunks of unequal length).
    #[test]
    fn chunked_filtfilt_equals_the_serial_passes() {
        let serial = |sections: &[[f64; 5]], x: &[f64], pad: usize| {
            let n = x.len();
            let pad = pad.min(n - 1);
            let mut v: Vec<f64> = (1..=pad).rev().map(|i| 2.0 * x[0] - x[i]).collect();
            v.extend_from_slice(x);
            v.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
            for s in sections {
                section(s, v.iter_mut());
            }
            for s in sections {
                section(s, v.iter_mut().rev());
            }
            v[pad..pad + n].to_vec()
        };
        let mut noise = noise(7);
        for (n, order, fc, offset) in [
            (300, 2, 40.0, 0.0),
            (4096, 2, 8.0, 0.0),
            (4096, 2, 8.0, 1e3),
            (5001, 4, 25.0, -3.0),
            (20000, 2, 2.0, 0.5),
            (4096, 2, 0.122, 0.0),
        ] {
            let x: Vec<f64> = (0..n)
                .map(|k| offset + (k as f64 * 0.01).sin() + 0.1 * noise())
                .collect();
            let sections = butterworth(order, fc, 4000.0);
            let pad = (3.0 * 4000.0 / fc) as usize;
            let (a, b) = (filtfilt(&sections, &x, pad), serial(&sections, &x, pad));
            let (scale, worst) = (largest(&x), worst_difference(&a, &b));
            assert_eq!(a.len(), n);
            // Poles near 1 (a corner far below the rate) amplify rounding.
            assert!(worst < 1e-10 * scale, "n {n}, fc {fc}: {worst:e}");
        }
    }
}
