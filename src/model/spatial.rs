//! The spatial clearance joint's contact geometry: a journal free in all five relative degrees of
//! freedom but its turn, touching the bore along the bearing's width and the bearing's faces with
//! its shoulders. Pure functions of poses and velocities, no Rapier state.
//!
//! # Geometry
//!
//! The bearing is a bore of radius `R_b` and width `L` (the [`BearingGeometry`]'s length) between
//! two flat faces; the journal a pin of radius `R_j = R_b - c` that runs through it, between two
//! shoulders (collars of outer radius `R_o`) `L + a` apart: `a` is the axial play, the free axial
//! travel of the journal when centred radially. The journal's axis may tilt against the bore's.
//!
//! # Contacts
//!
//! - **Bore**: the width is cut into `N` slices, sampled at `N + 1` stations in the bearing's
//!   planes `s_k = -L/2 + k L/N` (trapezoidal rule: the end stations carry half a slice). In each
//!   plane the journal's section is an ellipse (a tilted cylinder cut square to the bore); its
//!   reach along the radial direction `n` from the bore's axis is `R_j sqrt(1 + x^2/cos^2 theta)`,
//!   `x = n . a_j`, `cos theta = a_i . a_j` ([`bore_station`]). Each station carries the normal
//!   law for its share of the width (weights 1/(2N) at the ends, 1/N inside: a law of Liu's family
//!   is a force per unit width, so the shares add up to the law when the penetration is uniform,
//!   and the aligned joint gives the planar joint's force). The end stations are the bore's
//!   edges: a tilted journal loads them first (edge contact).
//! - **Faces**: each shoulder is sampled at [`FACE_POINTS`] points on the circle of radius
//!   `r_f = sqrt((R_j^2 + R_o^2)/2)`, each carrying `1/FACE_POINTS` of the face law. A ring at
//!   that radius has the annulus's polar second moment, so for a linear face law in full contact
//!   it gives the annulus's force and tilting moment exactly ([`face_station`]).
//!
//! Every station is a [`JournalState`]: penetration, rates, slip (the full tangential sliding
//! velocity at its point, axial sliding included) and the point where its equal-and-opposite
//! force pair acts, so the forces are momentum-exact.

use crate::error::{Error, Result, positive};
use crate::model::kinematics::{BodyMotion, JournalState};
use crate::model::laws::{BearingGeometry, NormalContact, NormalForceLaw};
use rapier3d_f64::math::Vector;

/// Stations on each shoulder's ring.
pub const FACE_POINTS: usize = 8;

/// Default number of slices across the bearing's width (9 stations), measured in
/// `tests/spatial.rs`: the edge forces under a pure moment do not depend on it (M/L); a load
/// off-centre along the width follows Winkler's line within `2/N^2` of its slope (2.3 % of the
/// load at the edges for N = 8); on an arm whose weight hangs 50 mm off the hinge's mid-plane
/// (the journal tilts and loads its edges) N = 8 gives the peak tilt within 0.5 % of N = 128
/// and the first impact's peak to all digits, the edge pressure within 5 % (N = 32: 0.1 % and
/// 1.8 %; `cargo test --release --test spatial -- --ignored --nocapture slice_count_table`).
/// The step count hardly depends on N; the cost per step grows with the stations.
pub const DEFAULT_SLICES: u32 = 8;

/// Upper bound on the slices (each is a contact evaluated every step).
pub const MAX_SLICES: u32 = 256;

/// The spatial geometry beyond the radial [`BearingGeometry`]: axial play, shoulder radius and
/// slice count.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpatialGeometry {
    /// Axial play `a`: the journal's free axial travel when it is centred, m (> 0).
    pub axial_play: f64,
    /// Outer radius of the journal's shoulders (collars) `R_o`, m (> `R_j`).
    pub collar_radius: f64,
    /// Slices across the width, `N` (1 to [`MAX_SLICES`]).
    pub slices: u32,
}

