//! FRF types: the order of antiresonances (`A`) and resonances (`R`) of an
//! undamped transfer function, and the exact classification of a TF at a
//! rational parameter point.

use poly::{interleave_roots, FieldElem, FieldPoly, Poly, Rat, RealField, SharedRoot, UPoly};
use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

/// Antiresonance (zero of the numerator) or resonance (zero of the
/// denominator), in `Omega = omega^2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Feature {
    /// A zero of `num`: an antiresonance.
    Antiresonance,
    /// A zero of `den`: a resonance.
    Resonance,
}

/// One token of an FRF type: a feature and how many roots coincide there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Token {
    /// Antiresonance or resonance.
    pub feature: Feature,
    /// `k` of `A^k` / `R^k`: the multiplicity of the root.
    pub multiplicity: u32,
}

impl Token {
    /// True for an antiresonance of multiplicity `m` (`A^m`).
    pub(crate) fn is_zero_of(&self, m: u32) -> bool {
        self.feature == Feature::Antiresonance && self.multiplicity == m
    }
}

/// The type of an undamped FRF (the paper's Tab. 3 vocabulary): the distinct
/// positive real zeros and poles of the reduced TF in increasing frequency,
/// with multiplicities, and whether zeros off the positive real axis exist
/// (`(nm)`, non-minimum phase in the paper's sense).
///
/// ```
/// use mms::analysis::FrfType;
/// let t: FrfType = "A^2RR".parse()?;
/// assert_eq!(t.resonances(), 2);
/// assert_eq!(t.antiresonances(), 2);
/// assert_eq!(t.to_string(), "A^2RR");
/// assert_eq!("RR (nm)".parse::<FrfType>()?.nonminimum_phase, true);
/// assert_eq!("C".parse::<FrfType>()?.tokens.len(), 0);
/// # Ok::<(), mms::analysis::ParseFrfTypeError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrfType {
    /// Tokens in increasing frequency.
    pub tokens: Vec<Token>,
    /// Zeros off the positive real axis (complex, negative or zero).
    pub nonminimum_phase: bool,
}

/// A string that is not an FRF type.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("not an FRF type: {0:?} (expected tokens A, R, A^k, R^k or C, optionally followed by \" (nm)\")")]
pub struct ParseFrfTypeError(pub String);

impl FrfType {
    /// Number of poles counted with multiplicity.
    pub fn resonances(&self) -> u32 {
        self.count(Feature::Resonance)
    }

    /// Number of positive real zeros counted with multiplicity.
    pub fn antiresonances(&self) -> u32 {
        self.count(Feature::Antiresonance)
    }

    /// True when every token is simple and the type shows all `poles`
    /// poles of its model: what a point with every root simple and none
    /// cancelled shows, and what every other type is a limit of.
    ///
    /// ```
    /// use mms::analysis::FrfType;
    /// let t = |s: &str| s.parse::<FrfType>().unwrap();
    /// assert!(t("ARAR").is_generic(2));
    /// assert!(!t("ARAR").is_generic(3)); // a pole cancelled
    /// assert!(!t("A^2RR").is_generic(2)); // a double zero
    /// ```
    pub fn is_generic(&self, poles: u32) -> bool {
        self.resonances() == poles && self.tokens.iter().all(|k| k.multiplicity == 1)
    }

    fn count(&self, f: Feature) -> u32 {
        self.tokens
            .iter()
            .filter(|t| t.feature == f)
            .map(|t| t.multiplicity)
            .sum()
    }

    /// True when antiresonances and resonances alternate and every root is
    /// simple, with no zero off the positive axis: what collocation allows.
    pub fn is_alternating(&self) -> bool {
        !self.nonminimum_phase
            && self.tokens.iter().all(|t| t.multiplicity == 1)
            && self.tokens.windows(2).all(|w| w[0].feature != w[1].feature)
    }

    /// `(AR)^k`, `k >= 0` (`C` for `k = 0`): what a receptance with a
    /// rigid-body pole and positive modal residues shows, since it rises
    /// from minus to plus infinity between consecutive poles and stays
    /// negative above the last.
    ///
    /// ```
    /// use mms::analysis::FrfType;
    /// let t = |s: &str| s.parse::<FrfType>().unwrap();
    /// assert!(t("ARAR").is_rigid_body_interlacing());
    /// assert!(t("C").is_rigid_body_interlacing());
    /// assert!(!t("RARA").is_rigid_body_interlacing());
    /// assert!(!t("ARA").is_rigid_body_interlacing());
    /// ```
    pub fn is_rigid_body_interlacing(&self) -> bool {
        self.is_alternating()
            && self.tokens.len().is_multiple_of(2)
            && self
                .tokens
                .first()
                .is_none_or(|t| t.feature == Feature::Antiresonance)
    }

    /// A resonance of multiplicity two or more.
    pub fn has_multiple_resonance(&self) -> bool {
        self.tokens
            .iter()
            .any(|t| t.feature == Feature::Resonance && t.multiplicity > 1)
    }
}

