//! A model's analysis carried over to another member of its renumbering
//! class: every polynomial, variable name and mass number renamed. The
//! mirrored model's transfer function is this one's with the names
//! replaced, so a witness stays a witness and a certificate a certificate
//! (the checker verifies every one it is given, as for any other).

use super::{
    AlgebraicWitness, BlockPoleSigns, BlockSign, Cancellation, ConditionRule, CriticalFactor,
    Definiteness, FactorProof, IsolatedWitness, MergePath, ModelAnalysis, OpenProof, PolePose,
    PoleSigns, Proof, RegionSample, RemainderFactor, SignCase, SignCondition, Substitution,
    TypeVerdict,
};
use crate::model::Model;
use poly::{Poly, Rat};
use std::collections::BTreeMap;

/// Parameter names and mass numbers of one model in another.
pub(crate) struct Renaming {
    names: BTreeMap<String, String>,
    masses: Vec<usize>,
}

impl Renaming {
    /// From `model` to its [`Model::mirrored`] model (the names that do not
    /// change are not in the map).
    pub(crate) fn mirror(model: &Model) -> Renaming {
        Renaming {
            names: crate::identifiability::mirror_renaming(model),
            masses: (0..=model.n_masses())
                .map(|i| model.mirrored_mass(i))
                .collect(),
        }
    }

    /// From `model` to itself or its reciprocal: nothing renamed.
    pub(crate) fn identity(model: &Model) -> Renaming {
        Renaming {
            names: BTreeMap::new(),
            masses: (0..=model.n_masses()).collect(),
        }
    }

    fn name(&self, v: &str) -> String {
        self.names.get(v).cloned().unwrap_or_else(|| v.to_string())
    }

    fn poly(&self, p: &Poly) -> Poly {
        p.rename(|v| self.name(v))
    }

    fn polys(&self, ps: &[Poly]) -> Vec<Poly> {
        ps.iter().map(|p| self.poly(p)).collect()
    }

    fn point(&self, p: &BTreeMap<String, Rat>) -> BTreeMap<String, Rat> {
        p.iter().map(|(k, v)| (self.name(k), v.clone())).collect()
    }

    /// `analysis` of the model this renaming starts from, as the analysis
    /// of `target`, the model it leads to.
    pub(crate) fn analysis(&self, a: &ModelAnalysis, target: &Model) -> ModelAnalysis {
        ModelAnalysis {
            id: target.name(),
            generic_id: target.id(),
            masses: target.n_masses(),
            gap: target.gap(),
            actuator: [target.actuator().plus, target.actuator().minus],
            sensor: [target.sensor().plus, target.sensor().minus],
            numerator: self.poly(&a.numerator),
            denominator: self.poly(&a.denominator),
            types: a.types.iter().map(|v| self.verdict(v)).collect(),
            pzc: a.pzc.iter().map(|c| self.cancellation(c)).collect(),
            critical: a.critical.iter().map(|c| self.critical(c)).collect(),
        }
    }

    pub(crate) fn verdict(&self, v: &TypeVerdict) -> TypeVerdict {
        TypeVerdict {
            frf_type: v.frf_type.clone(),
            status: v.status,
            witness: v.witness.as_ref().map(|w| self.point(w)),
            certificate: v.certificate.as_ref().map(|p| self.proof(p)),
            path: v.path.as_ref().map(|p| MergePath {
                parameters: p
                    .parameters
                    .iter()
                    .map(|(k, v)| (self.name(k), v.clone()))
                    .collect(),
            }),
            algebraic: v.algebraic.as_ref().map(|a| AlgebraicWitness {
                minimal: a.minimal.clone(),
                interval: a.interval.clone(),
                cancelled: a.cancelled.clone(),
                multiple: a.multiple.clone(),
                parameters: a
                    .parameters
                    .iter()
                    .map(|(k, v)| (self.name(k), v.clone()))
                    .collect(),
            }),
            isolated: v.isolated.as_ref().map(|w| IsolatedWitness {
                fixed: self.point(&w.fixed),
                free: w
                    .free
                    .iter()
                    .map(|(k, v)| (self.name(k), v.clone()))
                    .collect(),
                cancelled: w.cancelled.clone(),
                multiple: w.multiple.clone(),
                poses: w
                    .poses
                    .iter()
                    .map(|p| PolePose {
                        pole: p.pole,
                        double: p.double,
                        factors: p.factors.clone().map(|f| self.poly(&f)),
                        numerator: p.numerator.clone().map(|f| self.poly(&f)),
                        denominator: p.denominator.clone().map(|f| self.poly(&f)),
                    })
                    .collect(),
                partition: w.partition.clone(),
            }),
        }
    }

    fn cancellation(&self, c: &Cancellation) -> Cancellation {
        let (num, den) = (self.poly(&c.num), self.poly(&c.den));
        Cancellation {
            condition: self.poly(&c.condition),
            substitution: self.substitution(&c.substitution),
            reduced: format!("({num})/({den})"),
            num,
            den,
        }
    }

    fn critical(&self, c: &CriticalFactor) -> CriticalFactor {
        CriticalFactor {
            factor: c.factor.as_ref().map(|f| self.poly(f)),
            size: c.size,
            cancels: c.cancels,
            status: c.status,
            sign: c.sign,
            definiteness: c.definiteness.as_ref().map(|d| self.definiteness(d)),
            substitution: c.substitution.as_ref().map(|s| self.substitution(s)),
        }
    }

