//! Parser for the plain-text polynomial syntax.
//!
//! Grammar: `expr := term (('+'|'-') term)*`, `term := factor (('*'|'/') factor)*`
//! (division only by non-zero constants), `factor := ('-'|'+') factor | atom ('^' uint)?`,
//! `atom := number | identifier | '(' expr ')'`. Numbers are integers or
//! decimals, read exactly.

use crate::poly::Poly;
use crate::rat::Rat;
use std::str::FromStr;

/// Error when parsing a polynomial, with the byte offset where it occurred.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot parse polynomial at byte {offset}: {message}")]
pub struct ParsePolyError {
    /// Byte offset into the input.
    pub offset: usize,
    /// What was wrong there.
    pub message: String,
}

struct Parser<'a> {
    s: &'a [u8],
    pos: usize,
    depth: usize,
}

const MAX_DEPTH: usize = 200;
const MAX_EXPONENT: u32 = 10_000;

/// The largest polynomial a product or power may build, in bits: terms
/// times (coefficient bits + 64 for the exponents), about 16 MiB. Every
/// polynomial of the 8-mass analyses is far below it (some 15 000 terms of
/// small coefficients); `(m1 + m2 + m3 + c12 + c23 + Omega)^10000` would
/// have 1e21 terms.
pub const MAX_EXPANDED_BITS: f64 = (1u64 << 27) as f64;

/// The most work a product or power may take: pairs of terms multiplied,
/// each weighted by `1 + bits / 64` of its coefficients; 2e7 to 4e7 units
/// take a second here, so the limit is under half a second (and under ten
/// with the fuzzer's sanitizers). A size within [`MAX_EXPANDED_BITS`] can
/// still take long to build: `(a + b + 3/2)^203` has 20910 terms, but its
/// squarings multiply some 3e7 pairs of coefficients of hundreds of bits
/// (5e8 units, 14 s).
pub const MAX_EXPANSION_WORK: f64 = 1e7;

/// The largest coefficient a product or power may build, in bits (some
/// 79 000 decimal digits): products of far larger integers take seconds
/// each (`2.66666664666666666668^7668^71` is a coefficient of 7.6e7 bits).
pub const MAX_COEFFICIENT_BITS: f64 = (1u64 << 18) as f64;

/// An upper bound of a polynomial's size: terms, total degree, the bits of
/// its largest coefficient, and its variables.
struct Bound<'p> {
    terms: f64,
    degree: f64,
    bits: f64,
    vars: &'p [String],
}

