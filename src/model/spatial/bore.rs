//! The bore's contact: the tilted journal's section in each plane of the bearing, where along
//! the width it touches, and the quadrature of its line load over that region.

use super::quadrature::GAUSS_8;
use super::{ContactPoint, End, SpatialPose};
use crate::model::laws::BearingGeometry;
use rapier3d_f64::math::Vector;

/// Newton steps allowed to the section's farthest point: it starts from the point whose normal
/// is along the eccentricity (within the ellipse's flattening, `tan^2(tilt)`, of the answer) and
/// squares its error each step, so three reach rounding at any tilt below 0.3 rad (it stops
/// once a step falls below 1e-8 rad: two on average at the door's tilts).
const FARTHEST_POINT_STEPS: usize = 4;

/// Iterations allowed to the root of the penetration along the width (false position, Illinois
/// variant: a handful suffice; the cap only bounds a degenerate case).
const ROOT_ITERATIONS: usize = 100;

/// The journal's section by the bearing's plane at `s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoreSection {
    /// The section's deepest point against the bore's circle ([`ContactPoint::weight`] 0).
    pub contact: ContactPoint,
    /// Where the journal's axis crosses the plane, world.
    pub crossing: Vector,
    /// The bore's axis point in the plane, world.
    pub plane_center: Vector,
    /// The crossing's offset from the bore's axis, in the plane, m.
    pub eccentricity: Vector,
}

/// The journal's section by the bearing's plane at axial position `s` (m from the bearing's
/// centre along `a_i`): an ellipse (a tilted cylinder cut square to the bore), and its point
/// farthest from the bore's axis.
///
/// The farthest point `p` of the ellipse (centred at the crossing's eccentricity `e`) is where
/// the ellipse's normal is radial: a fixed point of "`p` is the ellipse's support point along
/// the direction of `e + p`". Its penetration `|e + p| - R_b` is the section's; aligned, `p` is
/// `R_j e/|e|` and the penetration `|e| - c`, the planar joint's. The penetration's gradient
/// (envelope theorem: the point is a maximum) is the radial unit `r` less the slide of the
/// section point along the journal's generator, `g = r - (r . a_j)/(a_i . a_j) a_i`: square to
/// `a_j`, the journal surface's normal there, of length `sqrt(1 + (r . a_j)^2/(a_i . a_j)^2)`.
pub fn bore_section(geometry: &BearingGeometry, pose: &SpatialPose, s: f64) -> BoreSection {
    let (ai, aj) = (pose.bearing_axis, pose.journal_axis);
    let cos = ai.dot(aj);
    let plane_center = pose.bearing_center + s * ai;
    let crossing = pose.journal_center + ((s - pose.axial_offset()) / cos) * aj;
    let raw = crossing - plane_center;
    // Remove the rounding's axial remainder: e lies in the plane.
    let eccentricity = raw - raw.dot(ai) * ai;
    let reach = eccentricity + farthest_point(eccentricity, ai, aj, cos, geometry.journal_radius());
    let distance = reach.length();
    let radial = reach / distance;
    BoreSection {
        contact: ContactPoint {
            depth: distance - geometry.bearing_radius(),
            gradient: radial - (radial.dot(aj) / cos) * ai,
            point: plane_center + reach,
            weight: 0.0,
        },
        crossing,
        plane_center,
        eccentricity,
    }
}

/// Where along the width the bore's contact region at `end` lies: from the bearing's end plane
/// `end_s` (`-L/2` or `+L/2`) to `inner_s`, where the penetration falls to zero or, when the
/// journal touches along the whole width, the point of least penetration (where the two ends'
/// regions meet). `None` when the journal does not touch the bore at that end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoreRegion {
    /// The end's plane, m from the bearing's centre.
    pub end_s: f64,
    /// The region's other bound, m from the bearing's centre.
    pub inner_s: f64,
}

impl BoreRegion {
    /// The region's length along the width, m.
    pub fn length(&self) -> f64 {
        (self.end_s - self.inner_s).abs()
    }
}

