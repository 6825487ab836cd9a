//! Isotropic linear-elastic materials.

use super::StructureError;

/// An isotropic material (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E, Pa.
    pub youngs_modulus: f64,
    /// Poisson's ratio ν, in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Shear modulus G, Pa; E/(2(1+ν)) unless given.
    pub shear_modulus: f64,
    /// Density ρ, kg/m³.
    pub density: f64,
}

impl Material {
    /// Validates E > 0, ρ > 0, −1 < ν < 0.5 and G > 0 (default E/(2(1+ν))).
    pub fn new(
        youngs_modulus: f64,
        poisson_ratio: f64,
        density: f64,
        shear_modulus: Option<f64>,
    ) -> Result<Self, StructureError> {
        super::positive("youngs_modulus", youngs_modulus)?;
        super::positive("density", density)?;
        if !(poisson_ratio.is_finite() && poisson_ratio > -1.0 && poisson_ratio < 0.5) {
            return Err(StructureError::PoissonRatio {
                value: poisson_ratio,
            });
        }
        let shear_modulus = shear_modulus.unwrap_or(youngs_modulus / (2.0 * (1.0 + poisson_ratio)));
        super::positive("shear_modulus", shear_modulus)?;
        Ok(Self {
            youngs_modulus,
            poisson_ratio,
            shear_modulus,
            density,
        })
    }
}
