//! The spatial clearance joint against independent references (`tests/support/spatial_reference.rs`,
//! written from the model's statement, not from the crate's code): the static equilibrium of a
//! body hung off-centre on a horizontal pin and of a door on a vertical one (tilt, deepest
//! penetration, each end's resultant, its point and its length), the energy of an undamped door,
//! and a tilted shoulder's rim strike on a face, the same turned about the hinge axis, against
//! a rigid-body ODE, and its velocity after a strike inside a sub-cycled world step.
//!
//! `cargo test --release --test spatial_exact -- --nocapture` prints every measured number.

use clearance_joint::model::laws::{BearingGeometry, Hertz, KelvinVoigt, NormalModel};
use clearance_joint::model::spatial::{FaceLaw, SpatialModel};
use clearance_joint::prelude::*;
use rapier3d_f64::prelude::*;

#[path = "support/spatial_reference.rs"]
mod reference;
use reference as r;

/// The pin: bearing radius 6 mm, radial clearance 0.1 mm, width 20 mm; axial play
/// 0.3 mm, shoulders of 10 mm.
const R_B: f64 = 0.006;
const C: f64 = 0.1e-3;
const L: f64 = 0.020;
const PLAY: f64 = 0.3e-3;
const COLLAR: f64 = 0.010;
/// The linear bore law for the whole width, N/m: `K/L = 5e9 N/m^2`.
const K: f64 = 1e8;
const G: f64 = 9.81;
/// The default step control's tolerance.
const TOLERANCE: f64 = 0.0075;
/// The target for the statics at the default tolerance.
const TARGET: f64 = 0.005;

/// The default face stiffness, computed here: a flat punch of the shoulder's radius on steel,
/// `K = 2 E* R_o`, `E* = E / (2 (1 - nu^2))` for two equal materials (E = 207 GPa, nu = 0.3).
fn steel_face_stiffness() -> f64 {
    let (e, nu) = (207e9, 0.3);
    2.0 * e / (2.0 * (1.0 - nu * nu)) * COLLAR
}

/// The reference's hinge with the bore law `bore`.
fn reference_hinge(bore: r::PowerLaw) -> r::Hinge {
    r::Hinge {
        bore_radius: R_B,
        clearance: C,
        width: L,
        play: PLAY,
        collar: COLLAR,
        bore,
        face_stiffness: steel_face_stiffness(),
    }
}

fn linear() -> r::PowerLaw {
    r::PowerLaw {
        stiffness: K,
        exponent: 1.0,
    }
}

/// The crate's spatial pin with the linear bore law (damping `damping`, N s/m, for the whole
/// width), no friction, the default face law (`SpatialModel::steel`).
fn linear_pin(damping: f64) -> HingeDesign {
    HingeDesign::new(
        BearingGeometry::from_clearance(R_B, C, L).unwrap(),
        NormalModel::KelvinVoigt(KelvinVoigt::new(K, damping).unwrap()),
    )
    .model(ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR)))
}

fn v3(v: Vector) -> r::V3 {
    [v.x, v.y, v.z]
}

/// `|a - b| <= tol |b|`, with the numbers in the message.
fn within(what: &str, measured: f64, reference: f64, tol: f64) -> Result<(), String> {
    if (measured - reference).abs() <= tol * reference.abs() {
        Ok(())
    } else {
        Err(format!(
            "{what}: {measured:.9e} against the reference {reference:.9e} ({:+.3} %, target {} %)",
            100.0 * (measured - reference) / reference,
            100.0 * tol
        ))
    }
}

#[test]
fn reference_self_checks() {
    for line in r::self_checks() {
        println!("{line}");
    }
    // The crate's default face law is the flat punch the reference assumes.
    let model = SpatialModel::steel(PLAY, COLLAR);
    assert!(
        (model.face.stiffness - steel_face_stiffness()).abs() < 1e-9 * steel_face_stiffness(),
        "default face stiffness {} N/m, 2 E* R_o = {} N/m",
        model.face.stiffness,
        steel_face_stiffness()
    );
}

/// The general reference (3-D sections, quadrature) against the closed forms of the linear law
/// in the plane of symmetry, and both against the textbook's rigid Winkler beam (which leaves
/// out the ellipse and the contact's height above the axis: 1 % of the edge forces at these
/// loads). Also the uniform case: `W/K` exactly.
#[test]
fn reference_equilibria_agree_with_closed_forms() {
    let h = reference_hinge(linear());
    let w = 10.0 * G;
    for d in [0.0, 0.005, 0.010, 0.025, 0.050] {
        let e = r::hanging_pin(&h, w, d);
        let (e0, tilt, ends, z, deepest) = r::hanging_pin_closed_form(&h, w, d);
        let (winkler, winkler_tilt) = r::rigid_winkler(K / L, w, d, C, L);
        let b = &e.contact.bore;
        println!(
            "d = {d} m: tilt {:.9e} rad (closed form {tilt:.9e}, Winkler {winkler_tilt:.6e}), \
             e0 {:.9e} m ({e0:.9e}), deepest {:.9e} m ({deepest:.9e}), ends {:.6} / {:.6} N \
             ({:.6} / {:.6}; Winkler {:.4} / {:.4}), residual {:.1e} N, {:.1e} N m",
            e.tilt,
            e.e0,
            e.contact.deepest,
            b.edges[0].force,
            b.edges[1].force,
            ends[0],
            ends[1],
            winkler[0],
            winkler[1],
            r::norm(e.residual_force),
            r::norm(e.residual_moment),
        );
        assert!(r::norm(e.residual_force) < 1e-9 * w);
        assert!((e.tilt - tilt).abs() <= 1e-9 * tilt.abs() + 1e-15);
        assert!((e.e0 - e0).abs() <= 1e-9 * e0);
        assert!((e.contact.deepest - deepest).abs() <= 1e-9 * deepest);
        for i in 0..2 {
            assert!((b.edges[i].force - ends[i]).abs() <= 1e-9 * w, "end {i}");
            if ends[i] > 0.0 {
                let zp = b.edges[i].point.unwrap()[2];
                assert!(
                    (zp - z[i]).abs() < 1e-12,
                    "end {i}: z {zp} against {}",
                    z[i]
                );
            }
            // Winkler within 2 % of the load (its geometry is the small-tilt limit's; the
            // uniform contact's split between the ends is a convention).
            if !b.uniform {
                let tol = 0.02 * winkler[i].max(w);
                assert!(
                    (b.edges[i].force - winkler[i]).abs() < tol,
                    "end {i}: Winkler"
                );
            }
        }
        // No face touches: the tilted bearing's faces stay clear of the fixed shoulders.
        assert!(e.contact.faces.iter().all(|f| f.deepest < -5e-6));
        if d == 0.0 {
            assert!((e.contact.deepest - w / K).abs() < 1e-12 * w / K);
            assert!((e.e0 - (C + w / K)).abs() < 1e-15);
        }
    }
}

