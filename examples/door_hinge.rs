//! A gate on one hinge, planar and spatial: what the planar clearance joint hides.
//!
//! A 2 kg panel (0.4 m wide along x from the hinge axis, 0.3 m tall, 20 mm thick) hangs on ONE
//! vertical steel pin: bearing radius 6 mm, radial clearance 0.1 mm, 20 mm wide, dry friction.
//! Its weight makes a moment of `m g x = 3.92 N m` across the hinge axis. The planar clearance
//! joint holds that moment and the weight with its ideal out-of-plane lock, so the panel neither
//! sags nor knocks. The spatial joint (`ClearanceModel::Spatial`, axial play 0.3 mm, collars of
//! 10 mm radius) locks nothing: the journal tilts until the bore's two edges hold the moment
//! (edge loading), the panel sags at its free edge, and the collar drops onto the bearing's top
//! face (an axial knock). The panel starts 0.15 mm above its centred axial position, swinging at
//! 1 rad/s about the axis.
//!
//! Each twin is a `ClearanceWorld` on the default adaptive steps.
//!
//! A static balance checks the spatial twin once the swing has died down: the weight's moment
//! `m g x` is held by the moments of the bore's and the faces' contact forces about the
//! bearing's centre (each quadrature point's normal and friction force at its point,
//! `ClearanceJoint::spatial_points`).
//!
//! `cargo run --release --example door_hinge`

use clearance_joint::Result;
use clearance_joint::model::angle::twist_angle;
use clearance_joint::model::laws::{Bai, FrictionModel};
use clearance_joint::model::spatial::SpatialModel;
use clearance_joint::prelude::*;
use clearance_joint::rapier::joint::{ClearanceJoint, Region};
use rapier3d_f64::prelude::*;
use std::process::ExitCode;

/// Simulated time, s.
pub const END: f64 = 1.0;
/// Panel mass, kg.
pub const MASS: f64 = 2.0;
/// Distance of the panel's centre of mass from the hinge axis, m.
pub const ARM: f64 = 0.2;
/// Bearing width, m.
pub const WIDTH: f64 = 0.020;
/// How far above its centred axial position the journal starts, m.
pub const DROP: f64 = 0.15e-3;

/// What one twin did.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// Steps taken.
    pub steps: u64,
    /// Swing angle at the end, deg.
    pub swing_deg: f64,
    /// Largest tilt of the journal against the bore, rad (0 for the planar joint).
    pub max_tilt: f64,
    /// The panel's free edge's sag at the end, mm (its drop below where the ideal hinge holds it).
    pub sag_mm: f64,
    /// Largest force at each bore edge, N.
    pub max_edge_force: [f64; 2],
    /// Edge forces averaged over the last 0.2 s, N.
    pub late_edge_force: [f64; 2],
    /// Force on both faces averaged over the last 0.2 s, N.
    pub late_face_force: f64,
    /// Moments about the bearing's centre, averaged over the last 0.2 s, N m: of the edge
    /// regions' resultants (their arms along the axis), of the faces' (their arms from it).
    pub late_moments: [f64; 2],
    /// Face knocks: contacts of a shoulder with a face that began after a free flight.
    pub face_knocks: u32,
    /// Largest force on the faces, N.
    pub max_face_force: f64,
    /// Impacts the joint counted.
    pub impacts: u32,
    /// Whether the guards stayed clean.
    pub clean: bool,
}

/// The pin: steel improved-Liu, bearing radius 6 mm, radial clearance 0.1 mm, dry friction.
pub fn pin() -> Result<HingeDesign> {
    Ok(HingeDesign::steel_improved_liu(0.006, 0.1e-3, WIDTH)?
        .friction(FrictionModel::Bai(Bai::DRY)))
}

/// The spatial model: axial play 0.3 mm, collars of 10 mm radius.
pub fn spatial_model() -> SpatialModel {
    SpatialModel::steel(0.3e-3, 0.010)
}

/// The moments that hold the weight's moment `m g x` once the swing has died down (last 0.2 s):
/// `[edges, face]`, N m.
pub fn holding_moments(o: &Outcome) -> [f64; 2] {
    o.late_moments
}

/// The moments about the bearing's centre (the origin) of the joint's contact forces on the
/// panel, N m: `[bore, faces]`, about the horizontal axis the weight's moment turns when the
/// panel's centre of mass is at `com` (square to it: the axis turns with the swing).
fn moments(joint: &ClearanceJoint, com: Vector) -> [f64; 2] {
    let across = Vector::new(-com.z, 0.0, com.x).normalize();
    let mut m = [0.0; 2];
    for p in joint.spatial_points() {
        let normal = -p.normal_force * p.contact.gradient.normalize();
        let speed = p.slip.length();
        let friction = if speed > 0.0 {
            -p.friction_force / speed * p.slip
        } else {
            Vector::ZERO
        };
        let k = usize::from(matches!(p.region, Region::Face(_)));
        m[k] += p.contact.point.cross(normal + friction).dot(across);
    }
    m
}

