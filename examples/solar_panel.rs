//! The paper's scene in code, no scene file (MODEL.md §4): a 768 kg satellite and a 7.68 kg solar
//! panel, free-floating, deployed by a torsion spring `T = T0 - k theta` about a hinge with 0.5 mm
//! radial clearance (steel, the paper's improved contact law, dry friction). An ideal twin (Rapier
//! revolute joint) and a clearance twin run side by side in one `ClearanceWorld` (the Rapier
//! world with the joints and the springs), with the paper's fixed step of 1e-4 s for 5 s.
//!
//! `cargo run --release --example solar_panel`

use clearance_joint::Result;
use clearance_joint::model::angle::{UnwrappedAngle, twist_angle};
use clearance_joint::model::laws::{
    Bai, BearingGeometry, FrictionModel, ImprovedLiu, Material, MaxDamping, NormalModel,
    effective_modulus,
};
use clearance_joint::rapier::hinge::design::HingeDesign;
use clearance_joint::rapier::joint::ClearanceJointHandle;
use clearance_joint::rapier::observers::reaction::{
    IdealJoint, ReactionSolver, prepare_mass_properties,
};
use clearance_joint::rapier::pipeline::stepper::StepControl;
use clearance_joint::rapier::pipeline::world::ClearanceWorld;
use clearance_joint::rapier::sources::drive::TorsionSpring;
use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    MassProperties, PhysicsWorld, RevoluteJointBuilder, RigidBodyBuilder, RigidBodyHandle,
};
use std::process::ExitCode;

/// The paper's step, s.
pub const DT: f64 = 1e-4;
/// Simulated time, s.
pub const END: f64 = 5.0;
const SATELLITE: (f64, [f64; 3], [f64; 3]) = (768.0, [104.96, 81.92, 104.96], [0.0, 0.0, 0.0]);
const PANEL: (f64, [f64; 3], [f64; 3]) = (7.68, [1.6137, 0.4156, 2.0293], [0.4, 0.0, 0.0]);
const HINGE_POINT: [f64; 3] = [0.4, 0.0, 0.4];
const AXIS: Vector = Vector::NEG_Y;
const T0: f64 = 0.135; // N m
const K_PER_DEG: f64 = 0.0015; // N m/deg

/// One twin: its bodies and (for the clearance twin) joint.
struct Twin {
    satellite: RigidBodyHandle,
    panel: RigidBodyHandle,
    clearance: Option<ClearanceJointHandle>,
    /// The ideal twin's revolute.
    revolute: Option<rapier3d_f64::prelude::ImpulseJointHandle>,
}

/// What one twin measured over every step.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// Final deployment (hinge) angle, deg.
    pub deployment_deg: f64,
    /// Final panel angle about the hinge axis, deg.
    pub panel_deg: f64,
    /// Final satellite angle about the hinge axis, deg.
    pub satellite_deg: f64,
    /// Final panel angular rate about the hinge axis, deg/s.
    pub panel_rate_deg_s: f64,
    /// Largest hinge force, N (ideal: the exact reaction of the ideal joint; clearance: the
    /// contact force).
    pub peak_force_n: f64,
    /// Contact onsets, chatter included.
    pub onsets: u64,
    /// Time of the first contact onset, s.
    pub first_impact_s: Option<f64>,
    /// Largest penetration, um.
    pub max_penetration_um: f64,
    /// Largest drift of total linear momentum over the largest body momentum.
    pub linear_momentum_drift: f64,
    /// Largest drift of total angular momentum (about the origin) over the largest body's.
    pub angular_momentum_drift: f64,
}

fn body(
    world: &mut ClearanceWorld,
    (mass, inertia, com): (f64, [f64; 3], [f64; 3]),
) -> RigidBodyHandle {
    world.rapier.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::from(com))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass,
                Vector::from(inertia),
            ))
            .can_sleep(false),
    )
}