impl fmt::Display for FrfType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.tokens.is_empty() {
            f.write_str("C")?;
        }
        for t in &self.tokens {
            let c = match t.feature {
                Feature::Antiresonance => 'A',
                Feature::Resonance => 'R',
            };
            if t.multiplicity == 1 {
                write!(f, "{c}")?;
            } else {
                write!(f, "{c}^{}", t.multiplicity)?;
            }
        }
        if self.nonminimum_phase {
            f.write_str(" (nm)")?;
        }
        Ok(())
    }
}

impl FromStr for FrfType {
    type Err = ParseFrfTypeError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || ParseFrfTypeError(s.to_string());
        let t = s.trim();
        let (body, nm) = match t.strip_suffix("(nm)") {
            Some(b) => (b.trim_end(), true),
            None => (t, false),
        };
        if body == "C" {
            return Ok(FrfType {
                tokens: Vec::new(),
                nonminimum_phase: nm,
            });
        }
        if body.is_empty() {
            return Err(bad());
        }
        let mut tokens = Vec::new();
        let chars: Vec<char> = body.chars().filter(|c| !c.is_whitespace()).collect();
        let mut i = 0;
        while i < chars.len() {
            let feature = match chars[i] {
                'A' => Feature::Antiresonance,
                'R' => Feature::Resonance,
                _ => return Err(bad()),
            };
            i += 1;
            let mut multiplicity = 1;
            if i < chars.len() && chars[i] == '^' {
                i += 1;
                let start = i;
                while i < chars.len() && chars[i].is_ascii_digit() {
                    i += 1;
                }
                multiplicity = chars[start..i]
                    .iter()
                    .collect::<String>()
                    .parse()
                    .map_err(|_| bad())?;
                if multiplicity < 2 {
                    return Err(bad());
                }
            }
            tokens.push(Token {
                feature,
                multiplicity,
            });
        }
        Ok(FrfType {
            tokens,
            nonminimum_phase: nm,
        })
    }
}

/// A univariate polynomial in `var` over Q as a primitive integer UPoly.
fn univariate(p: &Poly, var: &str) -> Option<UPoly> {
    UPoly::from_poly(p, var).map(|(_, u)| u)
}

/// The FRF type of `num/den` (polynomials in `var` and the parameters) at an
/// exact parameter point: substitute, cancel the common factor (pole-zero
/// cancellation), isolate the real roots exactly and read off the order.
/// `None` when the point leaves a parameter unset or makes `num` or `den`
/// vanish identically.
///
/// ```
/// use mms::analysis::frf_type_at;
/// use poly::{Poly, Rat};
/// use std::collections::BTreeMap;
/// let num: Poly = "c12*c23 - c12*m3*Omega".parse().unwrap();
/// let den: Poly = "(Omega - 1)*(Omega - 3)".parse().unwrap();
/// let p = |m3: i64| BTreeMap::from([("c12".into(), Rat::from(1)), ("c23".into(), Rat::from(2)),
///     ("m3".into(), Rat::from(m3))]);
/// assert_eq!(frf_type_at(&num, &den, "Omega", &p(1)).unwrap().to_string(), "RAR"); // zero at 2
/// assert_eq!(frf_type_at(&num, &den, "Omega", &p(2)).unwrap().to_string(), "R"); // cancels at 1
/// ```
pub fn frf_type_at(
    num: &Poly,
    den: &Poly,
    var: &str,
    point: &BTreeMap<String, Rat>,
) -> Option<FrfType> {
    let n = num.subs_point(point);
    let d = den.subs_point(point);
    let n = univariate(&n, var)?;
    let d = univariate(&d, var)?;
    frf_type_of(&n, &d)
}

/// The FRF type of a univariate `num/den` over Z (see [`frf_type_at`]).
pub fn frf_type_of(num: &UPoly, den: &UPoly) -> Option<FrfType> {
    if num.is_zero() || den.is_zero() {
        return None;
    }
    let g = num.gcd(den);
    let n = num.div_exact(&g)?;
    let d = den.div_exact(&g)?;
    let roots = interleave_roots(&[n.clone(), d.clone()]);
    Some(type_of_roots(&roots, n.degree().unwrap_or(0)))
}

/// The type read off the interleaved roots of a reduced `num/den` (no
/// root shared), `zeros` the degree of the reduced numerator.
fn type_of_roots(roots: &[SharedRoot], zeros: usize) -> FrfType {
    let mut tokens = Vec::new();
    let mut positive_zeros = 0usize;
    for r in roots.iter().filter(|r| r.is_positive()) {
        let (mn, md) = (r.multiplicities[0], r.multiplicities[1]);
        let (feature, multiplicity) = if mn > 0 {
            positive_zeros += mn as usize;
            (Feature::Antiresonance, mn)
        } else {
            (Feature::Resonance, md)
        };
        tokens.push(Token {
            feature,
            multiplicity,
        });
    }
    let nonminimum_phase = zeros > positive_zeros;
    FrfType {
        tokens,
        nonminimum_phase,
    }
}