impl<'p> Bound<'p> {
    fn of(p: &'p Poly) -> Bound<'p> {
        let bits = p
            .terms()
            .iter()
            .map(|t| (t.coef.numer().bits() + t.coef.denom().bits()) as f64)
            .fold(0.0, f64::max);
        Bound {
            terms: p.num_terms() as f64,
            degree: p.total_degree() as f64,
            bits,
            vars: p.vars(),
        }
    }

    /// `ln` of the number of monomials of total degree at most `d` in `v`
    /// variables, `C(v + d, v)`.
    fn ln_monomials(v: usize, d: f64) -> f64 {
        (1..=v).map(|i| ((d + i as f64) / i as f64).ln()).sum()
    }

    /// The size bound (bits) of a result with at most `ln_terms` (natural
    /// log) terms and coefficients of `bits`, in `v` variables up to total
    /// degree `d`.
    fn size(ln_terms: f64, v: usize, d: f64, bits: f64) -> f64 {
        if bits > MAX_COEFFICIENT_BITS {
            // Multiplying such numbers costs more than their size says.
            return f64::INFINITY;
        }
        let ln_t = ln_terms.min(Self::ln_monomials(v, d));
        ln_t.exp() * (bits + 64.0)
    }

    /// The bound of `self * other`.
    fn product(&self, other: &Bound) -> f64 {
        let v = self.vars.len() + other.vars.iter().filter(|x| !self.vars.contains(x)).count();
        let bits = self.bits + other.bits + self.terms.min(other.terms).max(1.0).log2();
        Self::size(
            self.terms.max(1.0).ln() + other.terms.max(1.0).ln(),
            v,
            self.degree + other.degree,
            bits,
        )
    }

    /// The work of `self * other` (see [`MAX_EXPANSION_WORK`]).
    fn product_work(&self, other: &Bound) -> f64 {
        self.terms * other.terms * (1.0 + (self.bits + other.bits) / 64.0)
    }

    /// The work of `self^e` by repeated squaring as [`Poly::pow`] does it,
    /// each power's terms and bits bounded as in [`Bound::power`].
    fn power_work(&self, e: u32) -> f64 {
        let v = self.vars.len();
        // A product of k of the t terms, with repetition: at most C(t - 1 +
        // k, t - 1) distinct ones, and no more than the monomials there are.
        let t = (self.terms.max(1.0) as usize).saturating_sub(1);
        let terms = |k: f64| {
            Self::ln_monomials(t, k)
                .min(Self::ln_monomials(v, k * self.degree))
                .exp()
        };
        let bits = |k: f64| k * (self.bits + self.terms.max(1.0).log2());
        let pair = |a: f64, b: f64| terms(a) * terms(b) * (1.0 + (bits(a) + bits(b)) / 64.0);
        // Exponents of the result so far and of the squared base.
        let (mut work, mut result, mut base, mut e) = (0.0, 0.0, 1.0, e);
        while e > 0 {
            if e & 1 == 1 {
                if result > 0.0 {
                    work += pair(result, base);
                }
                result += base;
            }
            e >>= 1;
            if e > 0 {
                work += pair(base, base);
                base *= 2.0;
            }
        }
        work
    }

    /// The bound of `self^e`.
    fn power(&self, e: u32) -> f64 {
        let e = e as f64;
        let bits = e * (self.bits + self.terms.max(1.0).log2());
        Self::size(
            e * self.terms.max(1.0).ln(),
            self.vars.len(),
            e * self.degree,
            bits,
        )
    }
}

impl<'a> Parser<'a> {
    fn err<T>(&self, msg: impl Into<String>) -> Result<T, ParsePolyError> {
        Err(ParsePolyError {
            offset: self.pos,
            message: msg.into(),
        })
    }

    fn too_large<T>(&self, size_bits: f64) -> Result<T, ParsePolyError> {
        if size_bits.is_infinite() {
            return self.err(format!(
                "the expansion could have a coefficient of more than {MAX_COEFFICIENT_BITS:.1e} bits"
            ));
        }
        self.err(format!(
            "the expanded polynomial could take up to {size_bits:.1e} bits, above the limit of \
             {MAX_EXPANDED_BITS:.1e}"
        ))
    }

    /// Refuses a result with a degree above [`MAX_EXPONENT`] in some
    /// variable: its text could not be read back.
    fn degree_cap(&self, degrees: impl Iterator<Item = u64>) -> Result<(), ParsePolyError> {
        match degrees.max() {
            Some(d) if d > MAX_EXPONENT as u64 => self.err(format!(
                "a degree of {d} in one variable, above {MAX_EXPONENT}"
            )),
            _ => Ok(()),
        }
    }

    fn too_slow<T>(&self, work: f64) -> Result<T, ParsePolyError> {
        self.err(format!(
            "the expansion could take up to {work:.1e} term products, above the limit of \
             {MAX_EXPANSION_WORK:.1e}"
        ))
    }

    fn skip_ws(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.pos).copied()
    }

    fn expr(&mut self) -> Result<Poly, ParsePolyError> {
        let mut parts = vec![self.term()?];
        while let Some(c) = self.peek() {
            match c {
                b'+' => {
                    self.pos += 1;
                    parts.push(self.term()?);
                }
                b'-' => {
                    self.pos += 1;
                    parts.push(-self.term()?);
                }
                _ => break,
            }
        }
        // Pairwise sums: linear merges of balanced sizes, not one long
        // accumulation (quadratic in the number of terms).
        while parts.len() > 1 {
            let mut next = Vec::with_capacity(parts.len().div_ceil(2));
            let mut it = parts.chunks(2);
            for ch in &mut it {
                next.push(match ch {
                    [a, b] => a + b,
                    [a] => a.clone(),
                    _ => unreachable!("chunks of two"),
                });
            }
            parts = next;
        }
        Ok(parts.pop().expect("one part"))
    }

