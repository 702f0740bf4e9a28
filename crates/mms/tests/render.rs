//! Rendering: plain text must parse back to the same polynomial; LaTeX
//! (with the paper's abbreviations) is read back by a small LaTeX reader
//! written here, which is first validated on the paper's own LaTeX source of
//! the printed equations.

use mms::render::{render_poly, Format, RenderOptions};
use mms::{Model, Output};
use poly::Poly;

/// Reads the paper's LaTeX notation into the plain-text polynomial syntax:
/// `m_{1.2}` (also `m_{1,2}` as the text extraction sometimes has it) is
/// `m1*m2`, `m_{1+2}` is `(m1 + m2)`, `c_{12}`/`c_1` are `c12`/`c1`,
/// `c_{9,10}` is `c9_10`, `\Omega` is `Omega`, juxtaposition is a product.
fn latex_to_text(src: &str) -> String {
    let s: Vec<char> = src
        .replace(r"\left(", "(")
        .replace(r"\right)", ")")
        .chars()
        .collect();
    let mut out: Vec<(String, bool, bool)> = Vec::new(); // (text, starts operand, ends operand)
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        if c.is_whitespace() || c == '$' {
            i += 1;
        } else if s[i..].starts_with(&['\\', 'O', 'm', 'e', 'g', 'a']) {
            out.push(("Omega".into(), true, true));
            i += 6;
        } else if c == '^' {
            let (e, ni) = if s[i + 1] == '{' {
                let end = i + 2 + s[i + 2..].iter().position(|&x| x == '}').unwrap();
                (s[i + 2..end].iter().collect::<String>(), end + 1)
            } else {
                (s[i + 1].to_string(), i + 2)
            };
            out.push((format!("^{e}"), false, true));
            i = ni;
        } else if c.is_ascii_alphabetic() {
            let (sub, ni) = if s.get(i + 1) == Some(&'_') {
                if s[i + 2] == '{' {
                    let end = i + 3 + s[i + 3..].iter().position(|&x| x == '}').unwrap();
                    (s[i + 3..end].iter().collect::<String>(), end + 1)
                } else {
                    (s[i + 2].to_string(), i + 3)
                }
            } else {
                (String::new(), i + 1)
            };
            let text = if c == 'm' && sub.contains('+') {
                let parts: Vec<String> = sub.split('+').map(|k| format!("m{k}")).collect();
                format!("({})", parts.join(" + "))
            } else if c == 'm' && (sub.contains('.') || sub.contains(',')) {
                let parts: Vec<String> = sub.split(['.', ',']).map(|k| format!("m{k}")).collect();
                format!("({})", parts.join("*"))
            } else {
                format!("{c}{}", sub.replace(',', "_"))
            };
            out.push((text, true, true));
            i = ni;
        } else if c.is_ascii_digit() {
            let mut j = i;
            while j < s.len() && s[j].is_ascii_digit() {
                j += 1;
            }
            out.push((s[i..j].iter().collect(), true, true));
            i = j;
        } else if c == '(' {
            out.push(("(".into(), true, false));
            i += 1;
        } else if c == ')' {
            out.push((")".into(), false, true));
            i += 1;
        } else if c == '+' || c == '-' {
            out.push((format!(" {c} "), false, false));
            i += 1;
        } else {
            panic!("unexpected {c:?} in {src}");
        }
    }
    let mut text = String::new();
    for k in 0..out.len() {
        if k > 0 && out[k - 1].2 && out[k].1 {
            text.push('*');
        }
        text.push_str(&out[k].0);
    }
    text
}

fn read_latex(src: &str) -> Poly {
    latex_to_text(src)
        .parse()
        .unwrap_or_else(|e| panic!("{src}: {e}"))
}

#[test]
fn latex_reader_reads_the_papers_equations() {
    // LaTeX source as in the paper's text, eqs. (10), (39), (42) and (57-).
    let cases = [
        (
            "A1",
            false,
            r"m_{1.2.3}\Omega^2 - (c_{12}(m_{1.3} + m_{2.3}) + c_{23}m_1 m_{2+3})\Omega + c_{12}c_{23}m_{1+2+3}",
        ),
        (
            "B1",
            true,
            r"m_3m_{1+2}\Omega^2 - (m_{1+2+3}c_{23} + m_3c_1)\Omega + c_1c_{23}",
        ),
        (
            "B2",
            true,
            r"m_{2,3}\Omega^2 - c_{23}m_{1+2+3}\Omega + c_1c_{23}",
        ),
        (
            "C2",
            true,
            r"-m_1 m_2 \Omega^2 + (m_{1+2+3} c_{12} + m_2 c_1) \Omega - c_1 c_{12}",
        ),
    ];
    for (id, is_num, src) in cases {
        let tf = Model::from_id(id).unwrap().undamped_tf();
        let want = if is_num { tf.num } else { tf.den };
        let got = read_latex(src);
        assert!(got == want || got == -want.clone(), "{id}: {got} vs {want}");
    }
}

