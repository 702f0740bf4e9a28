//! The nonlinear time simulation against independent references: the
//! linear FRF (steady state of a sine), Newton's law with Coulomb friction,
//! the energy balance, and the limit cases of backlash.

use mms::model_file::{ModelFile, Motion};
use mms::response::{ChainResponse, Effects, Parameters};
use mms::simulate::{simulate, SimOptions, Simulator};
use mms::{Model, Output, Port};
use num_complex::Complex64;
use std::f64::consts::PI;

fn file(model: Model, output: Output, values: Vec<f64>, effects: Effects) -> ModelFile {
    ModelFile {
        model,
        output,
        parameters: Parameters::from_values(&model, values).unwrap(),
        gain: 1.0,
        motion: Motion::Translational,
        effects,
    }
}

/// Least squares of `y ~ a + b t + c cos(w t) + d sin(w t)`: the sine's
/// complex amplitude `c - j d` (the rigid-body mode's free motion is the
/// `a + b t` part).
fn sine_amplitude(y: &[f64], t: &[f64], w: f64) -> Complex64 {
    let rows: Vec<[f64; 4]> = t
        .iter()
        .map(|&t| [1.0, t, (w * t).cos(), (w * t).sin()])
        .collect();
    let mut a = [[0.0; 5]; 4];
    for (r, &yk) in rows.iter().zip(y) {
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] += r[i] * r[j];
            }
            a[i][4] += r[i] * yk;
        }
    }
    // Gauss-Jordan with partial pivoting on the 4x4 normal equations.
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        for r in 0..4 {
            if r != c {
                let f = a[r][c] / a[c][c];
                let pivot = a[c];
                for (x, p) in a[r].iter_mut().zip(pivot).skip(c) {
                    *x -= f * p;
                }
            }
        }
    }
    let x: Vec<f64> = (0..4).map(|i| a[i][4] / a[i][i]).collect();
    Complex64::new(x[2], -x[3])
}

/// The complex amplitude of `file`'s sampled output in the steady state
/// of the input `sin(2 pi f t)` at rate `fs`: 4000 samples, the first 2000
/// (1 s at 2 kHz, where the flexible modes' transient has decayed) left
/// out.
fn steady_sine(file: &ModelFile, f: f64, fs: f64) -> Complex64 {
    let w = 2.0 * PI * f;
    let n = 4000;
    let u: Vec<f64> = (0..n).map(|k| (w * k as f64 / fs).sin()).collect();
    let y = simulate(file, &u, fs).unwrap();
    let t: Vec<f64> = (2000..n).map(|k| k as f64 / fs).collect();
    sine_amplitude(&y[2000..], &t, w)
}

/// Without nonlinearities the steady state of a sine input is the linear
/// FRF times the zero-order hold's `sinc(w T/2) e^(-j w T/2)`, for every
/// output and a 3-mass chain with a rigid-body mode, at frequencies below,
/// between and above its resonances. (Acceleration passes the held
/// input's images at `fs +- f` through the mass line and samples them back
/// onto `f`, so for it the reference holds only well below `fs`: the
/// highest frequency is left out.)
#[test]
fn linear_sine_matches_frf() {
    let a2 = Model::from_id("A2").unwrap();
    let p = vec![0.01, 0.012, 0.02, 400.0, 900.0, 0.3, 0.5];
    let fs = 2000.0;
    for output in Output::ALL {
        for f in [7.0, 23.0, 61.0, 140.0] {
            if output == Output::Acceleration && f > fs / 20.0 {
                continue;
            }
            let w = 2.0 * PI * f;
            let got = steady_sine(&file(a2, output, p.clone(), Effects::default()), f, fs);
            let g = ChainResponse::new(&a2, output).eval(&p, f).unwrap();
            let x = w / (2.0 * fs);
            let zoh = Complex64::from_polar(x.sin() / x, -x);
            // A sine sin(w t) has complex amplitude -j.
            let want = g * zoh * Complex64::new(0.0, -1.0);
            let err = (got - want).norm() / want.norm();
            assert!(err < 2e-3, "{output} {f} Hz: {got} vs {want} ({err:.2e})");
        }
    }
}