/// What the crate reports at one state, for [`compare`].
#[derive(Debug, Clone)]
struct Reading {
    tilt: f64,
    penetration: f64,
    report: clearance_joint::rapier::joint::SpatialReport,
    /// The bearing's centre and axis (world).
    bearing_center: Vector,
    bearing_axis: Vector,
}

fn read(
    world: &ClearanceWorld,
    h: ClearanceJointHandle,
    bearing_body: RigidBodyHandle,
    bearing_anchor: Vector,
    bearing_axis: Vector,
) -> Reading {
    let j = world.clearance.get(h).unwrap();
    let s = j.report().spatial.unwrap();
    let rb = &world.rapier.bodies[bearing_body];
    Reading {
        tilt: s.tilt[0].hypot(s.tilt[1]),
        penetration: j.report().state.penetration,
        report: s,
        bearing_center: rb.position().transform_point(bearing_anchor),
        bearing_axis: rb.rotation() * bearing_axis,
    }
}

/// Compares what the crate reads with the reference's contact `c` (the bore's regions, the
/// deepest point, the faces) and tilt; returns the mismatches above the target (and prints
/// everything).
fn compare(label: &str, rd: &Reading, tilt: f64, c: &r::Contact, weight: f64) -> Vec<String> {
    let s = &rd.report;
    let mut bad = Vec::new();
    println!("{label}:");
    println!(
        "  tilt       {:.9e} rad   reference {:.9e}   ({:+.4} %)",
        rd.tilt,
        tilt,
        if tilt != 0.0 {
            100.0 * (rd.tilt - tilt) / tilt
        } else {
            f64::NAN
        }
    );
    println!(
        "  deepest    {:.9e} m     reference {:.9e}   ({:+.4} %)",
        rd.penetration,
        c.deepest,
        100.0 * (rd.penetration - c.deepest) / c.deepest
    );
    if tilt == 0.0 {
        if rd.tilt > 1e-9 {
            bad.push(format!("tilt {} rad, the reference none", rd.tilt));
        }
    } else if let Err(e) = within("tilt", rd.tilt, tilt, TARGET) {
        bad.push(e);
    }
    if let Err(e) = within("deepest penetration", rd.penetration, c.deepest, TARGET) {
        bad.push(e);
    }
    let b = &c.bore;
    let (ci, ai) = (v3(rd.bearing_center), v3(rd.bearing_axis));
    // Distance from the bore's axis (the reference's points are the deepest points of the
    // journal's sections, about R_b from it).
    let radial = |x: r::V3| {
        let rel = r::sub(x, ci);
        r::norm(r::sub(rel, r::scale(ai, r::dot(rel, ai))))
    };
    for i in 0..2 {
        let re = &b.edges[i];
        let end = if i == 0 { "lower" } else { "upper" };
        println!(
            "  {end} end  {:.6} N at {:?}, {:.6e} m long   reference {:.6} N at {:?}, {:.6e} m long",
            s.edge_force[i], s.edge_point[i], s.edge_length[i], re.force, re.point, re.length
        );
        if b.uniform {
            continue;
        }
        if re.force > 0.0 {
            if let Err(e) = within(
                &format!("{end} end's force"),
                s.edge_force[i],
                re.force,
                TARGET,
            ) {
                bad.push(e);
            }
            if let Err(e) = within(
                &format!("{end} end's length"),
                s.edge_length[i],
                re.length,
                TARGET,
            ) {
                bad.push(e);
            }
            // The point: its inset from its end of the width (the resultant's lever to the end)
            // within the target, its distance from the bore's axis within the target, on the
            // same side.
            let p = re.point.unwrap();
            let q = v3(s.edge_point[i]);
            let inset_ref = 0.5 * L - r::dot(r::sub(p, ci), ai).abs();
            let inset = 0.5 * L - r::dot(r::sub(q, ci), ai).abs();
            println!(
                "            inset from the end {:.6e} m, reference {:.6e} ({:+.4} %); {:.3e} m from the reference's point",
                inset,
                inset_ref,
                100.0 * (inset - inset_ref) / inset_ref,
                r::norm(r::sub(q, p))
            );
            if let Err(e) = within(
                &format!("{end} end's point's inset"),
                inset,
                inset_ref,
                TARGET,
            ) {
                bad.push(e);
            }
            if let Err(e) = within(
                &format!("{end} end's point's distance from the axis"),
                radial(q),
                radial(p),
                TARGET,
            ) {
                bad.push(e);
            }
            if r::dot(r::sub(q, ci), r::sub(p, ci)) <= 0.0 {
                bad.push(format!(
                    "{end} end's point on the other side: {q:?} against {p:?}"
                ));
            }
        } else if s.edge_force[i] > TARGET * weight {
            bad.push(format!(
                "{end} end carries {} N, the reference nothing",
                s.edge_force[i]
            ));
        }
    }
    if b.uniform {
        let sum = s.edge_force[0] + s.edge_force[1];
        let want = b.edges[0].force + b.edges[1].force;
        println!("  uniform contact: the ends carry {sum:.6} N together, reference {want:.6} N");
        if let Err(e) = within("both ends together", sum, want, TARGET) {
            bad.push(e);
        }
    }
    for f in 0..2 {
        let rf = &c.faces[f];
        println!(
            "  face {f}     {:.6} N at {:?}   reference {:.6} N at {:?}",
            s.face_force[f], s.face_point[f], rf.magnitude, rf.point
        );
        if rf.magnitude > 0.0 {
            if let Err(e) = within(
                &format!("face {f}'s force"),
                s.face_force[f],
                rf.magnitude,
                TARGET,
            ) {
                bad.push(e);
            }
            // Its point's distance from the bore's axis (the sliver's lever).
            let q = v3(s.face_point[f]);
            println!(
                "            from the axis {:.6e} m, reference {:.6e}; {:.3e} m from the reference's point",
                radial(q),
                radial(rf.point),
                r::norm(r::sub(q, rf.point))
            );
            if let Err(e) = within(
                &format!("face {f}'s point's distance from the axis"),
                radial(q),
                radial(rf.point),
                TARGET,
            ) {
                bad.push(e);
            }
        } else if s.face_force[f] > TARGET * weight {
            bad.push(format!(
                "face {f} carries {} N, the reference nothing",
                s.face_force[f]
            ));
        }
    }
    bad
}

