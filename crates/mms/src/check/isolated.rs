//! The checker's reading of a witness isolated in a box
//! ([`crate::analysis::IsolatedWitness`]), written apart from the prover's
//! (`analysis/isolated.rs`): only `poly`'s arithmetic is shared. Where the
//! prover encloses the rests' coefficients first and maps the intervals,
//! this maps the exact polynomials first and encloses the results.
//!
//! The steps, each exact:
//! 1. the fixed and free parameters are the model's, each once; the fixed
//!    ones, the posed roots, the box's ends and the partition positive;
//! 2. the posed conditions (numerator and denominator at each cancelled
//!    pole, or a pose's two factors once its cofactors multiply out to the
//!    numerator and the denominator, and for a pole cancelled twice the
//!    numerator's derivative as well, once the denominator is a constant
//!    times the two factors; the numerator and its derivatives
//!    below the multiplicity at each multiple zero), the fixed parameters
//!    substituted, are as many
//!    as the free parameters; Krawczyk's operator with the rounded inverse
//!    of the Jacobian at the box's centre maps the box into its interior,
//!    so the box holds exactly one solution;
//! 3. with the posed roots divided out of numerator and denominator
//!    (division with remainder in `Omega`, exact at that solution), the
//!    leading coefficients and the values at the partition's points keep
//!    one sign on the box; on each piece, mapped to `(0, inf)`, the sign
//!    variations of each rest (the same on the whole box) are at most one
//!    and not one for both; every root of the denominator's rest is
//!    placed, and every multiple zero is a point of the partition.

use super::{poly_value, posed_roots, rat_value, Tok, Ty, OMEGA};
use poly::{Poly, Rat, RatInterval};
use serde_json::Value;
use std::collections::BTreeMap;

/// Bits of the entries of Krawczyk's preconditioner.
const PRECONDITIONER_BITS: u32 = 64;

/// The type at the one solution in the box of `v` (see the module docs).
pub(super) fn read_isolated(
    num: &Poly,
    den: &Poly,
    params: &[String],
    v: &Value,
) -> Result<Ty, String> {
    let w = Witness::parse(v, params)?;
    let mut n = num.clone();
    let mut d = den.clone();
    for (name, value) in &w.fixed {
        n = n.subs(name, value);
        d = d.subs(name, value);
    }
    // A pose's factors replace the numerator and the denominator at its
    // pole once the cofactors show that both vanish where the factors do.
    let mut posed: BTreeMap<usize, ([Poly; 2], bool)> = BTreeMap::new();
    for (i, pose) in w.poses.iter().enumerate() {
        let [f0, f1] = &pose.factors;
        let combined = |c: &[Poly; 2]| &(&c[0] * f0) + &(&c[1] * f1);
        if combined(&pose.numerator) != *num {
            return Err(format!(
                "isolated.poses[{i}]: the numerator is not n0 f0 + n1 f1"
            ));
        }
        if combined(&pose.denominator) != *den {
            return Err(format!(
                "isolated.poses[{i}]: the denominator is not d0 f0 + d1 f1"
            ));
        }
        // Cancelled twice: the denominator a constant times f0 f1, so a
        // double root where both vanish.
        if pose.double {
            let product = f0 * f1;
            let ratio = den.div_exact(&product).and_then(|q| q.as_constant());
            if ratio.is_none_or(|c| c.is_zero()) {
                return Err(format!(
                    "isolated.poses[{i}]: a double pole, but the denominator is not a constant times f0 f1"
                ));
            }
        }
        if pose.pole >= w.cancelled.len() || posed.contains_key(&pose.pole) {
            return Err(format!(
                "isolated.poses[{i}]: pole {} is no cancelled pole or posed twice",
                pose.pole
            ));
        }
        let mut fixed = [f0.clone(), f1.clone()];
        for f in fixed.iter_mut() {
            for (name, value) in &w.fixed {
                *f = f.subs(name, value);
            }
        }
        posed.insert(pose.pole, (fixed, pose.double));
    }
    let mut conditions = Vec::new();
    for (i, rho) in w.cancelled.iter().enumerate() {
        match posed.get(&i) {
            Some(([f0, f1], double)) => {
                conditions.extend([f0.subs(OMEGA, rho), f1.subs(OMEGA, rho)]);
                if *double {
                    conditions.push(n.derivative(OMEGA).subs(OMEGA, rho));
                }
            }
            None => conditions.extend([n.subs(OMEGA, rho), d.subs(OMEGA, rho)]),
        }
    }
    for (sigma, mu) in &w.multiple {
        let mut derivative = n.clone();
        for _ in 0..*mu {
            conditions.push(derivative.subs(OMEGA, sigma));
            derivative = derivative.derivative(OMEGA);
        }
    }
    if conditions.len() != w.free.len() {
        return Err(format!(
            "isolated: {} conditions posed, {} free parameters",
            conditions.len(),
            w.free.len()
        ));
    }
    krawczyk(&conditions, &w.free)?;
    let mut num_divisor = vec![Rat::ONE];
    let mut den_divisor = vec![Rat::ONE];
    for (i, rho) in w.cancelled.iter().enumerate() {
        let times = if posed.get(&i).is_some_and(|p| p.1) {
            2
        } else {
            1
        };
        for _ in 0..times {
            num_divisor = times_root(&num_divisor, rho);
            den_divisor = times_root(&den_divisor, rho);
        }
    }
    for (sigma, mu) in &w.multiple {
        for _ in 0..*mu {
            num_divisor = times_root(&num_divisor, sigma);
        }
    }
    let q = quotient(&n.coeffs_in(OMEGA), &num_divisor)
        .ok_or("isolated: the numerator's degree is below the posed roots'")?;
    let r = quotient(&d.coeffs_in(OMEGA), &den_divisor)
        .ok_or("isolated: the denominator's degree is below the cancelled poles'")?;
    read_rests(&q, &r, &w)
}