fn add_twin(world: &mut ClearanceWorld, with_clearance: bool) -> Result<Twin> {
    let satellite = body(world, SATELLITE);
    let panel = body(world, PANEL);
    let h = Vector::from(HINGE_POINT);
    let (a1, a2) = (h - Vector::from(SATELLITE.2), h - Vector::from(PANEL.2));
    let mut revolute_handle = None;
    let clearance = if with_clearance {
        // Table 2: 20 mm bearing, 16 mm wide, steel on steel, c = 0.5 mm; eta = 1 %; table 3: dry.
        let (radius, c, width) = (0.010, 0.5e-3, 0.016);
        let e_star = effective_modulus(&Material::STEEL, &Material::STEEL);
        let law = ImprovedLiu::new(e_star, width, c, 1.0, 1e-4, MaxDamping::Eta(0.01))?;
        let joint = HingeDesign::new(
            BearingGeometry::from_clearance(radius, c, width)?,
            NormalModel::ImprovedLiu(law),
        )
        .friction(FrictionModel::Bai(Bai::DRY))
        .name("hinge")
        .joint(a1, a2, AXIS, AXIS)?;
        Some(world.insert_clearance(satellite, panel, joint)?)
    } else {
        let revolute = RevoluteJointBuilder::new(AXIS)
            .local_anchor1(a1)
            .local_anchor2(a2)
            .contacts_enabled(false);
        revolute_handle = Some(
            world
                .rapier
                .impulse_joints
                .insert(satellite, panel, revolute, true),
        );
        None
    };
    world.drives.insert(TorsionSpring::new(
        satellite,
        panel,
        AXIS,
        T0,
        K_PER_DEG.to_degrees(),
    )?);
    Ok(Twin {
        satellite,
        panel,
        clearance,
        revolute: revolute_handle,
    })
}

/// Total linear and angular momentum (about the origin) of the twin's two bodies, and the
/// largest of each for a single body. From the scene's masses and inertias: Rapier's own mass
/// properties are only filled in at the first step.
fn momentum(world: &ClearanceWorld, twin: &Twin) -> (Vector, Vector, f64, f64) {
    let (mut p, mut l, mut max_p, mut max_l) = (Vector::ZERO, Vector::ZERO, 0.0f64, 0.0f64);
    for (h, (mass, inertia, _)) in [(twin.satellite, SATELLITE), (twin.panel, PANEL)] {
        let rb = &world.rapier.bodies[h];
        let q = *rb.rotation();
        // The velocities at the state: after a sub-cycled step Rapier's hold only part of the
        // step's contact impulse.
        let (v, w) = world.velocity_at_state(h).expect("in the world");
        // The body frame is at the centre of mass, along the principal axes.
        let iw = q * (Vector::from(inertia) * (q.inverse() * w));
        let pb = mass * v;
        let lb = rb.translation().cross(pb) + iw;
        p += pb;
        l += lb;
        max_p = max_p.max(pb.length());
        max_l = max_l.max(lb.length());
    }
    (p, l, max_p, max_l)
}