/// Compares the joint's wrench on `body` (index `side` of `last_wrenches`: 0 the bearing's body,
/// 1 the journal's) with the reference's contact `c` (force and moment about the origin on the
/// journal), the moment taken about the body's centre of mass `com`; `scale` is the moment's
/// scale for the target (N m).
fn compare_wrench(
    world: &ClearanceWorld,
    h: ClearanceJointHandle,
    side: usize,
    com: r::V3,
    c: &r::Contact,
    scale: f64,
) -> Vec<String> {
    let w = world.clearance.get(h).unwrap().last_wrenches().unwrap()[side];
    let sign = if side == 0 { -1.0 } else { 1.0 };
    let f_ref = r::scale(c.force, sign);
    let m_ref = r::sub(r::scale(c.moment, sign), r::cross(com, f_ref));
    let (df, dm) = (
        r::norm(r::sub(v3(w.force), f_ref)),
        r::norm(r::sub(v3(w.torque), m_ref)),
    );
    println!(
        "  wrench on the {} body: force {:?} N (reference {f_ref:.9?}, off by {df:.3e}), torque about its centre of mass {:?} N m (reference {m_ref:.9?}, off by {dm:.3e})",
        if side == 0 { "bearing's" } else { "journal's" },
        w.force,
        w.torque
    );
    let mut bad = Vec::new();
    if df > TARGET * r::norm(f_ref) {
        bad.push(format!("wrench force off by {df} N of {}", r::norm(f_ref)));
    }
    if dm > TARGET * scale {
        bad.push(format!("wrench torque off by {dm} N m (scale {scale} N m)"));
    }
    bad
}

/// The hanging pin's world: a 10 kg body (0.02 kg m^2 about each axis through its centre of mass)
/// on a fixed horizontal pin (the journal, along z through the origin), the body carrying the
/// bearing (its centre at the body's origin), its centre of mass on the bearing's axis `d` m
/// from the bearing's mid-plane: its weight is the load, and nothing turns it about the hinge.
/// Placed at the reference's equilibrium ([`r::hanging_pin`]: sunk by `e0`, tilted by `theta`
/// about x). The linear bore law with the damping `2e5 N s/m` (the sinking mode over-damped).
fn hanging_world(
    d: f64,
    tolerance: f64,
) -> (
    ClearanceWorld,
    RigidBodyHandle,
    ClearanceJointHandle,
    r::Equilibrium,
    f64,
) {
    let (mass, inertia) = (10.0, 0.02);
    let w = mass * G;
    let e = r::hanging_pin(&reference_hinge(linear()), w, d);
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -G, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, tolerance));
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let body = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(
                Vector::new(0.0, -e.e0, 0.0),
                Rotation::from_scaled_axis(Vector::new(e.tilt, 0.0, 0.0)),
            ))
            .additional_mass_properties(MassProperties::new(
                Vector::new(0.0, 0.0, d),
                mass,
                Vector::splat(inertia),
            ))
            .can_sleep(false),
    );
    let joint = linear_pin(2e5)
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let h = world.insert_clearance(body, base, joint).unwrap();
    world.prepare().unwrap();
    (world, body, h, e, w)
}

/// The statics: the crate's joint evaluated at the reference's equilibrium pose of the hanging
/// pin (no step taken) reads the reference's tilt, deepest penetration, each end's resultant,
/// point and length, and its wrench on the body is the reference's (which balances the weight).
fn offset_load_statics(d: f64) {
    let (world, body, h, e, w) = hanging_world(d, TOLERANCE);
    let rd = read(&world, h, body, Vector::ZERO, Vector::Z);
    let mut bad = compare(
        &format!("hanging pin at the reference's equilibrium, W = {w} N at d = {d} m"),
        &rd,
        e.tilt,
        &e.contact,
        w,
    );
    let com = r::add(e.pose.bearing_center, r::scale(e.pose.bearing_axis, d));
    let scale = e.contact.bore.edges[0]
        .force
        .max(e.contact.bore.edges[1].force)
        * L;
    bad.extend(compare_wrench(&world, h, 0, com, &e.contact, scale));
    assert!(bad.is_empty(), "d = {d} m:\n{}", bad.join("\n"));
}

