//! Types that could only occur as limits of generic types the model
//! cannot show.
//!
//! Where the numerator and denominator of the reduced TF have leading and
//! constant coefficients of one sign on the orthant, their degrees stay
//! the same and no root reaches `Omega = 0` or infinity, so the roots move
//! continuously with the parameters. Where also one point has both
//! square-free and coprime, the points with a multiple or shared root lie
//! on a proper algebraic subset (a discriminant or resultant that is not
//! identically zero): every point `p` is a limit of *generic* points `q`,
//! whose type has simple tokens and every pole.
//!
//! Near `p`, the positive roots of `q` gather at the positive roots of
//! `p` in consecutive runs (poles stay real; zeros near `rho` may also be
//! conjugate pairs off the axis, zeros near a point off the positive axis
//! stay off it). A run of `a` zeros, `2e` of them a pair landing there,
//! and `b` poles becomes at `p` one token `A^(a-b)` or `R^(b-a)`, or
//! nothing when `a = b`: `min(a, b)` poles cancelled. So a type `T` shows
//! at `p` only if the generic type of `q` *gathers into* `T` in this way
//! ([`gathers_into`]); if every generic type that gathers into `T` is
//! impossible, so is `T` ([`OpenProof::Limits`]). The rule comes last, on
//! the types every other rule and search left open.

use super::frf_type::{Feature, FrfType, Token};
use super::{ModelAnalysis, OpenProof, Proof, Status, TypeVerdict};
use crate::model::Model;
use crate::tf::OMEGA;
use poly::{gcd, Poly, Rat};
use std::collections::{BTreeMap, HashMap};

/// True when the generic type `g` (simple tokens, all `r` poles, `a`
/// zeros in all) of a TF with numerator degree `a` and denominator degree
/// `r` in `Omega` can turn into `t` as its roots gather: its tokens split
/// into consecutive runs, each with some of the off-axis zero pairs
/// landing on it, and pairs landing alone, each run becoming `t`'s next
/// token or cancelling out, with `t`'s count of zeros off the axis left
/// over. Every point of type `t` is a limit of points of such types
/// (where the premises of the rule hold, docs/analysis.md, "Limits of
/// generic types"), so a possible `g` that gathers into `t` is where a
/// witness of `t` would be approached from.
///
/// ```
/// use mms::analysis::{gathers_into, FrfType};
/// let t = |s: &str| s.parse::<FrfType>().unwrap();
/// // A pole and a zero meet and cancel.
/// assert!(gathers_into(&t("ARAR"), &t("AR"), 2, 2));
/// // A conjugate pair lands on the axis: a double zero, never two zeros.
/// assert!(gathers_into(&t("RR (nm)"), &t("RA^2R"), 2, 2));
/// assert!(!gathers_into(&t("RR (nm)"), &t("RAAR"), 2, 2));
/// ```
pub fn gathers_into(g: &FrfType, t: &FrfType, a: u32, r: u32) -> bool {
    let r_t = t.resonances();
    if r_t > r {
        return false;
    }
    let cancelled = r - r_t;
    let Some(off_t) = a.checked_sub(cancelled + t.antiresonances()) else {
        return false;
    };
    if t.nonminimum_phase != (off_t > 0) {
        return false;
    }
    let off_g = a - g.antiresonances();
    if off_g < off_t || (off_g - off_t) % 2 == 1 {
        return false;
    }
    let pairs = ((off_g - off_t) / 2) as usize;
    let mut memo = HashMap::new();
    runs(&g.tokens, &t.tokens, (0, 0, 0), pairs, &mut memo)
}

