//! Prints the paper's Tab. 3 as derived by the analysis engine: the
//! possible FRF types of every 3-mass model, and how many candidate types
//! were ruled out with a certificate.
//!
//! Run with `cargo run --release -p mms --example tab3`.

use mms::analysis::{analyze, SearchLimits, Status};
use mms::Model;

fn main() -> Result<(), mms::ModelError> {
    for (id, ..) in mms::PAPER_IDS {
        let model = Model::from_id(id)?;
        let start = std::time::Instant::now();
        let a = analyze(&model, &SearchLimits::default());
        let possible: Vec<String> = a.possible().iter().map(|t| t.to_string()).collect();
        let unknown: Vec<String> = a.unknown().iter().map(|t| t.to_string()).collect();
        let impossible = a
            .types
            .iter()
            .filter(|v| v.status == Status::Impossible)
            .count();
        println!(
            "{:4} possible: {:40} impossible: {:2} unknown: {:?} ({:.0} ms)",
            id,
            possible.join(", "),
            impossible,
            unknown,
            start.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
