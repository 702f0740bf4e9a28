//! Numeric frequency response of a damped model: `f64`, complex, over a
//! vector of frequencies, with the derivatives with respect to every
//! parameter (for fitting).
//!
//! The symbolic [`DampedTf`](crate::DampedTf) is exact but slow to
//! evaluate; this module solves the chain's dynamic-stiffness system
//! `Z(w) x = b`, `Z(w) = C + j w D - w^2 M`, at each frequency instead, which
//! costs a few hundred floating-point operations per line for 3 masses.
//! The sensor reads `y = c^T x` (position), times `j w` (velocity) or
//! `-w^2` (acceleration).
//!
//! Derivatives come from the same factorisation: `Z` is symmetric, so with
//! `x = Z^-1 b` and `w = Z^-1 c`, `dy/dp = -w^T (dZ/dp) x`, and `dZ/dp` is a
//! rank-one matrix for every mass, spring and damper.
//!
//! ```
//! use mms::response::{ChainResponse, Parameters};
//! use mms::{Model, Output};
//!
//! // Tab. 4 of the paper: the generating A2 model.
//! let a2 = Model::from_id("A2")?;
//! let p = Parameters::from_pairs(&a2, &[
//!     ("m1", 0.01), ("m2", 0.01), ("m3", 0.02),
//!     ("c12", 100.0), ("c23", 100.0), ("d12", 0.01), ("d23", 0.01),
//! ])?;
//! let g = ChainResponse::new(&a2, Output::Position);
//! let h = g.eval(p.values(), 0.1)?; // at 0.1 Hz
//! // Far below the first resonance the chain moves as one rigid body:
//! // x/F = -1/(w^2 (m1 + m2 + m3)).
//! let w = 2.0 * std::f64::consts::PI * 0.1;
//! assert!((h.re + 1.0 / (w * w * 0.04)).abs() < 1e-3 * h.norm());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::model::Model;
use crate::tf::Output;
use num_complex::Complex64;
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// The zero-order-hold equivalent at `w` (rad/s) with sample time `t`
/// from `sum = sum_k G(j w_k) / (j w_k)` over the sampling's images:
/// `(1 - e^(-j w t)) / t * sum` ([`ChainResponse::eval_held`]).
fn held(sum: Complex64, w: f64, t: f64) -> Complex64 {
    (Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, -w * t)) / t * sum
}

/// Why a response cannot be evaluated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ResponseError {
    /// A parameter the model needs is missing.
    #[error("missing parameter {0}")]
    MissingParameter(String),
    /// A parameter the model does not have.
    #[error("unknown parameter {name} (the model has {expected})")]
    UnknownParameter {
        /// The name given.
        name: String,
        /// The model's parameters, comma separated.
        expected: String,
    },
    /// A parameter value is NaN, infinite, or not positive (masses and
    /// springs must be positive, dampers non-negative).
    #[error("parameter {name} = {value} must be {rule}")]
    BadValue {
        /// Parameter name.
        name: String,
        /// Its value.
        value: f64,
        /// "positive" or "non-negative".
        rule: &'static str,
    },
    /// Wrong number of parameter values.
    #[error("expected {expected} parameter values, got {got}")]
    Count {
        /// Number the model needs.
        expected: usize,
        /// Number given.
        got: usize,
    },
    /// A frequency that is zero, negative or not finite: a chain with a
    /// rigid-body mode has no finite position response at `w = 0`.
    #[error("frequency {0} Hz must be positive and finite")]
    Frequency(f64),
    /// `Z(w)` is singular: the frequency hits an undamped resonance
    /// exactly.
    #[error("the dynamic stiffness is singular at {0} Hz (an undamped resonance)")]
    Singular(f64),
}

/// Values for every parameter of a model, in the model's order
/// ([`Model::parameters`]: masses, springs, dampers), in SI units (kg, N/m,
/// N s/m, or the rotary equivalents).
#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    names: Vec<String>,
    values: Vec<f64>,
}

impl Parameters {
    /// Parameters from `(name, value)` pairs, in any order; every parameter
    /// of `model` must be given exactly once, masses and springs positive,
    /// dampers non-negative.
    ///
    /// ```
    /// use mms::{response::Parameters, Model};
    /// let a1 = Model::from_id("A1").unwrap();
    /// let bad = Parameters::from_pairs(&a1, &[("m1", 1.0)]);
    /// assert_eq!(bad.unwrap_err().to_string(), "missing parameter m2");
    /// ```
    pub fn from_pairs(model: &Model, pairs: &[(&str, f64)]) -> Result<Parameters, ResponseError> {
        let names = model.parameters();
        let mut values = vec![f64::NAN; names.len()];
        let mut seen = vec![false; names.len()];
        for &(name, value) in pairs {
            let Some(i) = names.iter().position(|n| n == name) else {
                return Err(ResponseError::UnknownParameter {
                    name: name.to_string(),
                    expected: names.join(", "),
                });
            };
            values[i] = value;
            seen[i] = true;
        }
        if let Some(i) = seen.iter().position(|s| !s) {
            return Err(ResponseError::MissingParameter(names[i].clone()));
        }
        Parameters::from_values(model, values)
    }

