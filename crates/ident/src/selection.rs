//! Forward selection of effects, shared by the frequency-domain
//! ([`crate::diagnose`]), time-domain ([`crate::nonlinear`]) and
//! inverse-dynamics ([`crate::idim`]) diagnoses: each step tries every
//! remaining hypothesis on the model with the effects kept so far, keeps
//! the best if its score is positive, and stops when none is; the last
//! step's hypotheses are the rejected ones. What a hypothesis is, how it
//! is fitted and scored, is the caller's; the order of the decisions is
//! here, once.

use crate::diagnose::{EffectKind, EffectVerdict};
use crate::evidence::Evidence;
use std::collections::BTreeMap;

/// A hypothesis tried at one step: its verdict (score positive: it earns
/// its parameters) and the fitted state it leads to.
pub(crate) struct Trial<S> {
    pub verdict: EffectVerdict,
    pub state: S,
}

/// The outcome of [`forward_select`].
pub(crate) struct Selected<S> {
    /// The kept hypotheses in the order they were kept.
    pub kept: Vec<EffectVerdict>,
    /// The state after the last kept one (the base if none was kept).
    pub state: S,
    /// The hypotheses of the last step, best first: none earned its
    /// parameters.
    pub rejected: Vec<EffectVerdict>,
}

/// The verdict `none`, with the best rejected hypothesis as its evidence.
pub(crate) fn none(rejected: &[EffectVerdict]) -> EffectVerdict {
    EffectVerdict {
        kind: EffectKind::None,
        parameters: BTreeMap::new(),
        evidence: Evidence::Nothing {
            best: rejected.first().cloned().map(Box::new),
        },
        score: 0.0,
        step: 0,
        unresolved: None,
        standard_errors: Default::default(),
    }
}

/// Forward selection from `base`: `try_step(current, kept, step)` fits
/// every remaining hypothesis added to `current` (whose kept effects are
/// `kept`) and returns the trials; the best one the band resolves (ties
/// keep the order of the trials) is kept if its score is positive, and
/// the next step starts from its state. An error of `try_step` ends the selection.
pub(crate) fn forward_select<S, E>(
    base: S,
    mut try_step: impl FnMut(&S, &[EffectKind], usize) -> Result<Vec<Trial<S>>, E>,
) -> Result<Selected<S>, E> {
    let mut kept: Vec<EffectVerdict> = Vec::new();
    let mut kinds: Vec<EffectKind> = Vec::new();
    let mut state = base;
    let mut step = 1;
    loop {
        let mut tried = try_step(&state, &kinds, step)?;
        // Stable: equal scores keep the caller's order.
        tried.sort_by(|a, b| b.verdict.score.total_cmp(&a.verdict.score));
        let best = tried
            .iter()
            .position(|t| t.verdict.unresolved.is_none())
            .filter(|&i| tried[i].verdict.score > 0.0);
        if let Some(i) = best {
            let best = tried.remove(i);
            kinds.push(best.verdict.kind);
            kept.push(best.verdict);
            state = best.state;
            step += 1;
            continue;
        }
        return Ok(Selected {
            kept,
            state,
            rejected: tried.into_iter().map(|t| t.verdict).collect(),
        });
    }
}