/// Every chain length the simulator runs (each its own compiled
/// instance): a free chain of 1 to `MAX_MASSES` masses, driven at the first
/// and read at the last, meets the FRF's steady state at a frequency among
/// its modes.
#[test]
fn every_chain_length_matches_frf() {
    let fs = 1000.0;
    for n in 1..=mms::MAX_MASSES {
        let m = Model::new(n, 0, Port::new(1, 0), Port::new(n, 0)).unwrap();
        let mut p: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
        p.extend(std::iter::repeat_n(1.0e4, n - 1));
        p.extend(std::iter::repeat_n(20.0, n - 1));
        for f in [4.0, 13.0] {
            let w = 2.0 * PI * f;
            let u: Vec<f64> = (0..6000).map(|k| (w * k as f64 / fs).sin()).collect();
            let y = simulate(
                &file(m, Output::Position, p.clone(), Effects::default()),
                &u,
                fs,
            )
            .unwrap();
            let t: Vec<f64> = (3000..6000).map(|k| k as f64 / fs).collect();
            let got = sine_amplitude(&y[3000..], &t, w);
            let g = ChainResponse::new(&m, Output::Position)
                .eval(&p, f)
                .unwrap();
            let x = w / (2.0 * fs);
            let want = g * Complex64::from_polar(x.sin() / x, -x) * Complex64::new(0.0, -1.0);
            let err = (got - want).norm() / want.norm();
            assert!(
                err < 2e-3,
                "{n} masses, {f} Hz: {got} vs {want} ({err:.2e})"
            );
        }
    }
}

/// A pre-sliding stiffness is a spring to the ground: one mass on it,
/// damped by viscous friction, settles under a constant force at Hooke's
/// `F / k`, rings at `sqrt(k / m)` first, and its FRF is the closed form
/// `1 / (k - m w^2 + j w d)`.
#[test]
fn pre_sliding_stiffness_is_a_spring_to_ground() {
    let (m, k, d, force) = (2.0, 800.0, 8.0, 3.0);
    let model = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    let effects = Effects {
        pre_sliding_stiffness: Some(k),
        viscous_friction: Some(d),
        ..Effects::default()
    };
    let f = file(model, Output::Position, vec![m], effects);
    let fs = 2000.0;
    let y = simulate(&f, &vec![force; 20000], fs).unwrap();
    // Settled to e^-20 of the step after 10 s (zeta w_n = 2 / s).
    assert!((y[19999] / (force / k) - 1.0).abs() < 1e-7, "{}", y[19999]);
    // The first overshoot at half the damped period.
    let (wn, zeta) = ((k / m).sqrt(), d / (2.0 * (k * m).sqrt()));
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let peak = (0..4000).max_by(|&a, &b| y[a].total_cmp(&y[b])).unwrap();
    let want = PI / wd * fs;
    assert!((peak as f64 - want).abs() <= 2.0, "{peak} vs {want}");
    for hz in [1.0, 3.2, 10.0] {
        let w = 2.0 * PI * hz;
        let g = ChainResponse::with_effects(&model, Output::Position, &effects)
            .eval(&[m], hz)
            .unwrap();
        let want = Complex64::new(1.0, 0.0) / Complex64::new(k - m * w * w, w * d);
        assert!((g / want - 1.0).norm() < 1e-12, "{hz} Hz: {g} vs {want}");
    }
}

fn one_mass(m: f64, coulomb: f64, output: Output) -> ModelFile {
    let model = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
    file(
        model,
        output,
        vec![m],
        Effects {
            coulomb_friction: Some(coulomb),
            ..Effects::default()
        },
    )
}

/// Newton with dry friction: a constant force above `F_c` accelerates the
/// mass at `(F - F_c)/m` (position `a t^2 / 2`, exact for RK4), one below
/// it leaves the mass at rest, in both directions.
#[test]
fn coulomb_single_mass_newton_and_stiction() {
    let (m, fc, fs) = (2.5, 4.0, 500.0);
    for force in [10.0, -7.0, 4.5] {
        let x = simulate(&one_mass(m, fc, Output::Position), &[force; 501], fs).unwrap();
        let a = (force - fc * force.signum()) / m;
        for (k, &xk) in x.iter().enumerate() {
            let t = k as f64 / fs;
            assert!(
                (xk - 0.5 * a * t * t).abs() < 1e-9 * (1.0 + xk.abs()),
                "{force} N at {t} s"
            );
        }
    }
    for force in [3.99, -3.99, 0.0] {
        for output in Output::ALL {
            let y = simulate(&one_mass(m, fc, output), &[force; 200], fs).unwrap();
            assert!(y.iter().all(|&v| v == 0.0), "{force} N moved ({output})");
        }
    }
}

