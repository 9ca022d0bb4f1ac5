//! Generalised Newtonian fluids: a viscosity η(γ̇) that depends on the shear rate
//! γ̇ = √(2 D:D), D = (∇u + ∇uᵀ)/2, and no memory (τ = 2η(γ̇) D). A family beside the
//! viscoelastic models of Table I; case files name a law as `fluid.model`, with its
//! parameters as `fluid.<key>`.
//!
//! Every law is cut at η0 = `fluid.viscosity`, the largest viscosity the fluid takes, which
//! is also what the explicit viscous step limit (28) uses:
//!
//! | name | η(γ̇) | parameters |
//! | --- | --- | --- |
//! | `power-law` | min(η0, K γ̇^{n−1}) | `consistency` K, `power_index` n |
//! | `carreau-yasuda` | η∞ + (η0 − η∞)[1 + (λ_c γ̇)^a]^{(n−1)/a} (Yasuda et al. 1981) | `time_constant` λ_c, `power_index` n, `yasuda_exponent` a, `infinite_shear_viscosity` η∞ |
//! | `cross` | η∞ + (η0 − η∞)/[1 + (λ_c γ̇)^m] (Cross 1965) | `time_constant` λ_c, `cross_exponent` m, `infinite_shear_viscosity` η∞ |
//! | `herschel-bulkley` | min(η0, K γ̇^{n−1} + τ_y(1 − e^{−mγ̇})/γ̇) (Papanastasiou 1987) | `yield_stress` τ_y, `consistency` K, `power_index` n, `regularisation` m |
//! | `bingham` | herschel-bulkley with n = 1 (K the plastic viscosity) | `yield_stress`, `consistency`, `regularisation` |
//!
//! The power law's cut is its usual regularisation at vanishing shear rate (n < 1: η → ∞
//! on a channel's centre-line); Papanastasiou's exponential makes the Bingham and
//! Herschel–Bulkley viscosities finite (K + τ_y m at γ̇ = 0 when n = 1) and smooth, and the
//! regularised flow approaches the ideal one as m grows (plug where |τ| < τ_y).
//! The shear stress τ(γ̇) = η(γ̇)γ̇ is non-decreasing for every law here (n ≥ 0), so a steady
//! shear stress fixes the shear rate.

use crate::engine::rheology::models::Parameter;

/// A viscosity law η(γ̇) (module docs); `Constant` for the Newtonian and viscoelastic fluids.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViscosityLaw {
    Constant,
    PowerLaw {
        consistency: f64,
        power_index: f64,
    },
    CarreauYasuda {
        time_constant: f64,
        power_index: f64,
        yasuda_exponent: f64,
        infinite_shear_viscosity: f64,
    },
    Cross {
        time_constant: f64,
        exponent: f64,
        infinite_shear_viscosity: f64,
    },
    HerschelBulkley {
        yield_stress: f64,
        consistency: f64,
        power_index: f64,
        regularisation: f64,
    },
}

impl ViscosityLaw {
    pub fn is_constant(&self) -> bool {
        matches!(self, ViscosityLaw::Constant)
    }