/// The point of the section's ellipse (relative to its centre) farthest from the bore's axis,
/// the centre being `eccentricity` from it (`a_i`, `a_j` the bore's and the journal's axes, `cos`
/// their cosine). The ellipse has semi-axes `R_j/cos` along the journal axis's in-plane part
/// `a_j - cos a_i` and `R_j` across it; a circle when aligned.
/// Newton's method on the angle `phi` of `p = a cos(phi) u1 + b sin(phi) u2` for
/// `(e + p) . p' = 0`.
fn farthest_point(eccentricity: Vector, ai: Vector, aj: Vector, cos: f64, rj: f64) -> Vector {
    // The difference of two nearly equal unit vectors: take its axial remainder out again.
    let raw = aj - cos * ai;
    let in_plane = raw - raw.dot(ai) * ai;
    let sin = in_plane.length();
    let e = eccentricity.length();
    // Below 1e-12 rad the ellipse is a circle to rounding (its stretch is 1 + 5e-25), and the
    // direction of `in_plane` is rounding noise.
    if sin < 1e-12 {
        return if e > 0.0 {
            rj * eccentricity / e
        } else {
            Vector::ZERO
        };
    }
    let u1 = in_plane / sin;
    let u2 = ai.cross(u1);
    let (a, b) = (rj / cos, rj);
    let (ex, ey) = (eccentricity.dot(u1), eccentricity.dot(u2));
    // The point whose normal is along e: its angle's cosine and sine, `(a ex, b ey)` normalised.
    let (mut cs, mut sn) = match ((a * ex).powi(2) + (b * ey).powi(2)).sqrt() {
        n if n > 0.0 => (a * ex / n, b * ey / n),
        _ => (1.0, 0.0),
    };
    for _ in 0..FARTHEST_POINT_STEPS {
        let (px, py) = (a * cs, b * sn);
        let (dx, dy) = (-a * sn, b * cs);
        let slope = (ex + px) * dx + (ey + py) * dy;
        let curvature = dx * dx + dy * dy - (ex + px) * px - (ey + py) * py;
        if !(curvature < 0.0) {
            break;
        }
        let step = -slope / curvature;
        if step == 0.0 {
            break;
        }
        // The angle's Newton step as a rotation of (cos, sin): the point's trigonometry is
        // most of a spatial joint's cost, and after the first step the angle is tiny.
        let (s, c) = rotation(step);
        (cs, sn) = (cs * c - sn * s, sn * c + cs * s);
        // Newton squares the error: after a step this small the next is below rounding.
        if step.abs() < 1e-8 {
            break;
        }
    }
    a * cs * u1 + b * sn * u2
}

/// `(sin d, cos d)`: by their series to rounding below 1e-3 rad (the error terms `d^7/5040` and
/// `d^6/720` are below 1e-20), else by the library's.
fn rotation(d: f64) -> (f64, f64) {
    if d.abs() < 1e-3 {
        let d2 = d * d;
        (
            d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0)),
            1.0 - d2 / 2.0 * (1.0 - d2 / 12.0),
        )
    } else {
        d.sin_cos()
    }
}

/// The bore's contact region touching `end`. The crossing's eccentricity is affine in `s`, so
/// its length is convex with a minimum at `s_m` (the mid-plane when aligned); the section's
/// reach beyond `R_j` adds a term of order `R_j tan^2(tilt)` that does not change that shape.
/// The penetration therefore falls from each end towards `s_m`: a region touching an end runs
/// to the root between them, or to `s_m` itself if the penetration stays positive there.
pub fn bore_region(geometry: &BearingGeometry, pose: &SpatialPose, end: End) -> Option<BoreRegion> {
    let half = 0.5 * geometry.length();
    let end_s = end.sign() * half;
    let at_end = bore_section(geometry, pose, end_s).contact.depth;
    if !(at_end > 0.0) {
        return None;
    }
    let split = least_eccentricity(geometry, pose).clamp(-half, half);
    let at_split = bore_section(geometry, pose, split).contact.depth;
    let inner_s = if at_split >= 0.0 {
        split
    } else {
        root(
            |s| bore_section(geometry, pose, s).contact.depth,
            (split, at_split),
            (end_s, at_end),
            1e-12 * geometry.length(),
        )
    };
    Some(BoreRegion { end_s, inner_s })
}