#[test]
fn static_offset_load_centred() {
    offset_load_statics(0.0);
}

#[test]
fn static_offset_load_10_mm() {
    offset_load_statics(0.010);
}

#[test]
fn static_offset_load_25_mm() {
    offset_load_statics(0.025);
}

#[test]
fn static_offset_load_50_mm() {
    offset_load_statics(0.050);
}

/// The dynamics at rest: started at the equilibrium (the reference's and, by the statics tests,
/// the crate's), the hanging body must stay there at the default tolerance: over 0.3 s its
/// speed below 1e-6 m/s and its ends' forces steady to 1e-4, and (median over the last 10 % of
/// the steps) the reference's values to the target.
fn offset_load_stays(d: f64, tolerance: f64) {
    let until = 0.3;
    let (mut world, body, h, e, w) = hanging_world(d, tolerance);
    let mut samples: Vec<Reading> = Vec::new();
    let (mut speed, mut spin) = (0.0f64, 0.0f64);
    let mut first_jump: Option<(f64, [f64; 2], [f64; 2])> = None;
    let start = read(&world, h, body, Vector::ZERO, Vector::Z).report;
    while world.time() < until {
        world.step(until).unwrap();
        world.prepare().unwrap();
        let rb = &world.rapier.bodies[body];
        let rd = read(&world, h, body, Vector::ZERO, Vector::Z);
        if first_jump.is_none()
            && (0..2).any(|i| (rd.report.edge_force[i] - start.edge_force[i]).abs() > 1e-6 * w)
        {
            first_jump = Some((world.time(), rd.report.edge_force, rd.report.edge_length));
        }
        if world.time() > 0.9 * until {
            speed = speed.max(rb.linvel().length());
            spin = spin.max(rb.angvel().length());
            samples.push(rd);
        }
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    let median = |f: &dyn Fn(&Reading) -> f64| {
        let mut v: Vec<f64> = samples.iter().map(f).collect();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        v[v.len() / 2]
    };
    let spread = |f: &dyn Fn(&Reading) -> f64| {
        let v: Vec<f64> = samples.iter().map(f).collect();
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let mut typical = samples.last().unwrap().clone();
    typical.tilt = median(&|r| r.tilt);
    typical.penetration = median(&|r| r.penetration);
    for i in 0..2 {
        typical.report.edge_force[i] = median(&|r| r.report.edge_force[i]);
        typical.report.edge_length[i] = median(&|r| r.report.edge_length[i]);
        typical.report.edge_point[i].z = median(&|r| r.report.edge_point[i].z);
    }
    let steady = (0..2)
        .map(|i| spread(&|r| r.report.edge_force[i]))
        .fold(0.0, f64::max)
        / w;
    println!(
        "hanging pin left at rest, d = {d} m, tolerance {tolerance}: {} steps to {until} s; over the last 10 %: speed up to {speed:.2e} m/s, spin {spin:.2e} rad/s, the ends' forces spread over {steady:.2e} of the weight",
        world.steps()
    );
    match first_jump {
        Some((t, f, l)) => println!(
            "  first moved at t = {t:.6} s: ends {f:.4?} N, lengths {l:.4?} m (started at {:.4?} N, {:.4?} m)",
            start.edge_force, start.edge_length
        ),
        None => println!("  never moved"),
    }
    let bad = compare(
        "  (medians over the last 10 % of the steps)",
        &typical,
        e.tilt,
        &e.contact,
        w,
    );
    let mut problems = bad;
    if !(speed < 1e-6 && steady < 1e-4) {
        problems.push(format!(
            "not at rest: speed up to {speed:.3e} m/s, spin {spin:.3e} rad/s, the ends' forces spread over {steady:.3e} of the weight"
        ));
    }
    assert!(problems.is_empty(), "d = {d} m:\n{}", problems.join("\n"));
}

#[test]
fn offset_load_stays_at_rest_centred() {
    offset_load_stays(0.0, TOLERANCE);
}

#[test]
fn offset_load_stays_at_rest_10_mm() {
    offset_load_stays(0.010, TOLERANCE);
}

#[test]
fn offset_load_stays_at_rest_25_mm() {
    offset_load_stays(0.025, TOLERANCE);
}

#[test]
fn offset_load_stays_at_rest_50_mm() {
    offset_load_stays(0.050, TOLERANCE);
}

/// The door's world: a 2 kg panel (0.4 x 0.3 x 0.02 m) hung by its edge, its journal (at the
/// panel's `(-0.2, 0, 0)`) on a fixed vertical bearing (the post at the origin), the linear bore
/// law with the damping `2e5 N s/m`, placed at the reference's equilibrium ([`r::door`]).
fn door_world(
    tolerance: f64,
) -> (
    ClearanceWorld,
    RigidBodyHandle,
    ClearanceJointHandle,
    r::DoorEquilibrium,
    f64,
) {
    let (mass, arm) = (2.0, 0.2);
    let w = mass * G;
    let e = r::door(&reference_hinge(linear()), w, arm);
    println!(
        "door reference: e0 {:.6e} m, u {:.6e} m, tilt {:.9e} rad, residual {:.1e} N, {:.1e} N m",
        e.e0,
        e.u,
        e.tilt,
        r::norm(e.residual_force),
        r::norm(e.residual_moment)
    );
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -G, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, tolerance));
    let post = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    // The panel's origin (its centre of mass) is `arm` along its x from the journal's centre.
    let rot = Rotation::from_scaled_axis(Vector::new(0.0, 0.0, e.tilt));
    let jc = Vector::new(e.e0, e.u, 0.0);
    let panel = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(jc + rot * Vector::new(arm, 0.0, 0.0), rot))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::new(0.0150667, 0.0267333, 0.0416667),
            ))
            .can_sleep(false),
    );
    let joint = linear_pin(2e5)
        .joint(
            Vector::ZERO,
            Vector::new(-arm, 0.0, 0.0),
            Vector::Y,
            Vector::Y,
        )
        .unwrap();
    let h = world.insert_clearance(post, panel, joint).unwrap();
    world.prepare().unwrap();
    (world, panel, h, e, w)
}

