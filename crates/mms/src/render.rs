//! Paper-style rendering of polynomials and transfer functions.
//!
//! A polynomial is written grouped by descending powers of one variable
//! (`Omega` or `s`), each coefficient in parentheses when it has several
//! terms and with its sign pulled out, e.g.
//! `m1*m2*m3*Omega^2 - (c12*m1*m3 + ...)*Omega + ...`.
//!
//! With [`RenderOptions::abbreviate`] the coefficients are factored into a
//! monomial, sums of distinct masses and a remaining polynomial, whose terms
//! are collected by their spring/damper part and factored the same way
//! (`c23*m1 + c23*m2 + c1*m3` becomes `c23*(m1 + m2) + c1*m3`), and the
//! paper's abbreviations are used in LaTeX: `m_{1.2} = m1*m2` (product of
//! distinct masses) and `m_{1+2} = m1 + m2` (sum of distinct masses). Sums
//! of masses are found by trial division by every sum of two or more of the
//! masses that occur (largest first), products by collecting the masses of
//! a monomial. In plain text the factored form is kept, written so that
//! [`Poly`]'s parser reads it back: `c12*c23*(m1 + m2 + m3)`.
//!
//! Eq. (10) of the paper, `Den_A`, comes out as printed there up to the
//! order of factors:
//!
//! ```
//! use mms::render::{render_poly, RenderOptions};
//! let den = mms::Model::from_id("A1").unwrap().undamped_tf().den;
//! assert_eq!(
//!     render_poly(&den, "Omega", &RenderOptions::latex()),
//!     r"m_{1.2.3} \Omega^{2} - \left(c_{12} m_{3} m_{1+2} + c_{23} m_{1} m_{2+3}\right) \Omega + c_{12} c_{23} m_{1+2+3}"
//! );
//! let text = render_poly(&den, "Omega", &RenderOptions::text());
//! assert_eq!(text.parse::<poly::Poly>().unwrap(), den);
//! ```

use crate::tf::{DampedTf, OmegaTf, UndampedTf, OMEGA, S};
use poly::{Poly, Rat, Term};
use std::collections::BTreeMap;

/// Output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Plain text in the syntax of [`Poly`]'s parser.
    Text,
    /// LaTeX math (no surrounding `$`).
    Latex,
    /// Markdown: LaTeX in inline math, `$...$`.
    Markdown,
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderOptions {
    /// The format.
    pub format: Format,
    /// Factor the coefficients and use the paper's abbreviations
    /// `m_{1.2}`, `m_{1+2}` (LaTeX, Markdown) resp. factored sums (text).
    pub abbreviate: bool,
}

impl RenderOptions {
    /// Plain text, factored coefficients.
    pub fn text() -> RenderOptions {
        RenderOptions {
            format: Format::Text,
            abbreviate: true,
        }
    }

    /// LaTeX with abbreviations.
    pub fn latex() -> RenderOptions {
        RenderOptions {
            format: Format::Latex,
            abbreviate: true,
        }
    }

    /// Markdown (inline LaTeX) with abbreviations.
    pub fn markdown() -> RenderOptions {
        RenderOptions {
            format: Format::Markdown,
            abbreviate: true,
        }
    }

    /// The same options with abbreviations switched on or off.
    pub fn with_abbreviations(self, abbreviate: bool) -> RenderOptions {
        RenderOptions { abbreviate, ..self }
    }
}

/// One factor of a product.
#[derive(Clone, Debug)]
enum Factor {
    /// A variable to a power.
    Var(String, u32),
    /// Product of distinct masses (indices), all to the same power.
    MassProd(Vec<String>, u32),
    /// Sum of distinct masses (indices) to a power.
    MassSum(Vec<String>, u32),
    /// A general sum: a list of signed products.
    Sum(Vec<Product>),
}

/// `sign * coef * factors` with `coef > 0`.
#[derive(Clone, Debug)]
struct Product {
    neg: bool,
    coef: Rat,
    factors: Vec<Factor>,
}

/// The index of a mass variable `m<digits>`.
fn mass_index(name: &str) -> Option<&str> {
    let rest = name.strip_prefix('m')?;
    (!rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit())).then_some(rest)
}

