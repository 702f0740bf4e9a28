//! Model files: one damped model with its parameters, in TOML.
//!
//! ```toml
//! # the paper's Tab. 4 generating model
//! masses = 3
//! gap = 0
//! actuator = [1, 0]
//! sensor = [2, 0]
//! output = "position"        # position | velocity | acceleration
//!
//! [parameters]               # SI: kg, N/m, N s/m (or kg m^2, N m/rad, N m s/rad)
//! m1 = 0.01
//! m2 = 0.01
//! m3 = 0.02
//! c12 = 100
//! c23 = 100
//! d12 = 0.01
//! d23 = 0.01
//!
//! [effects]                  # optional; filled by the diagnosis
//! time_delay = { delay_s = 2e-4 }
//! friction = { viscous_ns_per_m = 0.5, coulomb_n = 0.2 }   # and pre_sliding_n_per_m
//! backlash = { gap = 1e-4 }  # m (or rad): dead zone in a spring
//! offset = { force_n = -3.2 } # N (or N m), either sign: a constant force bias
//! ```
//!
//! Every value must lie in its physical range ([`crate::ranges`]).
//!
//! `structure = "A2"` (a paper ID, or a generic ID such as
//! `"N4-g1-a2.1-s4.1"`) may stand in place of the four topology keys.
//! Optional top-level keys: `gain` (the signed product of actuator and sensor
//! constants the FRF is multiplied by; default 1) and `motion`
//! (`"translational"` or `"rotary"`, for units in reports). Unknown keys,
//! missing parameters and values outside their range are errors that name the line.
//!
//! ```
//! use mms::model_file::ModelFile;
//! let text = "structure = \"A1\"\noutput = \"acceleration\"\n[parameters]\n\
//!             m1 = 1\nm2 = 2\nm3 = 3\nc12 = 1e4\nc23 = 2e4\nd12 = 1\nd23 = 1\n";
//! let file = ModelFile::parse(text)?;
//! assert_eq!(file.model.paper_id(), Some("A1"));
//! assert_eq!(file.parameters.get("c23"), Some(2e4));
//! // Written back deterministically, then read again to the same value.
//! assert_eq!(ModelFile::parse(&file.to_toml())?, file);
//!
//! let err = ModelFile::parse("structure = \"A1\"\nmass = 3\n").unwrap_err();
//! assert_eq!(err.to_string(), "line 2: unknown key 'mass'");
//! # Ok::<(), mms::model_file::ModelFileError>(())
//! ```

use crate::model::{Model, Port};
use crate::ranges::{self, PhysicalRange};
use crate::response::{Effects, Parameters};
use crate::tf::Output;
use std::fmt::Write as _;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// Whether the parameters are translational (kg, N/m, N s/m) or rotary
/// (kg m^2, N m/rad, N m s/rad). The algebra is the same; only units in
/// reports differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Motion {
    /// Masses, forces, positions.
    #[default]
    Translational,
    /// Inertias, torques, angles.
    Rotary,
}

impl Motion {
    fn as_str(self) -> &'static str {
        match self {
            Motion::Translational => "translational",
            Motion::Rotary => "rotary",
        }
    }
}

/// A model file's content.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelFile {
    /// The chain: masses, gap, actuator, sensor.
    pub model: Model,
    /// The measured quantity.
    pub output: Output,
    /// Every parameter of the model.
    pub parameters: Parameters,
    /// Signed product of the actuator and sensor constants (1 if the FRF is
    /// in force and position units; negative for a sensor or actuator
    /// mounted the other way round).
    pub gain: f64,
    /// Translational or rotary units.
    pub motion: Motion,
    /// Physics beyond the chain (see [`Effects`]).
    pub effects: Effects,
}

