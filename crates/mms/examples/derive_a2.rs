//! Derives and prints the transfer function of the paper's model A2
//! (force on m1 against the ground, position of m2, free chain).
//!
//! Run with `cargo run -p mms --example derive_a2`.

use mms::render::RenderOptions;
use mms::{Model, Output};

fn main() -> Result<(), mms::ModelError> {
    let a2 = Model::from_id("A2")?;
    println!("model {} ({})", a2.name(), a2.id());
    println!("parameters: {}", a2.undamped_parameters().join(", "));
    let tf = a2.undamped_tf();
    println!(
        "inertance  G(Omega) = {}",
        tf.render(&RenderOptions::text())
    );
    println!("           LaTeX: {}", tf.render(&RenderOptions::latex()));
    println!(
        "receptance          = {}",
        tf.output(Output::Position).render(&RenderOptions::text())
    );
    let damped = a2.damped_tf(Output::Acceleration);
    println!(
        "damped inertance G(s) = {}",
        damped.render(&RenderOptions::text())
    );
    Ok(())
}