    /// Parameters from values in the model's order.
    pub fn from_values(model: &Model, values: Vec<f64>) -> Result<Parameters, ResponseError> {
        let names = model.parameters();
        if values.len() != names.len() {
            return Err(ResponseError::Count {
                expected: names.len(),
                got: values.len(),
            });
        }
        for (name, &value) in names.iter().zip(&values) {
            let damper = name.starts_with('d');
            let ok = value.is_finite() && if damper { value >= 0.0 } else { value > 0.0 };
            if !ok {
                return Err(ResponseError::BadValue {
                    name: name.clone(),
                    value,
                    rule: if damper { "non-negative" } else { "positive" },
                });
            }
        }
        Ok(Parameters { names, values })
    }

    /// Parameter names, in the model's order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Values, in the order of [`Parameters::names`].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value of one parameter.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.values[i])
    }

    /// `(name, value)` pairs in the model's order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        self.names
            .iter()
            .map(String::as_str)
            .zip(self.values.iter().copied())
    }
}

/// Physics beyond the chain's masses, springs and viscous dampers that
/// change its FRF, each off unless set (the `[effects]` table of a model
/// file; the diagnosis adds them).
///
/// ```
/// use mms::response::{ChainResponse, Effects};
/// use mms::{Model, Output};
/// let a1 = Model::from_id("A1").unwrap();
/// let p = [1.0, 1.0, 1.0, 1e4, 1e4, 1.0, 1.0];
/// let plain = ChainResponse::new(&a1, Output::Position);
/// let delayed = ChainResponse::with_effects(
///     &a1,
///     Output::Position,
///     &Effects { time_delay_s: Some(1e-3), ..Effects::default() },
/// );
/// let (g0, g1) = (plain.eval(&p, 50.0).unwrap(), delayed.eval(&p, 50.0).unwrap());
/// // A pure delay keeps the magnitude and lags the phase by w*T = 0.1 pi.
/// assert!((g1.norm() / g0.norm() - 1.0).abs() < 1e-12);
/// assert!(((g0 / g1).arg() - 0.1 * std::f64::consts::PI).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Effects {
    /// `time_delay {delay_s}`: dead time `e^(-s T)` in s.
    pub time_delay_s: Option<f64>,
    /// `lowpass {corner_hz}`: a first-order lag `1/(1 + s/(2 pi f_c))` of
    /// the actuator or the sensor (one FRF cannot tell which).
    pub lowpass_hz: Option<f64>,
    /// `gain_error {factor}`: the FRF times this factor (a wrong actuator
    /// or sensor constant).
    pub gain_factor: Option<f64>,
    /// `hysteretic_damping {loss_factor}`: every spring `c` becomes
    /// `c (1 + j eta)` (structural damping, frequency independent).
    pub loss_factor: Option<f64>,
    /// `friction {viscous_ns_per_m}`: a viscous damper from the driven mass
    /// (the actuator's `plus` mass) to the ground, damping the rigid-body
    /// motion.
    pub viscous_friction: Option<f64>,
    /// `friction {pre_sliding_n_per_m}`: the pre-sliding stiffness of the
    /// friction on the driven mass, a spring from that mass to the ground,
    /// N/m (or N m/rad). At rest, friction holds the rubbing surfaces in
    /// micro-slip, where its force grows with the displacement like a
    /// spring's until they break away (Dahl's pre-sliding regime), so under
    /// a small excitation at standstill the rigid-body mode becomes a
    /// resonance. Linear: the FRF has it, and [`crate::simulate`] takes it
    /// as a linear spring (the break-away into sliding is not modelled).
    pub pre_sliding_stiffness: Option<f64>,
    /// `friction {coulomb_n}`: Coulomb (dry) friction `F_c sign(v)` of the
    /// driven mass against the ground, N (or N m). Nonlinear: the FRF
    /// ignores it; [`crate::simulate`] models it in the time domain.
    pub coulomb_friction: Option<f64>,
    /// `backlash {gap}`: a dead zone of total width `gap` (m, or rad) in
    /// the first spring on the free side of the driven mass (see
    /// [`crate::simulate`]). Nonlinear: the FRF ignores it.
    pub backlash_gap: Option<f64>,
    /// `offset {force_n}`: a constant force bias on the driven mass, N (or
    /// N m), either sign, in the sense of the inverse dynamics `F = M q'' +
    /// ... + offset` (a measured force that carries an offset, or a
    /// constant load such as gravity on an inclined axis). It moves only
    /// the static equilibrium: the FRF ignores it; [`crate::simulate`]
    /// applies it in the time domain.
    pub offset_force: Option<f64>,
}

