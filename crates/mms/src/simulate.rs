//! Nonlinear time simulation of a chain model: the sampled output `y[k]`
//! of the sensor port for a sampled actuator force `u[k]` (zero-order hold
//! at rate `fs`), with Coulomb friction and backlash (the `friction
//! {coulomb_n}` and `backlash {gap}` of [`Effects`]) besides the chain's
//! linear masses, springs and dampers.
//!
//! Model (`x` the mass positions, `M x'' = b F - forces`):
//!
//! - **Input.** `F = gain * gain_factor * u`, held constant over each
//!   sample: the model file's gain is applied at the actuator, so the
//!   Coulomb force and the gap stay in the model's physical units (for a
//!   linear model it makes no difference where the gain sits). A `lowpass`
//!   effect is a first-order lag state on `F`; a `time_delay` shifts the
//!   held input by whole sub-steps, their count chosen so that the delay
//!   falls on one (to 1 % of it; [`delay_substeps`]). The hold itself is
//!   half a sample of dead time, which a delay fitted to a recording's FRF
//!   includes ([`SimOptions::delay_includes_hold`]). `hysteretic_damping` has no
//!   causal time-domain form and is refused.
//! - **Coulomb friction** `F_c sign(v)` on one mass against the ground
//!   (default: the driven mass, the actuator's `plus` mass, as for viscous
//!   `friction`), with Karnopp's stick-slip logic: a mass at rest sticks
//!   while the other forces on it stay within `F_c` (friction balances them
//!   exactly), and a slipping mass whose velocity changes sign during a
//!   sub-step is stopped there if the other forces cannot break it away.
//!   This is exact stiction, which a smooth `tanh(v / v_s)` law cannot give
//!   (it creeps under any force), and it needs no velocity scale chosen
//!   against the motion.
//! - **Backlash**: a dead zone of total width `gap` in one spring, force
//!   `c (d - gap/2 sign d)` outside the zone and 0 inside; the spring's
//!   damper acts only in contact (a damper across an open gap would
//!   transmit force). Default spring: the first one on the free side of
//!   the driven mass (between masses `p` and `p + 1` for `p` the actuator's
//!   `plus` mass), else the one on its ground side: the coupling next to
//!   the motor, where a gearbox or a coupling with play sits.
//! - **Offset** (`offset {force_n}`): a constant force `-force_n` on the
//!   driven mass (the inverse dynamics `F = M q'' + ... + offset`); at rest
//!   Coulomb friction balances it like any other force.
//! - **Pre-sliding stiffness** (`friction {pre_sliding_n_per_m}`): a linear
//!   spring from the driven mass to the ground, the small-motion regime of
//!   friction at rest; the break-away into sliding is not modelled.
//! - **Closed loop** ([`Simulator::run_closed_loop`]): a sampled position
//!   [`Controller`] computes the input from the simulated sensor reading
//!   and a reference, as the real controller did from the measured one.
//! - **Integration**: classical fixed-step RK4 with sub-steps per sample,
//!   `h <= 0.3 / rate`, where `rate` bounds the largest eigenvalue of the
//!   linear part (Gershgorin on `M^-1 C` for the stiffness, on `M^-1 D` for
//!   the damping, plus the lag's corner): RK4 is stable to `|lambda| h =
//!   2.8` and at `0.3` its amplitude error is about `1e-6` per step.
//!   Between the friction's and the backlash's switching points the chain
//!   is affine, and so is an RK4 step on it: on each such piece (sliding
//!   one way or stuck, one side of the gap) a sub-step is a precomputed
//!   affine map of the state and the input, checked to stay on its piece
//!   at every stage; a step that leaves it (a reversal, a contact made or
//!   lost, a break-away) is integrated stage by stage. Both give the same
//!   state up to rounding, the map in a fraction of the time.
//!
//! The simulation starts at rest; `y[k]` is the sensor's reading at `t_k =
//! k / fs`, before the input `u[k]` acts (acceleration: with `u[k]`).
//!
//! ```
//! use mms::model_file::{ModelFile, Motion};
//! use mms::response::{Effects, Parameters};
//! use mms::simulate::simulate;
//! use mms::{Model, Output, Port};
//!
//! // One mass of 2 kg with 3 N of Coulomb friction, pushed by 5 N.
//! let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0))?;
//! let file = ModelFile {
//!     model: m,
//!     output: Output::Velocity,
//!     parameters: Parameters::from_values(&m, vec![2.0])?,
//!     gain: 1.0,
//!     motion: Motion::Translational,
//!     effects: Effects { coulomb_friction: Some(3.0), ..Effects::default() },
//! };
//! let v = simulate(&file, &[5.0; 101], 100.0)?;
//! // (5 - 3) N / 2 kg = 1 m/s^2 for 1 s.
//! assert!((v[100] - 1.0).abs() < 1e-9);
//! // Below the friction force nothing moves.
//! let v = simulate(&file, &[2.9; 101], 100.0)?;
//! assert!(v.iter().all(|&v| v == 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::model::Model;
use crate::model_file::ModelFile;
use crate::response::{Effects, Parameters, ResponseError};
use crate::tf::Output;

/// Why a simulation cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimulateError {
    /// Bad parameters for the model.
    #[error(transparent)]
    Response(#[from] ResponseError),
    /// The sample rate is not positive and finite.
    #[error("sample rate {0} Hz must be positive and finite")]
    SampleRate(f64),
    /// An input sample that is not finite.
    #[error("input sample {0} is not finite")]
    Input(usize),
    /// An effect value out of range, or one without a time-domain model.
    #[error("effect {0}")]
    Effect(String),
    /// The place of a nonlinearity does not exist in the model.
    #[error("{0}")]
    Place(String),
    /// A controller or closed-loop setting that cannot run.
    #[error("closed loop: {0}")]
    Controller(String),
    /// The state left the finite numbers (a wrong step or parameters).
    #[error("the simulation diverged at sample {0}")]
    Diverged(usize),
}

/// Where the nonlinearities sit (defaults: see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SimOptions {
    /// The mass (1-based) Coulomb friction acts on; `None`: the driven mass.
    pub friction_mass: Option<usize>,
    /// The spring with backlash, by its lower node (0: the ground to m1,
    /// 1: m1 to m2, ...); `None`: the default place.
    pub backlash_link: Option<usize>,
    /// Sub-steps per sample; `None`: from the chain's fastest eigenvalue
    /// and, with a `time_delay`, enough for the delay to fall on a sub-step
    /// (see [`delay_substeps`]).
    pub substeps: Option<usize>,
    /// The model's `time_delay` is the whole dead time a sampled
    /// recording's FRF shows, the hold's half sample included (a delay
    /// fitted to a recording's FRF). The simulation holds each sample
    /// itself, so it applies only the rest (none if the delay is shorter
    /// than the hold). Without it the delay is dead time besides the hold.
    pub delay_includes_hold: bool,
}