/// The plane `s` where the crossing's eccentricity `e(s) = e0 + s e1` is least,
/// `-e0 . e1/|e1|^2`; the mid-plane for an aligned journal.
fn least_eccentricity(geometry: &BearingGeometry, pose: &SpatialPose) -> f64 {
    let (ai, aj) = (pose.bearing_axis, pose.journal_axis);
    let cos = ai.dot(aj);
    let e1 = (aj - cos * ai) / cos;
    let e0 = pose.mid_plane_eccentricity() - pose.axial_offset() * e1;
    let slope2 = e1.length_squared();
    // Aligned to rounding: the eccentricity moves less than 1e-12 of the clearance over the width.
    let width = geometry.length();
    if slope2 * width * width <= (1e-12 * geometry.clearance()).powi(2) {
        0.0
    } else {
        -e0.dot(e1) / slope2
    }
}

/// The root of `f` between `a` (`f < 0`) and `b` (`f > 0`), to `tolerance`: false position with
/// the Illinois halving (superlinear, and never leaves the bracket). Returns the last estimate
/// once it moves less than `tolerance` (or the bracket is that narrow).
fn root(f: impl Fn(f64) -> f64, a: (f64, f64), b: (f64, f64), tolerance: f64) -> f64 {
    let ((mut x0, mut f0), (mut x1, mut f1)) = (a, b);
    let mut side = 0;
    let mut last = f64::NAN;
    for _ in 0..ROOT_ITERATIONS {
        let x = x1 - f1 * (x1 - x0) / (f1 - f0);
        if !x.is_finite() || (x1 - x0).abs() <= tolerance {
            break;
        }
        if (x - last).abs() <= tolerance {
            return x;
        }
        last = x;
        let fx = f(x);
        if fx == 0.0 {
            return x;
        }
        if (fx > 0.0) == (f1 > 0.0) {
            (x1, f1) = (x, fx);
            if side == 1 {
                f0 *= 0.5;
            }
            side = 1;
        } else {
            (x0, f0) = (x, fx);
            if side == -1 {
                f1 *= 0.5;
            }
            side = -1;
        }
    }
    0.5 * (x0 + x1)
}