/// Factors of one monomial (vars and exponents, in the order of `vars`),
/// masses grouped into products when abbreviating.
fn monomial_factors(vars: &[String], exps: &[u32], abbreviate: bool) -> Vec<Factor> {
    let mut out = Vec::new();
    let mut masses: Vec<(String, u32)> = Vec::new();
    for (v, &e) in vars.iter().zip(exps) {
        if e == 0 {
            continue;
        }
        match mass_index(v) {
            Some(i) if abbreviate => masses.push((i.to_string(), e)),
            _ => out.push(Factor::Var(v.clone(), e)),
        }
    }
    let mut es: Vec<u32> = masses.iter().map(|m| m.1).collect();
    es.sort_unstable();
    es.dedup();
    for e in es {
        let idx: Vec<String> = masses
            .iter()
            .filter(|m| m.1 == e)
            .map(|m| m.0.clone())
            .collect();
        out.push(Factor::MassProd(idx, e));
    }
    out
}

fn term_product(vars: &[String], t: &Term, abbreviate: bool) -> Product {
    Product {
        neg: t.coef.signum() < 0,
        coef: t.coef.abs(),
        factors: monomial_factors(vars, &t.exps, abbreviate),
    }
}

/// A prime for the modular filter of [`ModImage`].
const PRIME: u64 = 1_000_000_007;

fn pow_mod(mut b: u64, mut e: u64) -> u64 {
    let mut r = 1;
    while e > 0 {
        if e & 1 == 1 {
            r = r * b % PRIME;
        }
        b = b * b % PRIME;
        e >>= 1;
    }
    r
}

/// A polynomial reduced modulo [`PRIME`], for a cheap necessary test of
/// divisibility by a sum of masses: if `m_a + m_b + ...` divides `p`, then
/// `p` vanishes at `m_a = -(m_b + ...)` for any values of the others. Only
/// candidates passing the test are tried by exact division, so the result
/// never depends on the filter.
struct ModImage {
    /// Position among the variables and value of each mass, by index text.
    masses: BTreeMap<String, (usize, u64)>,
    /// For each variable position `f`: the image of `p` as a polynomial in
    /// that variable alone (coefficient `k` = power `k`), all other
    /// variables at their fixed pseudo-random values.
    univariate: Vec<Vec<u64>>,
}

impl ModImage {
    fn new(p: &Poly) -> ModImage {
        let nv = p.vars().len();
        let values: Vec<u64> = (0..nv as u64)
            .map(|i| (i + 3).wrapping_mul(0x9E37_79B9_7F4A_7C15) % PRIME)
            .collect();
        let masses = p
            .vars()
            .iter()
            .enumerate()
            .filter_map(|(i, v)| mass_index(v).map(|k| (k.to_string(), (i, values[i]))))
            .collect::<BTreeMap<_, _>>();
        let mut univariate: Vec<Vec<u64>> = (0..nv)
            .map(|f| vec![0; p.degree(&p.vars()[f]) as usize + 1])
            .collect();
        for t in p.terms() {
            let n = t.coef.numer().rem_u64(PRIME);
            let d = t.coef.denom().rem_u64(PRIME);
            let c = n * pow_mod(d, PRIME - 2) % PRIME;
            let powers: Vec<u64> = values
                .iter()
                .zip(&t.exps)
                .map(|(&v, &e)| pow_mod(v, e as u64))
                .collect();
            for &(f, _) in masses.values() {
                let mut r = c;
                for (k, pk) in powers.iter().enumerate() {
                    if k != f {
                        r = r * pk % PRIME;
                    }
                }
                let slot = &mut univariate[f][t.exps[f] as usize];
                *slot = (*slot + r) % PRIME;
            }
        }
        ModImage { masses, univariate }
    }

    fn may_divide(&self, subset: &[String]) -> bool {
        let Some(&(first, _)) = self.masses.get(&subset[0]) else {
            return false;
        };
        let mut others = 0;
        for m in &subset[1..] {
            match self.masses.get(m) {
                Some(&(_, v)) => others = (others + v) % PRIME,
                None => return false,
            }
        }
        let x = (PRIME - others) % PRIME;
        let acc = self.univariate[first]
            .iter()
            .rev()
            .fold(0, |acc, &c| (acc * x + c) % PRIME);
        acc == 0
    }
}

/// Sums of two or more of `masses`, largest first, then lexicographic.
fn mass_subsets(masses: &[String]) -> Vec<Vec<String>> {
    let k = masses.len().min(12);
    let mut subsets: Vec<Vec<String>> = (1u32..(1 << k))
        .filter(|b| b.count_ones() >= 2)
        .map(|b| {
            (0..k)
                .filter(|i| b >> i & 1 == 1)
                .map(|i| masses[i].clone())
                .collect()
        })
        .collect();
    subsets.sort_by(|a, b| b.len().cmp(&a.len()).then(a.cmp(b)));
    subsets
}