/// The sub-steps per sample, at least `min`, on whose grid a dead time of
/// `delay` samples falls to within the larger of 1 % of itself and 0.002
/// of a sample (the first count that does, up to 256; where none does,
/// the count up to 256 that comes closest): the held input is shifted by whole
/// sub-steps, so a count chosen for the chain's speed alone would round a
/// dead time of a fraction of a sample to nothing or to a whole one.
///
/// ```
/// use mms::simulate::delay_substeps;
/// // A whole number of samples needs no sub-steps.
/// assert_eq!(delay_substeps(3.0, 1), 1);
/// // 0.221 of a sample: 9 sub-steps put it at 2/9 = 0.2222 (0.5 %).
/// assert_eq!(delay_substeps(0.221, 1), 9);
/// // Half a sample: 2 sub-steps, or any even count above `min`.
/// assert_eq!(delay_substeps(0.5, 3), 4);
/// ```
pub fn delay_substeps(delay: f64, min: usize) -> usize {
    const MAX_SUBSTEPS: usize = 256;
    let min = min.max(1);
    if !(delay.is_finite() && delay > 0.0) || min >= MAX_SUBSTEPS {
        return min;
    }
    let tolerance = (0.01 * delay).max(0.002);
    let error = |s: usize| {
        let steps = delay * s as f64;
        (steps - steps.round()).abs() / s as f64
    };
    let mut best = (f64::INFINITY, min);
    for s in min..=MAX_SUBSTEPS {
        let e = error(s);
        if e <= tolerance {
            return s;
        }
        if e < best.0 {
            best = (e, s);
        }
    }
    best.1
}

/// A compiled simulation: a model, its parameters and effects, a sample
/// rate. [`Simulator::run`] may be called for many inputs.
#[derive(Clone, Debug)]
pub struct Simulator {
    n: usize,
    /// `1 / m_i`.
    inv_m: Vec<f64>,
    /// Links `(a, b, c, d)`: nodes (0 = ground), spring, damper.
    links: Vec<(usize, usize, f64, f64)>,
    input: Vec<f64>,
    sensor: Vec<f64>,
    output: Output,
    /// Input scale: gain times gain factor.
    scale: f64,
    /// Viscous friction of `driven` (0-based), N s/m.
    viscous: f64,
    /// Pre-sliding stiffness of `driven`, N/m (0: none).
    pre_sliding: f64,
    driven: usize,
    /// Coulomb force and its mass (0-based).
    coulomb: f64,
    friction_mass: usize,
    /// Constant offset force on `driven` (subtracted).
    offset: f64,
    /// Backlash: the lower node of the spring that has it (0: the
    /// ground to m1), and the half gap.
    backlash: Option<(usize, f64)>,
    /// Lag: `2 pi f_c` (0: none).
    lag: f64,
    /// Delay in sub-steps.
    delay_steps: usize,
    substeps: usize,
    h: f64,
    /// Step by the affine maps of the pieces where the step stays on one
    /// (`false`: every step by the integrator, for the tests that compare
    /// the two).
    piecewise: bool,
}

/// What the integration shows a caller at each sample: positions,
/// velocities and, when asked for, accelerations. Index 0 is the ground
/// (always 0) and mass `i` is at index `i`.
struct Now<'a> {
    x: &'a [f64],
    v: &'a [f64],
    a: &'a [f64],
    /// The sensor's reading of the simulator's output quantity.
    y: f64,
}

/// The state of a chain with `L - 1` masses: positions, velocities, and the
/// lagged force. Index 0 of `x` and `v` is the ground (always 0) and mass
/// `i` is at index `i`, so a link reads its two nodes without asking which
/// one is the ground. The size is a constant so that the per-mass loops of
/// a step unroll: a step of a small chain is a few dozen operations, and
/// loop and bounds overhead would otherwise cost more than they.
#[derive(Clone, Copy, Debug)]
struct State<const L: usize> {
    x: [f64; L],
    v: [f64; L],
    f: f64,
}

/// A simulator's coefficients laid out for a chain of `L - 1` masses.
struct Kernel<'s, const L: usize> {
    sim: &'s Simulator,
    /// The actuator's input vector, with 0 for the ground.
    input: [f64; L],
    /// `1 / m_i`, with 0 for the ground.
    inv_m: [f64; L],
    /// The link from node `i` to node `i + 1` (a chain has no other):
    /// whether it exists, its spring and its damper. Indexed by node, the
    /// loops over links unroll with fixed places, and no force passes
    /// through a store and load at a place known only at run time.
    link: [bool; L],
    spring: [f64; L],
    damper: [f64; L],
    /// The node below the spring with backlash (`L`: none), and half its
    /// gap.
    backlash: (usize, f64),
}

impl Simulator {
    /// Compiles a model file (its parameters, gain and effects) for sample
    /// rate `fs`.
    pub fn new(
        file: &ModelFile,
        fs: f64,
        options: &SimOptions,
    ) -> Result<Simulator, SimulateError> {
        Simulator::with_parts(
            &file.model,
            file.output,
            file.parameters.values(),
            file.gain,
            &file.effects,
            fs,
            options,
        )
    }

    /// Compiles a model from its parts: parameter values in the order of
    /// [`Model::parameters`].
    pub fn with_parts(
        model: &Model,
        output: Output,
        values: &[f64],
        gain: f64,
        effects: &Effects,
        fs: f64,
        options: &SimOptions,
    ) -> Result<Simulator, SimulateError> {
        let p = Parameters::from_values(model, values.to_vec())?;
        let values = p.values();
        if !(fs.is_finite() && fs > 0.0) {
            return Err(SimulateError::SampleRate(fs));
        }
        if !(gain.is_finite() && gain != 0.0) {
            return Err(SimulateError::Effect(format!(
                "gain {gain} must be finite and non-zero"
            )));
        }
        let n = model.n_masses();
        let idx: Vec<usize> = (0..n).filter(|&i| model.has_link(i)).collect();
        let nl = idx.len();
        let links: Vec<(usize, usize, f64, f64)> = idx
            .iter()
            .enumerate()
            .map(|(k, &i)| (i, i + 1, values[n + k], values[n + nl + k]))
            .collect();
        let check = |name: &str, v: Option<f64>, zero_ok: bool| -> Result<f64, SimulateError> {
            match v {
                None => Ok(0.0),
                Some(x) if x.is_finite() && (x > 0.0 || (zero_ok && x == 0.0)) => Ok(x),
                Some(x) => Err(SimulateError::Effect(format!(
                    "{name} = {x} is out of range"
                ))),
            }
        };
        if effects.loss_factor.is_some() {
            return Err(SimulateError::Effect(
                "hysteretic_damping has no time-domain model".into(),
            ));
        }
        let gain_factor = match effects.gain_factor {
            None => 1.0,
            Some(g) => check("gain_error.factor", Some(g), false)?,
        };
        let viscous = check("friction.viscous_ns_per_m", effects.viscous_friction, true)?;
        let coulomb = check("friction.coulomb_n", effects.coulomb_friction, true)?;
        let pre_sliding = check(
            "friction.pre_sliding_n_per_m",
            effects.pre_sliding_stiffness,
            true,
        )?;
        let gap = check("backlash.gap", effects.backlash_gap, true)?;
        let offset = match effects.offset_force {
            Some(f) if !f.is_finite() => {
                return Err(SimulateError::Effect(format!(
                    "offset.force_n = {f} is not finite"
                )))
            }
            f => f.unwrap_or(0.0),
        };
        let delay = check("time_delay.delay_s", effects.time_delay_s, true)?;
        let delay = if options.delay_includes_hold {
            (delay - 0.5 / fs).max(0.0)
        } else {
            delay
        };
        let lag = match effects.lowpass_hz {
            None => 0.0,
            Some(f) => 2.0 * std::f64::consts::PI * check("lowpass.corner_hz", Some(f), false)?,
        };
        let driven = model.actuator().plus - 1;
        let friction_mass = match options.friction_mass {
            None => driven,
            Some(j) if (1..=n).contains(&j) => j - 1,
            Some(j) => {
                return Err(SimulateError::Place(format!(
                    "friction mass {j} is not a mass of {}",
                    model.name()
                )))
            }
        };
        let backlash = if effects.backlash_gap.is_some() {
            let want = match options.backlash_link {
                Some(i) => Some(i).filter(|&i| model.has_link(i)),
                None => default_backlash_link(model),
            };
            let Some(i) = want else {
                return Err(SimulateError::Place(match options.backlash_link {
                    Some(i) => format!("{} has no spring at link {i}", model.name()),
                    None => format!("{} has no spring next to the driven mass", model.name()),
                }));
            };
            Some((i, gap / 2.0))
        } else {
            None
        };
        let inv_m: Vec<f64> = values[..n].iter().map(|m| 1.0 / m).collect();
        // Gershgorin bounds of the linear part's eigenvalues.
        let mut k_row = vec![0.0; n];
        let mut d_row = vec![0.0; n];
        for &(a, b, c, d) in &links {
            for node in [a, b] {
                if node > 0 {
                    k_row[node - 1] += 2.0 * c;
                    d_row[node - 1] += 2.0 * d;
                }
            }
        }
        d_row[driven] += viscous;
        k_row[driven] += pre_sliding;
        let rate = (0..n)
            .map(|i| (k_row[i] * inv_m[i]).sqrt() + d_row[i] * inv_m[i])
            .fold(lag, f64::max);
        let substeps = match options.substeps {
            Some(s) => s.max(1),
            None => delay_substeps(delay * fs, ((rate / fs / 0.3).ceil() as usize).max(1)),
        };
        let h = 1.0 / (fs * substeps as f64);
        let to_f64 = |v: Vec<i64>| v.into_iter().map(|x| x as f64).collect();
        Ok(Simulator {
            n,
            inv_m,
            links,
            input: to_f64(model.input_vector()),
            sensor: to_f64(model.output_vector()),
            output,
            scale: gain * gain_factor,
            viscous,
            pre_sliding,
            driven,
            coulomb,
            friction_mass,
            offset,
            backlash,
            lag,
            delay_steps: (delay / h).round() as usize,
            substeps,
            h,
            piecewise: true,
        })
    }