    fn term(&mut self) -> Result<Poly, ParsePolyError> {
        let mut acc = self.factor()?;
        while let Some(c) = self.peek() {
            match c {
                b'*' => {
                    self.pos += 1;
                    let at = self.pos;
                    let f = self.factor()?;
                    let (a, b) = (Bound::of(&acc), Bound::of(&f));
                    let size = a.product(&b);
                    if size > MAX_EXPANDED_BITS {
                        self.pos = at;
                        return self.too_large(size);
                    }
                    let work = a.product_work(&b);
                    if work > MAX_EXPANSION_WORK {
                        self.pos = at;
                        return self.too_slow(work);
                    }
                    let degrees = acc
                        .vars()
                        .iter()
                        .chain(f.vars())
                        .map(|v| acc.degree(v) as u64 + f.degree(v) as u64);
                    if let Err(e) = self.degree_cap(degrees) {
                        self.pos = at;
                        return Err(e);
                    }
                    acc = &acc * &f;
                }
                b'/' => {
                    self.pos += 1;
                    let at = self.pos;
                    let d = self.factor()?;
                    match d.as_constant() {
                        Some(c) if !c.is_zero() => acc = acc.scale(&c.recip()),
                        _ => {
                            self.pos = at;
                            return self.err("division only by a non-zero constant");
                        }
                    }
                }
                _ => break,
            }
        }
        Ok(acc)
    }

    fn factor(&mut self) -> Result<Poly, ParsePolyError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return self.err("nesting too deep");
        }
        let r = match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                Ok(-self.factor()?)
            }
            Some(b'+') => {
                self.pos += 1;
                self.factor()
            }
            _ => {
                let base = self.atom()?;
                if self.peek() == Some(b'^') {
                    self.pos += 1;
                    self.skip_ws();
                    let start = self.pos;
                    while self.pos < self.s.len() && self.s[self.pos].is_ascii_digit() {
                        self.pos += 1;
                    }
                    let txt = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
                    match txt.parse::<u32>() {
                        Ok(e) if e <= MAX_EXPONENT => {
                            let b = Bound::of(&base);
                            let (size, work) = (b.power(e), b.power_work(e));
                            if size > MAX_EXPANDED_BITS {
                                self.pos = start;
                                self.too_large(size)
                            } else if work > MAX_EXPANSION_WORK {
                                self.pos = start;
                                self.too_slow(work)
                            } else if let Err(e) = self.degree_cap(
                                base.vars().iter().map(|v| base.degree(v) as u64 * e as u64),
                            ) {
                                self.pos = start;
                                Err(e)
                            } else {
                                Ok(base.pow(e))
                            }
                        }
                        Ok(_) => self.err(format!("exponent above {MAX_EXPONENT}")),
                        Err(_) => self.err("expected a non-negative integer exponent"),
                    }
                } else {
                    Ok(base)
                }
            }
        };
        self.depth -= 1;
        r
    }

    fn atom(&mut self) -> Result<Poly, ParsePolyError> {
        match self.peek() {
            Some(b'(') => {
                self.pos += 1;
                let e = self.expr()?;
                if self.peek() != Some(b')') {
                    return self.err("expected ')'");
                }
                self.pos += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => {
                let start = self.pos;
                while self.pos < self.s.len()
                    && (self.s[self.pos].is_ascii_digit() || self.s[self.pos] == b'.')
                {
                    self.pos += 1;
                }
                let txt = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
                match Rat::from_str(txt) {
                    Ok(r) => Ok(Poly::constant(r)),
                    Err(_) => {
                        self.pos = start;
                        self.err(format!("invalid number {txt:?}"))
                    }
                }
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.pos;
                while self.pos < self.s.len()
                    && (self.s[self.pos].is_ascii_alphanumeric() || self.s[self.pos] == b'_')
                {
                    self.pos += 1;
                }
                let name = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
                Ok(Poly::var(name))
            }
            Some(c) => self.err(format!("unexpected character {:?}", c as char)),
            None => self.err("unexpected end of input"),
        }
    }
}