/// The terms of a sum, with terms that share their non-mass part (springs,
/// dampers) collected and factored: `c23*m1 + c23*m2 + c1*m3` becomes
/// `c23*(m1 + m2) + c1*m3`, i.e. `c_{23} m_{1+2} + c_{1} m_{3}`. Groups keep
/// the order of their first term.
fn grouped_sum(p: &Poly, depth: u32) -> Vec<Product> {
    let vars = p.vars();
    let key = |t: &Term| -> Vec<u32> {
        vars.iter()
            .zip(&t.exps)
            .map(|(v, &e)| if mass_index(v).is_some() { 0 } else { e })
            .collect()
    };
    let mut groups: Vec<Vec<Term>> = Vec::new();
    let mut slot: BTreeMap<Vec<u32>, usize> = BTreeMap::new();
    for t in p.terms() {
        let g = *slot.entry(key(t)).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(t.clone());
    }
    if depth == 0 || groups.len() < 2 {
        return p
            .terms()
            .iter()
            .map(|t| term_product(vars, t, true))
            .collect();
    }
    groups
        .into_iter()
        .map(|ts| coefficient_product(&Poly::from_terms(vars, ts), true, depth - 1))
        .collect()
}

/// Splits a non-zero coefficient polynomial into a signed product; `depth`
/// bounds the nesting of [`grouped_sum`].
fn coefficient_product(p: &Poly, abbreviate: bool, depth: u32) -> Product {
    if !abbreviate {
        if p.num_terms() == 1 {
            return term_product(p.vars(), &p.terms()[0], false);
        }
        let neg = p.leading_coef().signum() < 0;
        let q = if neg { -p } else { p.clone() };
        return Product {
            neg,
            coef: Rat::ONE,
            factors: vec![Factor::Sum(
                q.terms()
                    .iter()
                    .map(|t| term_product(q.vars(), t, false))
                    .collect(),
            )],
        };
    }
    let (mut content, mut rest) = p.primitive();
    // Monomial content: the smallest exponent of each variable.
    let vars = rest.vars().to_vec();
    let mins: Vec<u32> = (0..vars.len())
        .map(|i| rest.terms().iter().map(|t| t.exps[i]).min().unwrap_or(0))
        .collect();
    let mut mono = Poly::from_terms(
        &vars,
        vec![Term {
            exps: mins,
            coef: Rat::ONE,
        }],
    );
    rest = rest.div_exact(&mono).expect("monomial content divides");
    // Sums of distinct masses.
    let mut sums: Vec<(Vec<String>, u32)> = Vec::new();
    'outer: while rest.num_terms() >= 2 {
        let masses: Vec<String> = rest
            .vars()
            .iter()
            .filter_map(|v| mass_index(v).map(str::to_string))
            .collect();
        let image = ModImage::new(&rest);
        for subset in mass_subsets(&masses) {
            if subset.len() > rest.num_terms() || !image.may_divide(&subset) {
                continue;
            }
            let sum = subset
                .iter()
                .fold(Poly::zero(), |acc, i| &acc + &Poly::var(&format!("m{i}")));
            if let Some(q) = rest.div_exact(&sum) {
                match sums.iter_mut().find(|s| s.0 == subset) {
                    Some(s) => s.1 += 1,
                    None => sums.push((subset, 1)),
                }
                rest = q;
                continue 'outer;
            }
        }
        break;
    }
    // A one-term leftover joins the monomial.
    if rest.num_terms() == 1 {
        let c = rest.leading_coef();
        mono = &mono * &rest.scale(&c.recip());
        content = &content * &c;
        rest = Poly::one();
    }
    let t = &mono.terms()[0];
    let mut factors = monomial_factors(mono.vars(), &t.exps, true);
    for (s, e) in sums {
        factors.push(Factor::MassSum(s, e));
    }
    if rest.num_terms() > 1 {
        factors.push(Factor::Sum(grouped_sum(&rest, depth)));
    }
    Product {
        neg: content.signum() < 0,
        coef: content.abs(),
        factors,
    }
}

/// The LaTeX name of a variable: `Omega` -> `\Omega`, `m1` -> `m_{1}`,
/// `c12` -> `c_{12}`, `c9_10` -> `c_{9,10}`, `s` -> `s`.
///
/// ```
/// assert_eq!(mms::render::latex_var("c9_10"), "c_{9,10}");
/// ```
pub fn latex_var(name: &str) -> String {
    if name == OMEGA {
        return r"\Omega".to_string();
    }
    match name.find(|c: char| c.is_ascii_digit()) {
        Some(i) if i > 0 => format!("{}_{{{}}}", &name[..i], name[i..].replace('_', ",")),
        _ => name.to_string(),
    }
}

fn is_latex(f: Format) -> bool {
    matches!(f, Format::Latex | Format::Markdown)
}

