//! Isotropic linear-elastic materials.

use super::{in_range, Field, StructureError};
use crate::limits as L;

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
    /// Validates E and G in [`L::MODULUS`] (G defaults to E/(2(1+ν))), ρ in [`L::DENSITY`]
    /// and −1 < ν < 0.5.
    ///
    /// ```
    /// use flexcraft::structure::{Field, Material, StructureError};
    /// let al = Material::new(70e9, 0.3, 2700.0, None).unwrap();
    /// assert!((al.shear_modulus - 70e9 / 2.6).abs() < 1.0);
    /// let e = Material::new(70e9, 0.5, 2700.0, None).unwrap_err();
    /// assert_eq!(e.field(), Field::PoissonRatio);
    /// ```
    pub fn new(
        youngs_modulus: f64,
        poisson_ratio: f64,
        density: f64,
        shear_modulus: Option<f64>,
    ) -> Result<Self, StructureError> {
        in_range(Field::YoungsModulus, youngs_modulus, L::MODULUS)?;
        in_range(Field::PoissonRatio, poisson_ratio, L::POISSON)?;
        in_range(Field::Density, density, L::DENSITY)?;
        let shear_modulus = match shear_modulus {
            Some(g) => in_range(Field::ShearModulus, g, L::MODULUS)?,
            None => youngs_modulus / (2.0 * (1.0 + poisson_ratio)),
        };
        Ok(Self {
            youngs_modulus,
            poisson_ratio,
            shear_modulus,
            density,
        })
    }
}