impl Effects {
    /// True if no effect is set.
    pub fn is_empty(&self) -> bool {
        *self == Effects::default()
    }

    /// The effects an FRF can show: these without Coulomb friction,
    /// backlash and offset, which only the time-domain simulation has.
    ///
    /// ```
    /// use mms::response::Effects;
    /// let e = Effects { time_delay_s: Some(1e-3), coulomb_friction: Some(2.0), ..Effects::default() };
    /// assert_eq!(e.linear(), Effects { time_delay_s: Some(1e-3), ..Effects::default() });
    /// assert!(Effects::default().linear().is_empty());
    /// ```
    pub fn linear(&self) -> Effects {
        Effects {
            coulomb_friction: None,
            backlash_gap: None,
            offset_force: None,
            ..*self
        }
    }

    /// The factor the chain's response is multiplied by at `omega` (rad/s):
    /// gain, delay and lag.
    fn output_factor(&self, omega: f64) -> Complex64 {
        let mut f = Complex64::new(self.gain_factor.unwrap_or(1.0), 0.0);
        if let Some(t) = self.time_delay_s {
            f *= Complex64::from_polar(1.0, -omega * t);
        }
        if let Some(fc) = self.lowpass_hz {
            f /= Complex64::new(1.0, omega / (2.0 * PI * fc));
        }
        f
    }
}

/// The derivatives of `G` with respect to the parameter of each linear
/// effect ([`ChainResponse::eval_with_effect_gradient`]), field by field
/// as in [`Effects`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EffectGradient {
    /// `dG/dT`, the dead time in s.
    pub time_delay_s: Complex64,
    /// `dG/df_c`, the lag's corner in Hz.
    pub lowpass_hz: Complex64,
    /// `dG/dk`, the gain factor.
    pub gain_factor: Complex64,
    /// `dG/d eta`, the loss factor.
    pub loss_factor: Complex64,
    /// `dG/db`, the viscous friction.
    pub viscous_friction: Complex64,
    /// `dG/dk_p`, the pre-sliding stiffness.
    pub pre_sliding_stiffness: Complex64,
}

/// One spring or damper: between node `a` and node `b` (1-based masses,
/// 0 = ground).
#[derive(Clone, Copy, Debug)]
struct Link {
    a: usize,
    b: usize,
}

/// The compiled response of one model for one output: evaluates
/// `G(j w)` and its parameter derivatives without any symbolic algebra.
///
/// Parameter vectors are in the order of [`Model::parameters`].
#[derive(Clone, Debug)]
pub struct ChainResponse {
    n: usize,
    links: Vec<Link>,
    input: Vec<f64>,
    sensor: Vec<f64>,
    output: Output,
    effects: Effects,
    /// The mass the friction's damper and spring ground (1-based).
    driven: usize,
}

impl ChainResponse {
    /// Compile `model` for `output`, without [`Effects`].
    pub fn new(model: &Model, output: Output) -> ChainResponse {
        ChainResponse::with_effects(model, output, &Effects::default())
    }

    /// Compile `model` for `output` with `effects`. The gradient of
    /// [`ChainResponse::eval_with_gradient`] stays with respect to the
    /// chain's parameters; the effects' own parameters are held fixed.
    pub fn with_effects(model: &Model, output: Output, effects: &Effects) -> ChainResponse {
        let n = model.n_masses();
        let links = (0..n)
            .filter(|&i| model.has_link(i))
            .map(|i| Link { a: i, b: i + 1 })
            .collect();
        let to_f64 = |v: Vec<i64>| v.into_iter().map(|x| x as f64).collect();
        ChainResponse {
            n,
            links,
            input: to_f64(model.input_vector()),
            sensor: to_f64(model.output_vector()),
            output,
            effects: *effects,
            driven: model.actuator().plus,
        }
    }

    /// Number of parameters: `N` masses, then the springs, then the dampers.
    pub fn n_parameters(&self) -> usize {
        self.n + 2 * self.links.len()
    }

    /// The output this response is compiled for.
    pub fn output(&self) -> Output {
        self.output
    }

    /// `G(j 2 pi f)` at one frequency `f` in Hz.
    pub fn eval(&self, values: &[f64], freq_hz: f64) -> Result<Complex64, ResponseError> {
        sized!(self.n, N, {
            let mut solver = self.solver::<N>(values, freq_hz)?;
            Ok(self.solve(&mut solver, false))
        })
    }

    /// `G(j 2 pi f)` and `dG/dp` for every parameter `p` (written into
    /// `gradient`, which must have [`ChainResponse::n_parameters`] entries).
    pub fn eval_with_gradient(
        &self,
        values: &[f64],
        freq_hz: f64,
        gradient: &mut [Complex64],
    ) -> Result<Complex64, ResponseError> {
        // The effects' derivatives come from the same solves, at the
        // cost of a few products.
        self.eval_with_effect_gradient(values, freq_hz, gradient)
            .map(|(g, _)| g)
    }