/// A model file that cannot be read; `line` is 1-based where known.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{message}", match line { Some(l) => format!("line {l}: "), None => String::new() })]
pub struct ModelFileError {
    /// The line of the offending key or value.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

const TOP_KEYS: [&str; 11] = [
    "masses",
    "gap",
    "actuator",
    "sensor",
    "sensors",
    "structure",
    "output",
    "gain",
    "motion",
    "parameters",
    "effects",
];

/// `(key, parameters)` of each effect in the `[effects]` table; every
/// effect needs at least one of its parameters.
const EFFECT_KEYS: [(&str, &[&str]); 7] = [
    ("time_delay", &["delay_s"]),
    ("lowpass", &["corner_hz"]),
    ("gain_error", &["factor"]),
    ("hysteretic_damping", &["loss_factor"]),
    (
        "friction",
        &["viscous_ns_per_m", "coulomb_n", "pre_sliding_n_per_m"],
    ),
    ("backlash", &["gap"]),
    ("offset", &["force_n"]),
];

/// The range of an effect's value by its key in [`EFFECT_KEYS`].
fn effect_range(key: &str) -> &'static PhysicalRange {
    match key {
        "delay_s" => &ranges::TIME_DELAY,
        "corner_hz" => &ranges::CORNER_FREQUENCY,
        "factor" => &ranges::GAIN_FACTOR,
        "loss_factor" => &ranges::LOSS_FACTOR,
        "viscous_ns_per_m" => &ranges::VISCOUS_FRICTION,
        "coulomb_n" => &ranges::COULOMB_FRICTION,
        "pre_sliding_n_per_m" => &ranges::PRE_SLIDING_STIFFNESS,
        "force_n" => &ranges::OFFSET_FORCE,
        _ => &ranges::BACKLASH_GAP,
    }
}

struct Reader<'a> {
    text: &'a str,
}

impl Reader<'_> {
    fn line_of(&self, offset: usize) -> usize {
        self.text[..offset.min(self.text.len())]
            .bytes()
            .filter(|&b| b == b'\n')
            .count()
            + 1
    }

    fn err(&self, span: std::ops::Range<usize>, message: impl Into<String>) -> ModelFileError {
        ModelFileError {
            line: Some(self.line_of(span.start)),
            message: message.into(),
        }
    }

    fn number(&self, key: &str, v: &Spanned<DeValue<'_>>) -> Result<f64, ModelFileError> {
        let x = match v.get_ref() {
            DeValue::Float(f) => f.as_str().replace('_', "").parse::<f64>().ok(),
            DeValue::Integer(i) if i.radix() == 10 => i
                .as_str()
                .replace('_', "")
                .parse::<i64>()
                .ok()
                .map(|n| n as f64),
            _ => None,
        };
        match x {
            Some(x) if x.is_finite() => Ok(x),
            Some(_) => Err(self.err(v.span(), format!("'{key}' must be finite"))),
            None => Err(self.err(v.span(), format!("'{key}' must be a number"))),
        }
    }

    fn count(&self, key: &str, v: &Spanned<DeValue<'_>>) -> Result<usize, ModelFileError> {
        match v.get_ref() {
            DeValue::Integer(i) if i.radix() == 10 => {
                i.as_str().replace('_', "").parse::<usize>().map_err(|_| {
                    self.err(v.span(), format!("'{key}' must be a non-negative integer"))
                })
            }
            _ => Err(self.err(v.span(), format!("'{key}' must be a non-negative integer"))),
        }
    }

    fn string<'v>(
        &self,
        key: &str,
        v: &'v Spanned<DeValue<'_>>,
    ) -> Result<&'v str, ModelFileError> {
        v.get_ref()
            .as_str()
            .ok_or_else(|| self.err(v.span(), format!("'{key}' must be a string")))
    }

    fn port(&self, key: &str, v: &Spanned<DeValue<'_>>) -> Result<Port, ModelFileError> {
        let msg = format!("'{key}' must be [plus, minus], e.g. [2, 0]");
        let arr = v
            .get_ref()
            .as_array()
            .ok_or_else(|| self.err(v.span(), &msg))?;
        if arr.len() != 2 {
            return Err(self.err(v.span(), msg));
        }
        Ok(Port::new(
            self.count(key, &arr[0])?,
            self.count(key, &arr[1])?,
        ))
    }

    fn table<'v, 'i>(
        &self,
        key: &str,
        v: &'v Spanned<DeValue<'i>>,
    ) -> Result<&'v DeTable<'i>, ModelFileError> {
        v.get_ref()
            .as_table()
            .ok_or_else(|| self.err(v.span(), format!("'{key}' must be a table")))
    }
}

impl ModelFile {
    /// Reads a model file from its text.
    pub fn parse(text: &str) -> Result<ModelFile, ModelFileError> {
        Ok(ModelFile::parse_with_sensors(text)?.0)
    }

