//! The range of every value a model holds that a motion system can have.
//!
//! A value outside its range is a typo, a slip of units or a degenerate
//! fit, never a machine: a mass of `5e-324` kg, a delay of `1e300` s. Model
//! files ([`crate::model_file`]) refuse such values with the line that
//! holds them, and the fits of `ident` keep their parameters inside, so
//! every model `mms` writes reads back.
//!
//! Bounds are in SI units (kg, N/m, N s/m, N, m, s, Hz; for rotary motion
//! kg m^2, N m/rad, N m s/rad, N m, rad). A model fitted to an FRF in the
//! recording's units (volts, counts) holds values in those units; the
//! ranges span 24 decades, so realistic actuator and sensor constants keep
//! them inside. The sample rates and frequencies of recordings have their
//! ranges in the `frf` crate (`frf::recording::SAMPLE_RATE_RANGE_HZ`,
//! `frf::MAX_FREQUENCY_HZ`); docs/identification.md lists them all.
//!
//! | quantity | range | zero allowed |
//! |---|---|---|
//! | mass (`m1`, ...) | 1e-12 to 1e12 | no |
//! | stiffness (`c1`, `c12`, ...) | 1e-12 to 1e12 | no |
//! | damping (`d1`, `d12`, ...), viscous friction | 1e-12 to 1e12 | yes |
//! | `gain` (either sign) | 1e-12 to 1e12 in magnitude | no |
//! | time delay | 1e-12 to 1e3 s | yes |
//! | low-pass corner | 1e-6 to 1e12 Hz | no |
//! | gain error factor | 1e-6 to 1e6 | no |
//! | loss factor (hysteretic damping) | 1e-12 to 10 | yes |
//! | Coulomb friction, offset force (either sign) | 1e-12 to 1e12 in magnitude | yes |
//! | pre-sliding stiffness | 1e-12 to 1e15 | yes |
//! | backlash gap | 1e-12 to 1e3 | yes |
//!
//! ```
//! use mms::ranges::{self, MASS};
//! assert!(MASS.check(0.5).is_ok());
//! let err = MASS.check(5e-324).unwrap_err();
//! assert_eq!(err.to_string(), "5e-324 is outside the range of a mass (1e-12 to 1e12)");
//! assert_eq!(ranges::of_parameter("d12").check(0.0), Ok(()));
//! assert_eq!(ranges::of_parameter("c23").quantity, "stiffness");
//! ```

use std::fmt;

/// The values a quantity may take: `min..=max` in magnitude, zero when
/// `zero` (the effect switched off), negative values when `signed`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicalRange {
    /// What the value is, in the user's words (`"mass"`).
    pub quantity: &'static str,
    /// The least non-zero magnitude.
    pub min: f64,
    /// The greatest magnitude.
    pub max: f64,
    /// Zero is allowed (an effect or a damper switched off).
    pub zero: bool,
    /// Negative values are allowed (a gain, a force).
    pub signed: bool,
}

/// Why a value is outside its [`PhysicalRange`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RangeError {
    /// Not a finite number.
    #[error("{} is not a finite {quantity}", shown(*.value))]
    NotFinite {
        /// The quantity.
        quantity: &'static str,
        /// The value.
        value: f64,
    },
    /// Negative where only positive values are allowed.
    #[error("a {quantity} must be {rule}, not {}", shown(*.value))]
    Negative {
        /// The quantity.
        quantity: &'static str,
        /// The value.
        value: f64,
        /// `"positive"` or `"non-negative"`.
        rule: &'static str,
    },
    /// Zero where zero is not allowed.
    #[error("a {quantity} must not be zero")]
    Zero {
        /// The quantity.
        quantity: &'static str,
    },
    /// Magnitude below `min` or above `max`.
    #[error("{} is outside the range of a {quantity} ({min:e} to {max:e})", shown(*.value))]
    Outside {
        /// The quantity.
        quantity: &'static str,
        /// The value.
        value: f64,
        /// The range's least non-zero magnitude.
        min: f64,
        /// The range's greatest magnitude.
        max: f64,
    },
}

impl PhysicalRange {
    /// `Ok` when `x` is a value of this quantity.
    pub fn check(&self, x: f64) -> Result<(), RangeError> {
        let quantity = self.quantity;
        if !x.is_finite() {
            return Err(RangeError::NotFinite { quantity, value: x });
        }
        if x == 0.0 {
            return if self.zero {
                Ok(())
            } else {
                Err(RangeError::Zero { quantity })
            };
        }
        if x < 0.0 && !self.signed {
            let rule = if self.zero {
                "non-negative"
            } else {
                "positive"
            };
            return Err(RangeError::Negative {
                quantity,
                value: x,
                rule,
            });
        }
        if x.abs() < self.min || x.abs() > self.max {
            return Err(RangeError::Outside {
                quantity,
                value: x,
                min: self.min,
                max: self.max,
            });
        }
        Ok(())
    }