/// The door with the linear bore law at the reference's equilibrium: the upper shoulder
/// rests on the upper face (a sliver at its rim, the tilted shoulder against the face), the
/// journal tilts onto the bore's two edges. The crate's reading and its wrench on the panel
/// against [`r::door`].
#[test]
fn static_door() {
    let (world, panel, h, e, w) = door_world(TOLERANCE);
    let post = world.clearance.get(h).unwrap().body1();
    let rd = read(&world, h, post, Vector::ZERO, Vector::Y);
    let mut bad = compare(
        "door at the reference's equilibrium",
        &rd,
        e.tilt.abs(),
        &e.contact,
        w,
    );
    let com = v3(world.rapier.bodies[panel].center_of_mass());
    let scale = e.contact.bore.edges[0]
        .force
        .max(e.contact.bore.edges[1].force)
        * L;
    bad.extend(compare_wrench(&world, h, 1, com, &e.contact, scale));
    assert!(bad.is_empty(), "door:\n{}", bad.join("\n"));
}

/// The door of docs/spatial-joint.md without any damping: a pure Hertz bore (`F = K delta^1.5`,
/// `K = (pi/2) E* L / sqrt(c)` = 3.6e11 N/m^1.5, Liu's steel line contact's stiffness at a
/// penetration of about c/5), elastic faces (restitution 1), no friction. It falls through its
/// axial play onto the upper face, sags onto the edges and rocks, swinging at 1 rad/s. Its total
/// energy is kinetic + gravity's + the joint's `elastic_energy()`, over 0.1 s; returned are its
/// largest drift (J) and the largest kinetic energy (J), at `tolerance`.
///
/// The stepper is variable-step Stormer-Verlet: after a step the bodies hold the new pose and
/// the velocity of the step just taken (a half-step velocity). The energy at a state is read with
/// synchronous velocities, the half-step velocities on either side of it weighted by the steps
/// (`v(t_k) = (h_{k+1} v_{k-1/2} + h_k v_{k+1/2})/(h_k + h_{k+1})`), as the crate's own energy
/// balance does; the joint's elastic energy is read at the same state (`prepare` after the step).
/// The naive reading (the half-step velocity with the new pose) is printed too: its error is
/// first order in the step. The joint's elastic energy is also compared with the reference's `U`
/// at the bodies' poses at every step.
fn undamped_door_drift(tolerance: f64) -> (f64, f64) {
    let (mass, arm, until) = (2.0, 0.2, 0.1);
    let inertia = Vector::new(0.0150667, 0.0267333, 0.0416667);
    let e_star = 207e9 / (2.0 * (1.0 - 0.3f64 * 0.3));
    let law = r::PowerLaw {
        stiffness: 0.5 * std::f64::consts::PI * e_star * L / C.sqrt(),
        exponent: 1.5,
    };
    let model = SpatialModel::steel(PLAY, COLLAR);
    let model = model.face(FaceLaw {
        stiffness: model.face.stiffness,
        restitution: 1.0,
    });
    // Explicit: the energy is read at each step's end, where the steps resolve the contacts.
    let pin = HingeDesign::new(
        BearingGeometry::from_clearance(R_B, C, L).unwrap(),
        NormalModel::Hertz(Hertz::new(law.stiffness, law.exponent).unwrap()),
    )
    .integration(ContactIntegration::Explicit)
    .model(ClearanceModel::Spatial(model));
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -G, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, tolerance));
    let post = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let panel = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(arm, 0.15e-3, 0.0))
            .linvel(Vector::new(0.0, 0.0, -0.2))
            .angvel(Vector::new(0.0, 1.0, 0.0))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, mass, inertia))
            .can_sleep(false),
    );
    let anchor2 = Vector::new(-arm, 0.0, 0.0);
    let joint = pin
        .joint(Vector::ZERO, anchor2, Vector::Y, Vector::Y)
        .unwrap();
    let h = world.insert_clearance(post, panel, joint).unwrap();
    let hinge = reference_hinge(law);
    world.prepare().unwrap();
    // The state's energies but the kinetic: (gravity's, the joint's elastic, the reference's U,
    // the rotation, the velocities held).
    struct State {
        pe: f64,
        el: f64,
        el_ref: f64,
        rot: Rotation,
        v: Vector,
        w: Vector,
    }
    let state = |world: &ClearanceWorld| {
        let rb = &world.rapier.bodies[panel];
        let j = world.clearance.get(h).unwrap();
        let pose = r::Pose {
            bearing_center: [0.0; 3],
            bearing_axis: [0.0, 1.0, 0.0],
            journal_center: v3(rb.position().transform_point(anchor2)),
            journal_axis: v3(rb.rotation() * Vector::Y),
        };
        State {
            pe: mass * G * rb.center_of_mass().y,
            el: j.elastic_energy(),
            el_ref: r::contact(&hinge, &pose, false).energy,
            rot: *rb.rotation(),
            v: rb.linvel(),
            w: rb.angvel(),
        }
    };
    let kinetic = |rot: Rotation, v: Vector, w: Vector| {
        let wb = rot.inverse() * w;
        0.5 * mass * v.length_squared()
            + 0.5 * (inertia.x * wb.x * wb.x + inertia.y * wb.y * wb.y + inertia.z * wb.z * wb.z)
    };
    let s0 = state(&world);
    let e0 = kinetic(s0.rot, s0.v, s0.w) + s0.pe + s0.el;
    let (mut prev, mut prev_dt) = (s0, 0.0);
    let (mut ke_max, mut el_max, mut drift, mut naive, mut el_err, mut el_ref_max) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut face_peak, mut tilt_peak, mut worst_t) = (0.0f64, 0.0f64, 0.0);
    while world.time() < until {
        let t_prev = world.time();
        let info = world.step(until).unwrap();
        world.prepare().unwrap();
        let now = state(&world);
        if prev_dt > 0.0 {
            // The previous state's synchronous velocities.
            let (h0, h1) = (prev_dt, info.dt);
            let v = (prev.v * h1 + now.v * h0) / (h0 + h1);
            let w = (prev.w * h1 + now.w * h0) / (h0 + h1);
            let ke = kinetic(prev.rot, v, w);
            ke_max = ke_max.max(ke);
            let e = ke + prev.pe + prev.el;
            if std::env::var("DBG_ENERGY").is_ok() {
                let s = world.clearance.get(h).unwrap().report().spatial.unwrap();
                println!(
                    "E t {t_prev:.6} dt {h0:.3e} dE {:.4e} ke {ke:.6e} pe {:.6e} el {:.6e} face {:.1} edges {:.1} {:.1} tilt {:.4e}",
                    e - e0,
                    prev.pe,
                    prev.el,
                    s.face_force[1],
                    s.edge_force[0],
                    s.edge_force[1],
                    s.tilt[0].hypot(s.tilt[1])
                );
            }
            if (e - e0).abs() > drift {
                drift = (e - e0).abs();
                worst_t = t_prev;
            }
        }
        naive = naive.max((kinetic(now.rot, now.v, now.w) + now.pe + now.el - e0).abs());
        el_max = el_max.max(now.el);
        el_ref_max = el_ref_max.max(now.el_ref);
        el_err = el_err.max((now.el - now.el_ref).abs());
        let s = world.clearance.get(h).unwrap().report().spatial.unwrap();
        face_peak = face_peak.max(s.face_force[1]);
        tilt_peak = tilt_peak.max(s.tilt[0].hypot(s.tilt[1]));
        prev = now;
        prev_dt = info.dt;
    }
    let fall = mass * G * PLAY;
    println!(
        "undamped door: {} steps to {until} s; peak face {face_peak:.1} N, peak tilt {tilt_peak:.4e} rad",
        world.steps()
    );
    println!(
        "  energy drift (synchronous velocities) {drift:.3e} J (worst at {worst_t:.5} s): {:.3e} of the largest kinetic energy {ke_max:.4e} J, \
         {:.3e} of the largest elastic energy {el_max:.4e} J, {:.3e} of the fall through the play {fall:.4e} J",
        drift / ke_max,
        drift / el_max,
        drift / fall
    );
    println!(
        "  (read naively, the half-step velocity with the new pose: {naive:.3e} J, {:.3e} of the largest kinetic energy)",
        naive / ke_max
    );
    println!(
        "  elastic energy against the reference's U at the same poses: worst {el_err:.3e} J \
         ({:.3e} of its peak {el_ref_max:.4e} J)",
        el_err / el_ref_max
    );
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    assert!(
        face_peak > 0.0 && tilt_peak > 2.0 * C / L,
        "the door neither knocked nor sagged"
    );
    assert!(
        el_err <= 1e-3 * el_ref_max,
        "the joint's elastic energy is {:.3e} of its peak off the reference's U",
        el_err / el_ref_max
    );
    (drift, ke_max)
}

