//! The shoulders' contact with the bearing's faces: the tilted annulus's region past the face
//! plane, and the quadrature of the face law's pressure over it.

use super::quadrature::{GAUSS_4, GAUSS_8};
use super::{ContactPoint, End, SpatialGeometry, SpatialPose};
use crate::model::laws::BearingGeometry;
use rapier3d_f64::math::Vector;
use std::f64::consts::{PI, TAU};

/// Points on a circle of the annulus in full contact (a uniform rule, exact for the
/// trigonometric polynomials of degree up to 7 a linear law's force and moment make of the
/// angle).
const FULL_CIRCLE_POINTS: usize = 8;

/// A journal's shoulder against the bearing's face at one end: a flat annulus (radii `R_j` to
/// `R_o`) square to `a_j`, against the face plane square to `a_i`.
///
/// A point of the annulus at radius `r` and angle `psi` from its deepest side `h` penetrates
/// `delta = delta_c + rho r cos(psi)`: `delta_c` the shoulder centre's intrusion past the face,
/// `rho` the sine of the tilt between the two planes. The contact region is where that is
/// positive: whole circles for `r < delta_c/rho`, arcs `|psi| < acos(-delta_c/(rho r))` beyond.
/// Every point's penetration gradient is the face's normal `n` (`delta_dot = n . v_rel`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shoulder {
    /// The shoulder's centre, world.
    pub center: Vector,
    /// The face's normal from the bearing towards the journal's side, `-sign a_i`: the force
    /// on the journal is `-F n`.
    pub normal: Vector,
    /// The centre's penetration past the face plane, m (negative: the gap).
    pub center_depth: f64,
    /// The sine of the tilt between the shoulder and the face.
    pub rho: f64,
    /// Unit vector in the shoulder's plane towards its deepest side.
    pub deepest: Vector,
    /// `a_j x deepest`.
    pub across: Vector,
    /// Inner and outer radius of the annulus, m.
    pub radii: [f64; 2],
}

impl Shoulder {
    /// The shoulder at `end` in `pose`.
    pub fn at(
        geometry: &BearingGeometry,
        spatial: &SpatialGeometry,
        pose: &SpatialPose,
        end: End,
    ) -> Self {
        let (ai, aj) = (pose.bearing_axis, pose.journal_axis);
        let sign = end.sign();
        let width = geometry.length();
        let center = pose.journal_center + (sign * 0.5 * (width + spatial.axial_play)) * aj;
        let face_point = pose.bearing_center + (sign * 0.5 * width) * ai;
        let normal = -sign * ai;
        // The face normal's part in the shoulder's plane points to its deepest side. Below a
        // tilt of 1e-12 rad that part is rounding noise: the shoulder is square to the face.
        let in_plane = normal - normal.dot(aj) * aj;
        let rho = in_plane.length();
        let (rho, towards) = if rho >= 1e-12 {
            (rho, in_plane)
        } else {
            (0.0, pose.bearing_transverse)
        };
        let deepest = (towards - towards.dot(aj) * aj).normalize();
        Shoulder {
            center,
            normal,
            center_depth: (center - face_point).dot(normal),
            rho,
            deepest,
            across: aj.cross(deepest),
            radii: [geometry.journal_radius(), spatial.collar_radius],
        }
    }

    /// The annulus's point at radius `r` and angle `psi` from the deepest side.
    pub fn point(&self, r: f64, psi: f64, weight: f64) -> ContactPoint {
        let (sin, cos) = psi.sin_cos();
        ContactPoint {
            depth: self.center_depth + self.rho * r * cos,
            gradient: self.normal,
            point: self.center + r * (cos * self.deepest + sin * self.across),
            weight,
        }
    }

    /// The deepest point: the outer rim on the deepest side.
    pub fn deepest_point(&self) -> ContactPoint {
        self.point(self.radii[1], 0.0, 0.0)
    }

    /// The area of the annulus, m^2.
    pub fn area(&self) -> f64 {
        let [ri, ro] = self.radii;
        PI * (ro * ro - ri * ri)
    }