fn all_options() -> Vec<RenderOptions> {
    let mut v = Vec::new();
    for format in [Format::Text, Format::Latex, Format::Markdown] {
        for abbreviate in [true, false] {
            v.push(RenderOptions { format, abbreviate });
        }
    }
    v
}

fn read_back(s: &str, opts: &RenderOptions) -> Poly {
    match opts.format {
        Format::Text => s.parse().unwrap_or_else(|e| panic!("{s}: {e}")),
        Format::Latex => read_latex(s),
        Format::Markdown => {
            assert!(s.starts_with('$') && s.ends_with('$'), "{s}");
            read_latex(&s[1..s.len() - 1])
        }
    }
}

#[test]
fn every_format_reads_back_to_the_same_polynomial() {
    let mut polys: Vec<(Poly, &str)> = Vec::new();
    for n in 1..=4 {
        for m in mms::basic_models(n)
            .unwrap()
            .into_iter()
            .step_by(if n < 4 { 1 } else { 5 })
        {
            let tf = m.undamped_tf();
            polys.push((tf.num, "Omega"));
            polys.push((tf.den, "Omega"));
        }
    }
    for m in mms::degradation_free_models(3).unwrap() {
        let tf = m.damped_tf(Output::Velocity);
        polys.push((tf.num, "s"));
        polys.push((tf.den, "s"));
    }
    // some shapes that do not come from models
    for s in [
        "0",
        "-3/2",
        "2*(m1 + m2)^2*Omega^3 - 4*c12*m1",
        "-(m1 + m3)*(m2 + m4)*m5*Omega + c1*d12",
    ] {
        polys.push((s.parse().unwrap(), "Omega"));
    }
    for (p, var) in &polys {
        for opts in all_options() {
            if matches!(opts.format, Format::Latex | Format::Markdown)
                && p.to_string().contains('/')
            {
                continue; // the reader here knows no \frac
            }
            let s = render_poly(p, var, &opts);
            assert_eq!(&read_back(&s, &opts), p, "{opts:?}: {s}");
        }
    }
}

#[test]
fn paper_style_of_the_printed_equations() {
    // Our LaTeX next to the paper's (same content, our order of factors).
    let l = RenderOptions::latex();
    let tf = |id: &str| Model::from_id(id).unwrap().undamped_tf();
    // eq. (42): m_{2,3}\Omega^2 - c_{23}m_{1+2+3}\Omega + c_1c_{23}
    assert_eq!(
        render_poly(&tf("B2").num, "Omega", &l),
        r"m_{2.3} \Omega^{2} - c_{23} m_{1+2+3} \Omega + c_{1} c_{23}"
    );
    // eq. (39): m_3m_{1+2}\Omega^2 - (m_{1+2+3}c_{23} + m_3c_1)\Omega + c_1c_{23}
    assert_eq!(
        render_poly(&tf("B1").num, "Omega", &l),
        r"m_{3} m_{1+2} \Omega^{2} - \left(c_{1} m_{3} + c_{23} m_{1+2+3}\right) \Omega + c_{1} c_{23}"
    );
    // eq. (34) expanded: (c12 - m1 W)(c23 - m3 W)
    assert_eq!(
        render_poly(&tf("A4").num, "Omega", &RenderOptions::text()),
        "m1*m3*Omega^2 - (c12*m3 + c23*m1)*Omega + c12*c23"
    );
    // Den_C with our sign: the paper's -m_{1.2.3}\Omega^2 + m_3(c_{12}m_{1+2} + m_2c_1)\Omega - c_1c_{12}m_3
    assert_eq!(
        render_poly(&tf("C1").den, "Omega", &l),
        r"m_{1.2.3} \Omega^{2} - m_{3} \left(c_{1} m_{2} + c_{12} m_{1+2}\right) \Omega + c_{1} c_{12} m_{3}"
    );
}

#[test]
fn fractions() {
    let tf = Model::from_id("A3").unwrap().undamped_tf();
    let t = tf.output(Output::Position).render(&RenderOptions::text());
    // -num/(Omega*den), and both parts parse
    let (num, den) = t
        .strip_prefix("-(")
        .unwrap()
        .split_once(")/(Omega*(")
        .unwrap();
    assert_eq!(num.parse::<Poly>().unwrap(), tf.num);
    assert_eq!(
        den.strip_suffix("))").unwrap().parse::<Poly>().unwrap(),
        tf.den
    );
    let md = tf.render(&RenderOptions::markdown());
    assert!(
        md.starts_with(r"$\frac{c_{12} c_{23}}{m_{1.2.3} \Omega^{2}") && md.ends_with('$'),
        "{md}"
    );
    let d = Model::from_id("A3").unwrap().damped_tf(Output::Position);
    let t = d.render(&RenderOptions::text());
    let (num, den) = t.split_once(")/(").unwrap();
    assert_eq!(
        num.strip_prefix('(').unwrap().parse::<Poly>().unwrap(),
        d.num
    );
    assert_eq!(
        den.strip_suffix(')').unwrap().parse::<Poly>().unwrap(),
        d.den
    );
}
