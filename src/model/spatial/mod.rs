//! The spatial clearance joint's contact geometry: a journal free in all five relative degrees of
//! freedom but its turn, touching the bore along the bearing's width and the bearing's faces with
//! its shoulders. Pure functions of poses and velocities, no Rapier state.
//!
//! # Geometry
//!
//! The bearing is a bore of radius `R_b` and width `L` (the [`BearingGeometry`]'s length) between
//! two flat faces; the journal a pin of radius `R_j = R_b - c` that runs through it, between two
//! shoulders (flat annuli from `R_j` to the collars' outer radius `R_o`) `L + a` apart: `a` is
//! the axial play, the free axial travel of the journal when centred radially. The journal's
//! axis may tilt against the bore's.
//!
//! # Contacts
//!
//! Each contact is a region of a surface, its law a pressure integrated over the region by
//! Gauss quadrature inside the region's exact bounds ([`bore`], [`face`]):
//!
//! - **Bore**: in each plane of the bearing across its width (axial position `s`) the journal's
//!   section is an ellipse; its farthest point from the bore's axis penetrates `delta(s)`. The
//!   bore's law (a force for the whole width at a uniform penetration) acts as the line load
//!   `F(delta(s))/L` wherever `delta(s) > 0`. That region is found in closed form up to a root:
//!   the eccentricity of the journal's axis is affine in `s`, so `delta(s)` falls from each end
//!   of the width towards one plane; each end has its own region (a journal tilted in its
//!   clearance bears on both edges, on opposite sides), running to the root of `delta` or, when
//!   the whole width touches, to the plane of least penetration.
//! - **Faces**: a shoulder point penetrates the face plane linearly in its position on the
//!   annulus (`delta_c + rho r cos(psi)`), so the region past the face is whole circles and arcs
//!   bounded in closed form; the face law's pressure is `F(delta)/A` over the annulus's area.
//!
//! Every quadrature point is a [`ContactPoint`]: its penetration, the penetration's gradient
//! (the force direction: the force on the journal is `-F gradient` at the point, on the bearing
//! the opposite, so the elastic forces are the gradient of the contacts' elastic energy, moments
//! included, and momentum is exact) and its share of the law.

pub mod bore;
pub mod face;
pub mod quadrature;

pub use bore::{BoreRegion, BoreSection, bore_points, bore_region, bore_section};
pub use face::Shoulder;

use crate::error::{Error, Result, positive};
use crate::model::laws::{BearingGeometry, NormalContact, NormalForceLaw};
use rapier3d_f64::math::Vector;

/// The spatial geometry beyond the radial [`BearingGeometry`]: axial play and shoulder radius.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpatialGeometry {
    /// Axial play `a`: the journal's free axial travel when it is centred, m (> 0).
    pub axial_play: f64,
    /// Outer radius of the journal's shoulders (collars) `R_o`, m (> `R_j`).
    pub collar_radius: f64,
}

impl SpatialGeometry {
    /// The smallest axial play, m: the radial clearance's floor in scenes (1 nm). Below it the
    /// shoulders press both faces at once and the play is lost in the rounding of the journal's
    /// position (measured on the spatial panel: a play of 1e-12 m runs 100 times slower than one
    /// of 1e-9 m, and 1e-300 m stalls).
    pub const MIN_AXIAL_PLAY: f64 = 1e-9;

    /// The largest collar radius, in bearing radii: a shoulder wider than that is a plate, not a
    /// collar, and its flat-punch face stiffness (proportional to the radius) leaves every range.
    pub const MAX_COLLAR_RADII: f64 = 10.0;

    /// Checks the values against the radial geometry `radial` (field names as in this struct):
    /// an axial play from [`MIN_AXIAL_PLAY`](Self::MIN_AXIAL_PLAY) to the bearing's width, a
    /// collar radius above the journal's and at most
    /// [`MAX_COLLAR_RADII`](Self::MAX_COLLAR_RADII) bearing radii. Lengths are in metres.
    pub fn validate(&self, radial: &BearingGeometry) -> Result<()> {
        positive("axial_play", self.axial_play)?;
        positive("collar_radius", self.collar_radius)?;
        let sig4 = crate::error::sig4;
        if self.axial_play < Self::MIN_AXIAL_PLAY {
            return Err(Error::invalid(
                "axial_play",
                format!(
                    "must be at least {} m (got {} m): a smaller play is lost in the rounding of                      the journal's position; for a journal held axially, lock its axial motion",
                    sig4(Self::MIN_AXIAL_PLAY),
                    sig4(self.axial_play)
                ),
            ));
        }
        let most = |field: &str, value: f64, hi: f64, what: &str| -> Result<()> {
            if value > hi {
                return Err(Error::invalid(
                    field,
                    format!(
                        "must be at most {what}, {} m (got {} m; lengths are in metres, not mm)",
                        sig4(hi),
                        sig4(value)
                    ),
                ));
            }
            Ok(())
        };
        most(
            "axial_play",
            self.axial_play,
            radial.length(),
            "the bearing's width",
        )?;
        most(
            "collar_radius",
            self.collar_radius,
            Self::MAX_COLLAR_RADII * radial.bearing_radius(),
            "ten bearing radii",
        )?;
        if self.collar_radius <= radial.journal_radius() {
            return Err(Error::invalid(
                "collar_radius",
                format!(
                    "must exceed the journal radius {} m (got {} m): the shoulder is a ring \
                     around the pin",
                    sig4(radial.journal_radius()),
                    sig4(self.collar_radius)
                ),
            ));
        }
        Ok(())
    }
}