/// The parsed witness.
struct Witness {
    fixed: BTreeMap<String, Rat>,
    free: BTreeMap<String, RatInterval>,
    cancelled: Vec<Rat>,
    multiple: Vec<(Rat, u32)>,
    poses: Vec<Pose>,
    partition: Vec<Rat>,
}

/// A cancelled pole posed by two factors, with the cofactors.
struct Pose {
    pole: usize,
    double: bool,
    factors: [Poly; 2],
    numerator: [Poly; 2],
    denominator: [Poly; 2],
}

impl Pose {
    fn parse(v: &Value, path: &str) -> Result<Pose, String> {
        let pole = v
            .get("pole")
            .and_then(Value::as_u64)
            .ok_or_else(|| format!("{path}.pole: expected an index"))? as usize;
        let pair = |key: &str| -> Result<[Poly; 2], String> {
            let a = v
                .get(key)
                .and_then(Value::as_array)
                .filter(|a| a.len() == 2)
                .ok_or_else(|| format!("{path}.{key}: expected two polynomials"))?;
            Ok([
                poly_value(&a[0], &format!("{path}.{key}[0]"))?,
                poly_value(&a[1], &format!("{path}.{key}[1]"))?,
            ])
        };
        let double = match v.get("double") {
            None => false,
            Some(d) => d
                .as_bool()
                .ok_or_else(|| format!("{path}.double: expected true or false"))?,
        };
        Ok(Pose {
            pole,
            double,
            factors: pair("factors")?,
            numerator: pair("numerator")?,
            denominator: pair("denominator")?,
        })
    }
}

impl Witness {
    fn parse(v: &Value, params: &[String]) -> Result<Witness, String> {
        let object = |key: &str| {
            v.get(key)
                .and_then(Value::as_object)
                .ok_or_else(|| format!("isolated.{key}: expected an object"))
        };
        let positive = |r: Rat, path: &str| {
            if r.signum() > 0 {
                Ok(r)
            } else {
                Err(format!("{path}: {r} is not positive"))
            }
        };
        let mut fixed = BTreeMap::new();
        for (k, x) in object("fixed")? {
            let path = format!("isolated.fixed.{k}");
            fixed.insert(k.clone(), positive(rat_value(x, &path)?, &path)?);
        }
        let mut free = BTreeMap::new();
        for (k, x) in object("free")? {
            let path = format!("isolated.free.{k}");
            let ends = x
                .as_array()
                .filter(|a| a.len() == 2)
                .ok_or_else(|| format!("{path}: expected [lower, upper]"))?;
            let lo = positive(rat_value(&ends[0], &path)?, &path)?;
            let hi = rat_value(&ends[1], &path)?;
            let range = RatInterval::new(lo, hi)
                .filter(|r| r.width().signum() > 0)
                .ok_or_else(|| format!("{path}: the lower end is not below the upper"))?;
            free.insert(k.clone(), range);
        }
        for k in fixed.keys().chain(free.keys()) {
            if !params.contains(k) {
                return Err(format!(
                    "isolated: {k} is not an undamped parameter of the model"
                ));
            }
        }
        for p in params {
            match (fixed.contains_key(p), free.contains_key(p)) {
                (true, true) => return Err(format!("isolated: {p} is both fixed and free")),
                (false, false) => return Err(format!("isolated: no value or range for {p}")),
                _ => {}
            }
        }
        let array = |key: &str| -> Result<Vec<Value>, String> {
            match v.get(key) {
                None => Ok(Vec::new()),
                Some(a) => a
                    .as_array()
                    .cloned()
                    .ok_or_else(|| format!("isolated.{key}: expected an array")),
            }
        };
        let (cancelled, multiple) = posed_roots(v, "isolated")?;
        for (i, r) in cancelled.iter().enumerate() {
            positive(r.clone(), &format!("isolated.cancelled[{i}]"))?;
        }
        for (i, (r, _)) in multiple.iter().enumerate() {
            positive(r.clone(), &format!("isolated.multiple[{i}]"))?;
        }
        let poses = array("poses")?
            .iter()
            .enumerate()
            .map(|(i, p)| Pose::parse(p, &format!("isolated.poses[{i}]")))
            .collect::<Result<Vec<Pose>, String>>()?;
        let partition = v
            .get("partition")
            .and_then(Value::as_array)
            .ok_or("isolated.partition: expected an array")?
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let path = format!("isolated.partition[{i}]");
                positive(rat_value(r, &path)?, &path)
            })
            .collect::<Result<Vec<Rat>, String>>()?;
        if partition.windows(2).any(|p| p[0] >= p[1]) {
            return Err("isolated.partition: not increasing".into());
        }
        for (s, _) in &multiple {
            if !partition.contains(s) {
                return Err(format!(
                    "isolated: the multiple zero {s} is not a point of the partition"
                ));
            }
        }
        Ok(Witness {
            fixed,
            free,
            cancelled,
            multiple,
            poses,
            partition,
        })
    }
}