    /// The name in case files (None for `Constant`).
    pub fn name(&self) -> Option<&'static str> {
        Some(match self {
            ViscosityLaw::Constant => return None,
            ViscosityLaw::PowerLaw { .. } => "power-law",
            ViscosityLaw::CarreauYasuda { .. } => "carreau-yasuda",
            ViscosityLaw::Cross { .. } => "cross",
            ViscosityLaw::HerschelBulkley { power_index, .. } if *power_index == 1.0 => "bingham",
            ViscosityLaw::HerschelBulkley { .. } => "herschel-bulkley",
        })
    }

    /// η(γ̇) for the cut η0 (γ̇ ≥ 0).
    pub fn viscosity(&self, eta0: f64, shear_rate: f64) -> f64 {
        let g = shear_rate.abs();
        match *self {
            ViscosityLaw::Constant => eta0,
            ViscosityLaw::PowerLaw {
                consistency,
                power_index,
            } => cut(eta0, consistency * g.powf(power_index - 1.0)),
            ViscosityLaw::CarreauYasuda {
                time_constant,
                power_index,
                yasuda_exponent: a,
                infinite_shear_viscosity: inf,
            } => cut(
                eta0,
                inf + (eta0 - inf)
                    * (1.0 + (time_constant * g).powf(a)).powf((power_index - 1.0) / a),
            ),
            ViscosityLaw::Cross {
                time_constant,
                exponent,
                infinite_shear_viscosity: inf,
            } => cut(
                eta0,
                inf + (eta0 - inf) / (1.0 + (time_constant * g).powf(exponent)),
            ),
            ViscosityLaw::HerschelBulkley {
                yield_stress,
                consistency,
                power_index,
                regularisation: m,
            } => {
                // τ_y(1 − e^{−mγ̇})/γ̇ → τ_y m as γ̇ → 0; −expm1 keeps it exact there.
                let plastic = if g * m > 1e-12 {
                    yield_stress * (-(-m * g).exp_m1()) / g
                } else {
                    yield_stress * m
                };
                cut(eta0, consistency * g.powf(power_index - 1.0) + plastic)
            }
        }
    }

    /// The shear stress η(γ̇)γ̇ (sign of γ̇).
    pub fn shear_stress(&self, eta0: f64, shear_rate: f64) -> f64 {
        self.viscosity(eta0, shear_rate) * shear_rate
    }
}

/// min(η0, η); an infinite or NaN η (0^{n−1} with n < 1) is cut too.
fn cut(eta0: f64, eta: f64) -> f64 {
    if eta.is_nan() || eta > eta0 {
        eta0
    } else {
        eta
    }
}

/// A law as case files name it: its parameters and how it is built from their values.
#[derive(Clone, Copy, Debug)]
pub struct LawEntry {
    pub name: &'static str,
    /// η(γ̇), for the key reference.
    pub meaning: &'static str,
    pub parameters: &'static [Parameter],
    pub build: fn(&[f64]) -> ViscosityLaw,
}

fn non_negative(v: f64) -> Result<f64, String> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be a non-negative number, got {v}"))
    }
}

fn positive(v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be a positive number, got {v}"))
    }
}

const CONSISTENCY: Parameter = Parameter {
    key: "consistency",
    meaning: "K > 0, the consistency",
    check: positive,
};
const POWER_INDEX: Parameter = Parameter {
    key: "power_index",
    meaning: "n ∈ (0, 3], the power-law index",
    check: |n| {
        if n.is_finite() && n > 0.0 && n <= 3.0 {
            Ok(n)
        } else {
            Err(format!("must be in (0, 3], got {n}"))
        }
    },
};
const TIME_CONSTANT: Parameter = Parameter {
    key: "time_constant",
    meaning: "λ_c > 0, the time constant",
    check: positive,
};
const INFINITE_SHEAR: Parameter = Parameter {
    key: "infinite_shear_viscosity",
    meaning: "η∞ ≥ 0, the infinite-shear viscosity",
    check: non_negative,
};
const YIELD_STRESS: Parameter = Parameter {
    key: "yield_stress",
    meaning: "τ_y ≥ 0, the yield stress",
    check: non_negative,
};
const REGULARISATION: Parameter = Parameter {
    key: "regularisation",
    meaning: "m > 0, Papanastasiou's regularisation exponent",
    check: positive,
};

