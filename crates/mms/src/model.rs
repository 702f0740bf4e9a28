//! The model description: a chain of masses with one gap, one actuator and
//! one sensor (Sec. 2 of Tantau et al.), parameter names, IDs and the chain
//! matrices.

use poly::Poly;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Largest number of masses a [`Model`] may have.
///
/// Enumeration alone would be cheap for much larger chains, but the symbolic
/// transfer functions grow quickly: the undamped denominator of a free chain
/// of `N` masses has on the order of `F(2N)` terms (Fibonacci numbers; 987
/// for `N = 8`) and the damped one roughly `3.7^N` terms (about 15 000 for
/// `N = 8`). Eight masses keep every derivation and rendering in this crate
/// at a fraction of a second in a release build.
///
/// Parameter names stay unambiguous beyond this limit (see
/// [`spring_name`]: `c9_10`), so raising it needs no change of naming.
pub const MAX_MASSES: usize = 8;

/// Errors when building or parsing a [`Model`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ModelError {
    /// `N = 0`: a model needs at least one mass.
    #[error("a model needs at least one mass")]
    NoMasses,
    /// `N` above [`MAX_MASSES`].
    #[error("{n} masses requested, at most {max} are supported")]
    TooManyMasses {
        /// Requested number of masses.
        n: usize,
        /// The limit, [`MAX_MASSES`].
        max: usize,
    },
    /// Rule (1) of the paper is violated.
    #[error("rule (1) violated: {0}")]
    Rule1(String),
    /// A model ID could not be parsed.
    #[error("invalid model ID {id:?}: {reason}")]
    InvalidId {
        /// The text that was given.
        id: String,
        /// Why it was rejected.
        reason: String,
    },
}

/// Checks `1 <= n <= MAX_MASSES`.
pub(crate) fn check_n(n: usize) -> Result<(), ModelError> {
    if n == 0 {
        Err(ModelError::NoMasses)
    } else if n > MAX_MASSES {
        Err(ModelError::TooManyMasses { n, max: MAX_MASSES })
    } else {
        Ok(())
    }
}

/// A pair of attachment points: `plus` is the point of actuation (resp.
/// measurement), `minus` the reference point (0 = the rigid environment).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Port {
    /// `n_act+` resp. `n_meas+`: a mass on the free side of the gap.
    pub plus: usize,
    /// `n_act-` resp. `n_meas-`: the ground (0) or a mass on the grounded side.
    pub minus: usize,
}

impl Port {
    /// The pair `(plus, minus)`.
    pub const fn new(plus: usize, minus: usize) -> Port {
        Port { plus, minus }
    }
}

/// Name of mass `i` (1-based): `m1`, `m2`, ..., `m10`.
///
/// ```
/// assert_eq!(mms::mass_name(3), "m3");
/// ```
pub fn mass_name(i: usize) -> String {
    format!("m{i}")
}

fn link_name(prefix: char, i: usize) -> String {
    if i == 0 {
        format!("{prefix}1")
    } else if i < 9 {
        format!("{prefix}{i}{}", i + 1)
    } else {
        format!("{prefix}{i}_{}", i + 1)
    }
}

/// Name of the spring between mass `i` and mass `i + 1` (`i = 0`: between
/// the ground and mass 1).
///
/// The paper's names: `c1` (ground to m1), then `c12`, `c23`, ..., `c89`.
/// Once an index has two digits the two indices are separated by an
/// underscore so the name stays unambiguous: `c9_10`, `c10_11`. The name
/// depends only on `i`, never on the length of the chain.
///
/// ```
/// assert_eq!(mms::spring_name(0), "c1");
/// assert_eq!(mms::spring_name(2), "c23");
/// assert_eq!(mms::spring_name(9), "c9_10");
/// ```
pub fn spring_name(i: usize) -> String {
    link_name('c', i)
}

