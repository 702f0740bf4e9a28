//! The identification's notes in words: one sentence per note, for the
//! Markdown and HTML reports and the JSON's `notes` arrays.

use ident::classify::feature_name;
use ident::identify::{EquivalentFamily, NoEquivalent};
use ident::notes::{CandidateNote, ClassifyNote, IdentifyNote, SensorsNote};

/// A classification note in words.
pub fn classify_note(n: &ClassifyNote) -> String {
    match n {
        ClassifyNote::AssumedAverages { averages } => format!(
            "the line uncertainty comes from the coherence with {averages} averages assumed (the \
             count is not known)"
        ),
        ClassifyNote::ZeroHzLeftOut => {
            "the 0 Hz line is left out (the inertance is undefined there)".into()
        }
        ClassifyNote::Unexcited { lines } => format!(
            "{lines} lines without excitation (or a zero response) carry no information and \
             are left out"
        ),
        ClassifyNote::BandAsGiven {
            low_hz,
            high_hz,
            lines,
        } => format!(
            "band {low_hz:.4} .. {high_hz:.4} Hz as given: all {lines} lines are used, each \
             weighted by its uncertainty"
        ),
        ClassifyNote::BandWholeRange {
            low_hz,
            high_hz,
            lines,
        } => format!(
            "band {low_hz:.4} .. {high_hz:.4} Hz (no coherence or standard deviation: the whole \
             range): all {lines} lines are used, each weighted by its uncertainty"
        ),
        ClassifyNote::BandInformative {
            low_hz,
            high_hz,
            informative_lines,
            excited_lines,
            max_std_dev_nepers,
            max_std_dev_db,
        } => format!(
            "band {low_hz:.4} .. {high_hz:.4} Hz: {informative_lines} of {excited_lines} excited \
             lines informative (smoothed uncertainty <= {max_std_dev_nepers} nepers, \
             {max_std_dev_db:.1} dB)"
        ),
        ClassifyNote::LowWeightKept {
            lines,
            max_gap_decades,
        } => format!(
            "{lines} less certain lines inside the band are kept with their low weight (gaps up to \
             {max_gap_decades} decades, typically at antiresonances)"
        ),
        ClassifyNote::InformativeOutside { lines } => {
            format!("{lines} informative lines outside the band are not used")
        }
        ClassifyNote::ZeroResponse { lines } => {
            format!("{lines} lines with a zero response are left out")
        }
        ClassifyNote::OutliersKept { lines } => {
            format!("{lines} lines scatter like outliers: too many to be outliers, all kept")
        }
        ClassifyNote::OutliersLeftOut { at_hz } => {
            // The first five name where; the count says how many.
            let at: Vec<String> = at_hz.iter().take(5).map(|f| format!("{f:.4}")).collect();
            format!(
                "{} outlier lines left out (at {} Hz{})",
                at_hz.len(),
                at.join(", "),
                if at_hz.len() > 5 { ", ..." } else { "" }
            )
        }
        ClassifyNote::Merged {
            feature,
            first_hz,
            second_hz,
        } => format!(
            "two {}s at {first_hz:.4} and {second_hz:.4} Hz merged (closer than their widths)",
            feature_name(*feature)
        ),
        ClassifyNote::PhaseOnly {
            feature,
            freq_hz,
            phase_change_deg,
        } => format!(
            "{} at {freq_hz:.4} Hz found from its phase {} of {:.0} deg alone (no magnitude \
             extremum)",
            feature_name(*feature),
            match feature {
                mms::analysis::Feature::Antiresonance => "rise",
                mms::analysis::Feature::Resonance => "fall",
            },
            phase_change_deg.abs()
        ),
        ClassifyNote::PhaseUndetermined {
            at_hz,
            max_std_dev_rad,
        } => {
            let list: Vec<String> = at_hz.iter().map(|f| format!("{f:.4}")).collect();
            format!(
                "{} feature candidate(s) at {} Hz not claimed: the lines there are too uncertain \
                 for their phase (smoothed uncertainty above {max_std_dev_rad} rad), so a phase \
                 step there can be a turn of noise",
                at_hz.len(),
                list.join(", ")
            )
        }
        ClassifyNote::NearCancellation {
            first,
            first_hz,
            second,
            second_hz,
            relative_separation,
            confidence_cap,
        } => format!(
            "near pole-zero cancellation: {} at {first_hz:.4} Hz and {} at {second_hz:.4} Hz are \
             {:.1} % apart (the undamped model may cancel them); confidence capped at \
             {confidence_cap}",
            feature_name(*first),
            feature_name(*second),
            100.0 * relative_separation
        ),
        ClassifyNote::GainPhaseBudget {
            level_db,
            phase_deg,
        } => format!(
            "gain-phase budget: the level rises {level_db:+.1} dB and the phase {phase_deg:+.0} \
             deg more from the bottom to the top of the band than the features explain"
        ),
        ClassifyNote::LevelRiseWithPhaseRise => {
            "the unexplained level rise comes with a phase rise: an antiresonance may have been \
             missed"
                .into()
        }
        ClassifyNote::LevelFalls => "the level falls more than the features explain: a \
                                     resonance missed or just outside the band"
            .into(),
        ClassifyNote::PhaseFalls => {
            "the phase falls more than the features explain: a delay, or a resonance missed".into()
        }
        ClassifyNote::NoBudget => {
            "no gain-phase budget: too few feature-free lines at the band ends".into()
        }
        ClassifyNote::CoarseGrid {
            relative_spacing,
            confidence_scale,
        } => format!(
            "coarse grid: lines {:.0} % apart (median): a resonance and an antiresonance closer \
             than two lines can be missed; all confidences scaled by {confidence_scale:.2}",
            100.0 * relative_spacing
        ),
        ClassifyNote::AtBandEdge { feature, freq_hz } => format!(
            "{} at {freq_hz:.4} Hz is at the band edge: lower confidence",
            feature_name(*feature)
        ),
        ClassifyNote::LeftOut {
            feature,
            freq_hz,
            confidence,
            min_confidence,
        } => format!(
            "{} at {freq_hz:.4} Hz left out of the type: confidence {confidence:.2} < \
             {min_confidence:.2}",
            feature_name(*feature)
        ),
        ClassifyNote::UnflatBottom {
            slope,
            output,
            confidence_cap,
        } => format!(
            "with the features divided out, the inertance has slope {slope:+.1} (ln|G| per ln w) \
             at the bottom of the band, where a free chain is flat: a feature just below the band \
             (the type may lack it), or a wrong output kind ({output}); the level budget is not \
             used for nm, and the type's confidence is at most {confidence_cap}"
        ),
    }
}