/// Whether `g[i..]` with `used` pairs already landed can become `t[k..]`
/// with all `pairs` landed.
fn runs(
    g: &[Token],
    t: &[Token],
    (i, k, used): (usize, usize, usize),
    pairs: usize,
    memo: &mut HashMap<(usize, usize, usize), bool>,
) -> bool {
    if i == g.len() && k == t.len() {
        return used == pairs;
    }
    if let Some(&v) = memo.get(&(i, k, used)) {
        return v;
    }
    let mut ok = false;
    // Pairs landing where no root of `q` is: a double (quadruple...) zero.
    if let Some(tok) = t.get(k) {
        let e = (tok.multiplicity / 2) as usize;
        if tok.feature == Feature::Antiresonance
            && tok.multiplicity.is_multiple_of(2)
            && used + e <= pairs
        {
            ok = runs(g, t, (i, k + 1, used + e), pairs, memo);
        }
    }
    let (mut zeros, mut poles) = (0usize, 0usize);
    for end in i + 1..=g.len() {
        if ok {
            break;
        }
        match g[end - 1].feature {
            Feature::Antiresonance => zeros += 1,
            Feature::Resonance => poles += 1,
        }
        for e in 0..=pairs - used {
            let z = zeros + 2 * e;
            let next = if z == poles {
                Some(k)
            } else {
                let want = if z > poles {
                    Token {
                        feature: Feature::Antiresonance,
                        multiplicity: (z - poles) as u32,
                    }
                } else {
                    Token {
                        feature: Feature::Resonance,
                        multiplicity: (poles - z) as u32,
                    }
                };
                (t.get(k) == Some(&want)).then_some(k + 1)
            };
            if let Some(k2) = next {
                if runs(g, t, (end, k2, used + e), pairs, memo) {
                    ok = true;
                    break;
                }
            }
        }
    }
    memo.insert((i, k, used), ok);
    ok
}

/// The reduced TF of `model` (its polynomial gcd divided out).
fn reduced(model: &Model) -> (Poly, Poly) {
    let tf = model.undamped_tf();
    let g = gcd(&tf.num, &tf.den);
    if g.is_constant() {
        (tf.num.clone(), tf.den.clone())
    } else {
        (
            tf.num.div_exact(&g).expect("the gcd divides"),
            tf.den.div_exact(&g).expect("the gcd divides"),
        )
    }
}

/// True when `p`, a polynomial in `Omega` alone, has no repeated root.
fn square_free_in_omega(p: &Poly) -> bool {
    gcd(p, &p.derivative(OMEGA)).is_constant()
}

/// The premises of the rule on `model`'s reduced TF: the leading and
/// constant coefficients in `Omega` of one sign on the orthant, and
/// `point` (a witness of a generic type) where numerator and denominator
/// are square-free and coprime.
fn premises_hold(num: &Poly, den: &Poly, point: &BTreeMap<String, Rat>) -> bool {
    let one_signed = |p: Poly| p.all_coefs_positive() || p.all_coefs_negative();
    let one_signed = [num, den]
        .iter()
        .all(|p| one_signed(p.lead_in(OMEGA)) && one_signed(p.subs(OMEGA, &Rat::ZERO)));
    let (Ok(n), Ok(d)) = (num.eval_except(OMEGA, point), den.eval_except(OMEGA, point)) else {
        return false;
    };
    one_signed && square_free_in_omega(&n) && square_free_in_omega(&d) && gcd(&n, &d).is_constant()
}

/// `analysis` (of `model`) with every unknown type that only generic
/// types certified impossible collapse to certified impossible as their
/// limit.
pub(crate) fn limits_of_generic_types(model: &Model, mut analysis: ModelAnalysis) -> ModelAnalysis {
    if certify_limits(model, &mut analysis.types) {
        analysis.types.sort_by_key(|v| super::status_rank(v.status)); // stable
    }
    analysis
}