    /// Sub-steps per sample.
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    /// [`Simulator::run`], and the same quantity (position, velocity or
    /// acceleration, as the model's output) read at each of `places` too:
    /// several sensors of one chain, as a motor and a load encoder.
    ///
    /// ```
    /// use mms::model_file::ModelFile;
    /// use mms::simulate::{SimOptions, Simulator};
    /// use mms::Port;
    /// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
    ///             output = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nc12 = 100\nd12 = 1\n";
    /// let sim = Simulator::new(&ModelFile::parse(text)?, 100.0, &SimOptions::default())?;
    /// let u = [1.0; 50];
    /// let (motor, at) = sim.run_at(&u, &[Port::new(2, 0), Port::new(2, 1)])?;
    /// let x = sim.positions(&u)?;
    /// assert_eq!(motor, sim.run(&u)?);
    /// assert_eq!(at[0][49], x[49][1]);
    /// assert_eq!(at[1][49], x[49][1] - x[49][0]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn run_at(
        &self,
        u: &[f64],
        places: &[crate::Port],
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), SimulateError> {
        let vectors = places
            .iter()
            .map(|&p| self.place_vector(p))
            .collect::<Result<Vec<_>, _>>()?;
        let mut y = Vec::with_capacity(u.len());
        let mut at: Vec<Vec<f64>> = vec![Vec::with_capacity(u.len()); places.len()];
        let dot = |w: &[f64], v: &[f64]| w.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let accelerations = self.output == Output::Acceleration;
        self.open_loop(u, accelerations, |s| {
            let q = match self.output {
                Output::Position => &s.x[1..],
                Output::Velocity => &s.v[1..],
                Output::Acceleration => &s.a[1..],
            };
            y.push(s.y);
            for (out, w) in at.iter_mut().zip(&vectors) {
                out.push(dot(w, q));
            }
            s.y.is_finite()
        })?;
        Ok((y, at))
    }

    /// The reading vector of a place of this chain (`+1` at `plus`, `-1`
    /// at `minus`; the ground's entry dropped).
    fn place_vector(&self, p: crate::Port) -> Result<Vec<f64>, SimulateError> {
        if !(p.plus >= 1 && p.plus <= self.n && p.minus < p.plus) {
            return Err(SimulateError::Place(format!(
                "[{}, {}] is not a place on a chain of {} masses",
                p.plus, p.minus, self.n
            )));
        }
        let mut v = vec![0.0; self.n];
        v[p.plus - 1] += 1.0;
        if p.minus > 0 {
            v[p.minus - 1] -= 1.0;
        }
        Ok(v)
    }

    /// Simulates the sensor output for the input samples `u` (the same
    /// length), starting at rest.
    pub fn run(&self, u: &[f64]) -> Result<Vec<f64>, SimulateError> {
        let mut y = Vec::with_capacity(u.len());
        let accelerations = self.output == Output::Acceleration;
        self.open_loop(u, accelerations, |s| {
            y.push(s.y);
            s.y.is_finite()
        })?;
        Ok(y)
    }

    /// Integrates the open-loop response to the input samples `u` from
    /// rest, handing every sample's state (with its accelerations if
    /// `accelerations`) to `record` (which says whether it stayed finite);
    /// a non-finite input is refused first.
    fn open_loop(
        &self,
        u: &[f64],
        accelerations: bool,
        record: impl FnMut(&Now) -> bool,
    ) -> Result<(), SimulateError> {
        if let Some(k) = u.iter().position(|x| !x.is_finite()) {
            return Err(SimulateError::Input(k));
        }
        self.integrate(u.len(), Start::Rest, accelerations, |k, _| u[k], record)
            .map(|_| ())
    }

    /// The position of every mass at every sample (`[k][i]`: sample `k`,
    /// mass `i + 1`), whatever the sensor: what a position sensor on each
    /// mass would read (without the gain).
    ///
    /// ```
    /// use mms::model_file::ModelFile;
    /// use mms::simulate::{SimOptions, Simulator};
    /// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [2, 0]\n\
    ///             output = \"position\"\n[parameters]\nm1 = 1\nm2 = 1\nc12 = 100\nd12 = 1\n";
    /// let file = ModelFile::parse(text)?;
    /// let sim = Simulator::new(&file, 100.0, &SimOptions::default())?;
    /// let x = sim.positions(&[1.0; 50])?;
    /// // The sensor reads mass 2.
    /// assert_eq!(sim.run(&[1.0; 50])?[49], x[49][1]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn positions(&self, u: &[f64]) -> Result<Vec<Vec<f64>>, SimulateError> {
        let mut out = Vec::with_capacity(u.len());
        self.open_loop(u, false, |s| {
            out.push(s.x[1..].to_vec());
            s.x.iter().all(|x| x.is_finite())
        })?;
        Ok(out)
    }

    /// Simulates the model inside a sampled position loop: at each sample
    /// `k` the controller reads the simulated sensor position (plus
    /// `initial_position`) and the reference `r[k]`, and its output `u[k]`
    /// (plus the disturbance `d[k]`, then saturated) is held until the next
    /// sample, as the recorded controller did. The model starts in a rigid
    /// motion at `initial_velocity` (every mass) with its springs relaxed,
    /// and the controller's past readings continue that motion. Returns the
    /// simulated sensor position and the controller output.
    ///
    /// The output must be a position.
    ///
    /// ```
    /// use mms::model_file::ModelFile;
    /// use mms::simulate::{ClosedLoop, Controller, SimOptions, Simulator};
    /// // A 10 kg body, 40 N/V drive, in the loop of a P position / P
    /// // velocity controller; the reference steps to 1 mm.
    /// let text = "masses = 1\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
    ///             output = \"position\"\ngain = 40\n[parameters]\nm1 = 10\n";
    /// let file = ModelFile::parse(text)?;
    /// let sim = Simulator::new(&file, 1000.0, &SimOptions::default())?;
    /// let r = vec![1e-3; 2000];
    /// let c = Controller::new(50.0, 20.0);
    /// let run = sim.run_closed_loop(&ClosedLoop::new(&c, &r))?;
    /// // The loop settles on the reference (no force is left at rest).
    /// assert!((run.y[1999] - 1e-3).abs() < 1e-9);
    /// assert!(run.u[1999].abs() < 1e-6);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn run_closed_loop(&self, cl: &ClosedLoop) -> Result<ClosedLoopRun, SimulateError> {
        if self.output != Output::Position {
            return Err(SimulateError::Controller(format!(
                "the controller reads a position; the model's output is {}",
                self.output
            )));
        }
        let bad = |s: String| Err(SimulateError::Controller(s));
        let n = cl.reference.len();
        if let Some(d) = cl.disturbance {
            if d.len() != n {
                return bad(format!(
                    "the disturbance has {} samples, the reference {n}",
                    d.len()
                ));
            }
        }
        let check = cl
            .reference
            .iter()
            .chain(cl.disturbance.unwrap_or(&[]))
            .position(|x| !x.is_finite());
        if let Some(k) = check {
            return Err(SimulateError::Input(k % n.max(1)));
        }
        if !(cl.initial_position.is_finite() && cl.initial_velocity.is_finite()) {
            return bad("the initial position and velocity must be finite".into());
        }
        cl.controller.validate()?;
        // The controller's own sensor, when it is not the model's.
        let feedback = match cl.feedback {
            None => None,
            Some(f) => {
                if !f.initial_position.is_finite() {
                    return bad("the initial position and velocity must be finite".into());
                }
                let v = self.place_vector(f.sensor).map_err(|e| {
                    SimulateError::Controller(format!("the controller's sensor: {e}"))
                })?;
                Some((v, f.initial_position))
            }
        };
        let observed = cl
            .observed
            .iter()
            .map(|&(p, q0)| {
                if !q0.is_finite() {
                    return Err(SimulateError::Controller(
                        "the initial position and velocity must be finite".into(),
                    ));
                }
                Ok((self.place_vector(p)?, q0))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut at: Vec<Vec<f64>> = vec![Vec::with_capacity(n); observed.len()];
        let fs = 1.0 / (self.h * self.substeps as f64);
        let dot = |w: &[f64], v: &[f64]| w.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let q0 = feedback.as_ref().map_or(cl.initial_position, |f| f.1);
        let mut hist = History::new(cl.controller, q0, cl.initial_velocity, fs);
        let mut y = Vec::with_capacity(n);
        let start = Start::Moving(cl.initial_velocity);
        let u = self.integrate(
            n,
            start,
            false,
            |k, x| {
                let output = dot(&self.sensor, &x[1..]) + cl.initial_position;
                y.push(output);
                for (out, (w, q0)) in at.iter_mut().zip(&observed) {
                    out.push(dot(w, &x[1..]) + q0);
                }
                let reading = match &feedback {
                    Some((v, q0)) => dot(v, &x[1..]) + q0,
                    None => output,
                };
                let d = cl.disturbance.map_or(0.0, |d| d[k]);
                hist.output(cl.controller, cl.reference[k], reading, d)
            },
            |s| s.x.iter().chain(s.v).all(|v| v.is_finite()),
        )?;
        Ok(ClosedLoopRun { y, u, at })
    }

    /// Integrates `n` samples from `start`; at each sample time `input(k,
    /// positions)` gives the sample's input `u[k]` (before the gain), then
    /// `sample(state)` is called (with the accelerations under the held
    /// input if `accelerations`) and returns false if the state is no
    /// longer finite. Returns the inputs.
    fn integrate(
        &self,
        samples: usize,
        start: Start,
        accelerations: bool,
        input: impl FnMut(usize, &[f64]) -> f64,
        sample: impl FnMut(&Now) -> bool,
    ) -> Result<Vec<f64>, SimulateError> {
        let a = (samples, start, accelerations);
        // One instance per chain length, up to MAX_MASSES.
        match self.n {
            1 => self.integrate_chain::<2>(a, input, sample),
            2 => self.integrate_chain::<3>(a, input, sample),
            3 => self.integrate_chain::<4>(a, input, sample),
            4 => self.integrate_chain::<5>(a, input, sample),
            5 => self.integrate_chain::<6>(a, input, sample),
            6 => self.integrate_chain::<7>(a, input, sample),
            7 => self.integrate_chain::<8>(a, input, sample),
            8 => self.integrate_chain::<9>(a, input, sample),
            n => Err(SimulateError::Place(format!(
                "{n} masses: a model has at most {}",
                crate::model::MAX_MASSES
            ))),
        }
    }

    /// [`Simulator::integrate`] for a chain of `L - 1` masses.
    fn integrate_chain<const L: usize>(
        &self,
        (samples, start, accelerations): (usize, Start, bool),
        mut input: impl FnMut(usize, &[f64]) -> f64,
        mut sample: impl FnMut(&Now) -> bool,
    ) -> Result<Vec<f64>, SimulateError> {
        let mut kernel = Kernel::<L> {
            sim: self,
            input: [0.0; L],
            inv_m: [0.0; L],
            link: [false; L],
            spring: [0.0; L],
            damper: [0.0; L],
            backlash: self.backlash.unwrap_or((L, 0.0)),
        };
        kernel.input[1..].copy_from_slice(&self.input);
        kernel.inv_m[1..].copy_from_slice(&self.inv_m);
        for &(a, b, c, d) in &self.links {
            debug_assert_eq!(b, a + 1, "a chain links neighbours");
            (kernel.link[a], kernel.spring[a], kernel.damper[a]) = (true, c, d);
        }
        let v0 = match start {
            Start::Rest => 0.0,
            Start::Moving(v) => v,
        };
        let mut s = State::<L> {
            x: [0.0; L],
            v: [v0; L],
            f: 0.0,
        };
        s.v[0] = 0.0;
        let mut u: Vec<f64> = Vec::with_capacity(samples);
        let mut a_now = [0.0; L];
        // The affine maps of the pieces, indexed by `slot`: each friction
        // direction (one without friction) times each side of the gap (one
        // without backlash).
        let backlash = kernel.backlash.0 < L - 1;
        let signs: &[f64] = if self.coulomb > 0.0 {
            &[-1.0, 0.0, 1.0]
        } else {
            &[0.0]
        };
        let contacts: &[Contact] = if backlash {
            &[Contact::Below, Contact::Gap, Contact::Above]
        } else {
            &[Contact::Gap]
        };
        let maps: Vec<AffineStep<L>> = if self.piecewise {
            signs
                .iter()
                .flat_map(|&sign| {
                    contacts.iter().map(move |&contact| Piece {
                        sign,
                        contact,
                        constants: true,
                    })
                })
                .map(|p| AffineStep::new(&kernel, p))
                .collect()
        } else {
            Vec::new()
        };
        // The slot of the piece the state is on: the friction mass's
        // direction (at rest, or no friction: 0) and the spring's side.
        let (gap_link, half) = kernel.backlash;
        let slot = |s: &State<L>| {
            let side = if backlash {
                Contact::of(s.x[gap_link + 1] - s.x[gap_link], half) as usize
            } else {
                0
            };
            let way = if signs.len() == 1 {
                0
            } else {
                let v = s.v[self.friction_mass + 1];
                if v > 0.0 {
                    2
                } else if v < 0.0 {
                    0
                } else {
                    1
                }
            };
            way * contacts.len() + side
        };
        let lagged = self.lag > 0.0;
        let held = |u: &[f64], step: usize| -> f64 {
            // The sub-step's input: the held sample, `delay_steps` earlier.
            match step.checked_sub(self.delay_steps) {
                Some(t) if self.substeps == 1 => self.scale * u[t],
                Some(t) => self.scale * u[t / self.substeps],
                None => 0.0,
            }
        };
        // The sensor's reading, as a dot product of fixed length (summed
        // from -0.0, in the order of an iterator's sum).
        let mut sensor = [0.0; L];
        sensor[1..].copy_from_slice(&self.sensor);
        let output = self.output;
        let read = |s: &State<L>, a: &[f64; L]| -> f64 {
            let q = match output {
                Output::Position => &s.x,
                Output::Velocity => &s.v,
                Output::Acceleration => a,
            };
            let mut y = -0.0;
            for i in 1..L {
                y += sensor[i] * q[i];
            }
            y
        };
        let j = self.friction_mass + 1;
        for k in 0..samples {
            let step0 = k * self.substeps;
            let uk = input(k, &s.x);
            if !uk.is_finite() {
                return Err(SimulateError::Diverged(k));
            }
            u.push(uk);
            if accelerations {
                kernel.deriv(&s, held(&u, step0), &mut a_now);
            }
            let now = Now {
                x: &s.x,
                v: &s.v,
                a: &a_now,
                y: read(&s, &a_now),
            };
            if !sample(&now) {
                return Err(SimulateError::Diverged(k));
            }
            for sub in 0..self.substeps {
                let f_in = held(&u, step0 + sub);
                // On a piece where the chain is affine, its map; where the
                // step leaves the piece (a velocity reversal, a contact
                // made or lost, a stuck mass), the integrator itself.
                let fast = !maps.is_empty()
                    && if lagged {
                        maps[slot(&s)].step::<true>(&mut s, f_in)
                    } else {
                        maps[slot(&s)].step::<false>(&mut s, f_in)
                    };
                if fast {
                    continue;
                }
                let v0 = s.v[j];
                s = kernel.step(&s, f_in, None).0;
                // Karnopp's stick: the friction mass's velocity crossed
                // zero (or reached it) in this sub-step and the other
                // forces cannot break it away: it stops here.
                if self.coulomb > 0.0 && (s.v[j] == 0.0 || s.v[j].signum() != v0.signum()) {
                    let f = if self.lag > 0.0 { s.f } else { f_in };
                    let saved = s.v[j];
                    s.v[j] = 0.0;
                    let mut forces = [0.0; L];
                    kernel.forces(&s, f, &mut forces);
                    if forces[j].abs() > self.coulomb {
                        s.v[j] = saved;
                    }
                }
            }
        }
        Ok(u)
    }
}