/// The undamped door (no damping, no friction, faces of restitution 1) keeps its energy to the
/// integration's accuracy, which the tolerance controls: its drift over the stiff edge and face
/// knocks falls at second order as the tolerance tightens (measured 2.6e-3 of the largest kinetic
/// energy at the default 0.0075, 2.4e-5 at 0.001).
#[test]
fn undamped_door_keeps_its_energy() {
    let (coarse, ke) = undamped_door_drift(TOLERANCE);
    let (fine, _) = undamped_door_drift(0.001);
    println!(
        "drift {:.3e} of the kinetic energy at {TOLERANCE}, {:.3e} at 0.001",
        coarse / ke,
        fine / ke
    );
    assert!(
        coarse <= 5e-3 * ke,
        "drift {:.3e} at the default",
        coarse / ke
    );
    assert!(fine <= 5e-5 * ke, "drift {:.3e} at 0.001", fine / ke);
    assert!(
        fine < coarse / 20.0,
        "no convergence: {coarse:.3e} J, then {fine:.3e} J"
    );
}

/// The rim strike: a free journal (0.5 kg, 1e-4 kg m^2 about each axis through its centre) in a
/// fixed bearing along z, no gravity, tilted 5 mrad about the bearing's x (no bore contact: its
/// ends stay 50 um clear), its upper shoulder's rim 1 um above the upper face, moving onto it at
/// 0.1 m/s. Returns the peak upper-face force over 1 ms (sampled at every step), the steps, and
/// the peak of the bore's force (which must stay 0).
///
/// `turn` rotates, about the hinge axis by `angle`: `Journal` the journal's initial pose (its
/// tilt's direction and its body frame), `Bearing` the fixed bearing body, `Spin` the journal
/// about its own axis (its body frame only).
#[derive(Clone, Copy, Debug)]
enum Turn {
    None,
    Journal,
    Bearing,
    Spin,
}

