//! Closed intervals of rationals, and the range of a polynomial over a box
//! of them.
//!
//! Every operation is exact: an interval's ends are rationals, and the
//! result of an operation contains every value the operation takes on its
//! operands' intervals. This is what a proof that holds for *all* points of
//! a box needs (Krawczyk's existence test, a root count that holds for
//! every point near an algebraic one), where `f64` interval arithmetic
//! would need outward rounding to be sound.

use crate::poly::Poly;
use crate::rat::Rat;
use std::collections::BTreeMap;
use std::fmt;
use std::ops::{Add, Mul, Neg, Sub};

/// The closed interval `[lo, hi]` of rationals, `lo <= hi`.
///
/// ```
/// use poly::{Rat, RatInterval};
/// let x = RatInterval::new(Rat::from(-1), Rat::from(2)).unwrap();
/// let y = RatInterval::point(Rat::from(3));
/// assert_eq!((&x * &y).to_string(), "[-3, 6]");
/// assert_eq!(x.pow(2).to_string(), "[0, 4]"); // not [-2, 4]: the even power
/// assert_eq!(x.sign(), None);
/// assert_eq!((&x + &y).sign(), Some(1));
/// ```
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct RatInterval {
    lo: Rat,
    hi: Rat,
}

impl RatInterval {
    /// `[lo, hi]`; `None` if `lo > hi`.
    pub fn new(lo: Rat, hi: Rat) -> Option<RatInterval> {
        (lo <= hi).then_some(RatInterval { lo, hi })
    }

    /// The one-point interval `[x, x]`.
    pub fn point(x: Rat) -> RatInterval {
        RatInterval {
            lo: x.clone(),
            hi: x,
        }
    }

    /// `[c - r, c + r]` for `r >= 0`; `None` if `r < 0`.
    pub fn around(c: &Rat, r: &Rat) -> Option<RatInterval> {
        RatInterval::new(c - r, c + r)
    }

    /// The lower end.
    pub fn lo(&self) -> &Rat {
        &self.lo
    }

    /// The upper end.
    pub fn hi(&self) -> &Rat {
        &self.hi
    }

    /// The midpoint.
    pub fn midpoint(&self) -> Rat {
        &(&self.lo + &self.hi) / &Rat::from(2)
    }

    /// `hi - lo`.
    pub fn width(&self) -> Rat {
        &self.hi - &self.lo
    }

    /// `+1` if every point is positive, `-1` if every point is negative,
    /// `None` if the interval holds zero.
    pub fn sign(&self) -> Option<i32> {
        if self.lo.signum() > 0 {
            Some(1)
        } else if self.hi.signum() < 0 {
            Some(-1)
        } else {
            None
        }
    }

    /// Whether `x` lies in the interval.
    pub fn contains(&self, x: &Rat) -> bool {
        &self.lo <= x && x <= &self.hi
    }

    /// Whether this interval lies in the interior of `other`
    /// (`other.lo < lo` and `hi < other.hi`).
    pub fn inside(&self, other: &RatInterval) -> bool {
        other.lo < self.lo && self.hi < other.hi
    }

    /// The interval scaled by `c` (the ends swap for a negative `c`).
    pub fn scale(&self, c: &Rat) -> RatInterval {
        let (a, b) = (&self.lo * c, &self.hi * c);
        if c.signum() >= 0 {
            RatInterval { lo: a, hi: b }
        } else {
            RatInterval { lo: b, hi: a }
        }
    }

    /// The `e`-th power: every `x^e` for `x` in the interval (so an even
    /// power of an interval around zero starts at zero).
    pub fn pow(&self, e: u32) -> RatInterval {
        if e == 0 {
            return RatInterval::point(Rat::ONE);
        }
        let (a, b) = (self.lo.pow(e as i32), self.hi.pow(e as i32));
        if e % 2 == 1 || self.lo.signum() >= 0 {
            RatInterval { lo: a, hi: b }
        } else if self.hi.signum() <= 0 {
            RatInterval { lo: b, hi: a }
        } else {
            RatInterval {
                lo: Rat::ZERO,
                hi: a.max(b),
            }
        }
    }
}

impl Add for &RatInterval {
    type Output = RatInterval;
    fn add(self, o: &RatInterval) -> RatInterval {
        RatInterval {
            lo: &self.lo + &o.lo,
            hi: &self.hi + &o.hi,
        }
    }
}

impl Sub for &RatInterval {
    type Output = RatInterval;
    fn sub(self, o: &RatInterval) -> RatInterval {
        RatInterval {
            lo: &self.lo - &o.hi,
            hi: &self.hi - &o.lo,
        }
    }
}

impl Mul for &RatInterval {
    type Output = RatInterval;
    fn mul(self, o: &RatInterval) -> RatInterval {
        let products = [
            &self.lo * &o.lo,
            &self.lo * &o.hi,
            &self.hi * &o.lo,
            &self.hi * &o.hi,
        ];
        let lo = products.iter().min().cloned().unwrap_or(Rat::ZERO);
        let hi = products.iter().max().cloned().unwrap_or(Rat::ZERO);
        RatInterval { lo, hi }
    }
}

impl Neg for &RatInterval {
    type Output = RatInterval;
    fn neg(self) -> RatInterval {
        RatInterval {
            lo: -&self.hi,
            hi: -&self.lo,
        }
    }
}