/// How a simulation starts.
#[derive(Clone, Copy)]
enum Start {
    /// At rest.
    Rest,
    /// Every mass at this velocity (a rigid motion, springs relaxed).
    Moving(f64),
}

/// A sampled P position loop around a P velocity loop, as in drives and
/// robot joints (and the EMPS benchmark):
///
/// ```text
/// u[k] = kv (kp (r[k] - q[k]) - v[k]),   v[k] = (qf[k] - qf[k-1]) fs,
/// qf[k] = sum_i filter[i] q[k - i]
/// ```
///
/// The velocity is the backward difference of the FIR-filtered position
/// (`filter = [0.5, 0.5]`, the EMPS default, makes it the central
/// difference `(q[k] - q[k-2]) fs / 2`), and the output is clipped to
/// `±saturation` if given.
///
/// ```
/// use mms::simulate::Controller;
/// // Recorded position, reference and output: the law reproduces u
/// // (from the third sample on, where it needs no reading before the
/// // record).
/// let c = Controller::new(160.18, 243.45);
/// let q: Vec<f64> = (0..8).map(|k| 1e-5 * (k * k) as f64).collect();
/// let r = [1e-4; 8];
/// let u: Vec<f64> = (0..8)
///     .map(|k| {
///         let v = if k < 2 { 0.0 } else { (q[k] - q[k - 2]) * 1000.0 / 2.0 };
///         243.45 * (160.18 * (r[k] - q[k]) - v)
///     })
///     .collect();
/// let check = c.check(&r, &q, &u, None, 1000.0)?;
/// assert!(check.rms_rel < 1e-12);
/// // A plain backward difference does not.
/// let backward = Controller { filter: vec![1.0], ..c };
/// assert!(backward.check(&r, &q, &u, None, 1000.0)?.rms_rel > 0.01);
/// # Ok::<(), mms::simulate::SimulateError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Controller {
    /// Position gain (1/s): velocity demand per position error.
    pub kp: f64,
    /// Velocity gain: controller output per velocity error (e.g. V per
    /// m/s).
    pub kv: f64,
    /// FIR taps applied to the position before the velocity difference.
    pub filter: Vec<f64>,
    /// Symmetric limit of the output, if any.
    pub saturation: Option<f64>,
}