/// The rule of [`limits_of_generic_types`] on a model's verdicts, left in
/// their order; true when it certified any.
pub(crate) fn certify_limits(model: &Model, types: &mut [TypeVerdict]) -> bool {
    if types.iter().all(|v| v.status != Status::Unknown) {
        return false;
    }
    let (num, den) = reduced(model);
    let (a, r) = (num.degree(OMEGA), den.degree(OMEGA));
    let Some(point) = types
        .iter()
        .filter(|v| v.status == Status::Possible && v.frf_type.is_generic(r))
        .find_map(|v| v.witness.clone())
    else {
        return false;
    };
    if !premises_hold(&num, &den, &point) {
        return false;
    }
    let generic: Vec<(FrfType, Status)> = types
        .iter()
        .filter(|v| v.frf_type.is_generic(r))
        .map(|v| (v.frf_type.clone(), v.status))
        .collect();
    let mut changed = false;
    for v in types
        .iter_mut()
        .filter(|v| v.status == Status::Unknown && !v.frf_type.is_generic(r))
    {
        let mut limit_of = Vec::new();
        let mut all_impossible = true;
        for (g, s) in &generic {
            if gathers_into(g, &v.frf_type, a, r) {
                all_impossible &= *s == Status::Impossible;
                limit_of.push(g.clone());
            }
        }
        if all_impossible {
            limit_of.sort();
            v.status = Status::Impossible;
            v.certificate = Some(Proof {
                stratum: Vec::new(),
                open: OpenProof::Limits {
                    point: point.clone(),
                    generic: limit_of,
                },
                factors: Vec::new(),
                unlisted: None,
            });
            changed = true;
        }
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(s: &str) -> FrfType {
        s.parse().unwrap()
    }

    #[test]
    fn examples_of_gathering() {
        // A pole and a zero meet and cancel: ARAR -> AR (either pair).
        assert!(gathers_into(&t("ARAR"), &t("AR"), 2, 2));
        // Two zeros between poles cannot come from alternating roots by
        // one cancellation next to them.
        assert!(!gathers_into(&t("ARAR"), &t("RAA"), 2, 2));
        // A conjugate pair lands on the axis as a double zero.
        assert!(gathers_into(&t("RR (nm)"), &t("RA^2R"), 2, 2));
        // ... but not as two simple zeros.
        assert!(!gathers_into(&t("RR (nm)"), &t("RAAR"), 2, 2));
        // Two zeros meet: a double zero.
        assert!(gathers_into(&t("RAAR"), &t("RA^2R"), 2, 2));
    }

    #[test]
    fn no_witnessed_type_is_certified_as_a_limit_and_certified_ones_come_out_again() {
        // At 4 masses every type is decided. Each non-generic verdict left
        // open again: a type with an exact witness must stay open (the
        // rule would contradict the witness), and an impossible one either
        // stays open or is certified again.
        use super::super::{analyze, SearchLimits};
        let mut again = 0;
        for id in [
            "N4-g0-a1.0-s2.0",
            "N4-g1-a2.1-s3.1",
            "N4-g2-a3.1-s3.2",
            "N4-g1-a3.1-s4.1",
        ] {
            let m = Model::from_id(id).unwrap();
            let full = analyze(&m, &SearchLimits::default());
            let r = full.denominator.degree(OMEGA);
            for (i, v) in full.types.iter().enumerate() {
                if v.frf_type.is_generic(r) || v.status == Status::Unknown {
                    continue;
                }
                let mut open = full.clone();
                open.types[i].status = Status::Unknown;
                open.types[i].certificate = None;
                open.types[i].witness = None;
                open.types[i].path = None;
                open.types[i].algebraic = None;
                open.types[i].isolated = None;
                let after = limits_of_generic_types(&m, open);
                let w = after
                    .types
                    .iter()
                    .find(|x| x.frf_type == v.frf_type)
                    .unwrap();
                match v.status {
                    Status::Possible => {
                        assert_eq!(
                            w.status,
                            Status::Unknown,
                            "{id}: {} has a witness",
                            v.frf_type
                        )
                    }
                    _ if w.status == Status::Impossible => {
                        again += 1;
                        // `mms prove` writes the argument out with the
                        // generic types it names.
                        let text = super::super::explain(
                            &after,
                            &v.frf_type,
                            super::super::ExplainFormat::Markdown,
                        )
                        .unwrap();
                        let Some(Proof {
                            open: OpenProof::Limits { generic, .. },
                            ..
                        }) = &w.certificate
                        else {
                            panic!("{id}: {} without a limits certificate", v.frf_type)
                        };
                        assert!(text.contains("as a limit of generic types"), "{text}");
                        assert!(
                            generic.iter().all(|g| text.contains(&g.to_string())),
                            "{text}"
                        );
                    }
                    _ => {}
                }
            }
        }
        assert!(again > 10, "{again}");
    }

    #[test]
    fn a_cancellation_between_two_zeros_of_a_chain_without_gap_is_a_limit_of_impossible_types() {
        // N5-g0-a1.0-s2.0: force on mass 1, position of mass 2, a free
        // chain. Its numerator is k12 times the determinant of masses
        // 3..5 held at mass 2, a chain of simple roots that interlace with
        // the poles (no generic type has two zeros in a row), so a pole
        // cancelled between or beside two zeros (RAARR) is the limit of
        // generic types with AA only.
        let m = Model::from_id("N5-g0-a1.0-s2.0").unwrap();
        let (num, den) = reduced(&m);
        let (a, r) = (num.degree(OMEGA), den.degree(OMEGA));
        let limit_of: Vec<FrfType> = super::super::candidate_types(a, r)
            .into_iter()
            .filter(|g| g.is_generic(r) && gathers_into(g, &t("RAARR"), a, r))
            .collect();
        assert!(!limit_of.is_empty());
        for g in &limit_of {
            let s = g.to_string();
            assert!(s.contains("AA") || g.nonminimum_phase, "{g}");
        }
    }
}