impl fmt::Display for RatInterval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}, {}]", self.lo, self.hi)
    }
}

impl fmt::Debug for RatInterval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl Poly {
    /// An interval holding every value of the polynomial on the box
    /// `ranges` (each variable's interval): the sum over the terms of the
    /// coefficient times the product of the variables' powers, in interval
    /// arithmetic. Exact ends, so the enclosure is sound; it is tight
    /// where the terms do not cancel, and its excess shrinks with the
    /// box's width. `Err` names a variable the box does not give.
    ///
    /// ```
    /// use poly::{Poly, Rat, RatInterval};
    /// use std::collections::BTreeMap;
    /// let p: Poly = "x*y - 2*x + 1".parse().unwrap();
    /// let r = |a: i64, b: i64| RatInterval::new(Rat::from(a), Rat::from(b)).unwrap();
    /// let range = p.enclose(&BTreeMap::from([("x".into(), r(1, 2)), ("y".into(), r(3, 4))])).unwrap();
    /// assert_eq!(range.to_string(), "[0, 7]"); // x*y in [3, 8], -2*x in [-4, -2]
    /// ```
    pub fn enclose(&self, ranges: &BTreeMap<String, RatInterval>) -> Result<RatInterval, String> {
        let vars: Vec<&RatInterval> = self
            .vars()
            .iter()
            .map(|v| ranges.get(v).ok_or_else(|| v.clone()))
            .collect::<Result<_, _>>()?;
        let mut sum = RatInterval::point(Rat::ZERO);
        for t in self.terms() {
            let mut m = RatInterval::point(t.coef.clone());
            for (x, &e) in vars.iter().zip(&t.exps) {
                if e > 0 {
                    m = &m * &x.pow(e);
                }
            }
            sum = &sum + &m;
        }
        Ok(sum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(a: i64, b: i64) -> Rat {
        &Rat::from(a) / &Rat::from(b)
    }

    fn iv(a: Rat, b: Rat) -> RatInterval {
        RatInterval::new(a, b).unwrap()
    }

    #[test]
    fn products_take_the_extreme_corners() {
        let x = iv(r(-2, 1), r(1, 1));
        let y = iv(r(-3, 1), r(-1, 1));
        assert_eq!(&x * &y, iv(r(-3, 1), r(6, 1)));
        assert_eq!(&x - &y, iv(r(-1, 1), r(4, 1)));
        assert_eq!(-&x, iv(r(-1, 1), r(2, 1)));
        assert_eq!(x.scale(&r(-1, 2)), iv(r(-1, 2), r(1, 1)));
        assert_eq!(y.pow(2), iv(r(1, 1), r(9, 1)));
        assert_eq!(y.pow(3), iv(r(-27, 1), r(-1, 1)));
        assert!(iv(r(1, 3), r(1, 2)).inside(&iv(r(0, 1), r(1, 1))));
        assert!(!iv(r(0, 1), r(1, 2)).inside(&iv(r(0, 1), r(1, 1))));
        assert!(RatInterval::new(r(1, 1), r(0, 1)).is_none());
    }

    #[test]
    fn an_enclosure_holds_the_values_at_every_point_sampled() {
        // Values at a grid of points of the box, computed by exact
        // evaluation (another route), all inside the enclosure.
        let p: Poly = "3*x^2*y - 5*x*y^3 + 7*z - x*z^2 + 11".parse().unwrap();
        let b = BTreeMap::from([
            ("x".to_string(), iv(r(-1, 2), r(3, 2))),
            ("y".to_string(), iv(r(1, 3), r(2, 1))),
            ("z".to_string(), iv(r(-2, 1), r(-1, 5))),
        ]);
        let e = p.enclose(&b).unwrap();
        for i in 0..=4 {
            for j in 0..=4 {
                for k in 0..=4 {
                    let at = |v: &str, t: i64| {
                        let w = &b[v];
                        w.lo() + &(&w.width() * &r(t, 4))
                    };
                    let pt = BTreeMap::from([
                        ("x".to_string(), at("x", i)),
                        ("y".to_string(), at("y", j)),
                        ("z".to_string(), at("z", k)),
                    ]);
                    assert!(e.contains(&p.eval(&pt).unwrap()), "{pt:?}");
                }
            }
        }
        assert_eq!(p.enclose(&BTreeMap::new()), Err("x".to_string()));
    }

    #[test]
    fn a_narrow_box_gives_a_narrow_enclosure() {
        // Around (1, 2), radius 2^-40: the width is twice the radius times
        // the sum of the terms' gradients' l1 norms (3 + 6 + 4), not more.
        let p: Poly = "x^3 - 2*x*y + y^2".parse().unwrap();
        let eps = Rat::from(2).pow(-40);
        let b = BTreeMap::from([
            (
                "x".to_string(),
                RatInterval::around(&Rat::ONE, &eps).unwrap(),
            ),
            (
                "y".to_string(),
                RatInterval::around(&Rat::from(2), &eps).unwrap(),
            ),
        ]);
        let e = p.enclose(&b).unwrap();
        assert!(e.contains(&Rat::ONE)); // 1 - 4 + 4
        assert!(e.width() <= &Rat::from(27) * &eps, "{e}");
    }
}