impl Controller {
    /// The EMPS law with gains `kp` and `kv`: filter `[0.5, 0.5]`, no
    /// saturation.
    pub fn new(kp: f64, kv: f64) -> Controller {
        Controller {
            kp,
            kv,
            filter: vec![0.5, 0.5],
            saturation: None,
        }
    }

    fn validate(&self) -> Result<(), SimulateError> {
        let bad = |s: String| Err(SimulateError::Controller(s));
        if !(self.kp.is_finite() && self.kv.is_finite() && self.kp > 0.0 && self.kv > 0.0) {
            return bad(format!(
                "gains kp = {} and kv = {} must be positive and finite",
                self.kp, self.kv
            ));
        }
        let sum: f64 = self.filter.iter().sum();
        if self.filter.is_empty()
            || self.filter.iter().any(|t| !t.is_finite())
            || (sum - 1.0).abs() > 1e-9
        {
            return bad(format!(
                "the position filter {:?} must have finite taps summing to 1",
                self.filter
            ));
        }
        if let Some(s) = self.saturation {
            if !(s.is_finite() && s > 0.0) {
                return bad(format!("saturation {s} must be positive and finite"));
            }
        }
        Ok(())
    }

    /// Applies the law to a recorded position `q` and reference `r` (with
    /// an additive `disturbance` if the record has one) and compares it
    /// with the recorded output `u`: a closed-loop simulation is only as
    /// good as this match. The first `filter.len()` samples, whose law
    /// needs readings from before the record, are not compared.
    pub fn check(
        &self,
        r: &[f64],
        q: &[f64],
        u: &[f64],
        disturbance: Option<&[f64]>,
        fs: f64,
    ) -> Result<ControllerCheck, SimulateError> {
        self.validate()?;
        let n = q.len();
        if r.len() != n || u.len() != n || disturbance.is_some_and(|d| d.len() != n) {
            return Err(SimulateError::Controller(
                "reference, position, output and disturbance differ in length".into(),
            ));
        }
        if n < self.filter.len() + 3 {
            return Err(SimulateError::Controller(format!(
                "{n} samples are too few to check the law"
            )));
        }
        if !(fs.is_finite() && fs > 0.0) {
            return Err(SimulateError::SampleRate(fs));
        }
        let v0 = (q[2] - q[0]) * fs / 2.0;
        let mut hist = History::new(self, q[0], v0, fs);
        let (mut e2, mut u2, mut max_abs) = (0.0, 0.0, 0.0f64);
        let mut saturated = 0;
        for k in 0..n {
            let d = disturbance.map_or(0.0, |d| d[k]);
            let law = hist.output(self, r[k], q[k], d);
            if k < self.filter.len() {
                continue;
            }
            if self.saturation.is_some_and(|s| law.abs() >= s) {
                saturated += 1;
            }
            let e = u[k] - law;
            e2 += e * e;
            u2 += u[k] * u[k];
            max_abs = max_abs.max(e.abs());
        }
        if !(e2.is_finite() && u2.is_finite()) {
            return Err(SimulateError::Controller("samples are not finite".into()));
        }
        Ok(ControllerCheck {
            rms_rel: if u2 > 0.0 {
                (e2 / u2).sqrt()
            } else {
                e2.sqrt()
            },
            max_abs,
            saturated,
        })
    }
}