    /// Reads a model file and the sensors of a recording with several
    /// outputs: the optional top-level `sensors = [[plus, minus], ...]`,
    /// one port per output in the order the outputs are given, the first
    /// the model's own `sensor` (empty without the key). Each must be a
    /// sensor the chain can have (rule (1) with the model's gap).
    ///
    /// ```
    /// use mms::model_file::ModelFile;
    /// use mms::Port;
    /// // A two-mass drive read at the motor and at the load.
    /// let text = "masses = 2\ngap = 0\nactuator = [1, 0]\nsensor = [1, 0]\n\
    ///             sensors = [[1, 0], [2, 0]]\noutput = \"position\"\n\
    ///             [parameters]\nm1 = 1\nm2 = 2\nc12 = 100\nd12 = 0.1\n";
    /// let (file, sensors) = ModelFile::parse_with_sensors(text)?;
    /// assert_eq!(sensors, vec![Port::new(1, 0), Port::new(2, 0)]);
    /// // It writes them back.
    /// assert_eq!(ModelFile::parse_with_sensors(&file.to_toml_with_sensors(&sensors))?.1, sensors);
    /// // A sensor that does not start the list with the model's is refused.
    /// let swapped = text.replace("[[1, 0], [2, 0]]", "[[2, 0], [1, 0]]");
    /// assert!(ModelFile::parse(&swapped).is_err());
    /// # Ok::<(), mms::model_file::ModelFileError>(())
    /// ```
    pub fn parse_with_sensors(text: &str) -> Result<(ModelFile, Vec<Port>), ModelFileError> {
        let r = Reader { text };
        let root = DeTable::parse(text).map_err(|e| ModelFileError {
            line: e.span().map(|s| r.line_of(s.start)),
            message: format!("invalid TOML: {}", e.message().trim()),
        })?;
        let root = root.get_ref();
        for (k, _) in root.iter() {
            if !TOP_KEYS.contains(&k.get_ref().as_ref()) {
                return Err(r.err(k.span(), format!("unknown key '{}'", k.get_ref())));
            }
        }
        let get = |k: &str| root.get(k);
        let missing = |k: &str| ModelFileError {
            line: None,
            message: format!("missing key '{k}'"),
        };

        let model = if let Some(v) = get("structure") {
            if let Some(k) = ["masses", "gap", "actuator", "sensor"]
                .into_iter()
                .find(|k| get(k).is_some())
            {
                return Err(r.err(
                    v.span(),
                    format!("'structure' and '{k}' exclude each other"),
                ));
            }
            let id = r.string("structure", v)?;
            Model::from_id(id).map_err(|e| r.err(v.span(), e.to_string()))?
        } else {
            let masses = r.count("masses", get("masses").ok_or_else(|| missing("masses"))?)?;
            let gap_v = get("gap").ok_or_else(|| missing("gap"))?;
            let gap = r.count("gap", gap_v)?;
            let act = r.port(
                "actuator",
                get("actuator").ok_or_else(|| missing("actuator"))?,
            )?;
            let meas = r.port("sensor", get("sensor").ok_or_else(|| missing("sensor"))?)?;
            Model::new(masses, gap, act, meas).map_err(|e| r.err(gap_v.span(), e.to_string()))?
        };

        let sensors = match get("sensors") {
            None => Vec::new(),
            Some(v) => {
                let msg = "'sensors' must be a list of [plus, minus], e.g. [[1, 0], [2, 0]]";
                let arr = v.get_ref().as_array().ok_or_else(|| r.err(v.span(), msg))?;
                let mut ports = Vec::with_capacity(arr.len());
                for p in arr.iter() {
                    let port = r.port("sensors", p)?;
                    Model::new(model.n_masses(), model.gap(), model.actuator(), port).map_err(
                        |e| {
                            r.err(
                                p.span(),
                                format!(
                                    "'sensors': no sensor at [{}, {}]: {e}",
                                    port.plus, port.minus
                                ),
                            )
                        },
                    )?;
                    ports.push(port);
                }
                if ports.first().is_some_and(|p| *p != model.sensor()) {
                    let s = model.sensor();
                    return Err(r.err(
                        v.span(),
                        format!(
                            "'sensors' must start with the model's sensor [{}, {}]",
                            s.plus, s.minus
                        ),
                    ));
                }
                ports
            }
        };

        let output = match get("output") {
            Some(v) => r
                .string("output", v)?
                .parse::<Output>()
                .map_err(|e| r.err(v.span(), e.to_string()))?,
            None => return Err(missing("output")),
        };
        let gain = match get("gain") {
            Some(v) => {
                let g = r.number("gain", v)?;
                // Negative: a sensor or actuator mounted the other way round.
                ranges::GAIN
                    .check(g)
                    .map_err(|e| r.err(v.span(), format!("'gain': {e}")))?;
                g
            }
            None => 1.0,
        };
        let motion = match get("motion") {
            None => Motion::Translational,
            Some(v) => match r.string("motion", v)? {
                "translational" => Motion::Translational,
                "rotary" => Motion::Rotary,
                other => {
                    return Err(r.err(
                        v.span(),
                        format!("'motion' is {other:?}, expected \"translational\" or \"rotary\""),
                    ))
                }
            },
        };

        let ptable_v = get("parameters").ok_or_else(|| missing("parameters"))?;
        let ptable = r.table("parameters", ptable_v)?;
        let names = model.parameters();
        let mut values = Vec::with_capacity(names.len());
        for (k, _) in ptable.iter() {
            if !names.iter().any(|n| n == k.get_ref().as_ref()) {
                return Err(r.err(
                    k.span(),
                    format!(
                        "unknown parameter '{}' (model {} has {})",
                        k.get_ref(),
                        model.name(),
                        names.join(", ")
                    ),
                ));
            }
        }
        for name in &names {
            let v = ptable
                .get(name.as_str())
                .ok_or_else(|| r.err(ptable_v.span(), format!("missing parameter '{name}'")))?;
            let x = r.number(name, v)?;
            ranges::of_parameter(name)
                .check(x)
                .map_err(|e| r.err(v.span(), format!("parameter '{name}': {e}")))?;
            values.push(x);
        }
        let parameters = Parameters::from_values(&model, values).map_err(|e| ModelFileError {
            line: None,
            message: e.to_string(),
        })?;

        let mut effects = Effects::default();
        if let Some(ev) = get("effects") {
            for (k, v) in r.table("effects", ev)?.iter() {
                let key = k.get_ref().as_ref();
                let Some(&(_, pnames)) = EFFECT_KEYS.iter().find(|(e, _)| *e == key) else {
                    let known: Vec<&str> = EFFECT_KEYS.iter().map(|(e, _)| *e).collect();
                    return Err(r.err(
                        k.span(),
                        format!("unknown effect '{key}' (known: {})", known.join(", ")),
                    ));
                };
                let t = r.table(key, v)?;
                for (pk, _) in t.iter() {
                    if !pnames.contains(&pk.get_ref().as_ref()) {
                        return Err(r.err(
                            pk.span(),
                            format!(
                                "unknown key '{}' in effect '{key}' (expected {})",
                                pk.get_ref(),
                                pnames.join(" or ")
                            ),
                        ));
                    }
                }
                if pnames.iter().all(|p| t.get(*p).is_none()) {
                    return Err(r.err(
                        v.span(),
                        format!("effect '{key}' needs '{}'", pnames.join("' or '")),
                    ));
                }
                for &pname in pnames {
                    let Some(pv) = t.get(pname) else { continue };
                    let x = r.number(pname, pv)?;
                    effect_range(pname)
                        .check(x)
                        .map_err(|e| r.err(pv.span(), format!("'{pname}': {e}")))?;
                    match pname {
                        "delay_s" => effects.time_delay_s = Some(x),
                        "corner_hz" => effects.lowpass_hz = Some(x),
                        "factor" => effects.gain_factor = Some(x),
                        "loss_factor" => effects.loss_factor = Some(x),
                        "viscous_ns_per_m" => effects.viscous_friction = Some(x),
                        "coulomb_n" => effects.coulomb_friction = Some(x),
                        "pre_sliding_n_per_m" => effects.pre_sliding_stiffness = Some(x),
                        "force_n" => effects.offset_force = Some(x),
                        _ => effects.backlash_gap = Some(x),
                    }
                }
            }
        }

        Ok((
            ModelFile {
                model,
                output,
                parameters,
                gain,
                motion,
                effects,
            },
            sensors,
        ))
    }