/// A note of the identification in words.
pub fn identify_note(n: &IdentifyNote) -> String {
    match n {
        IdentifyNote::Binned { lines, max_bins } => format!(
            "lines: the {lines} lines were averaged into at most {max_bins} log-spaced bins, each \
             weighted by its lines' uncertainty"
        ),
        IdentifyNote::CandidatesFromTypeTable { masses, frf_type } => format!(
            "candidates: the {masses}-mass structures whose exact FRF-type table lists {frf_type} \
             as possible"
        ),
        IdentifyNote::CandidatesFromDegrees { masses, frf_type } => format!(
            "candidates: the {masses}-mass structures whose transfer function has the degrees \
             {frf_type} needs (the exact type table is not used above 3 masses)"
        ),
        IdentifyNote::NoStructureShowsType { masses, frf_type } => format!(
            "no {masses}-mass structure can show {frf_type}: every structure is fitted instead"
        ),
        IdentifyNote::GainKnown { gain } => format!(
            "scale: the actuator/sensor gain is taken as known ({gain}); parameters are absolute"
        ),
        IdentifyNote::GainFitted => "scale: the gain is fitted and m1 held at its start value; \
                                     only ratios of parameters are identified"
            .into(),
        IdentifyNote::SensorReversed => {
            "polarity: below its features the inertance is negative, where every chain's is 1 / \
             (sum of masses) > 0: the sensor (or actuator) counts the other way, so the gain is \
             taken negative"
                .into()
        }
        IdentifyNote::EquivalentsNotSolved { masses } => format!(
            "equivalents: the exactly equivalent parameter sets (Tab. 7) are back-solved up to \
             {} masses; with {masses} the exact elimination of one candidate can take minutes",
            ident::identify::EQUIVALENTS_MAX_MASSES
        ),
        IdentifyNote::PolarityFromFit {
            score_db,
            reversed_db,
        } => format!(
            "polarity: the level below the features read says the sensor counts the other way, \
             but with it the best fit misses the lines by {reversed_db:.2} dB, with the sensor's \
             own polarity by {score_db:.2} dB: features missed between or below the lines had \
             set that level"
        ),
        IdentifyNote::TypeOpened {
            masses,
            structures,
            score_db,
            type_db,
        } => format!(
            "candidates: those that show the type read miss the lines by {type_db:.2} dB, so the \
             {structures} other {masses}-mass structures with as many modes were fitted too (an \
             antiresonance closer to its resonance than the line spacing shows in no type); the \
             best of all misses them by {score_db:.2} dB"
        ),
        IdentifyNote::MassesFromFit {
            masses,
            score_db,
            fewer_db,
        } => format!(
            "masses: {masses}, from the fit: with one fewer the best structure misses the lines \
             by {fewer_db:.2} dB, with {masses} by {score_db:.2} dB (a resonance and antiresonance \
             closer than the line spacing, or sharper than it, show in no type)"
        ),
        IdentifyNote::MoreModesTried {
            masses,
            score_db,
            kept_db,
        } => format!(
            "masses: the best structure misses the lines by {kept_db:.2} dB; with {masses} masses \
             the best misses them by {score_db:.2} dB, not far enough below to take a mode more"
        ),
        IdentifyNote::NotFitted { structure, error } => {
            format!("{structure}: not fitted: {error}")
        }
    }
}

