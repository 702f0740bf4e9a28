//! The symbolic transfer functions against an independent route: at
//! deterministic pseudo-random rational parameter points and frequencies,
//! `c^T (C - Omega*M)^-1 b` (resp. `(C + s*D + s^2*M)`) is solved exactly over
//! Q by Gaussian elimination written here, using only the model's matrices
//! and vectors, which are themselves checked entry by entry against the
//! chain definition.

use mms::{Model, Output};
use poly::{Poly, Rat};
use std::collections::BTreeMap;

/// Deterministic generator (64-bit LCG, high bits).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    /// A positive rational p/q with p in 1..=30, q in 1..=9.
    fn pos(&mut self) -> Rat {
        let p = (self.next() % 30 + 1) as i64;
        let q = (self.next() % 9 + 1) as i64;
        &Rat::from(p) / &Rat::from(q)
    }
    /// A non-zero rational of either sign.
    fn any(&mut self) -> Rat {
        let r = self.pos();
        if self.next().is_multiple_of(2) {
            -r
        } else {
            r
        }
    }
}

/// Solves `a x = b` over Q; `None` if singular.
fn solve(mut a: Vec<Vec<Rat>>, mut b: Vec<Rat>) -> Option<Vec<Rat>> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n).find(|&r| !a[r][col].is_zero())?;
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot_row = a[col].clone();
        let pivot_b = b[col].clone();
        for r in 0..n {
            if r != col && !a[r][col].is_zero() {
                let f = &a[r][col] / &pivot_row[col];
                for (x, p) in a[r][col..].iter_mut().zip(&pivot_row[col..]) {
                    *x = &*x - &(&f * p);
                }
                b[r] = &b[r] - &(&f * &pivot_b);
            }
        }
    }
    Some((0..n).map(|i| &b[i] / &a[i][i]).collect())
}

fn eval_matrix(m: &[Vec<Poly>], pt: &BTreeMap<String, Rat>) -> Vec<Vec<Rat>> {
    m.iter()
        .map(|row| row.iter().map(|p| p.eval(pt).unwrap()).collect())
        .collect()
}

fn dot(c: &[i64], x: &[Rat]) -> Rat {
    c.iter()
        .zip(x)
        .fold(Rat::ZERO, |acc, (&ci, xi)| &acc + &(&Rat::from(ci) * xi))
}

fn random_point(m: &Model, rng: &mut Lcg) -> BTreeMap<String, Rat> {
    m.parameters().into_iter().map(|p| (p, rng.pos())).collect()
}

/// Checks the undamped TF of `m` at `points` random points.
fn check_undamped(m: &Model, rng: &mut Lcg, points: usize) {
    let tf = m.undamped_tf();
    let (mm, cc) = (m.mass_matrix(), m.stiffness_matrix());
    let (b, c) = (m.input_vector(), m.output_vector());
    let mut done = 0;
    while done < points {
        let pt = random_point(m, rng);
        // Alternately Omega = -s^2 for a rational s (then velocity can be
        // checked too) and Omega = +s^2 (a real frequency, omega = s).
        let s = rng.any();
        let with_s = done % 2 == 0;
        let omega = if with_s { -(&s * &s) } else { &s * &s };
        let mv = eval_matrix(&mm, &pt);
        let cv = eval_matrix(&cc, &pt);
        let a: Vec<Vec<Rat>> = (0..m.n_masses())
            .map(|i| {
                (0..m.n_masses())
                    .map(|j| &cv[i][j] - &(&omega * &mv[i][j]))
                    .collect()
            })
            .collect();
        let rhs: Vec<Rat> = b.iter().map(|&x| Rat::from(x)).collect();
        let Some(x) = solve(a, rhs) else { continue };
        let y = dot(&c, &x);
        let Some(pos) = tf.output(Output::Position).eval(&pt, &omega) else {
            continue;
        };
        assert_eq!(pos, y, "{m} position at {pt:?}, Omega={omega}");
        let acc = tf.output(Output::Acceleration).eval(&pt, &omega).unwrap();
        assert_eq!(acc, &(-&omega) * &y, "{m} acceleration = -Omega * position");
        if !with_s {
            done += 1;
            continue;
        }
        // velocity: sign * s * Omega^-1 * num/den
        let v = tf.output(Output::Velocity);
        assert_eq!((v.sign, v.s_power, v.omega_power), (-1, 1, -1));
        let vel = &(&(&s * &acc) / &omega) * &Rat::from(-1);
        assert_eq!(vel, &s * &y, "{m} velocity");
        done += 1;
    }
}

