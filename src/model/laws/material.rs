//! Elastic materials of the journal and bearing (MODEL.md §2).

use crate::error::{Error, in_range, in_range_open_closed};
use crate::error::{Result, positive, sig4};

/// Physical range of Young's modulus, Pa: from soft rubber (1e5) to beyond diamond (1e13).
pub const YOUNGS_MODULUS_RANGE: (f64, f64) = (1e5, 1e13);
use serde::{Deserialize, Serialize};

/// An isotropic linear-elastic material.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus `E`, Pa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio `nu`, in (-1, 0.5].
    pub poisson_ratio: f64,
}

impl Material {
    /// Structural steel of the paper's table 2: E = 207 GPa, nu = 0.3.
    pub const STEEL: Material = Material {
        youngs_modulus_pa: 207e9,
        poisson_ratio: 0.3,
    };

    /// A validated material.
    pub fn new(youngs_modulus_pa: f64, poisson_ratio: f64) -> Result<Self> {
        let m = Material {
            youngs_modulus_pa,
            poisson_ratio,
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks the domain of both constants.
    pub fn validate(&self) -> Result<()> {
        in_range(
            "youngs_modulus_pa",
            self.youngs_modulus_pa,
            YOUNGS_MODULUS_RANGE.0,
            YOUNGS_MODULUS_RANGE.1,
            "Pa",
        )?;
        in_range_open_closed("poisson_ratio", self.poisson_ratio, -1.0, 0.5)?;
        Ok(())
    }

    /// `sigma = (1 - nu^2)/E` (MODEL.md §2).
    pub fn sigma(&self) -> f64 {
        (1.0 - self.poisson_ratio * self.poisson_ratio) / self.youngs_modulus_pa
    }
}

/// The composite modulus `E*` with `1/E* = sigma_i + sigma_j` (MODEL.md §2).
pub fn effective_modulus(bearing: &Material, journal: &Material) -> f64 {
    1.0 / (bearing.sigma() + journal.sigma())
}

/// Radial geometry of a journal bearing. Built only through validating constructors, so the
/// journal is always strictly smaller than the bearing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BearingGeometry {
    bearing_radius: f64,
    journal_radius: f64,
    length: f64,
}

impl BearingGeometry {
    /// A validated geometry: all lengths positive and the journal strictly smaller than the bearing.
    pub fn new(bearing_radius: f64, journal_radius: f64, length: f64) -> Result<Self> {
        positive("bearing_radius", bearing_radius)?;
        positive("journal_radius", journal_radius)?;
        positive("length", length)?;
        if journal_radius >= bearing_radius {
            return Err(Error::invalid(
                "journal_radius",
                format!(
                    "the journal ({} m) must be smaller than the bearing ({} m): \
                     the radial clearance R_b - R_j must be > 0",
                    sig4(journal_radius),
                    sig4(bearing_radius)
                ),
            ));
        }
        Ok(BearingGeometry {
            bearing_radius,
            journal_radius,
            length,
        })
    }

    /// From the bearing radius and the radial clearance `c = R_b - R_j`.
    pub fn from_clearance(bearing_radius: f64, clearance: f64, length: f64) -> Result<Self> {
        positive("clearance", clearance)?;
        positive("bearing_radius", bearing_radius)?;
        if clearance >= bearing_radius {
            return Err(Error::invalid(
                "clearance",
                format!(
                    "the clearance ({} m) must be smaller than the bearing radius ({} m)",
                    sig4(clearance),
                    sig4(bearing_radius)
                ),
            ));
        }
        Self::new(bearing_radius, bearing_radius - clearance, length)
    }

    /// Bearing (hole) radius `R_b`, m.
    pub fn bearing_radius(&self) -> f64 {
        self.bearing_radius
    }

    /// Journal (pin) radius `R_j`, m.
    pub fn journal_radius(&self) -> f64 {
        self.journal_radius
    }

    /// Axial length (bearing width) `L`, m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Radial clearance `c = R_b - R_j`.
    pub fn clearance(&self) -> f64 {
        self.bearing_radius - self.journal_radius
    }
}