/// What a candidate table adds after a failed fit's structure.
pub fn failed_mark(failed: bool) -> &'static str {
    if failed {
        " (failed: a parameter at an end of its range)"
    } else {
        ""
    }
}

/// A note on a fitted candidate in words.
pub fn candidate_note(n: &CandidateNote) -> String {
    match n {
        CandidateNote::MassSpread { factor } => {
            format!("masses span a factor {}", readable(*factor, 0))
        }
        CandidateNote::AtRangeEnd { parameter, value } => format!(
            "{parameter} ends at {value:e}, an end of its physical range: the fit degenerates"
        ),
        CandidateNote::HeavilyDamped {
            damper,
            damping_ratio,
        } => format!(
            "{damper} is heavily damped (link damping ratio {})",
            readable(*damping_ratio, 2)
        ),
        CandidateNote::NoBackSolution {
            reason,
            parameters,
            determinable,
        } => {
            let surplus = parameters - determinable;
            format!(
                "no positive undamped parameter set reproduces the classified features: \
                 {reason}{}",
                if surplus > 0 {
                    format!(
                        " ({determinable} of {parameters} parameters determinable, Tab. 5: the \
                         structure has {surplus} degree(s) of freedom fewer than its FRF type has \
                         numbers)"
                    )
                } else {
                    String::new()
                }
            )
        }
    }
}

/// A note of the identification from several sensors in words.
pub fn sensors_note(n: &SensorsNote) -> String {
    match n {
        SensorsNote::CandidatesShowingTypes { masses } => format!(
            "candidates: every {masses}-mass chain and actuator (rules (1) and (2) with the first \
             sensor) with the sensors at the given locations, whose outputs can each show the type \
             classified there (outputs with fewer resonances than the most are not used to choose)"
        ),
        SensorsNote::NoChainShowsTypes { masses } => format!(
            "candidates: no {masses}-mass chain shows every output's type with the sensors at \
             these locations: every such chain is fitted instead"
        ),
        SensorsNote::MassesFromSensorPlaces { masses, from_types } => format!(
            "masses: {masses}, from the sensor places (the types read imply {from_types}; a \
             resonance and antiresonance closer than the line spacing show in no type)"
        ),
        SensorsNote::NotFitted { candidate } => format!("{candidate}: not fitted"),
    }
}

/// `x` with `decimals` decimals, or three significant digits from 1e4 on:
/// a degenerate fit gives ratios of 1e300.
/// A family of equivalent sets: its dimension, free parameters and their
/// ranges.
pub fn equivalent_family(f: &EquivalentFamily) -> String {
    let free = f.free.join(", ");
    let ranges: Vec<String> = f
        .ranges
        .iter()
        .map(|r| {
            let hi = r.hi.map_or("inf".to_string(), |h| format!("{h:.4e}"));
            format!("{:.4e} < {free} < {hi}", r.lo)
        })
        .collect();
    let ranges = if ranges.is_empty() {
        String::new()
    } else {
        format!(" ({})", ranges.join("; "))
    };
    format!("a {}-parameter family, free: {free}{ranges}", f.dimension)
}