/// A sine force above `F_c`: the mass slips and sticks, and the work done
/// by the force equals the kinetic energy plus the friction's loss `F_c
/// times the path` (trapezoidal sums on a fine grid). It stands still
/// wherever `|F| < F_c` follows a stop.
#[test]
fn coulomb_energy_balance_and_stick_slip() {
    let (m, fc, fs) = (1.0, 1.0, 20000.0);
    let n = 20000;
    let u: Vec<f64> = (0..n)
        .map(|k| 2.0 * (2.0 * PI * k as f64 / fs).sin())
        .collect();
    let v = simulate(&one_mass(m, fc, Output::Velocity), &u, fs).unwrap();
    let dt = 1.0 / fs;
    let (mut work, mut path) = (0.0, 0.0);
    for k in 0..n - 1 {
        // The held force acts over [t_k, t_k+1).
        work += u[k] * 0.5 * (v[k] + v[k + 1]) * dt;
        path += 0.5 * (v[k].abs() + v[k + 1].abs()) * dt;
    }
    let kinetic = 0.5 * m * v[n - 1] * v[n - 1];
    let balance = work - kinetic - fc * path;
    assert!(
        balance.abs() < 1e-3 * work,
        "{work} vs {kinetic} + {}",
        fc * path
    );
    // It sticks for a while: many samples at exactly zero velocity.
    let stuck = v.iter().filter(|&&v| v == 0.0).count();
    assert!(stuck > n / 20 && stuck < n / 2, "{stuck} samples stuck");
}

fn two_masses(gap: Option<f64>, output: Output, sensor: usize, d: f64) -> ModelFile {
    let model = Model::new(2, 0, Port::new(1, 0), Port::new(sensor, 0)).unwrap();
    file(
        model,
        output,
        vec![1.0, 2.0, 4000.0, d],
        Effects {
            backlash_gap: gap,
            ..Effects::default()
        },
    )
}

/// Backlash limits: a vanishing gap is the linear chain; a gap wider than
/// the motion decouples the masses (the far one never moves, the driven one
/// moves as a free mass).
#[test]
fn backlash_limits() {
    let fs = 1000.0;
    let u: Vec<f64> = (0..2000)
        .map(|k| {
            (2.0 * PI * 5.0 * k as f64 / fs).sin() + 0.5 * (2.0 * PI * 31.0 * k as f64 / fs).cos()
        })
        .collect();
    for sensor in [1, 2] {
        let lin = simulate(&two_masses(None, Output::Position, sensor, 2.0), &u, fs).unwrap();
        let tiny = simulate(
            &two_masses(Some(1e-12), Output::Position, sensor, 2.0),
            &u,
            fs,
        )
        .unwrap();
        let scale = lin.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (a, b) in lin.iter().zip(&tiny) {
            assert!((a - b).abs() < 1e-6 * scale);
        }
    }
    let step = [3.0; 400];
    let far = simulate(&two_masses(Some(10.0), Output::Position, 2, 2.0), &step, fs).unwrap();
    assert!(far.iter().all(|&x| x == 0.0));
    let near = simulate(&two_masses(Some(10.0), Output::Position, 1, 2.0), &step, fs).unwrap();
    for (k, x) in near.iter().enumerate() {
        let t = k as f64 / fs;
        assert!((x - 1.5 * t * t).abs() < 1e-9);
    }
}

/// Undamped backlash conserves energy: the input's work equals the kinetic
/// energy plus the dead-zone spring's `c (|d| - gap/2)^2 / 2`, while the
/// masses hit and leave the stops many times.
#[test]
fn backlash_energy_balance() {
    let (fs, gap, c) = (20000.0, 2e-3, 4000.0);
    let n = 20000;
    let u: Vec<f64> = (0..n)
        .map(|k| 3.0 * (2.0 * PI * 3.0 * k as f64 / fs).sin())
        .collect();
    let run =
        |output, sensor| simulate(&two_masses(Some(gap), output, sensor, 0.0), &u, fs).unwrap();
    let (x1, x2) = (run(Output::Position, 1), run(Output::Position, 2));
    let (v1, v2) = (run(Output::Velocity, 1), run(Output::Velocity, 2));
    let dt = 1.0 / fs;
    let mut work = 0.0;
    let mut contacts = 0;
    for k in 0..n - 1 {
        work += u[k] * 0.5 * (v1[k] + v1[k + 1]) * dt;
        let open = |k: usize| ((x2[k] - x1[k]).abs() <= gap / 2.0) as i32;
        contacts += (open(k) != open(k + 1)) as i32;
    }
    let k = n - 1;
    let dz = ((x2[k] - x1[k]).abs() - gap / 2.0).max(0.0);
    let energy = 0.5 * v1[k] * v1[k] + 0.5 * 2.0 * v2[k] * v2[k] + 0.5 * c * dz * dz;
    assert!(contacts > 10, "{contacts} contact changes");
    assert!((work - energy).abs() < 2e-3 * work, "{work} vs {energy}");
}