    /// `G(j 2 pi f)`, `dG/dp` for every chain parameter `p` (as
    /// [`ChainResponse::eval_with_gradient`]) and `dG/dv` for the
    /// parameter `v` of every linear effect, from the same solves: an
    /// effect's derivative costs no further evaluation. An effect not set
    /// has the derivative of its neutral value (no delay, gain 1, no loss,
    /// no friction), except a missing lag, whose corner is infinite: 0.
    ///
    /// ```
    /// use mms::response::{ChainResponse, Effects};
    /// use mms::{Model, Output};
    /// let a1 = Model::from_id("A1").unwrap();
    /// let p = [1.0, 1.0, 1.0, 1e4, 1e4, 1.0, 1.0];
    /// let e = Effects { time_delay_s: Some(1e-3), ..Effects::default() };
    /// let r = ChainResponse::with_effects(&a1, Output::Position, &e);
    /// let mut grad = vec![Default::default(); r.n_parameters()];
    /// let (g, d) = r.eval_with_effect_gradient(&p, 50.0, &mut grad).unwrap();
    /// // A dead time T multiplies G by exp(-j w T): dG/dT = -j w G.
    /// let w = 2.0 * std::f64::consts::PI * 50.0;
    /// assert!((d.time_delay_s - g * num_complex::Complex64::new(0.0, -w)).norm() < 1e-12 * g.norm() * w);
    /// ```
    pub fn eval_with_effect_gradient(
        &self,
        values: &[f64],
        freq_hz: f64,
        gradient: &mut [Complex64],
    ) -> Result<(Complex64, EffectGradient), ResponseError> {
        assert_eq!(gradient.len(), self.n_parameters(), "gradient length");
        sized!(self.n, N, {
            let mut solver = self.solver::<N>(values, freq_hz)?;
            let g = self.solve(&mut solver, true);
            let scale = solver.factor;
            let (x, w) = (&solver.x, &solver.w);
            let omega = solver.omega;
            let node = |v: &[Complex64], k: usize| {
                if k == 0 {
                    ZERO
                } else {
                    v[k - 1]
                }
            };
            for i in 0..self.n {
                gradient[i] = scale * w[i] * x[i] * (omega * omega);
            }
            let nl = self.links.len();
            let eta = self.effects.loss_factor.unwrap_or(0.0);
            let spring = Complex64::new(1.0, eta);
            let mut d_loss = ZERO;
            for (k, l) in self.links.iter().enumerate() {
                let dx = node(x, l.b) - node(x, l.a);
                let dw = node(w, l.b) - node(w, l.a);
                let dy = -(scale * dw * dx);
                gradient[self.n + k] = dy * spring;
                gradient[self.n + nl + k] = dy * Complex64::new(0.0, omega);
                // dZ/d eta = j c (e_b - e_a)(e_b - e_a)^T.
                d_loss += dy * Complex64::new(0.0, values[self.n + k]);
            }
            // The friction's damper and spring ground the driven mass:
            // dZ/db = j w e_d e_d^T, dZ/dk = e_d e_d^T.
            let at_driven = -(scale * w[self.driven - 1] * x[self.driven - 1]);
            let lag = match self.effects.lowpass_hz {
                // L = 1 / (1 + j r), r = w / (2 pi fc): dL/dfc = L j r / (fc (1 + j r)).
                Some(fc) => {
                    let jr = Complex64::new(0.0, omega / (2.0 * PI * fc));
                    g * jr / ((1.0 + jr) * fc)
                }
                None => ZERO,
            };
            let effects = EffectGradient {
                time_delay_s: g * Complex64::new(0.0, -omega),
                lowpass_hz: lag,
                gain_factor: g / self.effects.gain_factor.unwrap_or(1.0),
                loss_factor: d_loss,
                viscous_friction: at_driven * Complex64::new(0.0, omega),
                pre_sliding_stiffness: at_driven,
            };
            Ok((g, effects))
        })
    }

    /// The position of every mass (`x_1 .. x_N`, relative to the ground)
    /// per unit actuator force at `freq_hz`, with the effects' gain, delay
    /// and lag but whatever the compiled output: what an extra position
    /// sensor at each mass would read.
    ///
    /// ```
    /// use mms::{response::ChainResponse, Model, Output};
    /// let a2 = Model::from_id("A2").unwrap();
    /// let p = [0.01, 0.01, 0.02, 100.0, 100.0, 0.01, 0.01];
    /// let g = ChainResponse::new(&a2, Output::Position);
    /// let x = g.mass_positions(&p, 7.0).unwrap();
    /// // A2's own sensor reads x_2.
    /// assert_eq!(x[1], g.eval(&p, 7.0).unwrap());
    /// ```
    pub fn mass_positions(
        &self,
        values: &[f64],
        freq_hz: f64,
    ) -> Result<Vec<Complex64>, ResponseError> {
        sized!(self.n, N, {
            let mut solver = self.solver::<N>(values, freq_hz)?;
            self.solve(&mut solver, false);
            let e = solver.effect;
            Ok(solver.x[..self.n].iter().map(|&x| x * e).collect())
        })
    }