/// Name of the viscous damper parallel to spring [`spring_name`]`(i)`:
/// `d1`, `d12`, ..., `d9_10`.
///
/// ```
/// assert_eq!(mms::damper_name(1), "d12");
/// ```
pub fn damper_name(i: usize) -> String {
    link_name('d', i)
}

/// The paper's IDs of the eleven 3-mass models of Tab. 2, as
/// `(id, gap, actuator, sensor)`.
///
/// The IDs follow from the printed numerators of Sec. 4.3 (checked in the
/// tests). C2 and C4 have the same transfer function (reciprocity), so the
/// paper's text cannot tell them apart; this crate fixes
/// C2 = actuator (3,1), sensor (3,2) and C4 = actuator (3,2), sensor (3,1).
pub const PAPER_IDS: [(&str, usize, Port, Port); 11] = [
    ("A1", 0, Port::new(1, 0), Port::new(1, 0)),
    ("A2", 0, Port::new(1, 0), Port::new(2, 0)),
    ("A3", 0, Port::new(1, 0), Port::new(3, 0)),
    ("A4", 0, Port::new(2, 0), Port::new(2, 0)),
    ("A5", 0, Port::new(2, 0), Port::new(3, 0)),
    ("B1", 1, Port::new(2, 1), Port::new(2, 1)),
    ("B2", 1, Port::new(2, 1), Port::new(3, 1)),
    ("C1", 2, Port::new(3, 1), Port::new(3, 1)),
    ("C2", 2, Port::new(3, 1), Port::new(3, 2)),
    ("C3", 2, Port::new(3, 2), Port::new(3, 2)),
    ("C4", 2, Port::new(3, 2), Port::new(3, 1)),
];

/// A multiple-mass model: `N` masses in a chain ground - m1 - ... - mN with
/// one missing spring (the gap), one actuator and one sensor.
///
/// Springs and dampers are present between the ground and m1 (`c1`, `d1`)
/// unless `gap = 0`, and between m_i and m_(i+1) (`c12`, `d12`, ...) unless
/// `i = gap`. Actuator and sensor act between a mass on the free side of the
/// gap (`plus`, in `gap+1 ..= N`) and the ground or a mass on the grounded
/// side (`minus`, in `0 ..= gap`): rule (1) of the paper.
///
/// Models order by `(N, gap, actuator, sensor)` (each port as
/// `(plus, minus)`), which is the order of every list this crate returns.
///
/// ```
/// use mms::{Model, Port};
/// let a2 = Model::from_id("A2").unwrap();
/// assert_eq!(a2, Model::new(3, 0, Port::new(1, 0), Port::new(2, 0)).unwrap());
/// assert_eq!(a2.id(), "N3-g0-a1.0-s2.0");
/// assert_eq!(a2.parameters(), ["m1", "m2", "m3", "c12", "c23", "d12", "d23"]);
/// assert!(!a2.is_collocated());
/// assert!(Model::new(3, 1, Port::new(1, 0), Port::new(2, 0)).is_err()); // act+ = 1 <= gap
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "RawModel", into = "RawModel")]
pub struct Model {
    n: usize,
    gap: usize,
    act: Port,
    meas: Port,
}

/// Unvalidated serde form of [`Model`].
#[derive(Serialize, Deserialize)]
struct RawModel {
    n: usize,
    gap: usize,
    act: Port,
    meas: Port,
}

impl TryFrom<RawModel> for Model {
    type Error = ModelError;
    fn try_from(r: RawModel) -> Result<Model, ModelError> {
        Model::new(r.n, r.gap, r.act, r.meas)
    }
}

impl From<Model> for RawModel {
    fn from(m: Model) -> RawModel {
        RawModel {
            n: m.n,
            gap: m.gap,
            act: m.act,
            meas: m.meas,
        }
    }
}