/// Why a structure has no equivalent set.
pub fn no_equivalent(n: &NoEquivalent) -> String {
    match n {
        NoEquivalent::NoSolution { reason } => reason.to_string(),
        NoEquivalent::NotBackSolved { error } => format!("not back-solved: {error}"),
    }
}

fn readable(x: f64, decimals: usize) -> String {
    if x.is_finite() && x >= 1e4 {
        format!("{x:.2e}")
    } else {
        format!("{x:.decimals$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mms::analysis::Feature;
    use mms::backsolve::NoSolution;

    /// Sentences of the SPERTE, F-16 and TU/e reports, from their notes.
    #[test]
    fn notes_read_as_in_the_reports() {
        assert_eq!(
            classify_note(&ClassifyNote::BandInformative {
                low_hz: 0.9765625,
                high_hz: 258.7890625,
                informative_lines: 232,
                excited_lines: 2048,
                max_std_dev_nepers: 0.2,
                max_std_dev_db: 0.2 * 20.0 / std::f64::consts::LN_10,
            }),
            "band 0.9766 .. 258.7891 Hz: 232 of 2048 excited lines informative (smoothed \
             uncertainty <= 0.2 nepers, 1.7 dB)"
        );
        assert_eq!(
            classify_note(&ClassifyNote::OutliersLeftOut {
                at_hz: vec![3.5, 4.0, 7.0]
            }),
            "3 outlier lines left out (at 3.5000, 4.0000, 7.0000 Hz)"
        );
        assert_eq!(
            classify_note(&ClassifyNote::OutliersLeftOut {
                at_hz: (1..=7).map(f64::from).collect()
            }),
            "7 outlier lines left out (at 1.0000, 2.0000, 3.0000, 4.0000, 5.0000 Hz, ...)"
        );
        assert_eq!(
            classify_note(&ClassifyNote::PhaseOnly {
                feature: Feature::Resonance,
                freq_hz: 0.1268,
                phase_change_deg: -178.2,
            }),
            "resonance at 0.1268 Hz found from its phase fall of 178 deg alone (no magnitude \
             extremum)"
        );
        assert_eq!(
            classify_note(&ClassifyNote::NearCancellation {
                first: Feature::Antiresonance,
                first_hz: 9.0678,
                second: Feature::Resonance,
                second_hz: 9.1713,
                relative_separation: 9.1713 / 9.0678 - 1.0,
                confidence_cap: 0.4,
            }),
            "near pole-zero cancellation: antiresonance at 9.0678 Hz and resonance at 9.1713 Hz \
             are 1.1 % apart (the undamped model may cancel them); confidence capped at 0.4"
        );
        assert_eq!(
            identify_note(&IdentifyNote::GainKnown { gain: -1.0 }),
            "scale: the actuator/sensor gain is taken as known (-1); parameters are absolute"
        );
        assert_eq!(
            identify_note(&IdentifyNote::CandidatesFromTypeTable {
                masses: 1,
                frf_type: "C (nm)".parse().unwrap(),
            }),
            "candidates: the 1-mass structures whose exact FRF-type table lists C (nm) as possible"
        );
        assert_eq!(
            candidate_note(&CandidateNote::MassSpread { factor: 2.70e5 }),
            "masses span a factor 2.70e5"
        );
        assert_eq!(
            candidate_note(&CandidateNote::AtRangeEnd {
                parameter: "m2".into(),
                value: 1e-12,
            }),
            "m2 ends at 1e-12, an end of its physical range: the fit degenerates"
        );
        assert_eq!(
            candidate_note(&CandidateNote::HeavilyDamped {
                damper: "d1".into(),
                damping_ratio: f64::INFINITY,
            }),
            "d1 is heavily damped (link damping ratio inf)"
        );
        assert_eq!(
            candidate_note(&CandidateNote::NoBackSolution {
                reason: NoSolution::Contradiction,
                parameters: 5,
                determinable: 4,
            }),
            "no positive undamped parameter set reproduces the classified features: the \
             coefficient equations have no solution with all parameters positive (4 of 5 \
             parameters determinable, Tab. 5: the structure has 1 degree(s) of freedom fewer \
             than its FRF type has numbers)"
        );
        assert_eq!(
            sensors_note(&SensorsNote::NoChainShowsTypes { masses: 2 }),
            "candidates: no 2-mass chain shows every output's type with the sensors at these \
             locations: every such chain is fitted instead"
        );
    }
}