    /// True when [`PhysicalRange::check`] accepts `x`.
    pub fn contains(&self, x: f64) -> bool {
        self.check(x).is_ok()
    }

    /// The magnitude bounds as natural logarithms, for fits that work on
    /// `ln |x|`.
    pub fn ln_bounds(&self) -> (f64, f64) {
        (self.min.ln(), self.max.ln())
    }

    /// The nearest value of the range to a finite `x` of the right sign:
    /// its magnitude clamped to `min..=max` (zero stays zero where zero is
    /// allowed).
    pub fn clamp(&self, x: f64) -> f64 {
        if x == 0.0 && self.zero {
            return 0.0;
        }
        let sign = if x < 0.0 && self.signed { -1.0 } else { 1.0 };
        sign * x.abs().clamp(self.min, self.max)
    }
}

impl fmt::Display for PhysicalRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:e} to {:e}", self.min, self.max)
    }
}

/// A value as a user reads it: plain between 1e-4 and 1e6, else in
/// scientific notation (never hundreds of digits).
fn shown(x: f64) -> String {
    if x == 0.0 || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

const fn range(quantity: &'static str, min: f64, max: f64, zero: bool) -> PhysicalRange {
    PhysicalRange {
        quantity,
        min,
        max,
        zero,
        signed: false,
    }
}

/// A mass or a moment of inertia (kg, kg m^2).
pub const MASS: PhysicalRange = range("mass", 1e-12, 1e12, false);
/// A spring's stiffness (N/m, N m/rad).
pub const STIFFNESS: PhysicalRange = range("stiffness", 1e-12, 1e12, false);
/// A damper (N s/m, N m s/rad); zero is an undamped link.
pub const DAMPING: PhysicalRange = range("damping", 1e-12, 1e12, true);
/// The signed product of the actuator and sensor constants.
pub const GAIN: PhysicalRange = PhysicalRange {
    signed: true,
    ..range("gain", 1e-12, 1e12, false)
};
/// A dead time (s).
pub const TIME_DELAY: PhysicalRange = range("time delay", 1e-12, 1e3, true);
/// The corner of a first-order low-pass (Hz).
pub const CORNER_FREQUENCY: PhysicalRange = range("corner frequency", 1e-6, 1e12, false);
/// A gain error factor (1 is none).
pub const GAIN_FACTOR: PhysicalRange = range("gain factor", 1e-6, 1e6, false);
/// The loss factor of hysteretic (structural) damping.
pub const LOSS_FACTOR: PhysicalRange = range("loss factor", 1e-12, 10.0, true);
/// Viscous friction to ground (N s/m, N m s/rad).
pub const VISCOUS_FRICTION: PhysicalRange = range("viscous friction", 1e-12, 1e12, true);
/// Coulomb friction (N, N m).
pub const COULOMB_FRICTION: PhysicalRange = range("Coulomb friction", 1e-12, 1e12, true);
/// The stiffness of pre-sliding friction (N/m, N m/rad).
pub const PRE_SLIDING_STIFFNESS: PhysicalRange = range("pre-sliding stiffness", 1e-12, 1e15, true);
/// The total play of a backlash (m, rad).
pub const BACKLASH_GAP: PhysicalRange = range("backlash gap", 1e-12, 1e3, true);
/// A constant force bias (N, N m), either sign.
pub const OFFSET_FORCE: PhysicalRange = PhysicalRange {
    signed: true,
    ..range("offset force", 1e-12, 1e12, true)
};

/// The range of a model parameter by its name: `m..` a mass, `c..` a
/// stiffness, `d..` a damper.
pub fn of_parameter(name: &str) -> &'static PhysicalRange {
    match name.as_bytes().first() {
        Some(b'm') => &MASS,
        Some(b'c') => &STIFFNESS,
        _ => &DAMPING,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_inclusive_and_signs_follow_the_quantity() {
        assert!(MASS.contains(1e-12) && MASS.contains(1e12));
        assert!(!MASS.contains(0.99e-12) && !MASS.contains(1.01e12));
        assert!(!MASS.contains(-1.0) && !MASS.contains(0.0) && !MASS.contains(f64::NAN));
        assert!(DAMPING.contains(0.0) && !DAMPING.contains(-0.1));
        assert!(GAIN.contains(-3.0) && !GAIN.contains(0.0));
        assert!(OFFSET_FORCE.contains(-3.0) && OFFSET_FORCE.contains(0.0));
        assert!(!TIME_DELAY.contains(1e300) && !TIME_DELAY.contains(f64::INFINITY));
        assert_eq!(GAIN.clamp(-1e20), -1e12);
        assert_eq!(MASS.clamp(4.8e-114), 1e-12);
        assert_eq!(DAMPING.clamp(0.0), 0.0);
        assert!(matches!(
            MASS.check(-2.0),
            Err(RangeError::Negative {
                rule: "positive",
                ..
            })
        ));
    }
}