fn panel_world(spatial: bool) -> Result<(ClearanceWorld, RigidBodyHandle, ClearanceJointHandle)> {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::new(0.0, -9.81, 0.0);
    rapier.integration_parameters.num_solver_iterations = 1;
    let post = rapier.bodies.insert(RigidBodyBuilder::fixed());
    // Box inertia of a 0.4 x 0.3 x 0.02 m panel about its centre.
    let (w, h, t) = (0.4_f64, 0.3_f64, 0.02_f64);
    let inertia = Vector::new(h * h + t * t, w * w + t * t, w * w + h * h) * (MASS / 12.0);
    let panel = rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(ARM, DROP, 0.0))
            .angvel(Vector::new(0.0, 1.0, 0.0))
            .linvel(Vector::new(0.0, 0.0, -ARM))
            .additional_mass_properties(MassProperties::new(Vector::ZERO, MASS, inertia))
            .can_sleep(false),
    );
    let mut pin = pin()?.name(if spatial { "spatial pin" } else { "planar pin" });
    if spatial {
        pin = pin.model(ClearanceModel::Spatial(spatial_model()));
    }
    let joint = pin.joint(
        Vector::ZERO,
        Vector::new(-ARM, 0.0, 0.0),
        Vector::Y,
        Vector::Y,
    )?;
    let mut world = ClearanceWorld::new(rapier, StepControl::adaptive(1e-3, 0.0075));
    let hinge = world.insert_clearance(post, panel, joint)?;
    Ok((world, panel, hinge))
}

/// Runs one twin.
pub fn run_twin(spatial: bool) -> Result<Outcome> {
    let (mut world, panel, hinge) = panel_world(spatial)?;
    let mut o = Outcome::default();
    let mut was_on_face = false;
    let (mut late_sum, mut late_face, mut late_time) = ([0.0; 2], 0.0, 0.0);
    let mut late_moments = [0.0; 2];
    while world.time() < END {
        let t0 = world.time();
        world.step(END)?;
        let dt = world.time() - t0;
        let r = *world.clearance.get(hinge).expect("inserted").report();
        o.impacts += r.impact as u32;
        if let Some(s) = r.spatial {
            o.max_tilt = o.max_tilt.max(s.tilt[0].hypot(s.tilt[1]));
            o.max_edge_force = [0, 1].map(|e| o.max_edge_force[e].max(s.edge_force[e]));
            if world.time() > END - 0.2 {
                late_sum = [0, 1].map(|e| late_sum[e] + s.edge_force[e] * dt);
                late_face += (s.face_force[0] + s.face_force[1]) * dt;
                let com = world.rapier.bodies[panel].center_of_mass();
                let m = moments(world.clearance.get(hinge).expect("inserted"), com);
                late_moments = [0, 1].map(|k| late_moments[k] + m[k] * dt);
                late_time += dt;
            }
            let on_face = s.face_force[0] + s.face_force[1] > 0.0;
            if on_face && !was_on_face {
                o.face_knocks += 1;
            }
            was_on_face = on_face;
            o.max_face_force = o.max_face_force.max(s.face_force[0].max(s.face_force[1]));
        }
    }
    let rb = &world.rapier.bodies[panel];
    // The swing: the panel's turn about the vertical axis.
    o.swing_deg = twist_angle(rb.rotation(), Vector::Y).to_degrees();
    // The free edge (0.4 m from the axis, at mid-height) against where the rigid hinge holds it.
    let edge = *rb.position() * Vector::new(ARM, 0.0, 0.0);
    o.sag_mm = -edge.y * 1e3;
    if late_time > 0.0 {
        o.late_edge_force = late_sum.map(|f| f / late_time);
        o.late_face_force = late_face / late_time;
        o.late_moments = late_moments.map(|m| m / late_time);
    }
    o.steps = world.steps();
    o.clean = world.guards().is_clean();
    Ok(o)
}

/// The planar and the spatial twin.
pub fn run() -> Result<(Outcome, Outcome)> {
    Ok((run_twin(false)?, run_twin(true)?))
}

/// The comparison as text.
pub fn report(runs: &(Outcome, Outcome)) -> Result<String> {
    let moment = MASS * 9.81 * ARM;
    let mut s = format!(
        "gate on one pin, {END} s: weight moment across the axis m g x = {moment:.3} N m, \
         M/L = {:.1} N\n",
        moment / WIDTH
    );
    s += "model    steps    swing(deg)  max tilt(mrad)  sag(mm)  edge max(N)      edge last 0.2 s(N)  face knocks  face max(N)  impacts  guards\n";
    for (name, o) in [("planar", &runs.0), ("spatial", &runs.1)] {
        s += &format!(
            "{name:<8} {:<8} {:<11.2} {:<15.3} {:<8.3} {:<7.1}/{:<8.1} {:<8.1}/{:<10.1} {:<12} {:<12.1} {:<8} {}\n",
            o.steps,
            o.swing_deg,
            o.max_tilt * 1e3,
            o.sag_mm,
            o.max_edge_force[0],
            o.max_edge_force[1],
            o.late_edge_force[0],
            o.late_edge_force[1],
            o.face_knocks,
            o.max_face_force,
            o.impacts,
            if o.clean { "clean" } else { "flagged" }
        );
    }
    let [edges, face] = holding_moments(&runs.1);
    s += &format!(
        "spatial, last 0.2 s: bore {edges:.3} N m + face {face:.3} N m \
         (W = {:.2} N) = {:.3} N m against m g x = {moment:.3} N m ({:+.2} %)\n",
        runs.1.late_face_force,
        edges + face,
        100.0 * ((edges + face) / moment - 1.0)
    );
    Ok(s)
}

fn main() -> ExitCode {
    match run().and_then(|runs| report(&runs)) {
        Ok(text) => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