/// The form [`Poly`]'s `Display` writes, a sum of monomials `[c*]x^a*y*..`
/// with integer or `p/q` coefficients, read monomial by monomial into one
/// [`Poly::from_terms`]: none of the general grammar's products and sums,
/// whose allocations dominated reading a table of certificates. `None`
/// when the text is not of that form (parentheses, decimals, a product of
/// numbers, an exponent above the cap, ...): the general parser decides,
/// and reports any error.
fn canonical(s: &str) -> Option<Poly> {
    let b = s.as_bytes();
    let mut pos = 0;
    let ws = |pos: &mut usize| {
        while *pos < b.len() && b[*pos] == b' ' {
            *pos += 1;
        }
    };
    let digits = |pos: &mut usize| {
        let start = *pos;
        while *pos < b.len() && b[*pos].is_ascii_digit() {
            *pos += 1;
        }
        (*pos > start).then_some(start)
    };
    let mut vars: Vec<&str> = Vec::new();
    let mut monomials: Vec<(Rat, Vec<(usize, u32)>)> = Vec::new();
    ws(&mut pos);
    let mut negative = false;
    if b.get(pos) == Some(&b'-') {
        negative = true;
        pos += 1;
    }
    loop {
        ws(&mut pos);
        let mut coef = Rat::ONE;
        let mut powers: Vec<(usize, u32)> = Vec::new();
        let mut expect_var = true;
        if b.get(pos).is_some_and(u8::is_ascii_digit) {
            let start = digits(&mut pos)?;
            if b.get(pos) == Some(&b'/') {
                pos += 1;
                digits(&mut pos)?;
            }
            coef = s[start..pos].parse().ok()?;
            expect_var = b.get(pos) == Some(&b'*');
            if expect_var {
                pos += 1;
            }
        }
        while expect_var {
            let start = pos;
            if !b
                .get(pos)
                .is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_')
            {
                return None;
            }
            while pos < b.len() && (b[pos].is_ascii_alphanumeric() || b[pos] == b'_') {
                pos += 1;
            }
            let name = &s[start..pos];
            let mut e = 1u32;
            if b.get(pos) == Some(&b'^') {
                pos += 1;
                let at = digits(&mut pos)?;
                e = s[at..pos].parse().ok().filter(|&e| e <= MAX_EXPONENT)?;
            }
            let k = match vars.iter().position(|v| *v == name) {
                Some(k) => k,
                None => {
                    vars.push(name);
                    vars.len() - 1
                }
            };
            powers.push((k, e));
            expect_var = b.get(pos) == Some(&b'*');
            if expect_var {
                pos += 1;
            }
        }
        monomials.push((if negative { -coef } else { coef }, powers));
        ws(&mut pos);
        match b.get(pos) {
            None => break,
            Some(b'+') => negative = false,
            Some(b'-') => negative = true,
            Some(_) => return None,
        }
        pos += 1;
    }
    let mut terms = Vec::with_capacity(monomials.len());
    for (coef, powers) in monomials {
        let mut exps = vec![0u32; vars.len()];
        for (k, e) in powers {
            exps[k] = exps[k].checked_add(e).filter(|&d| d <= MAX_EXPONENT)?;
        }
        terms.push(crate::poly::Term { exps, coef });
    }
    let names: Vec<String> = vars.iter().map(|v| v.to_string()).collect();
    Some(Poly::from_terms(&names, terms))
}

impl FromStr for Poly {
    type Err = ParsePolyError;