/// Checks the damped TFs of `m` at `points` random points and real rational s.
fn check_damped(m: &Model, rng: &mut Lcg, points: usize) {
    let tfs: Vec<_> = Output::ALL.iter().map(|&o| m.damped_tf(o)).collect();
    let (mm, cc, dd) = (m.mass_matrix(), m.stiffness_matrix(), m.damping_matrix());
    let (b, c) = (m.input_vector(), m.output_vector());
    let mut done = 0;
    while done < points {
        let mut pt = random_point(m, rng);
        let s = rng.any();
        let (mv, cv, dv) = (
            eval_matrix(&mm, &pt),
            eval_matrix(&cc, &pt),
            eval_matrix(&dd, &pt),
        );
        let s2 = &s * &s;
        let a: Vec<Vec<Rat>> = (0..m.n_masses())
            .map(|i| {
                (0..m.n_masses())
                    .map(|j| &(&cv[i][j] + &(&s * &dv[i][j])) + &(&s2 * &mv[i][j]))
                    .collect()
            })
            .collect();
        let rhs: Vec<Rat> = b.iter().map(|&x| Rat::from(x)).collect();
        let Some(x) = solve(a, rhs) else { continue };
        let y = dot(&c, &x);
        pt.insert("s".into(), s.clone());
        let mut sk = Rat::ONE;
        for tf in &tfs {
            let den = tf.den.eval(&pt).unwrap();
            if den.is_zero() {
                break;
            }
            assert_eq!(
                &tf.num.eval(&pt).unwrap() / &den,
                &sk * &y,
                "{m} {}",
                tf.output
            );
            sk = &sk * &s;
        }
        done += 1;
    }
}

#[test]
fn undamped_all_basic_models_up_to_four_masses() {
    let mut rng = Lcg(1);
    for n in 1..=4 {
        for m in mms::basic_models(n).unwrap() {
            check_undamped(&m, &mut rng, 50);
        }
    }
}

#[test]
fn undamped_degradation_free_five_masses() {
    let mut rng = Lcg(2);
    for m in mms::degradation_free_models(5).unwrap() {
        check_undamped(&m, &mut rng, 50);
    }
}

#[test]
fn undamped_largest_chains() {
    let mut rng = Lcg(3);
    let n = mms::MAX_MASSES;
    for m in mms::rule3_models(n).unwrap().into_iter().step_by(37) {
        check_undamped(&m, &mut rng, 5);
    }
}

#[test]
fn damped_three_and_four_masses() {
    let mut rng = Lcg(4);
    for m in mms::degradation_free_models(3).unwrap() {
        check_damped(&m, &mut rng, 50);
    }
    for m in mms::rule3_models(4).unwrap() {
        check_damped(&m, &mut rng, 10);
    }
    for m in mms::rule3_models(5).unwrap().into_iter().step_by(7) {
        check_damped(&m, &mut rng, 3);
    }
}

/// `p(s)` with only even powers of `s`, as a polynomial in `Omega = -s^2`.
fn even_in_s_to_omega(p: &Poly) -> Poly {
    let co = p.coeffs_in("s");
    let mut out = Poly::zero();
    for (k, c) in co.iter().enumerate() {
        if k % 2 == 1 {
            assert!(c.is_zero(), "odd power of s without damping");
            continue;
        }
        let sign = if (k / 2) % 2 == 0 { 1 } else { -1 };
        out = &out
            + &c.mul_var_pow("Omega", (k / 2) as u32)
                .scale(&Rat::from(sign));
    }
    out
}