/// The sub-step follows the chain's fastest eigenvalue, and options place
/// the nonlinearities or refuse a place that does not exist.
#[test]
fn substeps_and_places() {
    let soft = two_masses(None, Output::Position, 2, 0.0);
    let mut stiff = soft.clone();
    stiff.parameters = Parameters::from_values(&stiff.model, vec![1.0, 2.0, 4e8, 0.0]).unwrap();
    let s = |f: &ModelFile| {
        Simulator::new(f, 1000.0, &SimOptions::default())
            .unwrap()
            .substeps()
    };
    assert_eq!(s(&soft), 1);
    // sqrt(2 * 4e8 / 1) = 28284 rad/s: 28284 / 1000 / 0.3 -> 95 sub-steps.
    assert_eq!(s(&stiff), 95);
    let one = one_mass(1.0, 0.0, Output::Position);
    let mut gap = one.clone();
    gap.effects.backlash_gap = Some(1e-3);
    let err = Simulator::new(&gap, 100.0, &SimOptions::default()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "N1-g0-a1.0-s1.0 has no spring next to the driven mass"
    );
    let err = Simulator::new(
        &one,
        100.0,
        &SimOptions {
            friction_mass: Some(2),
            ..SimOptions::default()
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("friction mass 2"), "{err}");
    let mut hyst = soft.clone();
    hyst.effects.loss_factor = Some(0.01);
    assert!(simulate(&hyst, &[1.0], 100.0).is_err());
    assert!(simulate(&soft, &[f64::NAN], 100.0).is_err());
}

/// The offset force in the sense of the inverse dynamics `F = M a + ... +
/// offset`: with no input a mass accelerates at `-offset / m`; Coulomb
/// friction above the offset holds it at rest.
#[test]
fn offset_force_newton_and_stiction() {
    let mut f = one_mass(2.0, 0.0, Output::Position);
    f.effects.offset_force = Some(-3.0);
    let fs = 100.0;
    let y = simulate(&f, &[0.0; 101], fs).unwrap();
    // a = +1.5 m/s^2: x(1 s) = 0.75 m (exact for RK4 on a constant force).
    assert!((y[100] - 0.75).abs() < 1e-12, "{}", y[100]);
    f.effects.coulomb_friction = Some(3.5);
    let y = simulate(&f, &[0.0; 101], fs).unwrap();
    assert!(y.iter().all(|&v| v == 0.0));
    // The net force without friction is u + 3: u = -1 gives 2 < 3.5 and
    // sticks; u = 1 gives 4 and slips at (4 - 3.5) / 2 = 0.25 m/s^2; u =
    // -8 gives -5, slipping at (-5 + 3.5) / 2 = -0.75 m/s^2.
    for (u, a) in [(-1.0, 0.0), (1.0, 0.25), (-8.0, -0.75)] {
        let y = simulate(&f, &[u; 101], fs).unwrap();
        assert!((y[100] - 0.5 * a).abs() < 1e-12, "u = {u}: {}", y[100]);
    }
}

/// The sampled P/P loop against an independent evaluation: a frictionless
/// mass under a held force moves exactly as `x += v h + a h^2 / 2`, `v += a
/// h` per sample, and the law is evaluated here from its definition. RK4
/// is exact on a constant force, so the two agree to rounding.
#[test]
fn closed_loop_matches_exact_sampled_loop() {
    use mms::simulate::{ClosedLoop, Controller};
    let (m, gain, kp, kv, fs) = (5.0, 30.0, 80.0, 40.0, 1000.0);
    let mut f = one_mass(m, 0.0, Output::Position);
    f.effects.coulomb_friction = None;
    f.gain = gain;
    let n = 3000;
    let r: Vec<f64> = (0..n)
        .map(|k| 0.1 * (2.0 * PI * 0.7 * k as f64 / fs).sin() + 0.02)
        .collect();
    let (q0, v0) = (0.01, 0.05);
    let c = Controller::new(kp, kv);
    let sim = Simulator::new(&f, fs, &SimOptions::default()).unwrap();
    let run = sim
        .run_closed_loop(&ClosedLoop {
            initial_position: q0,
            initial_velocity: v0,
            ..ClosedLoop::new(&c, &r)
        })
        .unwrap();
    // Independent: exact ZOH update, law u = kv (kp (r - q) - (q[k] -
    // q[k-2]) fs / 2) with the past continuing the initial motion.
    let h = 1.0 / fs;
    let (mut x, mut v) = (q0, v0);
    let mut q = vec![q0 - 2.0 * v0 * h, q0 - v0 * h];
    for k in 0..n {
        q.push(x);
        let vel = (q[k + 2] - q[k]) * fs / 2.0;
        let u = kv * (kp * (r[k] - x) - vel);
        assert!((run.y[k] - x).abs() < 1e-12, "y[{k}]: {} vs {x}", run.y[k]);
        assert!((run.u[k] - u).abs() < 1e-8 * (1.0 + u.abs()), "u[{k}]");
        let a = gain * u / m;
        x += v * h + 0.5 * a * h * h;
        v += a * h;
    }
    // The law reproduces its own output exactly.
    let check = c.check(&r, &run.y, &run.u, None, fs).unwrap();
    assert!(check.rms_rel < 1e-12, "{check:?}");
}

/// At rest in the loop, a constant offset force is held by the position
/// error `offset / (gain kp kv)`; saturation clips the output; bad
/// controllers and outputs are errors.
#[test]
fn closed_loop_static_error_saturation_and_errors() {
    use mms::simulate::{ClosedLoop, Controller, SimulateError};
    let (gain, kp, kv) = (35.0, 160.0, 240.0);
    let mut f = one_mass(95.0, 0.0, Output::Position);
    f.effects.coulomb_friction = None;
    f.effects.viscous_friction = Some(200.0);
    f.effects.offset_force = Some(-3.2);
    f.gain = gain;
    let sim = Simulator::new(&f, 1000.0, &SimOptions::default()).unwrap();
    let r = vec![0.1; 4000];
    let c = Controller::new(kp, kv);
    let run = sim.run_closed_loop(&ClosedLoop::new(&c, &r)).unwrap();
    // gain u = offset at rest, u = kv kp (r - q).
    let want = 0.1 - (-3.2) / (gain * kp * kv);
    assert!(
        (run.y[3999] - want).abs() < 1e-12,
        "{} vs {want}",
        run.y[3999]
    );
    assert!((gain * run.u[3999] - (-3.2)).abs() < 1e-9);
    // The step of 0.1 m asks for kv kp 0.1 = 3840 V at first; a 10 V limit
    // clips it.
    let limited = Controller {
        saturation: Some(10.0),
        ..c.clone()
    };
    let run = sim.run_closed_loop(&ClosedLoop::new(&limited, &r)).unwrap();
    assert_eq!(run.u[0], 10.0);
    assert!(run.u.iter().all(|u| u.abs() <= 10.0));
    // Errors.
    let bad = Controller::new(-1.0, kv);
    assert!(matches!(
        sim.run_closed_loop(&ClosedLoop::new(&bad, &r)),
        Err(SimulateError::Controller(_))
    ));
    let bad_filter = Controller {
        filter: vec![0.5, 0.6],
        ..c.clone()
    };
    assert!(sim
        .run_closed_loop(&ClosedLoop::new(&bad_filter, &r))
        .is_err());
    let mut vel = f.clone();
    vel.output = Output::Velocity;
    let sim = Simulator::new(&vel, 1000.0, &SimOptions::default()).unwrap();
    let e = sim.run_closed_loop(&ClosedLoop::new(&c, &r)).unwrap_err();
    assert!(e.to_string().contains("reads a position"), "{e}");
    let short = [0.0; 2];
    assert!(c.check(&short, &short, &short, None, 1000.0).is_err());
}

/// The cost of one simulated sample of a two-mass chain with Coulomb
/// friction (the time-domain diagnosis's commonest run): `cargo test
/// --release -p mms --test simulate -- --ignored --nocapture`.
#[test]
#[ignore = "timing; meaningful in release only"]
fn benchmark_two_mass_coulomb() {
    let m = Model::new(2, 0, Port::new(1, 0), Port::new(2, 0)).unwrap();
    let effects = Effects {
        coulomb_friction: Some(0.3),
        ..Effects::default()
    };
    let f = file(m, Output::Position, vec![1.0, 2.0, 4.0e4, 5.0], effects);
    let fs = 4000.0;
    let sim = Simulator::new(&f, fs, &SimOptions::default()).unwrap();
    let u: Vec<f64> = (0..4096)
        .map(|k| {
            (2.0 * PI * 3.0 * k as f64 / fs).sin() + 0.5 * (2.0 * PI * 40.0 * k as f64 / fs).sin()
        })
        .collect();
    let runs = 400;
    let start = std::time::Instant::now();
    let mut sum = 0.0;
    for _ in 0..runs {
        sum += sim.run(&u).unwrap().iter().sum::<f64>();
    }
    let per = start.elapsed().as_secs_f64() / (runs * u.len() * sim.substeps()) as f64;
    println!(
        "two masses, Coulomb friction: {:.1} ns per step ({} sub-steps per sample; checksum {sum:.6e})",
        per * 1e9,
        sim.substeps()
    );
}

/// A dead time of a fraction of a sample: a constant force from sample 0
/// on, held and delayed by `tau`, moves a free mass as `F (t - tau)^2 /
/// 2m` from `t = tau` on (exact for RK4 on a double integrator), whether
/// `tau` is 0.3 of a sample, 1.6 samples, or 0.8 of a sample of which the
/// hold's half sample is part.
#[test]
fn a_dead_time_of_a_fraction_of_a_sample_is_kept() {
    let (m, force, fs) = (2.0, 3.0, 200.0);
    let free = |delay: f64, includes_hold: bool| -> Vec<f64> {
        let mut f = one_mass(m, 0.0, Output::Position);
        f.effects = Effects {
            time_delay_s: Some(delay),
            ..Effects::default()
        };
        let options = SimOptions {
            delay_includes_hold: includes_hold,
            ..SimOptions::default()
        };
        Simulator::new(&f, fs, &options)
            .unwrap()
            .run(&[force; 60])
            .unwrap()
    };
    for (delay, includes_hold, tau) in [
        (0.3 / fs, false, 0.3 / fs),
        (1.6 / fs, false, 1.6 / fs),
        (0.8 / fs, true, 0.3 / fs),
    ] {
        let x = free(delay, includes_hold);
        for (k, &xk) in x.iter().enumerate() {
            let t = (k as f64 / fs - tau).max(0.0);
            let exact = force * t * t / (2.0 * m);
            assert!(
                (xk - exact).abs() < 1e-9 * (1.0 + exact),
                "delay {delay} s (hold included: {includes_hold}) at sample {k}: {xk} vs {exact}"
            );
        }
    }
    // A delay shorter than the hold leaves the hold alone.
    assert_eq!(free(0.2 / fs, true), free(0.0, false));
}

/// The sampled response ([`ChainResponse::eval_held`]) is what the
/// simulator's samples show, to the integrator's accuracy (1e-3 at a fifth
/// of the rate, 1e-4 below a tenth), for a position and a velocity up to a
/// fifth of the rate, where a transfer function times the hold's
/// `sinc(w T/2) e^(-j w T/2)` misses by 0.4-1 % (the images folded back
/// from above the Nyquist frequency); the factor of
/// [`ChainResponse::held_factor`] turns the one into the other.
#[test]
fn the_held_response_is_what_the_samples_show() {
    let a2 = Model::from_id("A2").unwrap();
    let p = vec![0.01, 0.012, 0.02, 400.0, 900.0, 0.3, 0.5];
    let fs = 2000.0;
    let mut worst_sinc = 0.0f64;
    for output in [Output::Position, Output::Velocity] {
        for f in [7.0, 61.0, 140.0, 400.0] {
            let w = 2.0 * PI * f;
            let got = steady_sine(&file(a2, output, p.clone(), Effects::default()), f, fs);
            let g = ChainResponse::new(&a2, output);
            let want = g.eval_held(&p, f, fs).unwrap() * Complex64::new(0.0, -1.0);
            let err = (got - want).norm() / want.norm();
            assert!(err < 1e-3, "{output} {f} Hz: {got} vs {want} ({err:.2e})");
            let c = g.held_factor(&p, &[f], fs).unwrap()[0];
            let held = g.eval(&p, f).unwrap() * Complex64::from_polar(1.0, -w / (2.0 * fs)) * c;
            assert!((held * Complex64::new(0.0, -1.0) - want).norm() < 1e-3 * want.norm());
            let x = w / (2.0 * fs);
            let sinc = g.eval(&p, f).unwrap() * Complex64::from_polar(x.sin() / x, -x);
            worst_sinc =
                worst_sinc.max((sinc * Complex64::new(0.0, -1.0) - want).norm() / want.norm());
        }
    }
    assert!(worst_sinc > 5e-3, "{worst_sinc}");
}