impl SpatialGeometry {
    /// Checks the values against the radial geometry `radial` (field names as in this struct).
    pub fn validate(&self, radial: &BearingGeometry) -> Result<()> {
        positive("axial_play", self.axial_play)?;
        positive("collar_radius", self.collar_radius)?;
        if self.collar_radius <= radial.journal_radius() {
            return Err(Error::invalid(
                "collar_radius",
                format!(
                    "must exceed the journal radius {} m (got {} m): the shoulder is a ring \
                     around the pin",
                    crate::error::sig4(radial.journal_radius()),
                    crate::error::sig4(self.collar_radius)
                ),
            ));
        }
        if self.slices == 0 || self.slices > MAX_SLICES {
            return Err(Error::invalid(
                "slices",
                format!(
                    "must be 1 to {MAX_SLICES} (got {}): the width is cut into that many slices",
                    self.slices
                ),
            ));
        }
        Ok(())
    }

    /// The bore stations `(s_k, share_k)`: axial position from the bearing's centre (m) and the
    /// share of the law (trapezoidal weights summing to 1), `k = 0..=N`.
    pub fn bore_stations(&self, width: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let n = self.slices;
        (0..=n).map(move |k| {
            let s = width * (k as f64 / n as f64 - 0.5);
            let share = if k == 0 || k == n { 0.5 } else { 1.0 } / n as f64;
            (s, share)
        })
    }

    /// Radius of the shoulders' sampling ring, `sqrt((R_j^2 + R_o^2)/2)`, m.
    pub fn face_ring_radius(&self, radial: &BearingGeometry) -> f64 {
        let rj = radial.journal_radius();
        (0.5 * (rj * rj + self.collar_radius * self.collar_radius)).sqrt()
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
    /// Axial play, shoulders and slices.
    pub geometry: SpatialGeometry,
    /// The shoulders' law against the faces.
    pub face: FaceLaw,
}

impl SpatialModel {
    /// Steel shoulders of radius `collar_radius` (m) with axial play `axial_play` (m),
    /// [`DEFAULT_SLICES`] slices, and the face law of a flat steel punch
    /// ([`FaceLaw::flat_punch`], E = 207 GPa, nu = 0.3, restitution
    /// [`FaceLaw::DEFAULT_RESTITUTION`]).
    pub fn steel(axial_play: f64, collar_radius: f64) -> Self {
        let steel = crate::model::laws::Material::STEEL;
        let modulus = crate::model::laws::effective_modulus(&steel, &steel);
        SpatialModel {
            geometry: SpatialGeometry {
                axial_play,
                collar_radius,
                slices: DEFAULT_SLICES,
            },
            face: FaceLaw::flat_punch(modulus, collar_radius, FaceLaw::DEFAULT_RESTITUTION),
        }
    }