/// Every generalised Newtonian law, as case files name them.
pub const LAWS: &[LawEntry] = &[
    LawEntry {
        name: "power-law",
        meaning: "min(η0, K γ̇^{n−1})",
        parameters: &[CONSISTENCY, POWER_INDEX],
        build: |v| ViscosityLaw::PowerLaw {
            consistency: v[0],
            power_index: v[1],
        },
    },
    LawEntry {
        name: "carreau-yasuda",
        meaning: "η∞ + (η0 − η∞)[1 + (λ_c γ̇)^a]^{(n−1)/a} (Yasuda et al. 1981)",
        parameters: &[
            TIME_CONSTANT,
            POWER_INDEX,
            Parameter {
                key: "yasuda_exponent",
                meaning: "a > 0, the Yasuda exponent",
                check: positive,
            },
            INFINITE_SHEAR,
        ],
        build: |v| ViscosityLaw::CarreauYasuda {
            time_constant: v[0],
            power_index: v[1],
            yasuda_exponent: v[2],
            infinite_shear_viscosity: v[3],
        },
    },
    LawEntry {
        name: "cross",
        meaning: "η∞ + (η0 − η∞)/[1 + (λ_c γ̇)^m] (Cross 1965)",
        parameters: &[
            TIME_CONSTANT,
            Parameter {
                key: "cross_exponent",
                meaning: "m > 0, the Cross exponent",
                check: positive,
            },
            INFINITE_SHEAR,
        ],
        build: |v| ViscosityLaw::Cross {
            time_constant: v[0],
            exponent: v[1],
            infinite_shear_viscosity: v[2],
        },
    },
    LawEntry {
        name: "herschel-bulkley",
        meaning: "min(η0, K γ̇^{n−1} + τ_y(1 − e^{−mγ̇})/γ̇) (Papanastasiou 1987)",
        parameters: &[YIELD_STRESS, CONSISTENCY, POWER_INDEX, REGULARISATION],
        build: |v| ViscosityLaw::HerschelBulkley {
            yield_stress: v[0],
            consistency: v[1],
            power_index: v[2],
            regularisation: v[3],
        },
    },
    LawEntry {
        name: "bingham",
        meaning: "Herschel–Bulkley with n = 1 (K the plastic viscosity)",
        parameters: &[YIELD_STRESS, CONSISTENCY, REGULARISATION],
        build: |v| ViscosityLaw::HerschelBulkley {
            yield_stress: v[0],
            consistency: v[1],
            power_index: 1.0,
            regularisation: v[2],
        },
    },
];

impl LawEntry {
    /// The entry named `name`.
    pub fn named(name: &str) -> Option<&'static LawEntry> {
        LAWS.iter().find(|l| l.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each law at its limits: the power law is K γ̇^{n−1} below its cut; Carreau–Yasuda and
    /// Cross run from η0 at rest to η∞; Bingham's viscosity is K + τ_y/γ̇ once mγ̇ ≫ 1 and
    /// K + τ_y m at rest; every shear stress is non-decreasing.
    #[test]
    fn laws_at_their_limits() {
        let eta0 = 10.0;
        let power = ViscosityLaw::PowerLaw {
            consistency: 2.0,
            power_index: 0.5,
        };
        assert!((power.viscosity(eta0, 4.0) - 1.0).abs() < 1e-14);
        assert_eq!(power.viscosity(eta0, 0.0), eta0);
        let carreau = ViscosityLaw::CarreauYasuda {
            time_constant: 1.0,
            power_index: 0.4,
            yasuda_exponent: 2.0,
            infinite_shear_viscosity: 0.1,
        };
        assert_eq!(carreau.viscosity(eta0, 0.0), eta0);
        assert!((carreau.viscosity(eta0, 1e9) - 0.1).abs() < 1e-3);
        let cross = ViscosityLaw::Cross {
            time_constant: 1.0,
            exponent: 1.0,
            infinite_shear_viscosity: 0.0,
        };
        assert!((cross.viscosity(eta0, 1.0) - 5.0).abs() < 1e-14);
        let bingham = ViscosityLaw::HerschelBulkley {
            yield_stress: 3.0,
            consistency: 0.5,
            power_index: 1.0,
            regularisation: 1000.0,
        };
        assert!((bingham.viscosity(1e9, 2.0) - (0.5 + 1.5)).abs() < 1e-12);
        assert!((bingham.viscosity(1e9, 0.0) - (0.5 + 3000.0)).abs() < 1e-9);
        for law in [power, carreau, cross, bingham] {
            let mut last = 0.0;
            for k in 0..200 {
                let g = 1e-4 * 1.1f64.powi(k);
                let tau = law.shear_stress(eta0, g);
                assert!(tau >= last - 1e-12, "{law:?} at {g}");
                last = tau;
            }
        }
    }
}