/// Krawczyk's test for `conditions` on the box `free`.
fn krawczyk(conditions: &[Poly], free: &BTreeMap<String, RatInterval>) -> Result<(), String> {
    let names: Vec<&String> = free.keys().collect();
    let centre: BTreeMap<String, Rat> = free
        .iter()
        .map(|(k, r)| (k.clone(), r.midpoint()))
        .collect();
    let eval = |p: &Poly| p.eval(&centre).map_err(|e| format!("isolated: {e}"));
    let jacobian: Vec<Vec<Poly>> = conditions
        .iter()
        .map(|c| names.iter().map(|v| c.derivative(v)).collect())
        .collect();
    let at_centre = jacobian
        .iter()
        .map(|row| row.iter().map(eval).collect::<Result<Vec<Rat>, String>>())
        .collect::<Result<Vec<_>, String>>()?;
    let y: Vec<Vec<Rat>> = poly::inverse_rat(&at_centre)
        .ok_or("isolated: the Jacobian is singular at the box's centre")?
        .into_iter()
        .map(|row| {
            row.into_iter()
                .map(|e| e.round_to_bits(PRECONDITIONER_BITS))
                .collect()
        })
        .collect();
    let values = conditions
        .iter()
        .map(eval)
        .collect::<Result<Vec<Rat>, String>>()?;
    let over_box = jacobian
        .iter()
        .map(|row| {
            row.iter()
                .map(|p| {
                    p.enclose(free)
                        .map_err(|v| format!("isolated: {v} has no range"))
                })
                .collect::<Result<Vec<RatInterval>, String>>()
        })
        .collect::<Result<Vec<_>, String>>()?;
    for (i, name) in names.iter().enumerate() {
        // c_i - (Y F(c))_i
        let newton = (0..values.len()).fold(centre[*name].clone(), |acc, k| {
            &acc - &(&y[i][k] * &values[k])
        });
        let mut image = RatInterval::point(newton);
        for (j, other) in names.iter().enumerate() {
            // (I - Y J(X))_ij (X_j - c_j)
            let mut entry = (0..values.len()).fold(RatInterval::point(Rat::ZERO), |acc, k| {
                &acc + &over_box[k][j].scale(&y[i][k])
            });
            entry = &RatInterval::point(Rat::from(i64::from(i == j))) - &entry;
            let offset = &free[*other] - &RatInterval::point(centre[*other].clone());
            image = &image + &(&entry * &offset);
        }
        if !image.inside(&free[*name]) {
            return Err(format!(
                "isolated: Krawczyk's test fails: the operator maps {name} to {image}, not inside the box"
            ));
        }
    }
    Ok(())
}

/// `p (x - r)`, ascending coefficients.
fn times_root(p: &[Rat], r: &Rat) -> Vec<Rat> {
    let mut out = vec![Rat::ZERO; p.len() + 1];
    for (i, c) in p.iter().enumerate() {
        out[i + 1] = &out[i + 1] + c;
        out[i] = &out[i] - &(c * r);
    }
    out
}