const RIM_TILT: f64 = 0.005;
const RIM_SPEED: f64 = 0.1;

fn rim_strike(turn: Turn, angle: f64, restitution: f64) -> (f64, u64, f64) {
    let (peak, _, steps, bore) =
        rim_strike_integrated(turn, angle, restitution, ContactIntegration::Explicit);
    (peak, steps, bore)
}

/// The world of the rim strike of [`rim_strike`], turned by `(turn, angle)`, its face's
/// restitution `restitution`, integrated as `integration` and stepped by `control`, the journal
/// started `delay` s (at its speed) further from the face: `(world, journal, pin)`.
fn rim_strike_world(
    (turn, angle): (Turn, f64),
    restitution: f64,
    integration: ContactIntegration,
    control: StepControl,
    delay: f64,
) -> (ClearanceWorld, RigidBodyHandle, ClearanceJointHandle) {
    let (mass, inertia) = (0.5, 1e-4);
    let model = SpatialModel::steel(PLAY, COLLAR);
    let model = model.face(FaceLaw {
        stiffness: model.face.stiffness,
        restitution,
    });
    let pin = HingeDesign::steel_improved_liu(R_B, C, L)
        .unwrap()
        .integration(integration)
        .model(ClearanceModel::Spatial(model));
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.num_solver_iterations = 1;
    let mut world = ClearanceWorld::new(rapier, control);
    let z0 = r::rim_start(&reference_hinge(linear()), RIM_TILT) + RIM_SPEED * delay;
    let about_z = Rotation::from_scaled_axis(Vector::new(0.0, 0.0, angle));
    let tilt = Rotation::from_scaled_axis(Vector::new(RIM_TILT, 0.0, 0.0));
    let (bearing_rot, journal_rot) = match turn {
        Turn::None => (Rotation::IDENTITY, tilt),
        Turn::Journal => (Rotation::IDENTITY, about_z * tilt),
        Turn::Bearing => (about_z, tilt),
        Turn::Spin => (Rotation::IDENTITY, tilt * about_z),
    };
    let base = world
        .rapier
        .bodies
        .insert(RigidBodyBuilder::fixed().pose(Pose::from_parts(Vector::ZERO, bearing_rot)));
    let pin_body = world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(Vector::new(0.0, 0.0, z0), journal_rot))
            .linvel(Vector::new(0.0, 0.0, -RIM_SPEED))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::splat(inertia),
            ))
            .can_sleep(false),
    );
    let joint = pin
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let h = world.insert_clearance(base, pin_body, joint).unwrap();
    (world, pin_body, h)
}

/// The rim strike of [`rim_strike`] integrated as `integration`: the peak face force read at
/// the steps' ends, the peak normal force at the sub-steps' states (a sub-cycled joint's; 0 for
/// an explicit one), the steps and the bore's peak force.
fn rim_strike_integrated(
    turn: Turn,
    angle: f64,
    restitution: f64,
    integration: ContactIntegration,
) -> (f64, f64, u64, f64) {
    let control = StepControl::adaptive(1e-3, TOLERANCE);
    let (mut world, _, h) = rim_strike_world((turn, angle), restitution, integration, control, 0.0);
    let (mut peak, mut sub_peak, mut bore) = (0.0f64, 0.0f64, 0.0f64);
    while world.time() < 1e-3 {
        world.step(1e-3).unwrap();
        let j = world.clearance.get(h).unwrap();
        let s = j.report().spatial.unwrap();
        peak = peak.max(s.face_force[1]);
        bore = bore.max(s.bore_force);
        for sub in j.substeps() {
            sub_peak = sub_peak.max(sub.force.normal_force);
        }
    }
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    (peak, sub_peak, world.steps(), bore)
}

