use std::time::Instant;
fn main() {
    for n in [5usize, 6, 7, 8] {
        let ms = mms::rule3_models(n).unwrap();
        let m = ms[ms.len() / 3];
        let t = Instant::now();
        let u = m.undamped_tf();
        let t1 = t.elapsed();
        let d = m.damped_tf(mms::Output::Position);
        let t2 = t.elapsed();
        let r = d.render(&mms::render::RenderOptions::latex());
        let t3 = t.elapsed();
        let g = u.common_factor();
        let t4 = t.elapsed();
        println!("N={n} {m} und terms {}/{} {:?}; damped terms {}/{} {:?}; render {} chars {:?}; gcd {} {:?}", u.num.num_terms(), u.den.num_terms(), t1, d.num.num_terms(), d.den.num_terms(), t2 - t1, r.len(), t3 - t2, g, t4 - t3);
    }
}