    /// [`ModelFile::to_toml`] with the sensors of a recording with several
    /// outputs after the `sensor` line (see
    /// [`ModelFile::parse_with_sensors`]; none: the same text).
    pub fn to_toml_with_sensors(&self, sensors: &[Port]) -> String {
        let m = &self.model;
        let mut s = String::new();
        if let Some(id) = m.paper_id() {
            let _ = writeln!(s, "# paper model {id}");
        }
        let (a, b) = (m.actuator(), m.sensor());
        let _ = writeln!(s, "masses = {}", m.n_masses());
        let _ = writeln!(s, "gap = {}", m.gap());
        let _ = writeln!(s, "actuator = [{}, {}]", a.plus, a.minus);
        let _ = writeln!(s, "sensor = [{}, {}]", b.plus, b.minus);
        if !sensors.is_empty() {
            let list: Vec<String> = sensors
                .iter()
                .map(|p| format!("[{}, {}]", p.plus, p.minus))
                .collect();
            let _ = writeln!(s, "sensors = [{}]", list.join(", "));
        }
        let _ = writeln!(s, "output = \"{}\"", self.output);
        if self.gain != 1.0 {
            let _ = writeln!(s, "gain = {}", num(self.gain));
        }
        if self.motion != Motion::Translational {
            let _ = writeln!(s, "motion = \"{}\"", self.motion.as_str());
        }
        s.push_str("\n[parameters]\n");
        for (name, v) in self.parameters.iter() {
            let _ = writeln!(s, "{name} = {}", num(v));
        }
        let e = &self.effects;
        if !e.is_empty() {
            s.push_str("\n[effects]\n");
            let values: [&[(&str, Option<f64>)]; 7] = [
                &[("delay_s", e.time_delay_s)],
                &[("corner_hz", e.lowpass_hz)],
                &[("factor", e.gain_factor)],
                &[("loss_factor", e.loss_factor)],
                &[
                    ("viscous_ns_per_m", e.viscous_friction),
                    ("coulomb_n", e.coulomb_friction),
                    ("pre_sliding_n_per_m", e.pre_sliding_stiffness),
                ],
                &[("gap", e.backlash_gap)],
                &[("force_n", e.offset_force)],
            ];
            for ((key, _), params) in EFFECT_KEYS.iter().zip(values) {
                let set: Vec<String> = params
                    .iter()
                    .filter_map(|(p, v)| v.map(|v| format!("{p} = {}", num(v))))
                    .collect();
                if !set.is_empty() {
                    let _ = writeln!(s, "{key} = {{ {} }}", set.join(", "));
                }
            }
        }
        s
    }