/// Runs both twins in one world, stepped by `ClearanceWorld::step` (fixed steps of [`DT`]).
pub fn run() -> Result<(Outcome, Outcome)> {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.dt = DT;
    rapier.integration_parameters.num_solver_iterations = 1; // as the scenes run (sub-cycled, the default, takes any)
    // The scene's tolerance, which also sizes the sub-cycled contact's sub-steps.
    let control = StepControl {
        tolerance: 0.0075,
        ..StepControl::fixed(DT)
    };
    let mut world = ClearanceWorld::new(rapier, control);
    let [ideal, clear] = [add_twin(&mut world, false)?, add_twin(&mut world, true)?];
    // The ideal hinge's exact reaction at each state (not a momentum difference over a step).
    prepare_mass_properties(&mut world.rapier.bodies);
    let hinge = ideal
        .revolute
        .expect("the ideal twin's hinge is a revolute");
    let ideal_hinge = [IdealJoint::from_rapier(
        &world.rapier.impulse_joints,
        hinge,
    )?];
    let mut reactions = ReactionSolver::default();
    world.prepare()?;
    let mut out = [Outcome::default(), Outcome::default()];
    let mut angles = [[UnwrappedAngle::default(); 3]; 2];
    let mut p0 = [None; 2];
    // The start of the step that led to the current state, s.
    let mut t_prev = 0.0;
    let (mut dp, mut dl, mut sp, mut sl) = ([0.0f64; 2], [0.0f64; 2], [0.0f64; 2], [0.0f64; 2]);
    loop {
        // The state at the world's time, with the forces the next step applies.
        let t = world.time();
        for (k, twin) in [&ideal, &clear].into_iter().enumerate() {
            let (p, l, mp, ml) = momentum(&world, twin);
            let (p_start, l_start) = *p0[k].get_or_insert((p, l));
            dp[k] = dp[k].max((p - p_start).length());
            dl[k] = dl[k].max((l - l_start).length());
            sp[k] = sp[k].max(mp);
            sl[k] = sl[k].max(ml);
            let o = &mut out[k];
            let force = match twin.clearance {
                // With the spring's torque, at this state (the velocities' lag taken care of).
                None => world
                    .solve_reactions(&mut reactions, &ideal_hinge)
                    .map_or(0.0, |f| f[0].length()),
                Some(c) => {
                    let j = world.clearance.get(c).expect("inserted");
                    let r = j.report();
                    // The states of the step that led here: a sub-cycled joint's sub-steps (the
                    // last is this state), where it resolved the step's contacts; else this one.
                    let here = [(t, r.onset, r.state.penetration, r.force.on_journal)];
                    let inside = j.substeps().iter().map(|s| {
                        let at = t_prev + s.t;
                        (at, s.onset, s.state.penetration, s.force.on_journal)
                    });
                    let states: Vec<_> = if j.substeps().is_empty() {
                        here.to_vec()
                    } else {
                        inside.collect()
                    };
                    let mut peak = 0.0f64;
                    for (at, onset, penetration, force) in states {
                        if onset {
                            o.onsets += 1;
                            o.first_impact_s.get_or_insert(at);
                        }
                        o.max_penetration_um = o.max_penetration_um.max(penetration * 1e6);
                        peak = peak.max(force.length());
                    }
                    peak
                }
            };
            o.peak_force_n = o.peak_force_n.max(force);
            let bodies = &world.rapier.bodies;
            let (qs, qp) = (
                *bodies[twin.satellite].rotation(),
                *bodies[twin.panel].rotation(),
            );
            let a = &mut angles[k];
            o.satellite_deg = a[0].update(twist_angle(&qs, AXIS)).to_degrees();
            o.panel_deg = a[1].update(twist_angle(&qp, AXIS)).to_degrees();
            o.deployment_deg = a[2]
                .update(twist_angle(&(qs.inverse() * qp), AXIS))
                .to_degrees();
            o.panel_rate_deg_s = bodies[twin.panel].angvel().dot(AXIS).to_degrees();
        }
        if t >= END {
            break;
        }
        t_prev = t;
        world.step(END)?;
    }
    for k in 0..2 {
        out[k].linear_momentum_drift = dp[k] / sp[k].max(f64::MIN_POSITIVE);
        out[k].angular_momentum_drift = dl[k] / sl[k].max(f64::MIN_POSITIVE);
    }
    let [ideal, clearance] = out;
    Ok((ideal, clearance))
}

/// The printed comparison.
pub fn report((ideal, clear): &(Outcome, Outcome)) -> String {
    let mut s = format!(
        "solar_panel: the paper's satellite and panel, built in code; dt = {DT:e} s, {END} s\n\
         hinge: Rapier revolute vs clearance joint (c = 0.5 mm, improved law, dry friction), torque T\n\n\
         {:<32}{:>18}{:>18}\n",
        "", "ideal", "clearance"
    );
    let mut row = |label: &str, f: &dyn Fn(&Outcome) -> String| {
        s.push_str(&format!("{label:<32}{:>18}{:>18}\n", f(ideal), f(clear)));
    };
    row("final deployment angle (deg)", &|o| {
        format!("{:.4}", o.deployment_deg)
    });
    row("final panel angle (deg)", &|o| {
        format!("{:.4}", o.panel_deg)
    });
    row("final satellite angle (deg)", &|o| {
        format!("{:.4}", o.satellite_deg)
    });
    row("final panel rate (deg/s)", &|o| {
        format!("{:.4}", o.panel_rate_deg_s)
    });
    row("peak hinge force (N)", &|o| {
        format!("{:.4}", o.peak_force_n)
    });
    row("onsets", &|o| o.onsets.to_string());
    row("first impact (s)", &|o| {
        o.first_impact_s.map_or("-".into(), |t| format!("{t:.4}"))
    });
    row("max penetration (um)", &|o| {
        format!("{:.3}", o.max_penetration_um)
    });
    row("momentum drift lin/ang", &|o| {
        format!(
            "{:.1e}/{:.1e}",
            o.linear_momentum_drift, o.angular_momentum_drift
        )
    });
    s
}

fn main() -> ExitCode {
    match run() {
        Ok(outcomes) => {
            print!("{}", report(&outcomes));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