    /// The response of the chain sampled as a drive samples it: the input
    /// held over each sample at rate `fs`, the output (a position or a
    /// velocity) read at the sample instants. It is the zero-order-hold
    /// equivalent `G_d(e^(j w T)) = (1 - e^(-j w T)) / T * sum_k G(j w_k) /
    /// (j w_k)`, `w_k = w + 2 pi k fs`: half a sample of delay, the hold's
    /// droop `sinc(w T / 2)` and what folds back from above the Nyquist
    /// frequency, which a transfer function times `e^(-j w T / 2)` leaves
    /// out. The sum runs over `|k| <= 64` (the terms fall as `1/k^2` or
    /// faster for a position or velocity; an acceleration's fall as `1/k`,
    /// and its reading at the instant its input changes is another
    /// matter: not for accelerations).
    ///
    /// ```
    /// use mms::response::ChainResponse;
    /// use mms::{Model, Output, Port};
    /// // A free mass of 2 kg: G = 1/(m s^2), whose hold equivalent is
    /// // T^2 (z + 1) / (2 m (z - 1)^2).
    /// let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0))?;
    /// let g = ChainResponse::new(&m, Output::Position);
    /// let (fs, f) = (100.0, 20.0);
    /// let z = num_complex::Complex64::from_polar(1.0, 2.0 * std::f64::consts::PI * f / fs);
    /// let exact = (z + 1.0) / (2.0 * 2.0 * fs * fs * (z - 1.0) * (z - 1.0));
    /// let held = g.eval_held(&[2.0], f, fs)?;
    /// assert!((held - exact).norm() < 1e-4 * exact.norm());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn eval_held(
        &self,
        values: &[f64],
        freq_hz: f64,
        fs: f64,
    ) -> Result<Complex64, ResponseError> {
        if !(fs.is_finite() && fs > 0.0) {
            return Err(ResponseError::Frequency(fs));
        }
        let w = 2.0 * PI * freq_hz;
        let own = self.eval(values, freq_hz)? / Complex64::new(0.0, w);
        Ok(held(own + self.folded(values, freq_hz, fs)?, w, 1.0 / fs))
    }

    /// `sum_{k != 0, |k| <= 64} G(j w_k) / (j w_k)` of [`ChainResponse::eval_held`]:
    /// what folds back onto `freq_hz` from the images of the sampling.
    fn folded(&self, values: &[f64], freq_hz: f64, fs: f64) -> Result<Complex64, ResponseError> {
        const IMAGES: i32 = 64;
        let mut sum = Complex64::new(0.0, 0.0);
        for k in (-IMAGES..=IMAGES).filter(|&k| k != 0) {
            let f = freq_hz + k as f64 * fs;
            if f == 0.0 {
                continue;
            }
            // G(-j w) is the conjugate of G(j w): a real system.
            let g = if f > 0.0 {
                self.eval(values, f)?
            } else {
                self.eval(values, -f)?.conj()
            };
            sum += g / Complex64::new(0.0, 2.0 * PI * f);
        }
        Ok(sum)
    }

    /// [`ChainResponse::eval_held`] over a vector of frequencies, each
    /// divided by `G(j w) e^(-j w T / 2)`: the factor by which sampling
    /// with a held input changes the transfer function beyond its half
    /// sample of delay (1 at low frequencies). What folds back varies
    /// slowly with the frequency (it is the response far from it): it is
    /// computed on a grid of `fs / 512` and interpolated.
    ///
    /// ```
    /// use mms::response::ChainResponse;
    /// use mms::{Model, Output, Port};
    /// let m = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0))?;
    /// let g = ChainResponse::new(&m, Output::Velocity);
    /// let c = g.held_factor(&[2.0], &[1.0, 100.0], 1000.0)?;
    /// // Below a hundredth of the rate nothing changes; at a tenth, about
    /// // the hold's droop and the folded images.
    /// assert!((c[0] - 1.0).norm() < 1e-3);
    /// assert!((c[1] - 1.0).norm() > 1e-3 && (c[1] - 1.0).norm() < 0.05);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn held_factor(
        &self,
        values: &[f64],
        freq_hz: &[f64],
        fs: f64,
    ) -> Result<Vec<Complex64>, ResponseError> {
        if !(fs.is_finite() && fs > 0.0) {
            return Err(ResponseError::Frequency(fs));
        }
        let step = fs / 512.0;
        let mut grid: BTreeMap<i64, Complex64> = BTreeMap::new();
        let mut folded_at = |i: i64| -> Result<Complex64, ResponseError> {
            if let Some(v) = grid.get(&i) {
                return Ok(*v);
            }
            // (The grid's first point sits just above 0, where G is not
            // evaluated.)
            let v = self.folded(values, (i as f64 * step).max(1e-3 * step), fs)?;
            grid.insert(i, v);
            Ok(v)
        };
        let t = 1.0 / fs;
        freq_hz
            .iter()
            .map(|&f| {
                let w = 2.0 * PI * f;
                let g = self.eval(values, f)?;
                let x = f / step;
                let i = x.floor() as i64;
                let a = x - i as f64;
                let folded = folded_at(i)? * (1.0 - a) + folded_at(i + 1)? * a;
                let sampled = held(g / Complex64::new(0.0, w) + folded, w, t);
                Ok(sampled / (g * Complex64::from_polar(1.0, -w * t / 2.0)))
            })
            .collect()
    }

    /// `G` over a vector of frequencies.
    pub fn eval_many(
        &self,
        values: &[f64],
        freq_hz: &[f64],
    ) -> Result<Vec<Complex64>, ResponseError> {
        freq_hz.iter().map(|&f| self.eval(values, f)).collect()
    }

    // Inlined: the solver is built in its caller's frame, not moved
    // out of a `Result` per line.
    #[inline(always)]
    fn solver<const N: usize>(
        &self,
        values: &[f64],
        freq_hz: f64,
    ) -> Result<Solver<N>, ResponseError> {
        if values.len() != self.n_parameters() {
            return Err(ResponseError::Count {
                expected: self.n_parameters(),
                got: values.len(),
            });
        }
        if !(freq_hz.is_finite() && freq_hz > 0.0) {
            return Err(ResponseError::Frequency(freq_hz));
        }
        let n = self.n;
        let omega = 2.0 * PI * freq_hz;
        // Z is tridiagonal: diagonal `d`, off-diagonal `e` (Z[i][i+1] =
        // Z[i+1][i] = e[i]).
        let mut d = [ZERO; N];
        let mut e = [ZERO; N];
        for i in 0..n {
            d[i] = Complex64::new(-omega * omega * values[i], 0.0);
        }
        let nl = self.links.len();
        let spring = Complex64::new(1.0, self.effects.loss_factor.unwrap_or(0.0));
        if let Some(b) = self.effects.viscous_friction {
            d[self.driven - 1] += Complex64::new(0.0, omega * b);
        }
        if let Some(k) = self.effects.pre_sliding_stiffness {
            d[self.driven - 1] += Complex64::new(k, 0.0);
        }
        for (k, l) in self.links.iter().enumerate() {
            let y = spring * values[n + k] + Complex64::new(0.0, omega * values[n + nl + k]);
            if l.a > 0 {
                d[l.a - 1] += y;
                e[l.a - 1] = -y;
            }
            d[l.b - 1] += y;
        }
        let lu = Tridiagonal::factor(d, e).ok_or(ResponseError::Singular(freq_hz))?;
        let jw = Complex64::new(0.0, omega);
        let k = match self.output {
            Output::Position => Complex64::new(1.0, 0.0),
            Output::Velocity => jw,
            Output::Acceleration => jw * jw,
        };
        let effect = self.effects.output_factor(omega);
        Ok(Solver {
            lu,
            omega,
            factor: k * effect,
            effect,
            x: [ZERO; N],
            w: [ZERO; N],
        })
    }

    /// `G` and, if asked, the adjoint solution; see [`Solver`].
    // Inlined with `solver`, so the solver stays in its caller's frame.
    #[inline(always)]
    fn solve<const N: usize>(&self, solver: &mut Solver<N>, with_adjoint: bool) -> Complex64 {
        let n = self.n;
        for i in 0..n {
            solver.x[i] = Complex64::new(self.input[i], 0.0);
        }
        solver.lu.solve(&mut solver.x[..n]);
        if with_adjoint {
            // Z is symmetric, so Z^-T c = Z^-1 c.
            for i in 0..n {
                solver.w[i] = Complex64::new(self.sensor[i], 0.0);
            }
            solver.lu.solve(&mut solver.w[..n]);
        }
        let y: Complex64 = (0..n).map(|i| solver.x[i] * self.sensor[i]).sum();
        y * solver.factor
    }
}