impl Model {
    /// A model with `n` masses, the gap between masses `gap` and `gap + 1`,
    /// actuator `act` and sensor `meas`, validated against rule (1):
    /// `0 <= gap <= N-1`, `0 <= minus <= gap < plus <= N` for both ports.
    ///
    /// ```
    /// use mms::{Model, ModelError, Port};
    /// let b1 = Model::new(3, 1, Port::new(2, 1), Port::new(2, 1)).unwrap();
    /// assert_eq!(b1.paper_id(), Some("B1"));
    /// assert_eq!(Model::new(0, 0, Port::new(1, 0), Port::new(1, 0)), Err(ModelError::NoMasses));
    /// ```
    pub fn new(n: usize, gap: usize, act: Port, meas: Port) -> Result<Model, ModelError> {
        check_n(n)?;
        if gap >= n {
            return Err(ModelError::Rule1(format!(
                "gap {gap} must satisfy 0 <= gap <= N-1 = {}",
                n - 1
            )));
        }
        for (what, p) in [("actuator", act), ("sensor", meas)] {
            if p.minus > gap {
                return Err(ModelError::Rule1(format!(
                    "{what} reference point {} must satisfy 0 <= n- <= gap = {gap}",
                    p.minus
                )));
            }
            if p.plus <= gap || p.plus > n {
                return Err(ModelError::Rule1(format!(
                    "{what} point {} must satisfy gap+1 = {} <= n+ <= N = {n}",
                    p.plus,
                    gap + 1
                )));
            }
        }
        Ok(Model { n, gap, act, meas })
    }

    /// Number of masses `N`.
    pub fn n_masses(&self) -> usize {
        self.n
    }

    /// The gap `n_gap`: the missing spring lies between masses `gap` and
    /// `gap + 1` (0 = between the ground and m1).
    pub fn gap(&self) -> usize {
        self.gap
    }

    /// The actuator `(n_act+, n_act-)`.
    pub fn actuator(&self) -> Port {
        self.act
    }

    /// The sensor `(n_meas+, n_meas-)`.
    pub fn sensor(&self) -> Port {
        self.meas
    }

    /// Collocated: the actuator and the sensor act on the same pair of points.
    ///
    /// ```
    /// assert!(mms::Model::from_id("C3").unwrap().is_collocated());
    /// assert!(!mms::Model::from_id("C2").unwrap().is_collocated());
    /// ```
    pub fn is_collocated(&self) -> bool {
        self.act == self.meas
    }

    /// Rule (2): every mass is excited and seen by the sensor, i.e. `gap = 0`
    /// or both reference points are masses (`n_act- > 0`, `n_meas- > 0`).
    pub fn is_degradation_free(&self) -> bool {
        self.gap == 0 || (self.act.minus > 0 && self.meas.minus > 0)
    }

    /// The paper's rule (3): `n_act+ <= n_meas+` and
    /// `n_act+ <= gap + ceil((N - gap) / 2)`.
    pub fn satisfies_rule3(&self) -> bool {
        self.act.plus <= self.meas.plus
            && self.act.plus <= self.gap + (self.n - self.gap).div_ceil(2)
    }

    /// True if a spring (and damper) connects mass `i` to mass `i + 1`
    /// (`i = 0`: the ground to m1), i.e. `i < N` and `i != gap`.
    pub fn has_link(&self, i: usize) -> bool {
        i < self.n && i != self.gap
    }

    /// Mass names `m1 .. mN`.
    pub fn masses(&self) -> Vec<String> {
        (1..=self.n).map(mass_name).collect()
    }

    /// Spring names present, from the ground side: `c1` (if `gap != 0`),
    /// `c12`, `c23`, ... (see [`spring_name`]).
    pub fn springs(&self) -> Vec<String> {
        (0..self.n)
            .filter(|&i| self.has_link(i))
            .map(spring_name)
            .collect()
    }

    /// Damper names present, parallel to [`Model::springs`].
    pub fn dampers(&self) -> Vec<String> {
        (0..self.n)
            .filter(|&i| self.has_link(i))
            .map(damper_name)
            .collect()
    }

    /// All parameter names: masses, then springs, then dampers.
    pub fn parameters(&self) -> Vec<String> {
        let mut v = self.masses();
        v.extend(self.springs());
        v.extend(self.dampers());
        v
    }