    /// The quadrature points of the contact region, each carrying its share `dA/A` of the face
    /// law (nothing when the shoulder does not reach the face). Radially a 4-point Gauss rule
    /// on each part (whole circles, arcs), from the radius `|delta_c|/rho` where the arcs begin
    /// (their integrand grows from there like a power); along an arc an 8-point Gauss rule (the
    /// face law is linear: its pressure and energy are smooth in the angle up to the arc's
    /// ends), on a whole circle 8 uniform points.
    pub fn points(&self, out: &mut Vec<ContactPoint>) {
        let [ri, ro] = self.radii;
        if !(self.deepest_point().depth > 0.0) {
            return;
        }
        let area = self.area();
        let r0 = if self.rho > 0.0 {
            self.center_depth.abs() / self.rho
        } else {
            f64::INFINITY
        };
        if self.center_depth > 0.0 && r0 > ri {
            // Whole circles inside r0.
            for (r, wr) in GAUSS_4.on(ri, r0.min(ro)) {
                for k in 0..FULL_CIRCLE_POINTS {
                    let psi = TAU * k as f64 / FULL_CIRCLE_POINTS as f64;
                    let w = wr * r * (TAU / FULL_CIRCLE_POINTS as f64) / area;
                    out.push(self.point(r, psi, w));
                }
            }
        }
        if r0 >= ro {
            return;
        }
        // (From ri when the arcs begin inside the pin: the change of variable is then harmless.)
        for (r, wr) in GAUSS_4.from_root(r0.max(ri), ro) {
            let reach = (-self.center_depth / (self.rho * r))
                .clamp(-1.0, 1.0)
                .acos();
            for (psi, wp) in GAUSS_8.on(-reach, reach) {
                out.push(self.point(r, psi, wr * wp * r / area));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn radial() -> BearingGeometry {
        BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap()
    }
    fn spatial() -> SpatialGeometry {
        SpatialGeometry {
            axial_play: 0.4e-3,
            collar_radius: 0.015,
        }
    }
    use crate::model::spatial::pose_along_z as pose;

    /// `int (delta_c + rho x) x^k dA` over the part of the disk of radius `r` where
    /// `delta_c + rho x > 0` (`k` = 0, 1), in closed form: the circular segment `x > x0`,
    /// `x0 = -delta_c/rho`, with area `r^2 acos(x0/r) - x0 sqrt(r^2 - x0^2)`, first moment
    /// `2/3 (r^2 - x0^2)^(3/2)` and second moment `2 [F(r) - F(x0)]`,
    /// `F(x) = x (2x^2 - r^2) sqrt(r^2 - x^2)/8 + r^4 asin(x/r)/8`.
    fn disk(delta_c: f64, rho: f64, r: f64) -> [f64; 2] {
        let x0 = (-delta_c / rho).clamp(-r, r);
        let root = (r * r - x0 * x0).sqrt();
        let area = r * r * (x0 / r).acos() - x0 * root;
        let first = 2.0 / 3.0 * root.powi(3);
        let f = |x: f64| {
            x * (2.0 * x * x - r * r) * (r * r - x * x).max(0.0).sqrt() / 8.0
                + r.powi(4) * (x / r).clamp(-1.0, 1.0).asin() / 8.0
        };
        let second = 2.0 * (f(r) - f(x0));
        [delta_c * area + rho * first, delta_c * first + rho * second]
    }

    /// The same over the shoulder's annulus, over its area (the points' weights are shares).
    fn closed_form(s: &Shoulder) -> [f64; 2] {
        let [ri, ro] = s.radii;
        let (outer, inner) = (
            disk(s.center_depth, s.rho, ro),
            disk(s.center_depth, s.rho, ri),
        );
        [
            (outer[0] - inner[0]) / s.area(),
            (outer[1] - inner[1]) / s.area(),
        ]
    }

    fn quadrature(s: &Shoulder, f: impl Fn(&ContactPoint) -> f64) -> f64 {
        let mut pts = Vec::new();
        s.points(&mut pts);
        pts.iter().map(|p| p.weight * f(p)).sum()
    }

    #[test]
    fn aligned_and_pressed_the_whole_annulus_carries_the_law() {
        let s = Shoulder::at(
            &radial(),
            &spatial(),
            &pose(Vector::new(0.0, 0.0, 0.3e-3), Vector::Z),
            End::Lower,
        );
        assert!((s.center_depth - 0.1e-3).abs() < 1e-15 && s.rho == 0.0);
        let share: f64 = quadrature(&s, |_| 1.0);
        assert!((share - 1.0).abs() < 1e-14, "{share}");
        let mean = quadrature(&s, |p| p.depth);
        assert!((mean - 0.1e-3).abs() < 1e-17);
    }

    #[test]
    fn tilted_regions_match_the_closed_form() {
        // Tilt 0.01 rad about y; the lower shoulder from just touching at its rim to pressed
        // past its centre: the force and both moments of a linear law.
        for dz in [-0.15e-3, -0.05e-3, 0.0, 0.06e-3, 0.2e-3] {
            let tilt = 0.01f64;
            let p = pose(
                Vector::new(0.0, 0.0, 0.2e-3 + dz),
                Vector::new(tilt.sin(), 0.0, tilt.cos()),
            );
            let s = Shoulder::at(&radial(), &spatial(), &p, End::Lower);
            let force = quadrature(&s, |q| q.depth);
            let moment = quadrature(&s, |q| q.depth * (q.point - s.center).dot(s.deepest));
            let [f, m] = closed_form(&s);
            assert!((force - f).abs() < 1e-6 * f, "dz {dz}: force {force} {f}");
            assert!(
                (moment - m).abs() < 1e-6 * m.abs(),
                "dz {dz}: moment {moment} {m}"
            );
        }
    }

    #[test]
    fn the_region_does_not_depend_on_the_rings_orientation() {
        // The same tilt about two transverse axes 22.5 deg apart: the same force.
        let tilt = 0.01f64;
        let force = |angle: f64| {
            let axis = Vector::new(
                tilt.sin() * angle.cos(),
                tilt.sin() * angle.sin(),
                tilt.cos(),
            );
            let p = pose(Vector::new(0.0, 0.0, 0.1e-3), axis);
            let s = Shoulder::at(&radial(), &spatial(), &p, End::Lower);
            quadrature(&s, |q| q.depth)
        };
        let (a, b) = (force(0.0), force(22.5f64.to_radians()));
        assert!(a > 0.0 && (a - b).abs() < 1e-12 * a, "{a} {b}");
    }
}
