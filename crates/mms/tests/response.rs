//! The numeric response (`mms::response`, an LU solve of the dynamic
//! stiffness at each frequency) against the symbolic damped transfer
//! function (`Model::damped_tf`, adjugate and determinant of the chain
//! matrices): two independent routes to `G(j w)`.

use mms::response::{ChainResponse, Parameters};
use mms::{Model, Output};
use num_complex::Complex64;
use std::collections::BTreeMap;

/// Evaluates a polynomial in `s` with parameter coefficients at `s = j w`.
fn eval_in_s(p: &poly::Poly, params: &BTreeMap<String, f64>, omega: f64) -> Complex64 {
    let coeffs = p.coeffs_in("s");
    let s = Complex64::new(0.0, omega);
    coeffs
        .iter()
        .rev()
        .fold(Complex64::new(0.0, 0.0), |acc, c| {
            acc * s + c.eval_f64(params).expect("all parameters given")
        })
}

#[test]
fn numeric_response_matches_symbolic_damped_tf() {
    let mut checked = 0;
    for n in 2..=4 {
        for (k, model) in mms::basic_models(n).unwrap().iter().enumerate() {
            let names = model.parameters();
            // Deterministic, well spread values: masses ~0.01 kg, springs
            // ~100 N/m, dampers ~0.05 N s/m.
            let values: Vec<f64> = names
                .iter()
                .enumerate()
                .map(|(i, name)| {
                    let t = 1.0 + ((i * 7 + k * 3) % 11) as f64 / 5.0;
                    match name.as_bytes()[0] {
                        b'm' => 0.01 * t,
                        b'c' => 100.0 * t,
                        _ => 0.05 * t,
                    }
                })
                .collect();
            let p = Parameters::from_values(model, values.clone()).unwrap();
            let map: BTreeMap<String, f64> = p.iter().map(|(n, v)| (n.to_string(), v)).collect();
            for output in Output::ALL {
                let tf = model.damped_tf(output);
                let g = ChainResponse::new(model, output);
                for f in [0.5, 3.0, 11.0, 17.5, 40.0, 95.0, 300.0] {
                    let w = 2.0 * std::f64::consts::PI * f;
                    let want = eval_in_s(&tf.num, &map, w) / eval_in_s(&tf.den, &map, w);
                    let got = g.eval(p.values(), f).unwrap();
                    // Both are f64 evaluations of well-conditioned forms;
                    // 1e-9 relative leaves room for the polynomial route's
                    // cancellation at low frequency.
                    assert!(
                        (got - want).norm() <= 1e-9 * want.norm(),
                        "{model} {output} {f} Hz: {got} vs {want}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}

#[test]
fn bad_parameters_and_frequencies_are_errors() {
    let a1 = Model::from_id("A1").unwrap();
    let mut v = vec![1.0; a1.parameters().len()];
    v[0] = f64::NAN;
    assert!(Parameters::from_values(&a1, v.clone()).is_err());
    v[0] = -1.0;
    let e = Parameters::from_values(&a1, v.clone()).unwrap_err();
    assert_eq!(e.to_string(), "parameter m1 = -1 must be positive");
    v[0] = 1.0;
    let last = v.len() - 1;
    v[last] = 0.0; // a zero damper is allowed
    let p = Parameters::from_values(&a1, v).unwrap();
    let g = ChainResponse::new(&a1, Output::Acceleration);
    assert!(g.eval(p.values(), 0.0).is_err());
    assert!(g.eval(p.values(), f64::INFINITY).is_err());
    assert!(g.eval(&p.values()[1..], 1.0).is_err());
}

/// At one frequency `w0`, a loss factor `eta` on every spring is the same
/// as viscous dampers `d = eta c / w0`: an identity of the dynamic
/// stiffness, checked through the whole response.
#[test]
fn hysteretic_damping_equals_viscous_at_one_frequency() {
    use mms::response::Effects;
    let b2 = Model::from_id("B2").unwrap();
    let (m, c) = ([0.01, 0.01, 0.01], [100.0, 200.0]);
    let eta = 0.03;
    let f0 = 23.0;
    let w0 = 2.0 * std::f64::consts::PI * f0;
    let hyst = [m[0], m[1], m[2], c[0], c[1], 0.0, 0.0];
    let visc = [
        m[0],
        m[1],
        m[2],
        c[0],
        c[1],
        eta * c[0] / w0,
        eta * c[1] / w0,
    ];
    let eff = Effects {
        loss_factor: Some(eta),
        ..Effects::default()
    };
    let gh = ChainResponse::with_effects(&b2, Output::Position, &eff);
    let gv = ChainResponse::new(&b2, Output::Position);
    let (a, b) = (gh.eval(&hyst, f0).unwrap(), gv.eval(&visc, f0).unwrap());
    assert!((a - b).norm() <= 1e-12 * b.norm(), "{a} vs {b}");
    // ... and not at another frequency.
    let (a, b) = (
        gh.eval(&hyst, 2.0 * f0).unwrap(),
        gv.eval(&visc, 2.0 * f0).unwrap(),
    );
    assert!((a - b).norm() > 1e-3 * b.norm());
}

/// Viscous friction `b` on the driven mass of a free chain: far below the
/// resonances the chain is one rigid body `M` with a damper, so
/// `x/F = 1/(-w^2 M + j w b)` (to first order in `w^2/w_1^2`).
#[test]
fn viscous_friction_damps_the_rigid_body() {
    use mms::response::Effects;
    let a3 = Model::from_id("A3").unwrap();
    let p = [0.01, 0.02, 0.03, 1e4, 1e4, 0.0, 0.0];
    let b = 0.4;
    let eff = Effects {
        viscous_friction: Some(b),
        ..Effects::default()
    };
    let g = ChainResponse::with_effects(&a3, Output::Position, &eff);
    for f in [0.05, 0.5, 2.0] {
        let w = 2.0 * std::f64::consts::PI * f;
        let want = Complex64::new(1.0, 0.0) / Complex64::new(-w * w * 0.06, w * b);
        let got = g.eval(&p, f).unwrap();
        // First resonance ~ 100 Hz: relative corrections (f/100)^2 < 1e-3.
        assert!(
            (got - want).norm() <= 1e-3 * want.norm(),
            "{f}: {got} vs {want}"
        );
    }
}

/// A first-order lag at `f_c`: -3 dB and -45 degrees at the corner.
#[test]
fn lowpass_is_minus_3_db_at_its_corner() {
    use mms::response::Effects;
    let a1 = Model::from_id("A1").unwrap();
    let p = [0.01, 0.02, 0.03, 1e4, 1e4, 0.1, 0.1];
    let eff = Effects {
        lowpass_hz: Some(300.0),
        ..Effects::default()
    };
    let ratio = ChainResponse::with_effects(&a1, Output::Velocity, &eff)
        .eval(&p, 300.0)
        .unwrap()
        / ChainResponse::new(&a1, Output::Velocity)
            .eval(&p, 300.0)
            .unwrap();
    assert!((ratio.norm() - 0.5f64.sqrt()).abs() < 1e-12);
    assert!((ratio.arg().to_degrees() + 45.0).abs() < 1e-9);
}

/// At a frequency where the first diagonal entry of `Z` is zero (the
/// first mass resonates on its spring alone), elimination without row
/// interchanges would divide by zero; the response there is still finite
/// and equals the symbolic one.
#[test]
fn zero_pivot_frequency_is_handled() {
    let model = Model::from_id("A1").unwrap();
    let f0 = 5.0;
    let w0 = 2.0 * std::f64::consts::PI * f0;
    // m1 = 1, c12 = w0^2: Z[0][0] = c12 - w0^2 m1 = 0 at f0, undamped.
    let values = vec![1.0, 2.0, 3.0, w0 * w0, 7.0 * w0 * w0, 0.0, 0.0];
    let p = Parameters::from_values(&model, values).unwrap();
    let map: BTreeMap<String, f64> = p.iter().map(|(n, v)| (n.to_string(), v)).collect();
    for output in Output::ALL {
        let tf = model.damped_tf(output);
        let want = eval_in_s(&tf.num, &map, w0) / eval_in_s(&tf.den, &map, w0);
        let got = ChainResponse::new(&model, output)
            .eval(p.values(), f0)
            .unwrap();
        assert!(
            (got - want).norm() <= 1e-9 * want.norm(),
            "{output}: {got} vs {want}"
        );
    }
}