    /// The same with `slices` slices across the width.
    pub fn slices(mut self, slices: u32) -> Self {
        self.geometry.slices = slices;
        self
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

/// Where a joint's two bodies are, for the spatial stations.
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

/// The bore station at axial position `s` (m, from the bearing's centre along `a_i`): the
/// journal's section by the bearing's plane there, against the bore's circle.
///
/// The journal's axis crosses the plane at `x = P_j + t a_j`, `t = (s - u)/(a_i . a_j)`; its
/// eccentricity `e = x - (P_i + s a_i)` gives the radial direction `n = e/|e|`, and the section
/// (an ellipse) reaches `R_j sqrt(1 + x^2/cos^2 theta)` along `n`, so the penetration is
/// `|e| - c + R_j (sqrt(1 + q) - 1)`, `q = (n . a_j)^2/(a_i . a_j)^2` (written without
/// cancellation). Aligned, `q` vanishes and the station is the planar joint's
/// ([`journal_state`](crate::model::kinematics::journal_state)).
pub fn bore_station(
    geometry: &BearingGeometry,
    pose: &SpatialPose,
    s: f64,
    bearing: &BodyMotion,
    journal: &BodyMotion,
) -> JournalState {
    let (ai, aj) = (pose.bearing_axis, pose.journal_axis);
    let cos = ai.dot(aj);
    let plane = pose.bearing_center + s * ai;
    let crossing = pose.journal_center + ((s - pose.axial_offset()) / cos) * aj;
    let raw = crossing - plane;
    // Remove the rounding's axial remainder: e lies in the plane.
    let eccentricity = raw - raw.dot(ai) * ai;
    let e = eccentricity.length();
    let normal = if e > 0.0 {
        eccentricity / e
    } else {
        pose.bearing_transverse
    };
    let x = normal.dot(aj) / cos;
    let q = x * x;
    let reach_excess = geometry.journal_radius() * q / ((1.0 + q).sqrt() + 1.0);
    let penetration = e - geometry.clearance() + reach_excess;
    let q_j = crossing + (geometry.journal_radius() + reach_excess) * normal;
    let q_i = plane + geometry.bearing_radius() * normal;
    let v_rel = journal.velocity_at(q_j) - bearing.velocity_at(q_i);
    let penetration_rate = v_rel.dot(normal);
    let centres = journal.velocity_at(crossing) - bearing.velocity_at(plane);
    JournalState {
        eccentricity,
        normal,
        penetration,
        penetration_rate,
        slip: v_rel - penetration_rate * normal,
        eccentricity_rate: centres - centres.dot(ai) * ai,
        contact_point: 0.5 * (q_i + q_j),
    }
}

/// Which bearing face a shoulder meets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Face {
    /// The face at `-L/2` along `a_i`, met by the journal's shoulder at `-(L + a)/2` when the
    /// journal moves along `+a_i`.
    Lower,
    /// The face at `+L/2`, met when the journal moves along `-a_i`.
    Upper,
}

impl Face {
    /// Both faces, lower first.
    pub const BOTH: [Face; 2] = [Face::Lower, Face::Upper];

    /// `-1` for the lower face, `+1` for the upper.
    pub fn sign(self) -> f64 {
        match self {
            Face::Lower => -1.0,
            Face::Upper => 1.0,
        }
    }
}

/// The shoulder station `index` (0 to [`FACE_POINTS`] - 1) of `face`: a point of the journal's
/// shoulder ring (radius [`SpatialGeometry::face_ring_radius`], square to `a_j`) against the
/// bearing's face plane (square to `a_i`). Its penetration is the point's intrusion past the
/// face (`u - a/2` when aligned), its normal `-sign a_i` (the force on the journal pushes it back
/// towards the centre), its eccentricity the axial offset along that normal.
pub fn face_station(
    geometry: &BearingGeometry,
    spatial: &SpatialGeometry,
    pose: &SpatialPose,
    face: Face,
    index: usize,
    bearing: &BodyMotion,
    journal: &BodyMotion,
) -> JournalState {
    let (ai, aj) = (pose.bearing_axis, pose.journal_axis);
    let sign = face.sign();
    let width = geometry.length();
    let shoulder = pose.journal_center + (sign * 0.5 * (width + spatial.axial_play)) * aj;
    let face_point = pose.bearing_center + (sign * 0.5 * width) * ai;
    // The ring's reference directions: the bearing's transverse axes, made square to a_j.
    let t1 = pose.bearing_transverse;
    let d1 = (t1 - t1.dot(aj) * aj).normalize();
    let d2 = aj.cross(d1);
    let angle = std::f64::consts::TAU * index as f64 / FACE_POINTS as f64;
    let r = spatial.face_ring_radius(geometry);
    let point = shoulder + r * (angle.cos() * d1 + angle.sin() * d2);
    // Normal from the bearing towards the journal's side of the contact, as in the bore:
    // the force on the journal is -F_N n.
    let normal = -sign * ai;
    let penetration = (point - face_point).dot(normal);
    let on_face = point - penetration * normal;
    let v_rel = journal.velocity_at(point) - bearing.velocity_at(on_face);
    let penetration_rate = v_rel.dot(normal);
    let centres =
        journal.velocity_at(pose.journal_center) - bearing.velocity_at(pose.bearing_center);
    JournalState {
        eccentricity: (pose.axial_offset() * -sign) * normal,
        normal,
        penetration,
        penetration_rate,
        slip: v_rel - penetration_rate * normal,
        eccentricity_rate: centres.dot(ai) * ai,
        contact_point: 0.5 * (point + on_face),
    }
}

/// A normal law carrying `share` of its force: each station of the spatial joint carries its
/// slice's (or ring point's) share. Force, stiffness, damping and energy scale by `share`; the
/// impact rate the law reads is the station's own.
#[derive(Clone, Copy, Debug)]
pub struct Share<'a, L> {
    /// The whole law.
    pub law: &'a L,
    /// The fraction of it this station carries, in (0, 1]; for the step control's view of a
    /// whole contact, the stations' summed stiffness over the law's (above 1 when bore and
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::journal_state;