    /// Parameters of the undamped model: masses, then springs.
    pub fn undamped_parameters(&self) -> Vec<String> {
        let mut v = self.masses();
        v.extend(self.springs());
        v
    }

    /// The stable generic ID `N{N}-g{gap}-a{act+}.{act-}-s{meas+}.{meas-}`.
    ///
    /// ```
    /// let m = mms::Model::from_id("C4").unwrap();
    /// assert_eq!(m.id(), "N3-g2-a3.2-s3.1");
    /// assert_eq!(mms::Model::from_id(&m.id()).unwrap(), m);
    /// ```
    pub fn id(&self) -> String {
        format!(
            "N{}-g{}-a{}.{}-s{}.{}",
            self.n, self.gap, self.act.plus, self.act.minus, self.meas.plus, self.meas.minus
        )
    }

    /// The paper's ID (Tab. 2) for the eleven 3-mass models it analyses,
    /// without the star (see [`Model::paper_label`]); `None` otherwise.
    pub fn paper_id(&self) -> Option<&'static str> {
        if self.n != 3 {
            return None;
        }
        PAPER_IDS
            .iter()
            .find(|(_, g, a, s)| *g == self.gap && *a == self.act && *s == self.meas)
            .map(|(id, ..)| *id)
    }

    /// The paper's label as printed in Tab. 2: the ID with a star for
    /// collocated models (`A1*`, `A2`, ...).
    ///
    /// ```
    /// assert_eq!(mms::Model::from_id("a4").unwrap().paper_label().as_deref(), Some("A4*"));
    /// ```
    pub fn paper_label(&self) -> Option<String> {
        self.paper_id().map(|id| {
            if self.is_collocated() {
                format!("{id}*")
            } else {
                id.to_string()
            }
        })
    }

    /// The paper's ID if there is one, else the generic ID.
    pub fn name(&self) -> String {
        self.paper_id()
            .map(str::to_string)
            .unwrap_or_else(|| self.id())
    }

    /// Parses a paper ID (`A1` .. `C4`, with or without the star) or a generic
    /// ID (`N3-g0-a1.0-s2.0`), case-insensitively.
    ///
    /// ```
    /// use mms::Model;
    /// assert_eq!(Model::from_id("a1*").unwrap(), Model::from_id("N3-g0-a1.0-s1.0").unwrap());
    /// assert!(Model::from_id("A6").is_err());
    /// assert!(Model::from_id("n3-g1-a1.0-s2.1").is_err()); // fine syntax, but act+ <= gap
    /// ```
    pub fn from_id(id: &str) -> Result<Model, ModelError> {
        let t = id.trim();
        let bad = |reason: &str| ModelError::InvalidId {
            id: id.to_string(),
            reason: reason.to_string(),
        };
        let up = t.to_ascii_uppercase();
        let bare = up.strip_suffix('*').unwrap_or(&up);
        if let Some((_, g, a, s)) = PAPER_IDS.iter().find(|(p, ..)| *p == bare) {
            let m = Model::new(3, *g, *a, *s).expect("paper IDs are valid models");
            if bare.len() != up.len() && !m.is_collocated() {
                return Err(bad("the star marks collocated models only"));
            }
            return Ok(m);
        }
        if !up.starts_with('N') {
            return Err(bad(
                "expected a paper ID A1..A5, B1, B2, C1..C4 or N{N}-g{gap}-a{act+}.{act-}-s{meas+}.{meas-}",
            ));
        }
        let parts: Vec<&str> = up.split('-').collect();
        if parts.len() != 4 {
            return Err(bad("expected N{N}-g{gap}-a{act+}.{act-}-s{meas+}.{meas-}"));
        }
        let num = |s: &str, prefix: char| -> Result<usize, ModelError> {
            let rest = s
                .strip_prefix(prefix)
                .ok_or_else(|| bad(&format!("expected '{prefix}'")))?;
            if rest.is_empty() || !rest.bytes().all(|b| b.is_ascii_digit()) || rest.len() > 6 {
                return Err(bad(&format!("expected a number after '{prefix}'")));
            }
            rest.parse().map_err(|_| bad("number out of range"))
        };
        let port = |s: &str, prefix: char| -> Result<Port, ModelError> {
            let rest = s
                .strip_prefix(prefix)
                .ok_or_else(|| bad(&format!("expected '{prefix}'")))?;
            let (p, m) = rest
                .split_once('.')
                .ok_or_else(|| bad("expected plus.minus"))?;
            Ok(Port::new(
                num(&format!("X{p}"), 'X')?,
                num(&format!("X{m}"), 'X')?,
            ))
        };
        let n = num(parts[0], 'N')?;
        let gap = num(parts[1], 'G')?;
        let act = port(parts[2], 'A')?;
        let meas = port(parts[3], 'S')?;
        Model::new(n, gap, act, meas)
    }

    /// The model obtained from this one by swapping actuator and sensor.
    /// Its transfer function is the same (reciprocity: the matrices are
    /// symmetric), but it is a different model.
    pub fn reciprocal(&self) -> Model {
        Model {
            n: self.n,
            gap: self.gap,
            act: self.meas,
            meas: self.act,
        }
    }

    /// The same chain and actuator read by another sensor: same `N`, gap
    /// and actuator, sensor `sensor`, validated by rule (1) like
    /// [`Model::new`]. One chain with several sensors is a
    /// [`SensorSet`](crate::sensors::SensorSet).
    ///
    /// ```
    /// use mms::{Model, Port};
    /// let a2 = Model::from_id("A2")?; // force on m1, position of m2
    /// assert_eq!(a2.with_sensor(Port::new(3, 0))?.name(), "A3");
    /// let b2 = Model::from_id("B2")?; // gap 1
    /// assert!(b2.with_sensor(Port::new(1, 0)).is_err()); // meas+ = 1 <= gap
    /// # Ok::<(), mms::ModelError>(())
    /// ```
    pub fn with_sensor(&self, sensor: Port) -> Result<Model, ModelError> {
        Model::new(self.n, self.gap, self.act, sensor)
    }

    /// The renumbered model under the reversal of the free part: mass
    /// `gap + k` becomes mass `N + 1 - k` (for `k = 1 ..= N - gap`), the
    /// grounded part `0 ..= gap` stays. For `gap = 0` this reverses the whole
    /// chain. It is the only non-trivial renumbering of a chain with one gap
    /// (see [`Model::renumber`]).
    pub fn mirrored(&self) -> Model {
        let f = |i: usize| self.mirrored_mass(i);
        Model {
            n: self.n,
            gap: self.gap,
            act: Port::new(f(self.act.plus), self.act.minus),
            meas: Port::new(f(self.meas.plus), self.meas.minus),
        }
    }

    /// The number in the [`Model::mirrored`] model of mass `i` (0: the
    /// ground); the mirror is an involution, so this also maps back.
    pub fn mirrored_mass(&self, i: usize) -> usize {
        if i > self.gap {
            self.n + self.gap + 1 - i
        } else {
            i
        }
    }

    /// Applies a renumbering of the masses: `perm[i]` is the new number of
    /// mass `i` (`perm[0]` must be 0, the ground, and `perm` a permutation of
    /// `0 ..= N`). Returns the renumbered model when the relabelled springs
    /// again form a chain ground - m1 - ... - mN with one gap (springs,
    /// actuator and sensor are carried along), `None` otherwise.
    ///
    /// ```
    /// use mms::Model;
    /// let a2 = Model::from_id("A2").unwrap(); // act (1,0), sensor (2,0)
    /// let r = a2.renumber(&[0, 3, 2, 1]).unwrap(); // reverse the chain
    /// assert_eq!(r.id(), "N3-g0-a3.0-s2.0");
    /// assert_eq!(a2.renumber(&[0, 2, 1, 3]), None); // springs 2-1, 1-3: not a chain
    /// ```
    pub fn renumber(&self, perm: &[usize]) -> Option<Model> {
        let n = self.n;
        if perm.len() != n + 1 || perm[0] != 0 {
            return None;
        }
        let mut seen = vec![false; n + 1];
        for &p in perm {
            if p > n || seen[p] {
                return None;
            }
            seen[p] = true;
        }
        // Image of the spring set, as sorted pairs.
        let mut links: Vec<(usize, usize)> = (0..n)
            .filter(|&i| self.has_link(i))
            .map(|i| {
                let (a, b) = (perm[i], perm[i + 1]);
                (a.min(b), a.max(b))
            })
            .collect();
        links.sort_unstable();
        // The only chain with one gap that has this spring set.
        let gap = (0..n).find(|&g| {
            let want: Vec<(usize, usize)> =
                (0..n).filter(|&i| i != g).map(|i| (i, i + 1)).collect();
            want == links
        })?;
        let map = |p: Port| Port::new(perm[p.plus], perm[p.minus]);
        Model::new(n, gap, map(self.act), map(self.meas)).ok()
    }

    /// Diagonal mass matrix `M = diag(m1, ..., mN)`.
    pub fn mass_matrix(&self) -> Vec<Vec<Poly>> {
        let n = self.n;
        let mut m = vec![vec![Poly::zero(); n]; n];
        for (i, row) in m.iter_mut().enumerate() {
            row[i] = Poly::var(&mass_name(i + 1));
        }
        m
    }

    fn link_matrix(&self, name: fn(usize) -> String) -> Vec<Vec<Poly>> {
        let n = self.n;
        let mut k = vec![vec![Poly::zero(); n]; n];
        for i in (0..n).filter(|&i| self.has_link(i)) {
            let c = Poly::var(&name(i));
            // Link between node i and node i+1 (node 0 = ground, dropped).
            k[i][i] = &k[i][i] + &c;
            if i >= 1 {
                k[i - 1][i - 1] = &k[i - 1][i - 1] + &c;
                k[i - 1][i] = &k[i - 1][i] - &c;
                k[i][i - 1] = &k[i][i - 1] - &c;
            }
        }
        k
    }

    /// Stiffness matrix `C` (symmetric, tridiagonal): `C[i][i]` is the sum of
    /// the springs at mass `i+1`, `C[i][i+1] = -c_{i+1,i+2}`.
    ///
    /// ```
    /// let b = mms::Model::from_id("B1").unwrap();
    /// let c: Vec<Vec<String>> = b.stiffness_matrix().iter()
    ///     .map(|r| r.iter().map(|p| p.to_string()).collect()).collect();
    /// assert_eq!(c, [["c1", "0", "0"], ["0", "c23", "-c23"], ["0", "-c23", "c23"]]);
    /// ```
    pub fn stiffness_matrix(&self) -> Vec<Vec<Poly>> {
        self.link_matrix(spring_name)
    }

    /// Damping matrix `D`, built like [`Model::stiffness_matrix`] from the
    /// dampers.
    pub fn damping_matrix(&self) -> Vec<Vec<Poly>> {
        self.link_matrix(damper_name)
    }

    fn port_vector(&self, p: Port) -> Vec<i64> {
        let mut v = vec![0; self.n];
        v[p.plus - 1] += 1;
        if p.minus > 0 {
            v[p.minus - 1] -= 1;
        }
        v
    }

    /// Input vector `b`: +1 at `n_act+`, -1 at `n_act-` (the ground entry is
    /// dropped), so the generalised forces are `b * F`.
    ///
    /// ```
    /// assert_eq!(mms::Model::from_id("C4").unwrap().input_vector(), [0, -1, 1]);
    /// ```
    pub fn input_vector(&self) -> Vec<i64> {
        self.port_vector(self.act)
    }

    /// Output vector `c`: the sensor reads `c^T x = x_{meas+} - x_{meas-}`.
    pub fn output_vector(&self) -> Vec<i64> {
        self.port_vector(self.meas)
    }
}