fn pow_suffix(e: u32, latex: bool) -> String {
    match (e, latex) {
        (1, _) => String::new(),
        (_, true) => format!("^{{{e}}}"),
        (_, false) => format!("^{e}"),
    }
}

fn render_rat(r: &Rat, latex: bool) -> String {
    if latex && !r.is_integer() {
        format!(r"\frac{{{}}}{{{}}}", r.numer(), r.denom())
    } else {
        r.to_string()
    }
}

fn render_factor(f: &Factor, latex: bool) -> String {
    match f {
        Factor::Var(v, e) => {
            if latex {
                format!("{}{}", latex_var(v), pow_suffix(*e, true))
            } else {
                format!("{v}{}", pow_suffix(*e, false))
            }
        }
        Factor::MassProd(idx, e) => {
            if latex {
                format!("m_{{{}}}{}", idx.join("."), pow_suffix(*e, true))
            } else {
                idx.iter()
                    .map(|i| format!("m{i}{}", pow_suffix(*e, false)))
                    .collect::<Vec<_>>()
                    .join("*")
            }
        }
        Factor::MassSum(idx, e) => {
            if latex {
                format!("m_{{{}}}{}", idx.join("+"), pow_suffix(*e, true))
            } else {
                let s: Vec<String> = idx.iter().map(|i| format!("m{i}")).collect();
                format!("({}){}", s.join(" + "), pow_suffix(*e, false))
            }
        }
        Factor::Sum(ps) => {
            let inner = render_sum(ps, latex);
            if latex {
                format!(r"\left({inner}\right)")
            } else {
                format!("({inner})")
            }
        }
    }
}

/// The unsigned product `coef * factors` (`1` if empty).
fn render_unsigned(p: &Product, latex: bool) -> String {
    let mut parts: Vec<String> = Vec::new();
    if !p.coef.is_one() || p.factors.is_empty() {
        parts.push(render_rat(&p.coef, latex));
    }
    parts.extend(p.factors.iter().map(|f| render_factor(f, latex)));
    parts.join(if latex { " " } else { "*" })
}

fn render_sum(ps: &[Product], latex: bool) -> String {
    let mut s = String::new();
    for (k, p) in ps.iter().enumerate() {
        match (k, p.neg) {
            (0, true) => s.push('-'),
            (0, false) => {}
            (_, true) => s.push_str(" - "),
            (_, false) => s.push_str(" + "),
        }
        s.push_str(&render_unsigned(p, latex));
    }
    s
}

/// The polynomial as a list of signed products grouped by powers of `var`.
fn grouped(p: &Poly, var: &str, abbreviate: bool) -> Vec<Product> {
    let coeffs = p.coeffs_in(var);
    let mut out = Vec::new();
    for (k, c) in coeffs.iter().enumerate().rev() {
        if c.is_zero() {
            continue;
        }
        let mut prod = coefficient_product(c, abbreviate, 1);
        if k == 0 && !abbreviate {
            // Constant term: list its terms without parentheses.
            if let [Factor::Sum(ps)] = prod.factors.as_slice() {
                let flip = prod.neg;
                for t in ps {
                    let mut t = t.clone();
                    t.neg ^= flip;
                    out.push(t);
                }
                continue;
            }
        }
        if k > 0 {
            prod.factors.push(Factor::Var(var.to_string(), k as u32));
        }
        out.push(prod);
    }
    if out.is_empty() {
        out.push(Product {
            neg: false,
            coef: Rat::ZERO,
            factors: Vec::new(),
        });
    }
    out
}

fn wrap(s: String, f: Format) -> String {
    match f {
        Format::Markdown => format!("${s}$"),
        _ => s,
    }
}

fn body(p: &Poly, var: &str, opts: &RenderOptions) -> String {
    render_sum(&grouped(p, var, opts.abbreviate), is_latex(opts.format))
}

/// Renders `p` grouped by descending powers of `var`.
///
/// ```
/// use mms::render::{render_poly, Format, RenderOptions};
/// let p: poly::Poly = "c12*c23*m1 + c12*c23*m2 - c12*m3*Omega".parse().unwrap();
/// assert_eq!(render_poly(&p, "Omega", &RenderOptions::text()), "-c12*m3*Omega + c12*c23*(m1 + m2)");
/// let plain = RenderOptions::text().with_abbreviations(false);
/// assert_eq!(render_poly(&p, "Omega", &plain), "-c12*m3*Omega + c12*c23*m1 + c12*c23*m2");
/// assert_eq!(render_poly(&p, "Omega", &RenderOptions::markdown()),
///            r"$-c_{12} m_{3} \Omega + c_{12} c_{23} m_{1+2}$");
/// ```
pub fn render_poly(p: &Poly, var: &str, opts: &RenderOptions) -> String {
    wrap(body(p, var, opts), opts.format)
}

