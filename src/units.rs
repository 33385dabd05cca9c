//! Unit systems.
//!
//! | system | length | time | force | energy | drag γ | pressure | temperature |
//! |---|---|---|---|---|---|---|---|
//! | `cell` (default) | µm | s | pN | pN·µm | pN·s/µm | pN/µm² = Pa | K (kT = k_B·T, k_B = 1.380649e-5 pN·µm/K) |
//! | `lj` | σ | τ | ε/σ | ε | ε·τ/σ² | ε/σ³ | reduced: the `temperature` value *is* kT |
//!
//! In `cell` units kT at 298 K is 4.114e-3 pN·µm; pN·s/µm² = Pa·s, so a Stokes
//! drag 6πηa with η in Pa·s and a in µm comes out in pN·s/µm.

/// Boltzmann's constant in pN·µm/K (1.380649e-23 J/K).
pub const BOLTZMANN_PN_UM_PER_K: f64 = 1.380649e-5;

/// The unit system a deck runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum UnitSystem {
    /// µm, s, pN (the default).
    Cell,
    /// LAMMPS reduced units (σ, ε, τ; k_B = 1), for cross-checks.
    Lj,
}

/// A physical dimension a parameter or output column carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dim {
    Dimensionless,
    Length,
    Time,
    Force,
    Energy,
    /// Spring constant: force per length.
    Stiffness,
    /// Bending modulus κ: energy × length.
    BendingModulus,
    /// Angular stiffness: energy per rad².
    AngularStiffness,
    /// Angle in degrees.
    Degrees,
    Drag,
    Viscosity,
    Pressure,
    Temperature,
    /// Energy per length² (e.g. a surface tension).
    Tension,
    /// Events per unit time (a kinetic rate).
    Rate,
    /// Length per unit time.
    Velocity,
    /// Length² (a rest area).
    Area,
    /// Length³ (a rest volume).
    Volume,
    /// 1/length (a spontaneous curvature).
    Curvature,
}

impl UnitSystem {
    /// Parses the keyword used after `units` in a deck.
    pub fn from_keyword(word: &str) -> Option<Self> {
        match word {
            "cell" => Some(Self::Cell),
            "lj" => Some(Self::Lj),
            _ => None,
        }
    }

    /// kT (energy units) for a deck `temperature` value.
    pub fn kt(self, temperature: f64) -> f64 {
        match self {
            Self::Cell => BOLTZMANN_PN_UM_PER_K * temperature,
            Self::Lj => temperature,
        }
    }

    /// Human-readable unit of a dimension in this system.
    pub fn label(self, dim: Dim) -> &'static str {
        match (self, dim) {
            (_, Dim::Dimensionless) => "1",
            (_, Dim::Degrees) => "deg",
            (Self::Cell, Dim::Length) => "µm",
            (Self::Cell, Dim::Time) => "s",
            (Self::Cell, Dim::Force) => "pN",
            (Self::Cell, Dim::Energy) => "pN·µm",
            (Self::Cell, Dim::Stiffness) => "pN/µm",
            (Self::Cell, Dim::BendingModulus) => "pN·µm²",
            (Self::Cell, Dim::AngularStiffness) => "pN·µm/rad²",
            (Self::Cell, Dim::Drag) => "pN·s/µm",
            (Self::Cell, Dim::Viscosity) => "Pa·s",
            (Self::Cell, Dim::Pressure) => "Pa",
            (Self::Cell, Dim::Temperature) => "K",
            (Self::Cell, Dim::Tension) => "pN/µm",
            (Self::Cell, Dim::Rate) => "1/s",
            (Self::Cell, Dim::Velocity) => "µm/s",
            (Self::Cell, Dim::Area) => "µm²",
            (Self::Cell, Dim::Volume) => "µm³",
            (Self::Cell, Dim::Curvature) => "1/µm",
            (Self::Lj, Dim::Length) => "σ",
            (Self::Lj, Dim::Time) => "τ",
            (Self::Lj, Dim::Force) => "ε/σ",
            (Self::Lj, Dim::Energy) => "ε",
            (Self::Lj, Dim::Stiffness) => "ε/σ²",
            (Self::Lj, Dim::BendingModulus) => "ε·σ",
            (Self::Lj, Dim::AngularStiffness) => "ε/rad²",
            (Self::Lj, Dim::Drag) => "ε·τ/σ²",
            (Self::Lj, Dim::Viscosity) => "ε·τ/σ³",
            (Self::Lj, Dim::Pressure) => "ε/σ³",
            (Self::Lj, Dim::Temperature) => "ε/k_B",
            (Self::Lj, Dim::Tension) => "ε/σ²",
            (Self::Lj, Dim::Rate) => "1/τ",
            (Self::Lj, Dim::Velocity) => "σ/τ",
            (Self::Lj, Dim::Area) => "σ²",
            (Self::Lj, Dim::Volume) => "σ³",
            (Self::Lj, Dim::Curvature) => "1/σ",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kt_at_room_temperature_matches_the_brief() {
        let kt = UnitSystem::Cell.kt(298.0);
        assert!((kt - 4.114e-3).abs() < 5e-7, "kT(298 K) = {kt}");
    }
}