    /// The same model with every value moved to the nearest point of its
    /// physical range ([`crate::ranges`]): for writers whose values come
    /// out of `exp(ln x)` or a fit pinned at a bound, so that the file
    /// reads back. Values already inside are unchanged.
    ///
    /// ```
    /// use mms::model_file::ModelFile;
    /// let text = "structure = \"A1\"\noutput = \"position\"\n[parameters]\n\
    ///             m1 = 1\nm2 = 2\nm3 = 3\nc12 = 1e4\nc23 = 2e4\nd12 = 1\nd23 = 1\n";
    /// let mut file = ModelFile::parse(text)?;
    /// file.effects.time_delay_s = Some(1e300);
    /// let kept = file.within_ranges();
    /// assert_eq!(kept.effects.time_delay_s, Some(1e3));
    /// assert_eq!(kept.parameters, file.parameters);
    /// assert_eq!(ModelFile::parse(&kept.to_toml())?, kept);
    /// # Ok::<(), mms::model_file::ModelFileError>(())
    /// ```
    pub fn within_ranges(&self) -> ModelFile {
        let mut out = self.clone();
        let values: Vec<f64> = self
            .parameters
            .iter()
            .map(|(name, x)| ranges::of_parameter(name).clamp(x))
            .collect();
        out.parameters = Parameters::from_values(&self.model, values)
            .expect("a value clamped to its physical range is valid");
        if self.gain != 0.0 {
            out.gain = ranges::GAIN.clamp(self.gain);
        }
        let e = &mut out.effects;
        let fields: [(&mut Option<f64>, &PhysicalRange); 9] = [
            (&mut e.time_delay_s, &ranges::TIME_DELAY),
            (&mut e.lowpass_hz, &ranges::CORNER_FREQUENCY),
            (&mut e.gain_factor, &ranges::GAIN_FACTOR),
            (&mut e.loss_factor, &ranges::LOSS_FACTOR),
            (&mut e.viscous_friction, &ranges::VISCOUS_FRICTION),
            (&mut e.pre_sliding_stiffness, &ranges::PRE_SLIDING_STIFFNESS),
            (&mut e.coulomb_friction, &ranges::COULOMB_FRICTION),
            (&mut e.backlash_gap, &ranges::BACKLASH_GAP),
            (&mut e.offset_force, &ranges::OFFSET_FORCE),
        ];
        for (x, range) in fields {
            if let Some(v) = x.as_mut().filter(|v| v.is_finite()) {
                *v = range.clamp(*v);
            }
        }
        out
    }

    /// The file's text: deterministic (keys in a fixed order, numbers in
    /// Rust's shortest round-trip form), so it reads back to an equal
    /// [`ModelFile`] and diffs cleanly.
    pub fn to_toml(&self) -> String {
        self.to_toml_with_sensors(&[])
    }
}

/// A TOML float in Rust's shortest round-trip form (`{:?}` keeps the
/// decimal point or exponent that TOML needs to read it as a float).
fn num(x: f64) -> String {
    format!("{x:?}")
}