const MAX: usize = crate::model::MAX_MASSES;

/// Runs `$body` with the constant `$N` equal to the chain's number of
/// masses `$n` (1 to [`MAX`]), so that the solver's arrays have exactly
/// that size: no array of the largest size is cleared or copied per line.
macro_rules! sized {
    ($n:expr, $N:ident, $body:block) => {
        match $n {
            1 => {
                const $N: usize = 1;
                $body
            }
            2 => {
                const $N: usize = 2;
                $body
            }
            3 => {
                const $N: usize = 3;
                $body
            }
            4 => {
                const $N: usize = 4;
                $body
            }
            5 => {
                const $N: usize = 5;
                $body
            }
            6 => {
                const $N: usize = 6;
                $body
            }
            7 => {
                const $N: usize = 7;
                $body
            }
            _ => {
                const $N: usize = MAX;
                $body
            }
        }
    };
}
use sized;
const ZERO: Complex64 = Complex64::new(0.0, 0.0);

/// One frequency's factorised dynamic stiffness and solutions: `x = Z^-1
/// b` and (for gradients) `w = Z^-1 c`; fixed-size arrays, no allocation
/// per line.
struct Solver<const N: usize> {
    lu: Tridiagonal<N>,
    omega: f64,
    /// `(j w)^k` of the output times the effects' factor.
    factor: Complex64,
    /// Gain, delay and lag of the [`Effects`].
    effect: Complex64,
    x: [Complex64; N],
    w: [Complex64; N],
}