/// How well a [`Controller`] reproduces a recorded output
/// ([`Controller::check`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerCheck {
    /// RMS of `u - law` over the RMS of `u`.
    pub rms_rel: f64,
    /// Largest `|u - law|`.
    pub max_abs: f64,
    /// Samples where the law reached the saturation.
    pub saturated: usize,
}

/// The controller's memory: past readings for the FIR filter and the
/// last filtered position.
struct History {
    q: Vec<f64>,
    qf_prev: f64,
    fs: f64,
}

impl History {
    /// Past readings of a motion through `q0` at velocity `v0`.
    fn new(c: &Controller, q0: f64, v0: f64, fs: f64) -> History {
        let past = |i: usize| q0 - v0 * i as f64 / fs;
        let q: Vec<f64> = (1..=c.filter.len()).map(past).collect();
        let qf_prev = c
            .filter
            .iter()
            .enumerate()
            .map(|(i, t)| t * past(i + 1))
            .sum();
        History { q, qf_prev, fs }
    }

    /// The output for reference `r` and reading `q` (the newest), plus `d`.
    fn output(&mut self, c: &Controller, r: f64, q: f64, d: f64) -> f64 {
        // Shift in the new reading.
        self.q.rotate_right(1);
        self.q[0] = q;
        let qf: f64 = c.filter.iter().zip(&self.q).map(|(t, q)| t * q).sum();
        let v = (qf - self.qf_prev) * self.fs;
        self.qf_prev = qf;
        let u = c.kv * (c.kp * (r - q) - v) + d;
        match c.saturation {
            Some(s) => u.clamp(-s, s),
            None => u,
        }
    }
}

/// A closed position loop around the model
/// ([`Simulator::run_closed_loop`]).
#[derive(Clone, Copy, Debug)]
pub struct ClosedLoop<'a> {
    /// The controller.
    pub controller: &'a Controller,
    /// The position reference, one sample per output sample.
    pub reference: &'a [f64],
    /// A known signal added to the controller's output (e.g. injected
    /// pulses), in its units.
    pub disturbance: Option<&'a [f64]>,
    /// The model's sensor's position at the start.
    pub initial_position: f64,
    /// The velocity at the start (every mass).
    pub initial_velocity: f64,
    /// The sensor the controller reads, when it is not the model's own (a
    /// loop closed on the motor's encoder, the model read at the load's);
    /// `None`: the model's sensor.
    pub feedback: Option<Feedback>,
    /// Further places read beside the model's sensor, each with its
    /// position at the start ([`ClosedLoopRun::at`]).
    pub observed: &'a [(crate::Port, f64)],
}

/// The sensor a [`ClosedLoop`]'s controller reads when it is not the
/// model's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Feedback {
    /// Where it reads: the position of mass `plus` relative to `minus`
    /// (0: the ground), masses counted as in the model.
    pub sensor: crate::Port,
    /// Its reading at the start.
    pub initial_position: f64,
}

impl<'a> ClosedLoop<'a> {
    /// A loop starting at rest at position 0, without disturbance.
    pub fn new(controller: &'a Controller, reference: &'a [f64]) -> ClosedLoop<'a> {
        ClosedLoop {
            controller,
            reference,
            disturbance: None,
            initial_position: 0.0,
            initial_velocity: 0.0,
            feedback: None,
            observed: &[],
        }
    }
}

/// The result of [`Simulator::run_closed_loop`].
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedLoopRun {
    /// Simulated sensor position.
    pub y: Vec<f64>,
    /// Controller output (the model's input before its gain).
    pub u: Vec<f64>,
    /// The position at each of [`ClosedLoop::observed`]'s places.
    pub at: Vec<Vec<f64>>,
}

/// `out = s + dt * (v, a, g)`.
#[inline(always)]
fn stage<const L: usize>(s: &State<L>, v: &[f64; L], a: &[f64; L], g: f64, dt: f64) -> State<L> {
    let mut out = *s;
    for i in 0..L {
        out.x[i] = s.x[i] + dt * v[i];
        out.v[i] = s.v[i] + dt * a[i];
    }
    out.f = s.f + dt * g;
    out
}

