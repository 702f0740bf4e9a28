//! [`Poly`] and [`Rat`] in serde formats as their text: `Display` out,
//! `FromStr` in (whose size limits apply, so a hostile file cannot make
//! reading it expand a polynomial without bound).

use crate::{Poly, Rat};
use serde::de::{Deserialize, Deserializer, Error, Visitor};
use serde::ser::{Serialize, Serializer};
use std::fmt;
use std::marker::PhantomData;
use std::str::FromStr;

/// Reads a string and parses it as `T`, naming what was expected.
struct Text<T>(PhantomData<T>, &'static str);

impl<T: FromStr> Visitor<'_> for Text<T>
where
    T::Err: fmt::Display,
{
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{} as a string", self.1)
    }

    fn visit_str<E: Error>(self, s: &str) -> Result<T, E> {
        s.parse()
            .map_err(|e| E::custom(format_args!("not {} ({e}): {s:?}", self.1)))
    }
}

impl Serialize for Poly {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Poly {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Poly, D::Error> {
        d.deserialize_str(Text(PhantomData, "a polynomial"))
    }
}

impl Serialize for Rat {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Rat {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Rat, D::Error> {
        d.deserialize_str(Text(PhantomData, "a rational number"))
    }
}

#[cfg(test)]
mod tests {
    use crate::{Poly, Rat};

    /// Text out and back gives the same value, and a string that is not
    /// one is refused with what was expected.
    #[test]
    fn polynomials_and_rationals_round_trip_as_text() {
        let p: Poly = "c12^2*m1 - 3/7*c23*m2 + 1".parse().unwrap();
        let s = serde_json::to_string(&p).unwrap();
        assert_eq!(s, format!("\"{p}\""));
        assert_eq!(serde_json::from_str::<Poly>(&s).unwrap(), p);
        let r: Rat = "-22/7".parse().unwrap();
        assert_eq!(serde_json::to_string(&r).unwrap(), "\"-22/7\"");
        assert_eq!(serde_json::from_str::<Rat>("\"-22/7\"").unwrap(), r);
        let e = serde_json::from_str::<Poly>("\"m1 +* 2\"").unwrap_err();
        assert!(e.to_string().contains("not a polynomial"), "{e}");
        assert!(serde_json::from_str::<Rat>("3").is_err());
    }
}