/// The law of the shoulders against the bearing's faces: a linear spring with Flores et al.'s
/// hysteresis damping, `F = K delta (1 + 8(1-cr)/(5 cr) delta_dot/delta_dot0)`, whose
/// restitution stays close to `cr` over its whole range (unlike Lankarani-Nikravesh's).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FaceLaw {
    /// Axial stiffness `K` of one shoulder against its face, N/m.
    pub stiffness: f64,
    /// Coefficient of restitution `cr`, in (0, 1].
    pub restitution: f64,
}

impl FaceLaw {
    /// The default restitution of a face knock (steel on steel, as the slider-crank benchmark's
    /// bore law).
    pub const DEFAULT_RESTITUTION: f64 = 0.9;

    /// A flat rigid punch of the shoulder's radius `collar_radius` (m) on an elastic half-space of
    /// effective modulus `effective_modulus` (Pa): Boussinesq's `K = 2 E* R_o`. An upper bound for
    /// the annulus (the pin's hole takes its middle away), and the order of a flat steel contact
    /// that has bedded in; choose your own stiffness when you know the collar's compliance.
    pub fn flat_punch(effective_modulus: f64, collar_radius: f64, restitution: f64) -> Self {
        FaceLaw {
            stiffness: 2.0 * effective_modulus * collar_radius,
            restitution,
        }
    }

    /// The normal law it stands for (checked: positive stiffness, restitution in (0, 1]).
    pub fn law(&self) -> Result<crate::model::laws::NormalModel> {
        let law = crate::model::laws::FloresEtAl::new(self.stiffness, 1.0, self.restitution)
            .map_err(|e| e.within("face"))?;
        Ok(crate::model::laws::NormalModel::FloresEtAl(law))
    }
}

/// Everything the spatial model of a clearance joint adds to the planar one: the geometry along
/// the axis and the faces' law.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpatialModel {
    /// Axial play and shoulders.
    pub geometry: SpatialGeometry,
    /// The shoulders' law against the faces.
    pub face: FaceLaw,
}

impl SpatialModel {
    /// Steel shoulders of radius `collar_radius` (m) with axial play `axial_play` (m) and the
    /// face law of a flat steel punch
    /// ([`FaceLaw::flat_punch`], E = 207 GPa, nu = 0.3, restitution
    /// [`FaceLaw::DEFAULT_RESTITUTION`]).
    pub fn steel(axial_play: f64, collar_radius: f64) -> Self {
        let steel = crate::model::laws::Material::STEEL;
        let modulus = crate::model::laws::effective_modulus(&steel, &steel);
        SpatialModel {
            geometry: SpatialGeometry {
                axial_play,
                collar_radius,
            },
            face: FaceLaw::flat_punch(modulus, collar_radius, FaceLaw::DEFAULT_RESTITUTION),
        }
    }

    /// The same with the face law `face`.
    pub fn face(mut self, face: FaceLaw) -> Self {
        self.face = face;
        self
    }

    /// Checks the geometry against `radial` and the face law; returns the face law.
    pub fn validate(&self, radial: &BearingGeometry) -> Result<crate::model::laws::NormalModel> {
        self.geometry.validate(radial)?;
        self.face.law()
    }
}

/// Where a joint's two bodies are, for the spatial contacts.
#[derive(Clone, Copy, Debug)]
pub struct SpatialPose {
    /// Bearing centre (mid-width on the bore's axis), world.
    pub bearing_center: Vector,
    /// Bore axis `a_i` (unit), world.
    pub bearing_axis: Vector,
    /// A unit vector square to `a_i`, fixed in the bearing body: the first tilt axis and the
    /// reference of the shoulder rings.
    pub bearing_transverse: Vector,
    /// Journal centre (mid-way between its shoulders, on its axis), world.
    pub journal_center: Vector,
    /// Journal axis `a_j` (unit), world.
    pub journal_axis: Vector,
}