    /// Parses the plain-text syntax written by [`Poly`]'s `Display`.
    ///
    /// ```
    /// use poly::Poly;
    /// let p: Poly = "2*(x + y)^2 - 4*x*y".parse().unwrap();
    /// assert_eq!(p.to_string(), "2*x^2 + 2*y^2");
    /// assert!("x +".parse::<Poly>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if let Some(p) = canonical(s) {
            return Ok(p);
        }
        let mut p = Parser {
            s: s.as_bytes(),
            pos: 0,
            depth: 0,
        };
        let e = p.expr()?;
        if p.peek().is_some() {
            return p.err("unexpected trailing input");
        }
        Ok(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The canonical form read monomial by monomial is the polynomial the
    /// general grammar builds, and what it does not take falls through to
    /// the general parser (with its errors).
    #[test]
    fn canonical_form_reads_as_the_grammar_does() {
        let general = |s: &str| {
            let mut p = Parser {
                s: s.as_bytes(),
                pos: 0,
                depth: 0,
            };
            p.expr().unwrap()
        };
        for s in [
            "Omega^2*m1*m2*m3 - 3/2*c12*m1 + 7",
            "-x^10*y + 25/4*z",
            "0",
            "-1",
            "-22/7",
            "c9_10^2*m10 - m10 + c9_10*m10",
            "x*x^2*y - x^3*y + 2",
            "a - a",
            "0*x + 1",
            "c1*c23*m2 + c1*c23*m3 - Omega*c23*m2*m3",
        ] {
            let fast = canonical(s).unwrap_or_else(|| panic!("{s}: not canonical"));
            assert_eq!(fast, general(s), "{s}");
            assert_eq!(fast.to_string().parse::<Poly>().unwrap(), fast, "{s}");
        }
        for s in [
            "(x + 1)^2",
            "0.5*x",
            "2*3",
            "x +",
            "x^10001",
            "3*-x",
            "1/0*x",
        ] {
            assert!(canonical(s).is_none(), "{s}");
        }
        assert!("x^10001".parse::<Poly>().is_err());
        assert_eq!("2*3".parse::<Poly>().unwrap(), Poly::int(6));
    }

    #[test]
    fn roundtrip_display() {
        for s in [
            "Omega^2*m1*m2*m3 - 3/2*c12*m1 + 7",
            "-x^10*y + 0.25*z",
            "0",
            "-1",
        ] {
            let p: Poly = s.parse().unwrap();
            let q: Poly = p.to_string().parse().unwrap();
            assert_eq!(p, q, "{s}");
        }
    }

    #[test]
    fn errors_name_position() {
        let e = "x + * y".parse::<Poly>().unwrap_err();
        assert_eq!(e.offset, 4);
        assert!("x / y".parse::<Poly>().is_err());
        assert!("x^99999".parse::<Poly>().is_err());
        // What is read prints to a text that reads back: no degree above
        // the exponent cap by a product or power (a fuzzer's find).
        assert!("y^972*y^9797".parse::<Poly>().is_err());
        assert!("(y^5000)^3".parse::<Poly>().is_err());
        assert!("y^5000*y^5000".parse::<Poly>().is_ok());
        // A coefficient too large to multiply in time (a fuzzer's find).
        let e = "2.66666664666666666668^7668^71"
            .parse::<Poly>()
            .unwrap_err();
        assert!(e.message.contains("coefficient"), "{e}");
        assert!("3^10000".parse::<Poly>().is_ok());
        assert!("(x".parse::<Poly>().is_err());
        assert!("((((((((((((((((((((".repeat(20).parse::<Poly>().is_err());
    }

    /// Expressions that would expand beyond the limit are refused before
    /// they are expanded (each in well under a second), at the power or
    /// product that would build them; the expansions of real analyses and
    /// exact powers of size within it are read.
    #[test]
    fn expansions_beyond_the_limit_are_refused_first() {
        let start = std::time::Instant::now();
        for (s, at) in [
            ("(m1+m2+m3+c12+c23+Omega)^10000", 25),
            ("((x+y)^100)^100", 12),
            ("(a+b+c+d+e)^20*(f+g+h+i+j)^20", 15),
            ("(2*x+3)^10000", 8),
        ] {
            let e = s.parse::<Poly>().unwrap_err();
            assert_eq!(e.offset, at, "{s}: {e}");
            assert!(e.message.contains("above the limit"), "{e}");
        }
        // Within the size, beyond the work: refused as fast (the first
        // took 428 s to expand before).
        for (s, at) in [("(m + m115zxOm + 3/2)^203", 21), ("(m+n+3/2)^150", 10)] {
            let e = s.parse::<Poly>().unwrap_err();
            assert_eq!(e.offset, at, "{s}: {e}");
            assert!(e.message.contains("term products"), "{s}: {e}");
        }
        assert!(start.elapsed().as_secs_f64() < 5.0);
        // Within both: read, C(92, 2) terms, and its value at m = n = 1 is
        // (7/2)^90 (exact rationals, another route).
        let p: Poly = "(m+n+3/2)^90".parse().unwrap();
        assert_eq!(p.num_terms(), 4186);
        let at_one = p.terms().iter().fold(Rat::from(0), |acc, t| &acc + &t.coef);
        assert_eq!(at_one, Rat::new(7.into(), 2.into()).pow(90));
        // The size bound holds the exact sizes: C(v + d, v) terms.
        let p: Poly = "(a+b+c+1)^12".parse().unwrap();
        assert_eq!(p.num_terms(), 455);
        let q: Poly = "x^10000 * (y + 1)^50".parse().unwrap();
        assert_eq!(q.num_terms(), 51);
        assert_eq!(q.total_degree(), 10050);
    }
}