/// `body` in parentheses unless it is a single product.
fn paren_text(p: &Poly, var: &str, opts: &RenderOptions) -> String {
    let g = grouped(p, var, opts.abbreviate);
    let s = render_sum(&g, is_latex(opts.format));
    if g.len() == 1 && !g[0].neg {
        s
    } else if is_latex(opts.format) {
        format!(r"\left({s}\right)")
    } else {
        format!("({s})")
    }
}

/// Renders `prefix_sign * [s *] num / ([Omega *] den)`; `extra_num`
/// and `extra_den` are optional leading factors (`s`, `Omega`).
fn render_fraction(
    neg: bool,
    num: &Poly,
    den: &Poly,
    var: &str,
    extra_num: Option<&str>,
    extra_den: Option<&str>,
    opts: &RenderOptions,
) -> String {
    let latex = is_latex(opts.format);
    let sign = if neg { "-" } else { "" };
    let s = if latex {
        let part = |extra: Option<&str>, p: &Poly| match extra {
            Some(x) => format!("{} {}", latex_var(x), paren_text(p, var, opts)),
            None => body(p, var, opts),
        };
        format!(
            r"{sign}\frac{{{}}}{{{}}}",
            part(extra_num, num),
            part(extra_den, den)
        )
    } else {
        let part = |extra: Option<&str>, p: &Poly| match extra {
            Some(x) => format!("({x}*{})", paren_text(p, var, opts)),
            None => format!("({})", body(p, var, opts)),
        };
        format!("{sign}{}/{}", part(extra_num, num), part(extra_den, den))
    };
    wrap(s, opts.format)
}

impl UndampedTf {
    /// The inertance `num/den` rendered as a fraction in `Omega`.
    ///
    /// ```
    /// use mms::render::RenderOptions;
    /// let tf = mms::Model::from_id("A3").unwrap().undamped_tf();
    /// assert!(tf.render(&RenderOptions::text()).starts_with("(c12*c23)/(m1*m2*m3*Omega^2 - ("));
    /// ```
    pub fn render(&self, opts: &RenderOptions) -> String {
        render_fraction(false, &self.num, &self.den, OMEGA, None, None, opts)
    }
}

impl OmegaTf {
    /// Rendered as `sign * [s *] num / ([Omega *] den)`.
    ///
    /// ```
    /// use mms::{render::RenderOptions, Model, Output};
    /// let tf = Model::from_id("A4").unwrap().undamped_tf().output(Output::Velocity);
    /// let t = tf.render(&RenderOptions::text());
    /// assert!(t.starts_with("-(s*(m1*m3*Omega^2 - (c12*m3 + c23*m1)*Omega + c12*c23))/(Omega*(m1*m2*m3*Omega^2"), "{t}");
    /// ```
    pub fn render(&self, opts: &RenderOptions) -> String {
        render_fraction(
            self.sign < 0,
            &self.num,
            &self.den,
            OMEGA,
            (self.s_power == 1).then_some(S),
            (self.omega_power == -1).then_some(OMEGA),
            opts,
        )
    }
}

impl DampedTf {
    /// Rendered as `num/den` grouped by powers of `s`.
    pub fn render(&self, opts: &RenderOptions) -> String {
        render_fraction(false, &self.num, &self.den, S, None, None, opts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    #[test]
    fn factoring_finds_sums_and_products() {
        let c = p("c12*c23*m1 + c12*c23*m2 + c12*c23*m3");
        let t = render_poly(&c, "Omega", &RenderOptions::latex());
        assert_eq!(t, "c_{12} c_{23} m_{1+2+3}");
        let c = p("-(m1 + m2)^2*m3*(m1 + c12)");
        let t = render_poly(&c, "Omega", &RenderOptions::text());
        assert_eq!(t.parse::<Poly>().unwrap(), c, "{t}");
        assert!(t.contains("(m1 + m2)^2"), "{t}");
    }

    #[test]
    fn zero_and_constants() {
        assert_eq!(
            render_poly(&Poly::zero(), "Omega", &RenderOptions::text()),
            "0"
        );
        assert_eq!(
            render_poly(&p("-3/2"), "Omega", &RenderOptions::latex()),
            r"-\frac{3}{2}"
        );
        assert_eq!(
            render_poly(&p("-Omega^2"), "Omega", &RenderOptions::text()),
            "-Omega^2"
        );
    }
}