impl fmt::Display for Model {
    /// The generic ID ([`Model::id`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.id())
    }
}

impl FromStr for Model {
    type Err = ModelError;
    /// Same as [`Model::from_id`].
    fn from_str(s: &str) -> Result<Model, ModelError> {
        Model::from_id(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rule1_rejections() {
        let p = Port::new;
        assert!(Model::new(3, 3, p(3, 0), p(3, 0)).is_err()); // gap = N
        assert!(Model::new(3, 1, p(2, 2), p(2, 1)).is_err()); // act- > gap
        assert!(Model::new(3, 1, p(4, 1), p(2, 1)).is_err()); // act+ > N
        assert!(Model::new(3, 1, p(2, 1), p(1, 0)).is_err()); // meas+ <= gap
        assert_eq!(
            Model::new(MAX_MASSES + 1, 0, p(1, 0), p(1, 0)),
            Err(ModelError::TooManyMasses {
                n: MAX_MASSES + 1,
                max: MAX_MASSES
            })
        );
        assert!(Model::new(MAX_MASSES, 0, p(1, 0), p(1, 0)).is_ok());
    }

    #[test]
    fn parameter_lists() {
        let c1 = Model::from_id("C1").unwrap();
        assert_eq!(
            c1.parameters(),
            ["m1", "m2", "m3", "c1", "c12", "d1", "d12"]
        );
        let one = Model::new(1, 0, Port::new(1, 0), Port::new(1, 0)).unwrap();
        assert_eq!(one.parameters(), ["m1"]);
        assert_eq!(spring_name(8), "c89");
        assert_eq!(spring_name(10), "c10_11");
    }

    #[test]
    fn ids_parse_and_reject() {
        for (id, ..) in PAPER_IDS {
            let m = Model::from_id(id).unwrap();
            assert_eq!(m.paper_id(), Some(id));
            assert_eq!(Model::from_id(&id.to_lowercase()).unwrap(), m);
            assert_eq!(Model::from_id(&m.id()).unwrap(), m);
            assert_eq!(m.id().parse::<Model>().unwrap(), m);
        }
        assert!(Model::from_id("A1*").is_ok());
        assert!(Model::from_id("A2*").is_err());
        for bad in [
            "",
            "N3",
            "N3-g0-a1-s1.0",
            "N3-g0-a1.0-s1.x",
            "X3-g0-a1.0-s1.0",
            "N9-g0-a1.0-s1.0",
        ] {
            assert!(Model::from_id(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn serde_roundtrip_validates() {
        let m = Model::from_id("B2").unwrap();
        let j = serde_json::to_string(&m).unwrap();
        assert_eq!(serde_json::from_str::<Model>(&j).unwrap(), m);
        let bad = r#"{"n":3,"gap":1,"act":{"plus":1,"minus":0},"meas":{"plus":2,"minus":1}}"#;
        assert!(serde_json::from_str::<Model>(bad).is_err());
    }

    #[test]
    fn matrices_of_a_gap0_chain() {
        let a = Model::from_id("A1").unwrap();
        let s = |m: Vec<Vec<Poly>>| -> Vec<Vec<String>> {
            m.iter()
                .map(|r| r.iter().map(|p| p.to_string()).collect())
                .collect()
        };
        assert_eq!(
            s(a.stiffness_matrix()),
            [
                ["c12", "-c12", "0"],
                ["-c12", "c12 + c23", "-c23"],
                ["0", "-c23", "c23"]
            ]
        );
        assert_eq!(s(a.damping_matrix())[1][1], "d12 + d23");
        assert_eq!(s(a.mass_matrix())[2], ["0", "0", "m3"]);
        assert_eq!(a.input_vector(), [1, 0, 0]);
        assert_eq!(Model::from_id("A5").unwrap().output_vector(), [0, 0, 1]);
    }
}