/// The quotient of `sum a[i] x^i` by the monic `sum b[i] x^i` (ascending),
/// the remainder dropped; `None` if `a` has the lower degree.
fn quotient(a: &[Poly], b: &[Rat]) -> Option<Vec<Poly>> {
    let (n, m) = (a.len().checked_sub(1)?, b.len().checked_sub(1)?);
    let mut rest: Vec<Poly> = a.to_vec();
    let mut q = vec![Poly::zero(); n.checked_sub(m)? + 1];
    for k in (0..=n - m).rev() {
        let c = rest[k + m].clone();
        for (i, bi) in b.iter().enumerate() {
            rest[k + i] = &rest[k + i] - &c.scale(bi);
        }
        q[k] = c;
    }
    Some(q)
}

/// The type from the rests `q` and `r` (coefficients in the free
/// parameters) and the witness's partition.
fn read_rests(q: &[Poly], r: &[Poly], w: &Witness) -> Result<Ty, String> {
    let range = |p: &Poly| {
        p.enclose(&w.free)
            .map_err(|v| format!("isolated: {v} has no range"))
    };
    let sign = |p: &Poly, what: &str| -> Result<i32, String> {
        range(p)?
            .sign()
            .ok_or_else(|| format!("isolated: {what} takes no one sign on the box"))
    };
    let (qd, rd) = (q.len() - 1, r.len() - 1);
    sign(&q[qd], "the leading coefficient of the numerator's rest")?;
    sign(&r[rd], "the leading coefficient of the denominator's rest")?;
    let omega = Poly::var(OMEGA);
    let as_poly = |c: &[Poly]| Poly::from_coeffs_in(OMEGA, c);
    let (qp, rp) = (as_poly(q), as_poly(r));
    for t in &w.partition {
        sign(&qp.subs(OMEGA, t), &format!("the numerator's rest at {t}"))?;
        sign(
            &rp.subs(OMEGA, t),
            &format!("the denominator's rest at {t}"),
        )?;
    }
    let mut toks = Vec::new();
    let (mut zeros, mut poles) = (0usize, 0usize);
    for i in 0..=w.partition.len() {
        let a = if i == 0 {
            Rat::ZERO
        } else {
            w.partition[i - 1].clone()
        };
        let b = w.partition.get(i);
        let piece = match b {
            Some(b) => format!("({a}, {b})"),
            None => format!("({a}, inf)"),
        };
        let count = |p: &Poly, c: &[Poly], what: &str| -> Result<usize, String> {
            // Roots in (a, b) are the positive roots of
            // (1 + Omega)^d p((b + a Omega) / (1 + Omega)); in (a, inf),
            // of p(a + Omega).
            let mapped = match b {
                Some(b) => {
                    let d = c.len() - 1;
                    let lin = &Poly::constant(b.clone()) + &omega.scale(&a);
                    let one = &Poly::one() + &omega;
                    c.iter().enumerate().fold(Poly::zero(), |acc, (k, ck)| {
                        &acc + &(&(ck * &lin.pow(k as u32)) * &one.pow((d - k) as u32))
                    })
                }
                None => p.subs_poly(OMEGA, &(&omega + &Poly::constant(a.clone()))),
            };
            let mut last = 0;
            let mut changes = 0;
            for coefficient in mapped.coeffs_in(OMEGA) {
                if coefficient.is_zero() {
                    continue;
                }
                let s = range(&coefficient)?.sign().ok_or_else(|| {
                    format!("isolated: on {piece} a coefficient of the {what} takes no one sign")
                })?;
                if last != 0 && s != last {
                    changes += 1;
                }
                last = s;
            }
            if changes > 1 {
                return Err(format!(
                    "isolated: on {piece} the {what} has {changes} sign variations"
                ));
            }
            Ok(changes)
        };
        match (
            count(&qp, q, "numerator's rest")?,
            count(&rp, r, "denominator's rest")?,
        ) {
            (0, 0) => {}
            (1, 0) => {
                zeros += 1;
                toks.push(Tok {
                    zero: true,
                    mult: 1,
                });
            }
            (0, 1) => {
                poles += 1;
                toks.push(Tok {
                    zero: false,
                    mult: 1,
                });
            }
            _ => {
                return Err(format!(
                    "isolated: a zero and a pole share the piece {piece}"
                ))
            }
        }
        if let Some((_, mu)) = b.and_then(|b| w.multiple.iter().find(|(s, _)| s == b)) {
            toks.push(Tok {
                zero: true,
                mult: *mu,
            });
        }
    }
    if poles != rd {
        return Err(format!(
            "isolated: {poles} of the denominator rest's {rd} roots placed"
        ));
    }
    Ok(Ty {
        toks,
        nm: qd > zeros,
    })
}