/// The same rim strike turned by 22.5 deg about the hinge axis gives the same peak face force
/// within 1e-6: the journal's pose, the fixed bearing, and the journal about its own axis; with
/// the default face restitution (0.9) and an elastic face (measured within 1e-12). The face's
/// contact region is measured from the tilt, and the stepper's division of the time left into
/// equal steps does not let rounding add a step (it did: the turned runs took a first step of
/// 1 ms/201 against 1 ms/200, and peaked 1.2e-4 higher).
#[test]
fn rim_strike_is_the_same_turned_about_the_axis() {
    let angle = 22.5f64.to_radians();
    let mut bad = Vec::new();
    for restitution in [FaceLaw::DEFAULT_RESTITUTION, 1.0] {
        let (base, steps, bore) = rim_strike(Turn::None, 0.0, restitution);
        println!(
            "rim strike, restitution {restitution}: peak face force {base:.9} N in {steps} steps (bore {bore} N)"
        );
        assert!(base > 100.0, "no strike: {base} N");
        assert_eq!(bore, 0.0, "the bore touched");
        for turn in [Turn::Journal, Turn::Bearing, Turn::Spin] {
            let (peak, steps, _) = rim_strike(turn, angle, restitution);
            let rel = (peak - base) / base;
            println!("  turned ({turn:?}): {peak:.9} N in {steps} steps, {rel:+.3e}");
            if rel.abs() > 1e-6 {
                bad.push(format!(
                    "restitution {restitution}, {turn:?}: {peak} N against {base} N ({rel:+.3e})"
                ));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The rim strike with an elastic face against the reference: the journal's axial motion and
/// tilt as a 2-DOF rigid-body ODE (classical Runge-Kutta, 0.1 us steps) under the annulus's
/// sliver force integrated exactly ([`r::rim_strike`]). The crate's peak is sampled at its
/// steps (explicit) or at its sub-steps (sub-cycled, the default: its world steps span the
/// strike, and their ends read 617 N against the reference's 646 N): within 1 % (printed).
/// The reference ODE's rim strike of [`rim_strike`] (elastic face; RK4 at 0.1 us): the
/// largest force (N), its time and the contact's end from the start (s), and the exit
/// velocities ([`r::rim_strike`]).
fn reference_rim_strike() -> (f64, f64, f64, [f64; 2]) {
    r::rim_strike(
        &reference_hinge(linear()),
        0.5,
        1e-4,
        RIM_TILT,
        RIM_SPEED,
        1e-7,
    )
}

#[test]
fn rim_strike_peak_matches_the_reference_ode() {
    let (peak, steps, _) = rim_strike(Turn::None, 0.0, 1.0);
    let (_, sub_peak, sub_steps, _) =
        rim_strike_integrated(Turn::None, 0.0, 1.0, ContactIntegration::SubCycled);
    let (want, at, end, _) = reference_rim_strike();
    println!(
        "rim strike, elastic face: peak {peak:.6} N in {steps} steps; reference {want:.6} N at {:.3} us (contact over by {:.3} us), {:+.4} %",
        at * 1e6,
        end * 1e6,
        100.0 * (peak - want) / want
    );
    println!(
        "  sub-cycled: peak {sub_peak:.6} N over the sub-steps in {sub_steps} steps, {:+.4} %",
        100.0 * (sub_peak - want) / want
    );
    assert!(
        (peak - want).abs() < 0.01 * want,
        "peak {peak} N, reference {want} N"
    );
    assert!(
        (sub_peak - want).abs() < 0.01 * want,
        "sub-cycled: peak {sub_peak} N, reference {want} N"
    );
}

/// The journal's velocity (axial speed along `z`, m/s, and spin about `x`, rad/s) at the world
/// state at 2 ms after the rim strike of [`rim_strike`] started 1.5 ms further from the face (it
/// strikes at 1.51 ms), its face elastic, integrated as `integration` and stepped by `control`:
/// the velocity at the state ([`ClearanceWorld::velocity_at_state`]) and Rapier's.
fn rim_strike_state(integration: ContactIntegration, control: StepControl) -> ([f64; 2], [f64; 2]) {
    let (mut world, journal, _) =
        rim_strike_world((Turn::None, 0.0), 1.0, integration, control, 1.5e-3);
    while world.time() < 2e-3 - 1e-12 {
        world.step(2e-3).unwrap();
    }
    assert!((world.time() - 2e-3).abs() < 1e-12, "{}", world.time());
    assert!(world.guards().is_clean(), "{:?}", world.guards());
    let (v, w) = world.velocity_at_state(journal).unwrap();
    let rb = &world.rapier.bodies[journal];
    ([v.z, w.x], [rb.linvel().z, rb.angvel().x])
}

/// A spatial sub-cycled joint's velocity at the state holds the whole of an impact inside its
/// world step: the rim strike of [`rim_strike`] (elastic face) inside the second of 1 ms world
/// steps (from 1.51 ms to 1.76 ms: the reference's contact ends 260 us after its start). At the
/// state after that step (2 ms) the journal's axial speed and spin at the state
/// ([`ClearanceWorld::velocity_at_state`], from the joint's
/// [`ClearanceJoint::state_velocity`]) are the explicit joint's at fixed 1 us steps within 2e-3
/// of the strike's change of each: the sub-steps' error at the default tolerance (measured
/// 2.5e-4 and 2.9e-4). That run's are the reference ODE's exit velocities (classical
/// Runge-Kutta at 0.1 us) within 1e-4 of the change (measured 5.5e-7 and 8.2e-7). Rapier's
/// velocities there, the mean over the step, lack the part of the strike's impulse delivered
/// with the next step: 0.64 of the change off in each.
#[test]
fn rim_strike_inside_a_step_is_whole_in_the_velocity_at_the_state() {
    let (_, _, end, exit) = reference_rim_strike();
    println!(
        "the reference's strike is over {:.1} us from its start",
        end * 1e6
    );
    let change = [exit[0] + RIM_SPEED, exit[1]];
    let (fine, _) = rim_strike_state(ContactIntegration::Explicit, StepControl::fixed(1e-6));
    let control = StepControl {
        tolerance: TOLERANCE,
        ..StepControl::fixed(1e-3)
    };
    let (state, rapier) = rim_strike_state(ContactIntegration::SubCycled, control);
    let mut bad = Vec::new();
    for (k, what) in ["axial speed (m/s)", "spin (rad/s)"]
        .into_iter()
        .enumerate()
    {
        let off = |x: f64, y: f64| (x - y).abs() / change[k].abs();
        let (reference, sub, mean) = (
            off(fine[k], exit[k]),
            off(state[k], fine[k]),
            off(rapier[k], fine[k]),
        );
        println!(
            "{what}: ODE {:.7e}, explicit at 1 us {:.7e} ({reference:.1e} of the change), \
             sub-cycled at the state {:.7e} ({sub:.1e}), Rapier's {:.7e} ({mean:.2})",
            exit[k], fine[k], state[k], rapier[k]
        );
        if reference > 1e-4 || sub > 2e-3 {
            bad.push(format!(
                "{what}: {reference:.1e} and {sub:.1e} of the change off"
            ));
        }
        assert!(
            mean > 0.1,
            "{what}: Rapier's mean velocity {mean:.2e} of the change off"
        );
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