/// The FRF type of `num/den` at a point whose coordinates lie in the real
/// number field `field` (see [`frf_type_at`]): substitute, cancel the
/// common factor over the field, isolate the real roots exactly and read
/// off the order. `None` when the point leaves a parameter unset or makes
/// `num` or `den` vanish identically.
///
/// ```
/// use mms::analysis::frf_type_at_algebraic;
/// use poly::{Poly, RealField, UPoly};
/// use std::collections::BTreeMap;
/// // m3 = sqrt(2): the zero c23/m3 = sqrt(2) between the poles 1 and 3.
/// let k = &RealField::real_roots_of(&UPoly::from_i64s(&[-2, 0, 1]))[1];
/// let num: Poly = "c23 - m3*Omega".parse().unwrap();
/// let den: Poly = "(Omega - 1)*(Omega - 3)".parse().unwrap();
/// let p = BTreeMap::from([("c23".into(), k.from_rat(&2.into())), ("m3".into(), k.generator())]);
/// assert_eq!(frf_type_at_algebraic(&num, &den, "Omega", k, &p).unwrap().to_string(), "RAR");
/// ```
pub fn frf_type_at_algebraic(
    num: &Poly,
    den: &Poly,
    var: &str,
    field: &RealField,
    point: &BTreeMap<String, FieldElem>,
) -> Option<FrfType> {
    let n = field.univariate(num, var, point).ok()?;
    let d = field.univariate(den, var, point).ok()?;
    frf_type_over(field, &n, &d)
}

/// The FRF type of a univariate `num/den` over a real number field (see
/// [`frf_type_at_algebraic`]).
pub fn frf_type_over(field: &RealField, num: &FieldPoly, den: &FieldPoly) -> Option<FrfType> {
    if num.is_zero() || den.is_zero() {
        return None;
    }
    let g = field.poly_gcd(num, den);
    let n = field.poly_div_exact(num, &g)?;
    let d = field.poly_div_exact(den, &g)?;
    let roots = field.interleave_roots(&[n.clone(), d]);
    Some(type_of_roots(&roots, n.degree().unwrap_or(0)))
}

/// Every FRF type a TF with a numerator of degree `a` and a denominator of
/// degree `r` in `Omega` could show a priori (real poles assumed, as for
/// every chain model): `k` pole-zero cancellations, any grouping of the
/// remaining poles and of the positive real zeros into coincident roots, in
/// any order, with the other zeros off the positive axis `(nm)`. Sorted by
/// the number of tokens descending, then by the text.
///
/// ```
/// use mms::analysis::candidate_types;
/// let all: Vec<String> = candidate_types(1, 2).iter().map(|t| t.to_string()).collect();
/// assert_eq!(all, ["ARR", "RAR", "RRA", "AR^2", "R^2A", "RR (nm)", "R", "R^2 (nm)"]);
/// ```
pub fn candidate_types(a: u32, r: u32) -> Vec<FrfType> {
    let mut out = Vec::new();
    for k in 0..=a.min(r) {
        let (ap, rp) = (a - k, r - k);
        for rc in compositions(rp) {
            for apos in 0..=ap {
                let nm = apos < ap;
                for ac in compositions(apos) {
                    interleavings(&ac, &rc, &mut Vec::new(), 0, 0, nm, &mut out);
                }
            }
        }
    }
    out.sort_by(|x, y| {
        y.tokens
            .len()
            .cmp(&x.tokens.len())
            .then_with(|| x.nonminimum_phase.cmp(&y.nonminimum_phase))
            .then_with(|| x.to_string().cmp(&y.to_string()))
    });
    out.dedup();
    out
}

/// Ordered compositions of `n` (all ways to write `n` as an ordered sum of
/// positive parts); `[[]]` for 0.
fn compositions(n: u32) -> Vec<Vec<u32>> {
    if n == 0 {
        return vec![Vec::new()];
    }
    let mut out = Vec::new();
    for first in 1..=n {
        for mut rest in compositions(n - first) {
            rest.insert(0, first);
            out.push(rest);
        }
    }
    out
}

fn interleavings(
    a: &[u32],
    r: &[u32],
    acc: &mut Vec<Token>,
    i: usize,
    j: usize,
    nm: bool,
    out: &mut Vec<FrfType>,
) {
    if i == a.len() && j == r.len() {
        out.push(FrfType {
            tokens: acc.clone(),
            nonminimum_phase: nm,
        });
        return;
    }
    if i < a.len() {
        acc.push(Token {
            feature: Feature::Antiresonance,
            multiplicity: a[i],
        });
        interleavings(a, r, acc, i + 1, j, nm, out);
        acc.pop();
    }
    if j < r.len() {
        acc.push(Token {
            feature: Feature::Resonance,
            multiplicity: r[j],
        });
        interleavings(a, r, acc, i, j + 1, nm, out);
        acc.pop();
    }
}

/// A type is written as its text (`A^2RR (nm)`), as in the tables.
impl serde::Serialize for FrfType {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for FrfType {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<FrfType, D::Error> {
        let text = String::deserialize(d)?;
        text.parse()
            .map_err(|e: ParseFrfTypeError| serde::de::Error::custom(e))
    }
}