impl<const L: usize> Kernel<'_, L> {
    /// All forces on the masses except Coulomb friction, for force `f` at
    /// the actuator, into `out` (indexed as the state: `out[0]` takes the
    /// ground's reactions and is not read).
    #[inline(always)]
    fn forces(&self, s: &State<L>, f: f64, out: &mut [f64; L]) {
        self.forces_in(s, f, None, out);
    }

    /// [`Kernel::forces`], with the backlash spring held on the side of
    /// `piece` and the constant forces (offset, the gap's shift) only if
    /// it says so; `None`: the side the state is on, constants included.
    #[inline(always)]
    fn forces_in(&self, s: &State<L>, f: f64, piece: Option<Piece>, out: &mut [f64; L]) {
        let sim = self.sim;
        let (x, v) = (&s.x, &s.v);
        let constants = piece.is_none_or(|p| p.constants);
        // The ground's input is 0 (its reactions are not read).
        for (o, i) in out.iter_mut().zip(&self.input) {
            *o = i * f;
        }
        let offset = if constants { sim.offset } else { 0.0 };
        out[sim.driven + 1] -= sim.viscous * v[sim.driven + 1] + offset;
        if sim.pre_sliding > 0.0 {
            out[sim.driven + 1] -= sim.pre_sliding * x[sim.driven + 1];
        }
        let (backlash, half) = self.backlash;
        for a in 0..L - 1 {
            if !self.link[a] {
                continue;
            }
            let (b, c, d) = (a + 1, self.spring[a], self.damper[a]);
            let dx = x[b] - x[a];
            let dv = v[b] - v[a];
            let force = if a == backlash {
                let shift = if constants { half } else { 0.0 };
                match piece.map_or_else(|| Contact::of(dx, half), |p| p.contact) {
                    Contact::Above => c * (dx - shift) + d * dv,
                    Contact::Below => c * (dx + shift) + d * dv,
                    Contact::Gap => 0.0,
                }
            } else {
                c * dx + d * dv
            };
            out[b] -= force;
            out[a] += force;
        }
    }

    /// Friction force on the friction mass given the other forces `other`
    /// on it and its velocity (Karnopp: at rest it balances up to `F_c`).
    #[inline(always)]
    fn friction(&self, v: f64, other: f64) -> f64 {
        let coulomb = self.sim.coulomb;
        if coulomb == 0.0 {
            0.0
        } else if v == 0.0 {
            -other.clamp(-coulomb, coulomb)
        } else {
            -coulomb * v.signum()
        }
    }

    /// Accelerations (into `a`, indexed as the state, the ground's 0) and
    /// the lag's derivative, for held input `u_in` (already scaled).
    #[inline(always)]
    fn deriv(&self, s: &State<L>, u_in: f64, a: &mut [f64; L]) -> f64 {
        self.deriv_in(s, u_in, None, a)
    }

    /// [`Kernel::deriv`] on one piece (see [`Kernel::forces_in`]; the
    /// friction mass slides in the piece's direction).
    #[inline(always)]
    fn deriv_in(&self, s: &State<L>, u_in: f64, piece: Option<Piece>, a: &mut [f64; L]) -> f64 {
        let lag = self.sim.lag;
        let f = if lag > 0.0 { s.f } else { u_in };
        let mut forces = [0.0; L];
        self.forces_in(s, f, piece, &mut forces);
        let j = self.sim.friction_mass + 1;
        forces[j] += match piece {
            None => self.friction(s.v[j], forces[j]),
            // Stuck: friction balances the other forces.
            Some(p) if self.sim.coulomb > 0.0 && p.sign == 0.0 => -forces[j],
            Some(p) if p.constants => -self.sim.coulomb * p.sign,
            Some(_) => 0.0,
        };
        a[0] = 0.0;
        for i in 1..L {
            a[i] = forces[i] * self.inv_m[i];
        }
        if lag > 0.0 {
            lag * (u_in - s.f)
        } else {
            0.0
        }
    }

    /// One RK4 sub-step from `s` under the held input `f_in` (see
    /// [`Kernel::deriv_in`] for `piece`): the new state (before the stick
    /// logic) and the states of stages 2 to 4.
    #[inline(always)]
    fn step(&self, s: &State<L>, f_in: f64, piece: Option<Piece>) -> (State<L>, [State<L>; 3]) {
        let h = self.sim.h;
        let (mut k1, mut k2, mut k3, mut k4) = ([0.0; L], [0.0; L], [0.0; L], [0.0; L]);
        // RK4 on (x, v, f): k = velocity derivative (acceleration);
        // position derivative is the stage's velocity.
        let g1 = self.deriv_in(s, f_in, piece, &mut k1);
        let s2 = stage(s, &s.v, &k1, g1, 0.5 * h);
        let g2 = self.deriv_in(&s2, f_in, piece, &mut k2);
        let s3 = stage(s, &s2.v, &k2, g2, 0.5 * h);
        let g3 = self.deriv_in(&s3, f_in, piece, &mut k3);
        let s4 = stage(s, &s3.v, &k3, g3, h);
        let g4 = self.deriv_in(&s4, f_in, piece, &mut k4);
        let mut out = *s;
        for i in 1..L {
            out.x[i] += h / 6.0 * (s.v[i] + 2.0 * s2.v[i] + 2.0 * s3.v[i] + s4.v[i]);
            out.v[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        out.f += h / 6.0 * (g1 + 2.0 * g2 + 2.0 * g3 + g4);
        (out, [s2, s3, s4])
    }
}

/// Which side of its gap the spring with backlash is on (in the order of
/// the stretch).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Contact {
    Below = 0,
    Gap = 1,
    Above = 2,
}

impl Contact {
    #[inline(always)]
    fn of(dx: f64, half: f64) -> Contact {
        if dx > half {
            Contact::Above
        } else if dx < -half {
            Contact::Below
        } else {
            Contact::Gap
        }
    }
}

/// A piece of the state space on which the chain is affine: the friction
/// mass slides one way (`sign` +1 or -1) or sticks (`sign` 0, its friction
/// balancing the other forces; without friction `sign` is 0 and means
/// nothing), and the backlash spring stays on one side of its gap.
/// `constants: false` drops the constant forces, leaving the linear part.
#[derive(Clone, Copy, Debug)]
struct Piece {
    sign: f64,
    contact: Contact,
    constants: bool,
}

/// The RK4 sub-step on one piece as an affine map of the state and the
/// held input, `s' = A s + b u + c`, with the same kind of map for what
/// says whether the step stayed on the piece. An RK4 step of an affine
/// system is affine, so the map gives the step's result up to rounding,
/// in a fraction of the operations (a matrix-vector product without the
/// stages' chain of dependent evaluations).
struct AffineStep<const L: usize> {
    piece: Piece,
    /// The Coulomb force (0: none) and the friction mass's index.
    coulomb: f64,
    j: usize,
    /// Half the backlash gap, if there is backlash.
    half: Option<f64>,
    /// Rows of `A` with `b` and `c` for each component of the new state.
    x: [Row<L>; L],
    v: [Row<L>; L],
    f: Row<L>,
    /// Sliding: the friction mass's velocity at stages 2 to 4 (the first
    /// row unused); sticking: the other forces on it at stages 1 to 4.
    friction: [Row<L>; 4],
    /// The backlash spring's stretch at stages 2 to 4.
    stretch: [Row<L>; 3],
}

/// One affine form `a . s + b u + c` of the state.
#[derive(Clone, Copy)]
struct Row<const L: usize> {
    a: State<L>,
    b: f64,
    c: f64,
}

impl<const L: usize> Row<L> {
    const ZERO: Row<L> = Row {
        a: State {
            x: [0.0; L],
            v: [0.0; L],
            f: 0.0,
        },
        b: 0.0,
        c: 0.0,
    };

    /// The form at `s` and `u`; without a lag (`LAGGED` false) the lagged
    /// force is 0 and its term is left out.
    #[inline(always)]
    fn at<const LAGGED: bool>(&self, s: &State<L>, u: f64) -> f64 {
        let mut sum = self.c + self.b * u;
        if LAGGED {
            sum += self.a.f * s.f;
        }
        let a = self.a.x[1..].iter().zip(&self.a.v[1..]);
        for ((ax, av), (x, v)) in a.zip(s.x[1..].iter().zip(&s.v[1..])) {
            sum += ax * x + av * v;
        }
        sum
    }
}