/// The quadrature points of the bore's region `region`: Gauss points from its inner bound
/// (where the penetration vanishes) to its end, each carrying the law's share `ds/L` (its
/// quadrature weight over the width). Appends `(s, point)` to `out`.
pub fn bore_points(
    geometry: &BearingGeometry,
    pose: &SpatialPose,
    region: &BoreRegion,
    out: &mut Vec<(f64, ContactPoint)>,
) {
    let width = geometry.length();
    for (s, w) in GAUSS_8.from_root(region.inner_s, region.end_s) {
        let section = bore_section(geometry, pose, s);
        let contact = ContactPoint {
            weight: w / width,
            ..section.contact
        };
        out.push((s, contact));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn radial() -> BearingGeometry {
        BearingGeometry::from_clearance(0.010, 0.5e-3, 0.016).unwrap()
    }

    use crate::model::spatial::pose_along_z as pose;

    /// The farthest point of the section by brute force over the ellipse's parameter.
    fn brute_depth(g: &BearingGeometry, p: &SpatialPose, s: f64) -> f64 {
        let (ai, aj) = (p.bearing_axis, p.journal_axis);
        let cos = ai.dot(aj);
        let crossing = p.journal_center + ((s - p.axial_offset()) / cos) * aj;
        let w = aj - cos * ai;
        let (u1, u2) = if w.length() > 0.0 {
            let u1 = w.normalize();
            (u1, ai.cross(u1))
        } else {
            (Vector::X, Vector::Y)
        };
        let rj = g.journal_radius();
        let mut best = f64::NEG_INFINITY;
        let n = 200_000;
        for k in 0..n {
            let phi = std::f64::consts::TAU * k as f64 / n as f64;
            let q = crossing + (rj / cos) * phi.cos() * u1 + rj * phi.sin() * u2;
            let r = q - p.bearing_center - s * ai;
            best = best.max(r.length());
        }
        best - g.bearing_radius()
    }

    #[test]
    fn the_deepest_point_is_the_ellipses_farthest() {
        let g = radial();
        for (tilt, e) in [(0.01f64, 0.4e-3), (0.05, 0.1e-3), (0.002, 0.0)] {
            let axis = Vector::new(tilt.sin() * 0.6, tilt.sin() * 0.8, tilt.cos());
            let p = pose(Vector::new(e, -0.5 * e, 0.1e-3), axis);
            for s in [-0.008, -0.003, 0.0, 0.008] {
                let got = bore_section(&g, &p, s).contact.depth;
                let want = brute_depth(&g, &p, s);
                assert!((got - want).abs() < 1e-12, "{tilt} {s}: {got} {want}");
            }
        }
    }

    #[test]
    fn aligned_sections_are_the_planar_contact() {
        let g = radial();
        let p = pose(Vector::new(0.6e-3, 0.0, 0.1e-3), Vector::Z);
        let c = bore_section(&g, &p, 0.004).contact;
        assert!((c.depth - 0.1e-3).abs() < 1e-18);
        assert!((c.gradient - Vector::X).length() < 1e-15);
        let r = bore_region(&g, &p, End::Upper).unwrap();
        assert_eq!((r.end_s, r.inner_s), (0.008, 0.0));
    }

    #[test]
    fn the_gradient_is_the_depths_derivative() {
        // Move the journal by a small rigid motion; the depth changes by g . v dt at the point.
        let g = radial();
        let tilt = 0.01f64;
        let p = pose(
            Vector::new(0.45e-3, 0.1e-3, 0.0),
            Vector::new(tilt.sin(), 0.0, tilt.cos()),
        );
        let s = 0.006;
        let c = bore_section(&g, &p, s).contact;
        let (v, w) = (Vector::new(0.3, -0.2, 0.5), Vector::new(2.0, -1.0, 3.0));
        let moved = |h: f64| {
            let rot = rapier3d_f64::math::Rotation::from_scaled_axis(w * h);
            let pose = SpatialPose {
                journal_center: p.journal_center + v * h,
                journal_axis: rot * p.journal_axis,
                ..p
            };
            bore_section(&g, &pose, s).contact.depth
        };
        // The rotation about the journal centre moves the point by w x (point - centre).
        let rate = c.gradient.dot(v + w.cross(c.point - p.journal_center));
        let h = 1e-6;
        let numeric = (moved(h) - moved(-h)) / (2.0 * h);
        assert!(
            (numeric - rate).abs() < 1e-6 * rate.abs().max(1.0),
            "{numeric} {rate}"
        );
    }

    #[test]
    fn a_tilted_journal_touches_both_ends_to_the_roots() {
        // Centred, tilted 0.1 rad: each end's region runs from the edge to where the
        // penetration is zero, on opposite sides.
        let g = radial();
        let tilt = 0.1f64;
        let p = pose(Vector::ZERO, Vector::new(tilt.sin(), 0.0, tilt.cos()));
        for end in End::BOTH {
            let r = bore_region(&g, &p, end).unwrap();
            assert_eq!(r.end_s, end.sign() * 0.008);
            assert!(r.inner_s * end.sign() > 0.0 && r.inner_s.abs() < 0.008);
            assert!(bore_section(&g, &p, r.inner_s).contact.depth.abs() < 1e-15);
        }
        // Untilted and centred: no contact.
        assert!(bore_region(&g, &pose(Vector::ZERO, Vector::Z), End::Lower).is_none());
    }
}