    fn radial() -> BearingGeometry {
        BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap()
    }
    fn spatial() -> SpatialGeometry {
        SpatialGeometry {
            axial_play: 0.4e-3,
            collar_radius: 0.015,
            slices: 4,
        }
    }
    fn pose(journal_center: Vector, journal_axis: Vector) -> SpatialPose {
        SpatialPose {
            bearing_center: Vector::ZERO,
            bearing_axis: Vector::Z,
            bearing_transverse: Vector::X,
            journal_center,
            journal_axis: journal_axis.normalize(),
        }
    }

    #[test]
    fn stations_are_a_trapezoidal_rule() {
        let st: Vec<_> = spatial().bore_stations(0.016).collect();
        assert_eq!(st.len(), 5);
        assert_eq!(st[0], (-0.008, 0.125));
        assert_eq!(st[2], (0.0, 0.25));
        assert!((st[4].0 - 0.008).abs() < 1e-18 && st[4].1 == 0.125);
        assert!((st.iter().map(|s| s.1).sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn aligned_station_is_the_planar_state() {
        let g = radial();
        let p = pose(Vector::new(0.6e-3, 0.0, 0.1e-3), Vector::Z);
        let journal = BodyMotion {
            center_of_mass: Vector::new(0.0, 0.0, 0.0),
            linvel: Vector::new(0.01, 0.02, 0.0),
            angvel: Vector::ZERO,
        };
        let planar = journal_state(
            &g,
            p.bearing_center,
            p.journal_center,
            Vector::Z,
            &BodyMotion::default(),
            &journal,
        );
        for (s, _) in spatial().bore_stations(g.length()) {
            let st = bore_station(&g, &p, s, &BodyMotion::default(), &journal);
            assert_eq!(st.penetration, planar.penetration);
            assert_eq!(st.normal, planar.normal);
            assert_eq!(st.penetration_rate, planar.penetration_rate);
            assert!((st.slip - planar.slip).length() < 1e-18);
            // The same point, moved to the station's plane.
            let moved = planar.contact_point + (s - 0.05e-3) * Vector::Z;
            assert!((st.contact_point - moved).length() < 1e-15, "{s}");
        }
    }

    #[test]
    fn tilted_journal_reaches_further_at_the_edges() {
        // Journal centred, tilted by 0.01 rad about y: its axis crosses the plane s at x = s tan.
        let g = radial();
        let tilt = 0.01_f64;
        let p = pose(Vector::ZERO, Vector::new(tilt.sin(), 0.0, tilt.cos()));
        let at = |s: f64| bore_station(&g, &p, s, &BodyMotion::default(), &BodyMotion::default());
        let edge = at(0.008);
        // e = 8 mm tan(0.01) along x; the ellipse's reach R_j/cos(0.01) along its major axis.
        let e = 0.008 * tilt.tan();
        let reach = g.journal_radius() / tilt.cos();
        let expected = e + reach - g.bearing_radius();
        assert!(
            (edge.penetration - expected).abs() < 1e-15,
            "{}",
            edge.penetration - expected
        );
        assert!((edge.normal - Vector::X).length() < 1e-15);
        assert_eq!(p.tilt()[0], 0.0);
        assert!((p.tilt()[1] - tilt).abs() < 1e-15);
        let other = at(-0.008);
        assert!((other.normal + Vector::X).length() < 1e-15);
        assert!((other.penetration - expected).abs() < 1e-15);
    }

    #[test]
    fn face_penetration_by_hand() {
        let (g, sp) = (radial(), spatial());
        // Journal moved 0.3 mm along +z: the lower shoulder is 0.1 mm past the lower face.
        let p = pose(Vector::new(0.0, 0.0, 0.3e-3), Vector::Z);
        let journal = BodyMotion {
            center_of_mass: Vector::ZERO,
            linvel: Vector::new(0.0, 0.0, 0.5),
            angvel: Vector::new(0.0, 0.0, 2.0),
        };
        let r = sp.face_ring_radius(&g);
        assert!((r - (0.5 * (0.0095f64.powi(2) + 0.015f64.powi(2))).sqrt()).abs() < 1e-15);
        for i in 0..FACE_POINTS {
            let lo = face_station(
                &g,
                &sp,
                &p,
                Face::Lower,
                i,
                &BodyMotion::default(),
                &journal,
            );
            assert!((lo.penetration - 0.1e-3).abs() < 1e-15);
            assert_eq!(lo.normal, Vector::Z);
            assert!((lo.penetration_rate - 0.5).abs() < 1e-15);
            // The spin slides the point tangentially at w r.
            assert!((lo.slip.length() - 2.0 * r).abs() < 1e-12);
            let up = face_station(
                &g,
                &sp,
                &p,
                Face::Upper,
                i,
                &BodyMotion::default(),
                &journal,
            );
            assert!((up.penetration + 0.5e-3).abs() < 1e-15);
        }
    }

    #[test]
    fn tilted_shoulder_intrudes_at_its_rim() {
        let (g, sp) = (radial(), spatial());
        let tilt = 0.01_f64;
        let p = pose(Vector::ZERO, Vector::new(tilt.sin(), 0.0, tilt.cos()));
        let r = sp.face_ring_radius(&g);
        let deepest = (0..FACE_POINTS)
            .map(|i| {
                face_station(
                    &g,
                    &sp,
                    &p,
                    Face::Lower,
                    i,
                    &BodyMotion::default(),
                    &BodyMotion::default(),
                )
                .penetration
            })
            .fold(f64::NEG_INFINITY, f64::max);
        // The shoulder at -(L+a)/2 along a_j, its ring point at angle 0 (along +x tilted) rises
        // by r sin(tilt); the shoulder's centre sinks by (L+a)/2 (1 - cos(tilt)).
        let half = 0.5 * (0.016 + 0.4e-3);
        let expected = -half * tilt.cos() + 0.008 + r * tilt.sin();
        assert!((deepest - expected).abs() < 1e-12, "{deepest} {expected}");
    }

    #[test]
    fn bad_spatial_geometry_is_refused_by_name() {
        let g = radial();
        let mut s = spatial();
        s.slices = 0;
        assert!(s.validate(&g).unwrap_err().to_string().contains("slices"));
        let mut s = spatial();
        s.collar_radius = 0.009;
        assert!(
            s.validate(&g)
                .unwrap_err()
                .to_string()
                .contains("collar_radius")
        );
        let mut s = spatial();
        s.axial_play = f64::NAN;
        assert!(
            s.validate(&g)
                .unwrap_err()
                .to_string()
                .contains("axial_play")
        );
    }
}