/// LU factorisation with partial pivoting of a complex symmetric
/// tridiagonal matrix (row interchanges fill a second superdiagonal).
/// Pivoting matters: the diagonal `c - w^2 m` passes through zero at the
/// resonances of sub-chains.
struct Tridiagonal<const N: usize> {
    /// Multipliers (sub-diagonal of L).
    l: [Complex64; N],
    /// Reciprocals of the diagonal of U.
    d: [Complex64; N],
    /// First and second superdiagonals of U.
    u1: [Complex64; N],
    u2: [Complex64; N],
    /// Whether rows i and i+1 were interchanged at step i.
    swapped: [bool; N],
}

impl<const N: usize> Tridiagonal<N> {
    // Inlined into `solver`: the factors are built in place, not moved
    // out of an `Option` per line.
    #[inline(always)]
    fn factor(mut d: [Complex64; N], e: [Complex64; N]) -> Option<Tridiagonal<N>> {
        let n = N;
        // Squared moduli throughout: `norm()` is a hypot call, too slow for
        // the inner loop of a fit.
        let scale = d[..n]
            .iter()
            .chain(&e[..n.saturating_sub(1)])
            .map(|z| z.norm_sqr())
            .fold(0.0, f64::max);
        let tiny = scale * 1e-30;
        let mut l = [ZERO; N];
        let mut u1 = e; // superdiagonal, before interchanges
        let mut u2 = [ZERO; N];
        let mut swapped = [false; N];
        for i in 0..n.saturating_sub(1) {
            let sub = e[i]; // Z[i+1][i]
            if d[i].norm_sqr() >= sub.norm_sqr() {
                if d[i].norm_sqr() <= tiny {
                    return None;
                }
                let f = sub / d[i];
                l[i] = f;
                d[i + 1] -= f * u1[i];
            } else {
                // Row i+1 becomes the pivot row: it holds (sub, d[i+1],
                // u1[i+1]) in columns i, i+1, i+2.
                let f = d[i] / sub;
                l[i] = f;
                swapped[i] = true;
                let (a, b) = (u1[i], d[i + 1]);
                d[i] = sub;
                u1[i] = b;
                d[i + 1] = a - f * b;
                if i + 2 < n {
                    u2[i] = u1[i + 1];
                    u1[i + 1] = -f * u1[i + 1];
                }
            }
        }
        if n == 0 || d[n - 1].norm_sqr() <= tiny {
            return None;
        }
        // Solves multiply by the reciprocal pivots: one division each here
        // instead of one per solve.
        let mut inv = [ZERO; N];
        for i in 0..n {
            inv[i] = d[i].inv();
        }
        Some(Tridiagonal {
            l,
            d: inv,
            u1,
            u2,
            swapped,
        })
    }