impl SpatialPose {
    /// The journal's axial offset along the bore's axis, `u = (P_j - P_i) . a_i`, m.
    pub fn axial_offset(&self) -> f64 {
        (self.journal_center - self.bearing_center).dot(self.bearing_axis)
    }

    /// The journal centre's offset from the bore's axis, square to it, m: the eccentricity at
    /// the bearing's mid-plane (`d - (d . a_i) a_i`, `d = P_j - P_i`).
    pub fn mid_plane_eccentricity(&self) -> Vector {
        let d = self.journal_center - self.bearing_center;
        d - d.dot(self.bearing_axis) * self.bearing_axis
    }

    /// The journal axis's tilt against the bore's, rad: its components along the bearing's
    /// transverse axes `t1 = bearing_transverse` and `t2 = a_i x t1` (the rotation about `t1`,
    /// then about `t2`, that carries `a_i` to `a_j`, small-angle components
    /// `asin(a_j . t2)`-like, exact as `atan2`).
    pub fn tilt(&self) -> [f64; 2] {
        let (ai, t1) = (self.bearing_axis, self.bearing_transverse);
        let t2 = ai.cross(t1);
        let aj = self.journal_axis;
        let along = aj.dot(ai);
        // A rotation by +phi about t1 moves a_i towards -t2; about t2, towards +t1.
        [(-aj.dot(t2)).atan2(along), aj.dot(t1).atan2(along)]
    }
}

/// A point of the journal's surface against the bearing (a quadrature point of a contact
/// region, or a region's deepest point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    /// Penetration `delta`, m (negative: the gap).
    pub depth: f64,
    /// The penetration's gradient with respect to the journal's motion at `point`:
    /// `delta_dot = gradient . (v_journal(point) - v_bearing(point))`. The law's force `F` acts
    /// as `-F gradient` on the journal and `+F gradient` on the bearing, at `point`.
    pub gradient: Vector,
    /// The journal's surface point, world.
    pub point: Vector,
    /// The share of the region's law the point carries (its quadrature weight over the width
    /// or the area); 0 for a region's deepest point, which only represents it.
    pub weight: f64,
}

/// One end of the bearing along its axis: its face, and the bore's edge there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The end at `-L/2` along `a_i`: its face is met by the journal's shoulder at `-(L + a)/2`
    /// when the journal moves along `+a_i`.
    Lower,
    /// The end at `+L/2`: its face is met when the journal moves along `-a_i`.
    Upper,
}

impl End {
    /// Both ends, lower first.
    pub const BOTH: [End; 2] = [End::Lower, End::Upper];

    /// `-1` for the lower end, `+1` for the upper.
    pub fn sign(self) -> f64 {
        match self {
            End::Lower => -1.0,
            End::Upper => 1.0,
        }
    }
}

/// A normal law carrying `share` of its force: each quadrature point of the spatial joint
/// carries its share of the width or the area. Force, stiffness, damping and energy scale by
/// `share`; the impact rate the law reads is the point's region's.
#[derive(Clone, Copy, Debug)]
pub struct Share<'a, L> {
    /// The whole law.
    pub law: &'a L,
    /// The fraction of it this point carries, in (0, 1]; for the step control's view of a
    /// whole contact, the regions' summed stiffness over the law's (above 1 when bore and
    /// faces press together).
    pub share: f64,
}

impl<L: NormalForceLaw> NormalForceLaw for Share<'_, L> {
    fn normal_force(&self, c: &NormalContact) -> f64 {
        self.share * self.law.normal_force(c)
    }
    fn elastic_force(&self, penetration: f64) -> f64 {
        self.share * self.law.elastic_force(penetration)
    }
    fn tangent_stiffness(&self, penetration: f64) -> f64 {
        self.share * self.law.tangent_stiffness(penetration)
    }
    fn damping_coefficient(&self, c: &NormalContact) -> f64 {
        self.share * self.law.damping_coefficient(c)
    }
    fn damping_slope(&self, c: &NormalContact) -> f64 {
        self.share * self.law.damping_slope(c)
    }
    fn elastic_energy(&self, penetration: f64) -> f64 {
        self.share * self.law.elastic_energy(penetration)
    }
    fn uses_impact_rate(&self) -> bool {
        self.law.uses_impact_rate()
    }
}