impl<const L: usize> AffineStep<L> {
    /// The map of `kernel`'s sub-step on `piece`, from the step of every
    /// unit state, of the unit input and of the constants alone.
    fn new(kernel: &Kernel<'_, L>, piece: Piece) -> AffineStep<L> {
        let sim = kernel.sim;
        let zero = State {
            x: [0.0; L],
            v: [0.0; L],
            f: 0.0,
        };
        let linear = Piece {
            constants: false,
            ..piece
        };
        let j = sim.friction_mass + 1;
        let (link, half) = kernel.backlash;
        let mut m = AffineStep {
            piece,
            coulomb: sim.coulomb,
            j,
            half: (link < L - 1).then_some(half),
            x: [Row::ZERO; L],
            v: [Row::ZERO; L],
            f: Row::ZERO,
            friction: [Row::ZERO; 4],
            stretch: [Row::ZERO; 3],
        };
        let stuck = sim.coulomb > 0.0 && piece.sign == 0.0;
        // One column: the response to one unit source (a state component,
        // the input, or the constants), stored by `coef`.
        let column = |m: &mut AffineStep<L>,
                      from: &State<L>,
                      u: f64,
                      p: Piece,
                      coef: &dyn Fn(&mut Row<L>) -> &mut f64| {
            let (out, stages) = kernel.step(from, u, Some(p));
            for i in 1..L {
                *coef(&mut m.x[i]) = out.x[i];
                *coef(&mut m.v[i]) = out.v[i];
            }
            *coef(&mut m.f) = out.f;
            for (k, st) in [from].into_iter().chain(&stages).enumerate() {
                *coef(&mut m.friction[k]) = if stuck {
                    let mut forces = [0.0; L];
                    let f = if sim.lag > 0.0 { st.f } else { u };
                    kernel.forces_in(st, f, Some(p), &mut forces);
                    forces[j]
                } else {
                    st.v[j]
                };
                if k > 0 && link < L - 1 {
                    *coef(&mut m.stretch[k - 1]) = st.x[link + 1] - st.x[link];
                }
            }
        };
        for i in 1..L {
            let mut e = zero;
            e.x[i] = 1.0;
            column(&mut m, &e, 0.0, linear, &|r| &mut r.a.x[i]);
            let mut e = zero;
            e.v[i] = 1.0;
            column(&mut m, &e, 0.0, linear, &|r| &mut r.a.v[i]);
        }
        let mut e = zero;
        e.f = 1.0;
        column(&mut m, &e, 0.0, linear, &|r| &mut r.a.f);
        column(&mut m, &zero, 1.0, linear, &|r| &mut r.b);
        column(&mut m, &zero, 0.0, piece, &|r| &mut r.c);
        m
    }

    /// Takes the sub-step from `s` under held input `u` in place if every
    /// stage stayed on the piece and the step ends on it (a sliding mass
    /// still slides, a stuck one is still held); otherwise returns false
    /// with `s` untouched, leaving the step to the integrator, whose stick
    /// logic then decides. `LAGGED`: whether the force lags the input (else
    /// the lagged force is 0 and its terms are left out).
    #[inline(always)]
    fn step<const LAGGED: bool>(&self, s: &mut State<L>, u: f64) -> bool {
        let p = self.piece;
        if self.coulomb > 0.0 {
            let held = if p.sign == 0.0 {
                self.friction
                    .iter()
                    .all(|r| r.at::<LAGGED>(s, u).abs() <= self.coulomb)
            } else {
                self.friction[1..]
                    .iter()
                    .all(|r| p.sign * r.at::<LAGGED>(s, u) > 0.0)
            };
            if !held {
                return false;
            }
        }
        if let Some(half) = self.half {
            if self
                .stretch
                .iter()
                .any(|r| Contact::of(r.at::<LAGGED>(s, u), half) != p.contact)
            {
                return false;
            }
        }
        // (Index 0, the ground, stays 0.)
        let (mut x, mut v) = ([0.0; L], [0.0; L]);
        for i in 1..L {
            x[i] = self.x[i].at::<LAGGED>(s, u);
            v[i] = self.v[i].at::<LAGGED>(s, u);
        }
        // (NaN slides nowhere: the integrator decides.)
        let slides_on = p.sign * v[self.j] > 0.0;
        if self.coulomb > 0.0 && p.sign != 0.0 && !slides_on {
            return false;
        }
        // Without a lag the lagged force stays 0.
        if LAGGED {
            s.f = self.f.at::<true>(s, u);
        }
        s.x = x;
        s.v = v;
        true
    }
}

/// Simulates a model file for input samples `u` at rate `fs` with the
/// default places of the nonlinearities (see the module documentation).
pub fn simulate(file: &ModelFile, u: &[f64], fs: f64) -> Result<Vec<f64>, SimulateError> {
    Simulator::new(file, fs, &SimOptions::default())?.run(u)
}

/// The spring that gets backlash by default, by its lower node (0: the
/// ground to m1): the one between the driven mass `p` and `p + 1`, else the
/// one between `p - 1` and `p`; `None` if the driven mass has no spring.
///
/// ```
/// use mms::{simulate::default_backlash_link, Model};
/// assert_eq!(default_backlash_link(&Model::from_id("A1").unwrap()), Some(1)); // c12
/// assert_eq!(default_backlash_link(&Model::from_id("A5").unwrap()), Some(2)); // c23
/// ```
pub fn default_backlash_link(model: &Model) -> Option<usize> {
    let p = model.actuator().plus;
    [p, p - 1].into_iter().find(|&i| model.has_link(i))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model_file::Motion;
    use crate::Port;

    /// The affine maps of the pieces against the integrator stepping every
    /// sub-step itself: the same outputs up to rounding, on chains of one
    /// to four masses with every effect the simulator has, on inputs that
    /// reverse, stop and hold (stick-slip, contacts made and lost).
    #[test]
    fn piecewise_steps_equal_the_integrator() {
        let mut seed = 11u64;
        let mut uniform = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst = 0.0f64;
        let mut cases = 0;
        for n in 1..=4 {
            for gap in 0..n {
                for variant in 0..6 {
                    let m = Model::new(n, gap, Port::new(gap + 1, 0), Port::new(n, 0)).unwrap();
                    let values: Vec<f64> = m
                        .parameters()
                        .iter()
                        .map(|p| match p.chars().next() {
                            Some('m') => 0.5 + 1.5 * uniform(),
                            Some('c') => 1e3 * (1.0 + 9.0 * uniform()),
                            _ => 0.5 + 4.5 * uniform(),
                        })
                        .collect();
                    let has_spring = crate::simulate::default_backlash_link(&m).is_some();
                    let effects = Effects {
                        coulomb_friction: (variant % 2 == 0).then_some(0.3 + uniform()),
                        backlash_gap: (variant >= 2 && has_spring)
                            .then_some(2e-4 + 1e-3 * uniform()),
                        lowpass_hz: (variant == 3).then_some(200.0),
                        time_delay_s: (variant == 4).then_some(3.3e-4),
                        offset_force: (variant == 5).then_some(0.2),
                        viscous_friction: (variant == 1).then_some(0.7),
                        ..Effects::default()
                    };
                    let file = ModelFile {
                        model: m,
                        output: Output::Position,
                        parameters: Parameters::from_values(&m, values).unwrap(),
                        gain: 1.0,
                        motion: Motion::Translational,
                        effects,
                    };
                    let fs = 1000.0;
                    // Slow reversals, a stop, a hold below the friction.
                    let u: Vec<f64> = (0..3000)
                        .map(|k| {
                            let t = k as f64 / fs;
                            match k {
                                0..=1499 => {
                                    3.0 * (2.0 * std::f64::consts::PI * 1.3 * t).sin()
                                        + 0.5 * (2.0 * std::f64::consts::PI * 17.0 * t).sin()
                                }
                                1500..=1999 => 0.0,
                                2000..=2499 => 0.2,
                                _ => -2.0 * (2.0 * std::f64::consts::PI * 3.1 * t).cos(),
                            }
                        })
                        .collect();
                    let fast = Simulator::new(&file, fs, &SimOptions::default()).unwrap();
                    let slow = Simulator {
                        piecewise: false,
                        ..fast.clone()
                    };
                    let (a, b) = (fast.run(&u).unwrap(), slow.run(&u).unwrap());
                    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    let diff = a
                        .iter()
                        .zip(&b)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    worst = worst.max(diff / scale);
                    cases += 1;
                }
            }
        }
        eprintln!("{cases} cases, worst relative difference {worst:e}");
        assert!(worst < 1e-9, "{worst:e}");
    }
}