    fn solve(&self, b: &mut [Complex64]) {
        let n = N;
        for i in 0..n.saturating_sub(1) {
            if self.swapped[i] {
                b.swap(i, i + 1);
                let t = b[i];
                b[i + 1] -= self.l[i] * t;
            } else {
                let t = b[i];
                b[i + 1] -= self.l[i] * t;
            }
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            if i + 1 < n {
                s -= self.u1[i] * b[i + 1];
            }
            if i + 2 < n {
                s -= self.u2[i] * b[i + 2];
            }
            b[i] = s * self.d[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(model: &Model, seed: u64) -> Vec<f64> {
        let mut rng = crate::xorshift::XorShift::new(seed);
        model
            .parameters()
            .iter()
            .map(|name| {
                let base = if name.starts_with('m') {
                    0.01
                } else if name.starts_with('c') {
                    100.0
                } else {
                    0.02
                };
                base * (0.3 + 2.0 * rng.uniform())
            })
            .collect()
    }

    /// The gradient agrees with central differences (relative step 1e-6,
    /// tolerance 1e-5 of the response's size) for every 3- and 4-mass
    /// model and every output.
    #[test]
    fn gradient_matches_finite_differences() {
        for n in [3, 4] {
            for (k, model) in crate::basic_models(n).unwrap().iter().enumerate() {
                let effects = Effects {
                    time_delay_s: Some(1e-3),
                    lowpass_hz: Some(80.0),
                    gain_factor: Some(1.3),
                    loss_factor: Some(0.02),
                    viscous_friction: Some(0.5),
                    pre_sliding_stiffness: Some(40.0),
                    ..Effects::default()
                };
                for (output, effects) in
                    Output::ALL
                        .into_iter()
                        .zip([Effects::default(), effects, effects])
                {
                    let g = ChainResponse::with_effects(model, output, &effects);
                    let p = params(model, 7 + k as u64);
                    let f = 37.0;
                    let mut grad = vec![Complex64::new(0.0, 0.0); p.len()];
                    let y = g.eval_with_gradient(&p, f, &mut grad).unwrap();
                    for i in 0..p.len() {
                        let h = p[i] * 1e-6;
                        let (mut up, mut dn) = (p.clone(), p.clone());
                        up[i] += h;
                        dn[i] -= h;
                        let fd = (g.eval(&up, f).unwrap() - g.eval(&dn, f).unwrap()) / (2.0 * h);
                        let err = (fd - grad[i]).norm() * p[i];
                        assert!(
                            err <= 1e-5 * y.norm(),
                            "{model} {output} {}",
                            model.parameters()[i]
                        );
                    }
                }
            }
        }
    }

    /// The effects' derivatives agree with central differences in each
    /// effect's parameter (relative step 1e-6, tolerance 1e-6 of the
    /// response's size), with every effect set and with none (their
    /// neutral values), for every 3-mass model and every output.
    #[test]
    fn effect_gradient_matches_finite_differences() {
        let all = Effects {
            time_delay_s: Some(1e-3),
            lowpass_hz: Some(80.0),
            gain_factor: Some(1.3),
            loss_factor: Some(0.02),
            viscous_friction: Some(0.5),
            pre_sliding_stiffness: Some(40.0),
            ..Effects::default()
        };
        type Field = fn(&mut Effects) -> &mut Option<f64>;
        type Of = fn(&EffectGradient) -> Complex64;
        let fields: [(Field, Of, f64); 6] = [
            (|e| &mut e.time_delay_s, |d| d.time_delay_s, 1e-3),
            (|e| &mut e.lowpass_hz, |d| d.lowpass_hz, 80.0),
            (|e| &mut e.gain_factor, |d| d.gain_factor, 1.0),
            (|e| &mut e.loss_factor, |d| d.loss_factor, 0.02),
            (|e| &mut e.viscous_friction, |d| d.viscous_friction, 0.5),
            (
                |e| &mut e.pre_sliding_stiffness,
                |d| d.pre_sliding_stiffness,
                40.0,
            ),
        ];
        for (k, model) in crate::basic_models(3).unwrap().iter().enumerate() {
            for output in Output::ALL {
                for base in [all, Effects::default()] {
                    let g = ChainResponse::with_effects(model, output, &base);
                    let p = params(model, 11 + k as u64);
                    let f = 37.0;
                    let mut grad = vec![ZERO; p.len()];
                    let (y, d) = g.eval_with_effect_gradient(&p, f, &mut grad).unwrap();
                    for (field, of, scale) in fields {
                        let mut e = base;
                        let Some(v) = *field(&mut e) else {
                            // Unset: the lag's derivative is 0; the others
                            // are taken at their neutral value below.
                            if scale == 80.0 {
                                assert_eq!(of(&d), ZERO);
                                continue;
                            }
                            let neutral = if scale == 1.0 { 1.0 } else { 0.0 };
                            let h = 1e-6 * scale;
                            let (mut up, mut dn) = (base, base);
                            *field(&mut up) = Some(neutral + h);
                            *field(&mut dn) = Some(neutral - h);
                            let at = |e: &Effects| {
                                ChainResponse::with_effects(model, output, e)
                                    .eval(&p, f)
                                    .unwrap()
                            };
                            let fd = (at(&up) - at(&dn)) / (2.0 * h);
                            assert!(
                                (fd - of(&d)).norm() * scale <= 1e-6 * y.norm(),
                                "{model} {output}"
                            );
                            continue;
                        };
                        let h = 1e-6 * v;
                        let (mut up, mut dn) = (base, base);
                        *field(&mut up) = Some(v + h);
                        *field(&mut dn) = Some(v - h);
                        let at = |e: &Effects| {
                            ChainResponse::with_effects(model, output, e)
                                .eval(&p, f)
                                .unwrap()
                        };
                        let fd = (at(&up) - at(&dn)) / (2.0 * h);
                        assert!(
                            (fd - of(&d)).norm() * v <= 1e-6 * y.norm(),
                            "{model} {output} {}",
                            (fd - of(&d)).norm() * v / y.norm()
                        );
                    }
                }
            }
        }
    }
}