/// A bearing at the origin along z (transverse x) and a journal at `journal_center` along
/// `journal_axis` (normalised): the tests' pose.
#[cfg(test)]
pub(crate) fn pose_along_z(journal_center: Vector, journal_axis: Vector) -> SpatialPose {
    SpatialPose {
        bearing_center: Vector::ZERO,
        bearing_axis: Vector::Z,
        bearing_transverse: Vector::X,
        journal_center,
        journal_axis: journal_axis.normalize(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_spatial_geometry_is_refused_by_name() {
        let g = BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap();
        let good = SpatialGeometry {
            axial_play: 0.4e-3,
            collar_radius: 0.015,
        };
        assert!(good.validate(&g).is_ok());
        let mut s = good;
        s.collar_radius = 0.009;
        assert!(
            s.validate(&g)
                .unwrap_err()
                .to_string()
                .contains("collar_radius")
        );
        let mut s = good;
        s.axial_play = f64::NAN;
        assert!(
            s.validate(&g)
                .unwrap_err()
                .to_string()
                .contains("axial_play")
        );
    }
}

#[cfg(test)]
mod conservation {
    //! The points' elastic forces are the gradient of the points' elastic energy: for any small
    //! rigid motion of the journal, the energy changes by minus their work.
    use super::*;
    use crate::model::laws::{BearingGeometry, Hertz, NormalForceLaw};

    use super::pose_along_z as pose;

    /// All contact points of `p`, with whether each is a face's: both bore regions and both
    /// faces.
    fn points(
        g: &BearingGeometry,
        sp: &SpatialGeometry,
        p: &SpatialPose,
    ) -> Vec<(bool, ContactPoint)> {
        let mut out = Vec::new();
        for end in End::BOTH {
            if let Some(r) = bore_region(g, p, end) {
                let mut bore = Vec::new();
                bore_points(g, p, &r, &mut bore);
                out.extend(bore.into_iter().map(|(_, c)| (false, c)));
            }
            let mut face = Vec::new();
            Shoulder::at(g, sp, p, end).points(&mut face);
            out.extend(face.into_iter().map(|c| (true, c)));
        }
        out
    }

    #[test]
    fn forces_are_the_energys_gradient() {
        let g = BearingGeometry::from_clearance(0.006, 0.1e-3, 0.020).unwrap();
        let sp = SpatialGeometry {
            axial_play: 0.3e-3,
            collar_radius: 0.010,
        };
        // Hertz in the bore, the (linear) face law at the faces.
        let bore = Hertz::new(1e10, 1.5).unwrap();
        let face = FaceLaw {
            stiffness: 4e9,
            restitution: 1.0,
        }
        .law()
        .unwrap();
        let law = |on_face: bool| -> &dyn NormalForceLaw { if on_face { &face } else { &bore } };
        let energy = |p: &SpatialPose| -> f64 {
            points(&g, &sp, p)
                .iter()
                .map(|(f, c)| c.weight * law(*f).elastic_energy(c.depth))
                .sum()
        };
        // Two edges (tilted past 2c/L), one edge pressed, the whole width, a face at its rim.
        let cases = [
            (Vector::new(0.0, 0.0, 0.0), Vector::new(0.012, 0.001, 1.0)),
            (
                Vector::new(0.09e-3, 0.02e-3, 0.0),
                Vector::new(0.004, 0.0, 1.0),
            ),
            (
                Vector::new(0.0, -0.103e-3, 0.0),
                Vector::new(0.0, 0.0005, 1.0),
            ),
            (Vector::new(0.0, 0.0, 0.16e-3), Vector::new(0.02, 0.0, 1.0)),
        ];
        let (v, w) = (Vector::new(0.3, -0.2, 0.5), Vector::new(2.0, -1.0, 3.0));
        for (center, axis) in cases {
            let p = pose(center, axis);
            let u0 = energy(&p);
            assert!(u0 > 0.0, "{center:?} {axis:?}: no contact");
            let power: f64 = points(&g, &sp, &p)
                .iter()
                .map(|(on_face, c)| {
                    let f = c.weight * law(*on_face).elastic_force(c.depth);
                    f * c.gradient.dot(v + w.cross(c.point - p.journal_center))
                })
                .sum();
            let moved = |h: f64| {
                let rot = rapier3d_f64::math::Rotation::from_scaled_axis(w * h);
                energy(&SpatialPose {
                    journal_center: p.journal_center + v * h,
                    journal_axis: rot * p.journal_axis,
                    ..p
                })
            };
            let h = 1e-8;
            let numeric = (moved(h) - moved(-h)) / (2.0 * h);
            println!("{center:?}: dU/dt {numeric:.9e}, force power {power:.9e}");
            assert!(
                (numeric - power).abs() < 1e-6 * power.abs().max(1e-9),
                "{center:?} {axis:?}: dU/dt {numeric}, power {power}"
            );
        }
    }
}