#[test]
fn damped_without_dampers_is_the_undamped_tf() {
    for n in 1..=5 {
        for m in mms::degradation_free_models(n).unwrap() {
            let und = m.undamped_tf();
            for out in Output::ALL {
                let d = m.damped_tf(out);
                let zero = |q: &Poly| {
                    m.dampers()
                        .iter()
                        .fold(q.clone(), |acc, name| acc.subs(name, &Rat::ZERO))
                };
                let (dn, dd) = (zero(&d.num), zero(&d.den));
                // den = s^(2 - k) * Q(s) and num/Q is the acceleration,
                // which must be even in s without dampers.
                let k = out.s_power();
                let sk = Poly::var("s").pow(2 - k);
                let dd = dd.div_exact(&sk).expect("den carries s^(2-k)");
                let (dn, dd) = (even_in_s_to_omega(&dn), even_in_s_to_omega(&dd));
                // dn/dd == und.num/und.den
                assert_eq!(&dn * &und.den, &dd * &und.num, "{m} {out}");
            }
        }
    }
}

#[test]
fn matrices_follow_the_chain_definition() {
    // Independent construction: the potential energy of the chain is
    // 1/2 sum_links c (x_i - x_j)^2 with x_0 = 0, so C = Hessian.
    for m in mms::basic_models(4).unwrap() {
        let n = m.n_masses();
        let x: Vec<Poly> = (0..=n)
            .map(|i| {
                if i == 0 {
                    Poly::zero()
                } else {
                    Poly::var(&format!("x{i}"))
                }
            })
            .collect();
        let mut energy = Poly::zero();
        for i in (0..n).filter(|&i| i != m.gap()) {
            let name = mms::spring_name(i);
            assert!(m.springs().contains(&name));
            let dx = &x[i + 1] - &x[i];
            energy = &energy + &(&Poly::var(&name) * &dx.pow(2)).scale(&"1/2".parse().unwrap());
        }
        let c = m.stiffness_matrix();
        for i in 1..=n {
            for j in 1..=n {
                let h = energy
                    .derivative(&format!("x{i}"))
                    .derivative(&format!("x{j}"));
                assert_eq!(c[i - 1][j - 1], h, "{m} C[{i}][{j}]");
            }
        }
        assert_eq!(m.springs().len(), n - 1);
    }
}

#[test]
fn adjugate_form_agrees_with_poly_det_and_cofactors() {
    // The continuant formulas in the library against poly's general
    // determinant and cofactors of C - Omega*M.
    for n in 1..=5 {
        for m in mms::degradation_free_models(n)
            .unwrap()
            .into_iter()
            .step_by(3)
        {
            let om = Poly::var("Omega");
            let (mm, cc) = (m.mass_matrix(), m.stiffness_matrix());
            let a: Vec<Vec<Poly>> = (0..n)
                .map(|i| (0..n).map(|j| &cc[i][j] - &(&om * &mm[i][j])).collect())
                .collect();
            let (num, det) = m.undamped_adjugate_form();
            assert_eq!(det, poly::det(&a), "{m}");
            let (b, c) = (m.input_vector(), m.output_vector());
            let mut want = Poly::zero();
            for (i, &ci) in c.iter().enumerate() {
                for (j, &bj) in b.iter().enumerate() {
                    if ci != 0 && bj != 0 {
                        // adj(A)[i][j] = cofactor(A, j, i)
                        want = &want + &poly::cofactor(&a, j, i).scale(&Rat::from(ci * bj));
                    }
                }
            }
            assert_eq!(num, want, "{m}");
        }
    }
}