    fn substitution(&self, s: &Substitution) -> Substitution {
        Substitution {
            var: self.name(&s.var),
            alpha: self.poly(&s.alpha),
            beta: self.poly(&s.beta),
        }
    }

    fn definiteness(&self, d: &Definiteness) -> Definiteness {
        match d {
            Definiteness::CompletedSquare { var, inner } => Definiteness::CompletedSquare {
                var: self.name(var),
                inner: Box::new(self.definiteness(inner)),
            },
            other => other.clone(),
        }
    }

    fn proof(&self, p: &Proof) -> Proof {
        Proof {
            stratum: p.stratum.iter().map(|s| self.substitution(s)).collect(),
            open: self.open(&p.open),
            factors: p.factors.iter().map(|f| self.factor(f)).collect(),
            unlisted: p.unlisted,
        }
    }

    fn factor(&self, f: &FactorProof) -> FactorProof {
        match f {
            FactorProof::Definite {
                factor,
                sign,
                definiteness,
            } => FactorProof::Definite {
                factor: self.poly(factor),
                sign: *sign,
                definiteness: self.definiteness(definiteness),
            },
            FactorProof::NeedsNoCancellation { factor } => FactorProof::NeedsNoCancellation {
                factor: self.poly(factor),
            },
            FactorProof::NeedsCancellation { factor } => FactorProof::NeedsCancellation {
                factor: self.poly(factor),
            },
            FactorProof::Wall {
                factor,
                substitution,
                proof,
            } => FactorProof::Wall {
                factor: self.poly(factor),
                substitution: self.substitution(substitution),
                proof: Box::new(self.proof(proof)),
            },
        }
    }

    fn open(&self, o: &OpenProof) -> OpenProof {
        match o {
            OpenProof::CollocatedModes {
                num_at_zero,
                den_at_zero,
            } => OpenProof::CollocatedModes {
                num_at_zero: self.poly(num_at_zero),
                den_at_zero: self.poly(den_at_zero),
            },
            OpenProof::PoleSigns(p) => OpenProof::PoleSigns(PoleSigns {
                remainder_unit: p.remainder_unit.clone(),
                remainder_factors: self.remainder_factors(&p.remainder_factors),
            }),
            OpenProof::BlockPoleSigns(b) => {
                let mut blocks: Vec<BlockSign> = b
                    .blocks
                    .iter()
                    .map(|s| {
                        // A run of masses stays a run, numbered upwards.
                        let mut masses: Vec<usize> =
                            s.masses.iter().map(|&i| self.masses[i]).collect();
                        masses.sort_unstable();
                        BlockSign {
                            masses,
                            numerator: self.poly(&s.numerator),
                            remainder: s.remainder,
                            unit: s.unit.clone(),
                            factors: self.remainder_factors(&s.factors),
                        }
                    })
                    .collect();
                // In chain order, as the prover lists them.
                blocks.sort_by_key(|s| s.masses.first().copied());
                OpenProof::BlockPoleSigns(BlockPoleSigns { blocks })
            }
            OpenProof::Descartes {
                part,
                sign_changes,
                needed,
            } => OpenProof::Descartes {
                part: self.poly(part),
                sign_changes: *sign_changes,
                needed: *needed,
            },
            OpenProof::Regions {
                var,
                walls,
                gaps,
                samples,
            } => OpenProof::Regions {
                var: var.as_ref().map(|v| self.name(v)),
                walls: walls.iter().map(|w| self.substitution(w)).collect(),
                gaps: self.polys(gaps),
                samples: samples
                    .iter()
                    .map(|s| RegionSample {
                        point: self.point(&s.point),
                        frf_type: s.frf_type.clone(),
                    })
                    .collect(),
            },
            OpenProof::SignConditions {
                linear_parts,
                cases,
            } => OpenProof::SignConditions {
                linear_parts: self.polys(linear_parts),
                cases: cases
                    .iter()
                    .map(|c| SignCase {
                        assignment: c.assignment.clone(),
                        conditions: c.conditions.iter().map(|s| self.condition(s)).collect(),
                        multipliers: self.polys(&c.multipliers),
                    })
                    .collect(),
            },
            OpenProof::Limits { point, generic } => OpenProof::Limits {
                point: self.point(point),
                generic: generic.clone(),
            },
            OpenProof::TooManyResonances { .. }
            | OpenProof::TooFewResonances { .. }
            | OpenProof::Multiplicity
            | OpenProof::SimpleResonances => o.clone(),
        }
    }

    fn remainder_factors(&self, fs: &[RemainderFactor]) -> Vec<RemainderFactor> {
        fs.iter()
            .map(|f| RemainderFactor {
                factor: self.poly(&f.factor),
                exponent: f.exponent,
            })
            .collect()
    }

    fn condition(&self, c: &SignCondition) -> SignCondition {
        SignCondition {
            rule: match &c.rule {
                ConditionRule::SignAt {
                    other,
                    part,
                    derivative,
                    roots_above,
                } => ConditionRule::SignAt {
                    other: self.poly(other),
                    part: *part,
                    derivative: *derivative,
                    roots_above: *roots_above,
                },
                ConditionRule::RealRoots { other } => ConditionRule::RealRoots {
                    other: self.poly(other),
                },
                rule => rule.clone(),
            },
            derived: self.poly(&c.derived),
            square: self.poly(&c.square),
            positive: self.poly(&c.positive),
            reduced: self.poly(&c.reduced),
            strict: c.strict,
        }
    }
}
