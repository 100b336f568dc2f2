//! The spatial clearance joint against independent values: a static moment's edge forces
//! (the moment balance of the two edge regions), a load off-centre along the width (Winkler's
//! linear distribution), momentum of a free-floating pair, an axial knock's restitution (the
//! face law's), the planar joint as its aligned limit, convergence in the tolerance of a tilted
//! arm, and its guards broken on purpose.

use clearance_joint::Error;
use clearance_joint::model::laws::{
    Bai, FrictionModel, KelvinVoigt, NormalModel, impact_restitution,
};
use clearance_joint::model::spatial::{End, FaceLaw, SpatialModel};
use clearance_joint::prelude::*;
use clearance_joint::rapier::joint::Region;
use clearance_joint::rapier::pipeline::protocol::GuardKind;
use rapier3d_f64::prelude::*;

#[path = "support/arm.rs"]
mod support;

/// Bearing radius, radial clearance and width of the test hinges, m.
const R: f64 = 0.010;
const C: f64 = 0.2e-3;
const L: f64 = 0.016;
/// Axial play and shoulder radius, m: the shoulders (ring radius 12.7 mm) meet the faces at a
/// tilt of about 0.04 rad, beyond the 0.025 rad at which the journal's ends meet the bore.
const PLAY: f64 = 1.0e-3;
const COLLAR: f64 = 0.015;

/// An empty world without gravity, one solver iteration (the compliant joints need it).
fn empty_world() -> PhysicsWorld {
    let mut rapier = PhysicsWorld::new();
    rapier.gravity = Vector::ZERO;
    rapier.integration_parameters.num_solver_iterations = 1;
    rapier
}

/// A dynamic body of `mass` (kg) with the spherical inertia `inertia` (kg m^2) about its origin.
fn body(mass: f64, inertia: f64) -> RigidBodyBuilder {
    RigidBodyBuilder::dynamic()
        .additional_mass_properties(MassProperties::new(
            Vector::ZERO,
            mass,
            Vector::splat(inertia),
        ))
        .can_sleep(false)
}

/// The steel improved-Liu pin with explicit contact: these tests read the joint's report at each
/// step's end, which resolves every contact only when the steps do (a sub-cycled joint, the
/// default, resolves its contacts inside the steps: `tests/spatial_sub_cycling.rs`).
fn steel_liu() -> clearance_joint::Result<HingeDesign> {
    Ok(HingeDesign::steel_improved_liu(R, C, L)?.integration(ContactIntegration::Explicit))
}

/// Steel improved-Liu bore, steel shoulders.
fn steel_spatial() -> HingeDesign {
    steel_liu()
        .unwrap()
        .model(ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR)))
}

/// A fixed bearing at the origin and a free journal (0.5 kg, 1e-4 kg m^2) centred in it, hinge
/// along z, in a world without gravity.
fn fixed_bearing(
    clearance: &HingeDesign,
    control: StepControl,
) -> (ClearanceWorld, RigidBodyHandle, ClearanceJointHandle) {
    let mut world = ClearanceWorld::new(empty_world(), control);
    let base = world.rapier.bodies.insert(RigidBodyBuilder::fixed());
    let pin = world.rapier.bodies.insert(body(0.5, 1e-4));
    let joint = clearance
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let h = world.insert_clearance(base, pin, joint).unwrap();
    (world, pin, h)
}

/// A pure moment M about x across an aligned journal (hinge along z): the journal tilts until
/// its ends touch the bore on opposite sides; settled, the two edge regions carry equal and
/// opposite resultants (no net force) whose couple balances M: `F d = M`, `d` the distance
/// between their points of action (a little less than L: each region's load grows towards its
/// edge), and the faces carry nothing. The moment is a user torque: the joint set's ledger
/// replaces only its own forces, so it persists over the steps.
#[test]
fn static_moment_loads_the_edges_as_a_couple() {
    let (mut world, pin, h) = fixed_bearing(&steel_spatial(), StepControl::adaptive(1e-3, 0.02));
    let moment = 2.0;
    world.rapier.bodies[pin].add_torque(Vector::new(moment, 0.0, 0.0), true);
    world.step_to(0.2).unwrap();
    let j = world.clearance.get(h).unwrap();
    let r = j.report().spatial.unwrap();
    let [f0, f1] = r.edge_force;
    let arm = (r.edge_point[0] - r.edge_point[1]).dot(Vector::Z).abs();
    println!(
        "edges {f0} N and {f1} N, {arm} m apart along the axis (L = {L} m), lengths {:?} m",
        r.edge_length
    );
    assert!((f0 - f1).abs() < 1e-4 * f0, "edges {f0} {f1}");
    assert!(arm < L && arm > 0.9 * L, "points of action {arm} m apart");
    // The points' forces (along their gradients, square to the tilted journal) hold M about
    // the pin's centre (the origin).
    let held = j
        .spatial_points()
        .iter()
        .map(|p| {
            p.contact
                .point
                .cross(-p.normal_force * p.contact.gradient.normalize())
        })
        .fold(Vector::ZERO, |a, m| a + m);
    assert!(
        (held.x + moment).abs() < 1e-3 * moment,
        "the contact holds {held:?} N m"
    );
    assert_eq!(r.bore_force, f0 + f1);
    assert_eq!(r.face_force, [0.0; 2]);
    // The journal tilted about x (the moment's axis), its ends pressed on opposite sides.
    let tilt = (r.tilt[0].powi(2) + r.tilt[1].powi(2)).sqrt();
    assert!(tilt > 2.0 * C / L, "tilt {tilt} rad");
    let side = |e: End| {
        j.spatial_points()
            .iter()
            .filter(|p| p.region == Region::Bore(e))
            .map(|p| p.contact.gradient.normalize())
            .fold(Vector::ZERO, |a, n| a + n)
            .normalize()
    };
    assert!(side(End::Lower).dot(side(End::Upper)) < -0.999_999);
    assert!(world.guards().is_clean(), "{:?}", world.guards());
}

/// A radial load P at an axial offset z0 (|z0| < L/6) on a journal held from tilting by the
/// contact alone, with a linear law: Winkler's rigid journal on a linear foundation, loaded over
/// the whole width by the line load `f(s) = (P/L)(1 + 12 z0 s/L^2)`. Every quadrature point
/// carries `f(s) ds`: its force over its share `ds/L` is `P (1 + 12 z0 s/L^2)`. The journal's
/// axial translation is locked: the contact's forces are square to the tilted journal, so the
/// load's small component along it (`P` times the tilt) would slide a frictionless journal
/// onto a face.
#[test]
fn off_centre_load_spreads_as_winkler() {
    let (p, z0) = (100.0, L / 8.0);
    // 1e8 N/m over the whole width; its damping makes the radial mode critically damped
    // (0.5 kg) and the tilt's a third of that.
    let law = NormalModel::KelvinVoigt(KelvinVoigt::new(1e8, 1.4e4).unwrap());
    let clearance = HingeDesign::new(
        clearance_joint::model::laws::BearingGeometry::from_clearance(R, C, L).unwrap(),
        law,
    )
    .model(ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR)));
    let (mut world, pin, h) = fixed_bearing(&clearance, StepControl::adaptive(1e-3, 0.02));
    world.rapier.bodies[pin].set_locked_axes(LockedAxes::TRANSLATION_LOCKED_Z, true);
    world.rapier.bodies[pin].add_force_at_point(
        Vector::new(0.0, -p, 0.0),
        Vector::new(0.0, 0.0, z0),
        true,
    );
    world.step_to(0.1).unwrap();
    let j = world.clearance.get(h).unwrap();
    let bore: Vec<_> = j
        .spatial_points()
        .iter()
        .filter(|pt| matches!(pt.region, Region::Bore(_)))
        .collect();
    assert_eq!(bore.len(), 16, "two regions of 8 points");
    let widths: f64 = bore.iter().map(|pt| pt.contact.weight).sum();
    assert!(
        (widths - 1.0).abs() < 1e-12,
        "the regions cover {widths} of the width"
    );
    // The joint's elastic energy: each point's share of K delta^2/2.
    let energy: f64 = bore
        .iter()
        .map(|pt| pt.contact.weight * 0.5 * 1e8 * pt.contact.depth.powi(2))
        .sum();
    assert!((j.elastic_energy() - energy).abs() < 1e-12 * energy);
    let mut worst: f64 = 0.0;
    for pt in &bore {
        let winkler = p * (1.0 + 12.0 * z0 * pt.s / (L * L));
        worst = worst.max((pt.normal_force / pt.contact.weight - winkler).abs() / p);
    }
    println!("worst point {worst:.3e} of P off Winkler's line");
    // The forces' components along the bore's axis (P times the tilt, at the bore's radius R)
    // add a moment of about `P tilt R`: 5e-4 of `P z0` here.
    assert!(worst < 1e-3, "{worst} of P off Winkler's line");
    let r = j.report().spatial.unwrap();
    assert!(
        (r.bore_force - p).abs() < 1e-5 * p,
        "bore carries {} N",
        r.bore_force
    );
}

/// Linear momentum and angular momentum about the origin of the bodies `(handle, mass,
/// spherical inertia)` (their centres of mass at their origins).
fn momentum(world: &ClearanceWorld, bodies: &[(RigidBodyHandle, f64, f64)]) -> (Vector, Vector) {
    let (mut p, mut l) = (Vector::ZERO, Vector::ZERO);
    for &(h, m, i) in bodies {
        let rb = &world.rapier.bodies[h];
        p += m * rb.linvel();
        l += rb.translation().cross(m * rb.linvel()) + i * rb.angvel();
    }
    (p, l)
}

/// A free-floating pair (no gravity, nothing fixed, spherical inertias, so Rapier's rotation
/// step conserves angular momentum): the journal is thrown across the bore, along the axis and
/// tumbling, so it knocks the bore, its edges and both faces. The force pairs act at one point
/// on both bodies: linear and angular momentum stay what they were, to rounding.
#[test]
fn free_floating_pair_conserves_momentum() {
    let mut world = ClearanceWorld::new(empty_world(), StepControl::adaptive(1e-3, 0.02));
    let bearing = world.rapier.bodies.insert(body(1.0, 2e-4));
    let pin = world.rapier.bodies.insert(body(0.5, 1e-4));
    world.rapier.bodies[pin].set_linvel(Vector::new(0.05, 0.02, 0.08), true);
    world.rapier.bodies[pin].set_angvel(Vector::new(0.6, -0.4, 3.0), true);
    world.rapier.bodies[bearing].set_angvel(Vector::new(0.0, 0.0, -1.0), true);
    let joint = steel_spatial()
        .friction(FrictionModel::Bai(Bai::DRY))
        .joint(Vector::ZERO, Vector::ZERO, Vector::Z, Vector::Z)
        .unwrap();
    let h = world.insert_clearance(bearing, pin, joint).unwrap();
    let bodies = [(bearing, 1.0, 2e-4), (pin, 0.5, 1e-4)];
    let (p0, l0) = momentum(&world, &bodies);
    let (mut impacts, mut edge, mut inner, mut face) = (0, 0.0_f64, 0.0_f64, [0.0_f64; 2]);
    let (mut dp, mut dl) = (0.0_f64, 0.0_f64);
    while world.time() < 0.1 {
        world.step(0.1).unwrap();
        let r = *world.clearance.get(h).unwrap().report();
        impacts += r.impact as u32;
        let s = r.spatial.unwrap();
        edge = edge.max(s.edge_force[0].max(s.edge_force[1]));
        inner = inner.max(s.bore_force);
        face = [face[0].max(s.face_force[0]), face[1].max(s.face_force[1])];
        let (p, l) = momentum(&world, &bodies);
        dp = dp.max((p - p0).length());
        dl = dl.max((l - l0).length());
    }
    println!(
        "{} steps, {impacts} impacts, peak edge {edge} N, inner {inner} N, faces {face:?} N, \
         |dp| {dp:.3e} of {:.3e}, |dL| {dl:.3e} of {:.3e}",
        world.steps(),
        p0.length(),
        l0.length()
    );
    assert!(impacts >= 4, "{impacts} impacts");
    assert!(edge > 0.0 && inner > 0.0 && face[0] > 0.0 && face[1] > 0.0);
    assert!(dp < 1e-12 * p0.length(), "linear momentum drifted by {dp}");
    assert!(dl < 1e-12 * l0.length(), "angular momentum drifted by {dl}");
}

/// The journal knocks a face axially (aligned, centred, no gravity, bearing fixed), integrated
/// as `integration`: its restitution is the face law's for the journal's mass and approach speed
/// (returned: measured, the law's). Read one world step after the contact's end, in free flight:
/// a sub-cycled joint's Rapier velocities at a step's end are the mean over the step, and the
/// part of the knock's impulse they do not carry is delivered with the next step (read at the
/// contact's end, 0.858 against the law's 0.894).
fn axial_knock(integration: ContactIntegration) -> (f64, f64) {
    let model = SpatialModel::steel(PLAY, COLLAR);
    let clearance = steel_liu()
        .unwrap()
        .integration(integration)
        .model(ClearanceModel::Spatial(model));
    let (mut world, pin, h) = fixed_bearing(&clearance, StepControl::adaptive(1e-3, 0.005));
    let (mass, speed) = (0.5, 0.2);
    world.rapier.bodies[pin].set_linvel(Vector::new(0.0, 0.0, speed), true);
    // Whether the last step touched the face: at its end, or at a sub-step's.
    let touching = |world: &ClearanceWorld| {
        let j = world.clearance.get(h).unwrap();
        j.report().spatial.unwrap().face_force[0] > 0.0
            || j.substeps().iter().any(|s| s.force.normal_force > 0.0)
    };
    let mut touched = false;
    while world.time() < 0.02 {
        world.step(0.02).unwrap();
        let now = touching(&world);
        touched |= now;
        if touched && !now {
            break;
        }
    }
    assert!(touched, "the shoulder never met the face");
    world.step(0.02).unwrap();
    assert!(!touching(&world), "the journal met a face again");
    let v = world.rapier.bodies[pin].linvel();
    assert!(
        v.x.abs() + v.y.abs() < 1e-12,
        "the knock moved the journal radially: {v:?}"
    );
    let measured = -v.z / speed;
    let expected = impact_restitution(&model.face.law().unwrap(), mass, speed);
    println!("{integration:?}: restitution measured {measured}, law {expected}");
    (measured, expected)
}

#[test]
fn axial_knock_restitution_is_the_face_law_s() {
    for integration in [ContactIntegration::Explicit, ContactIntegration::SubCycled] {
        let (measured, expected) = axial_knock(integration);
        assert!(
            (measured - expected).abs() < 0.01 * expected,
            "{integration:?}: measured {measured}, the face law's {expected}"
        );
    }
}

/// The shared arm (`tests/support/arm.rs`) with friction on its pin, ready to run.
fn arm(clearance: HingeDesign, offset: f64, control: StepControl) -> ArmRun {
    let (world, arm, pin) = support::arm(clearance, offset, control);
    ArmRun { world, arm, pin }
}

struct ArmRun {
    world: ClearanceWorld,
    arm: RigidBodyHandle,
    pin: ClearanceJointHandle,
}

/// What the arm's run gives: steps, impacts, the arm's final state, peaks.
#[derive(Debug)]
struct ArmResult {
    steps: u64,
    impacts: u32,
    position: Vector,
    linvel: Vector,
    angvel: Vector,
    /// Peak resultant normal force over the first impact, N.
    first_peak: f64,
    /// Peak resultant of either bore edge's region, N, and the peak line load there (a
    /// point's force over its share of the width, N).
    peak_edge: f64,
    peak_edge_pressure: f64,
    /// Largest tilt, rad.
    peak_tilt: f64,
}

impl ArmRun {
    fn run(mut self, until: f64) -> ArmResult {
        let (mut impacts, mut first_peak, mut peak_edge, mut edge_p, mut peak_tilt) =
            (0, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
        while self.world.time() < until {
            self.world.step(until).unwrap();
            let j = self.world.clearance.get(self.pin).unwrap();
            let r = j.report();
            impacts += r.impact as u32;
            if impacts == 1 {
                first_peak = first_peak.max(r.force.normal_force);
            }
            if let Some(s) = r.spatial {
                let e = s.edge_force[0].max(s.edge_force[1]);
                peak_edge = peak_edge.max(e);
                for pt in j.spatial_points() {
                    if matches!(pt.region, Region::Bore(_)) && pt.contact.weight > 0.0 {
                        edge_p = edge_p.max(pt.normal_force / pt.contact.weight);
                    }
                }
                peak_tilt = peak_tilt.max(s.tilt[0].hypot(s.tilt[1]));
            }
        }
        assert!(self.world.guards().is_clean(), "{:?}", self.world.guards());
        let rb = &self.world.rapier.bodies[self.arm];
        ArmResult {
            steps: self.world.steps(),
            impacts,
            position: rb.translation(),
            linvel: rb.linvel(),
            angvel: rb.angvel(),
            first_peak,
            peak_edge,
            peak_edge_pressure: edge_p,
            peak_tilt,
        }
    }
}

/// The planar limit: the arm's loads are all in the hinge's plane, so the frictionless spatial
/// joint (nothing locked) runs the planar joint's run, unlocked or locked by the default
/// GenericJoint: the same steps, the same impacts, the same trajectory to rounding (measured
/// after 0.3 s and 34 impacts: 2.8e-15 m, 1.0e-11 m/s, 1.2e-10 rad/s, the first peak 9.5e-10 N
/// apart).
#[test]
fn aligned_spatial_joint_is_the_planar_joint() {
    let control = StepControl::adaptive(1e-3, 0.0075);
    let steel = || steel_liu().unwrap();
    let model = ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR));
    let until = 0.3;
    let spatial = arm(steel().model(model), 0.0, control).run(until);
    assert!(spatial.impacts >= 3, "{spatial:?}");
    assert!(spatial.peak_tilt < 1e-15, "{spatial:?}");
    for lock in [OutOfPlaneLock::None, OutOfPlaneLock::Joint] {
        let planar = arm(steel().lock(lock), 0.0, control).run(until);
        assert_eq!(planar.steps, spatial.steps, "{lock:?}");
        assert_eq!(planar.impacts, spatial.impacts, "{lock:?}");
        let dx = (planar.position - spatial.position).length();
        let dv = (planar.linvel - spatial.linvel).length();
        let dw = (planar.angvel - spatial.angvel).length();
        let df = (planar.first_peak - spatial.first_peak).abs();
        println!(
            "{lock:?}: |dx| {dx:.3e} m, |dv| {dv:.3e} m/s, |dw| {dw:.3e} rad/s, dF {df:.3e} N"
        );
        assert!(
            dx < 1e-12 && dv < 1e-10 && dw < 1e-9 && df < 1e-11 * planar.first_peak,
            "{lock:?}: planar {planar:?}, spatial {spatial:?}"
        );
    }
}

/// With friction the aligned spatial joint stays in the plane. Its axial slip, which the planar
/// joint's lock holds, is a tangential damper of its own (friction across the slip, `F_N mu/v`)
/// that the step control resolves: without it a rounding-level axial slip grew to a 4e-9 rad
/// tilt. Where that limit is the shorter the steps differ from the planar run's, so both are
/// judged against a fine run (tolerance 1e-3): at the default 0.0075 both first impacts are
/// within 1e-3 of the fine run's peak (measured 1.3e-5 planar, 6.5e-4 spatial) and both leave the
/// arm within 4 um of the fine run's after 0.3 s (measured 0.7 um planar, 1.5 um spatial).
/// (With the laws given Rapier's stored rates, half a step old, the planar peak was 1.5 % off
/// and the arms 5.1 and 6.7 um; with the contact step at one tolerance of a period, not two,
/// the peaks were 6e-5 and 2.7e-4 off.)
#[test]
fn aligned_spatial_joint_with_friction_stays_planar() {
    let steel = || steel_liu().unwrap().friction(FrictionModel::Bai(Bai::DRY));
    let model = ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR));
    let until = 0.3;
    let control = StepControl::adaptive(1e-3, 0.0075);
    let spatial = arm(steel().model(model), 0.0, control).run(until);
    let planar = arm(steel(), 0.0, control).run(until);
    let fine = arm(steel(), 0.0, StepControl::adaptive(1e-3, 0.001)).run(until);
    println!("planar {planar:?}\nspatial {spatial:?}\nfine planar {fine:?}");
    assert!(spatial.peak_tilt < 1e-15, "{spatial:?}");
    assert!(spatial.position.z.abs() < 1e-15, "{spatial:?}");
    let off = |r: &ArmResult| (r.first_peak - fine.first_peak).abs() / fine.first_peak;
    for r in [&planar, &spatial] {
        let dx = (r.position - fine.position).length();
        println!("{dx:.3e} m, first peak {:.2e} from the fine run", off(r));
        assert!(dx < 4e-6 && off(r) < 1e-3, "{r:?}");
    }
}

/// The arm of [`arm`] with its centre of mass 50 mm off the hinge's mid-plane along the axis:
/// its weight makes a moment across the hinge, the journal tilts and loads the bore's edges.
/// Metrics at `tolerance` over `until` s.
fn tilted_arm(tolerance: f64, until: f64) -> ArmResult {
    let clearance = steel_liu()
        .unwrap()
        .friction(FrictionModel::Bai(Bai::DRY))
        .model(ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR)));
    arm(clearance, 0.05, StepControl::adaptive(1e-3, tolerance)).run(until)
}

/// The tilted arm at the default tolerance against a tight one (0.05 s, the first impact and
/// the arm's edge-loaded swing): the peak tilt, the first impact's peak, the edge regions' peak
/// resultant and line load within 1 %.
#[test]
fn tilted_arm_converges_in_the_tolerance() {
    let (coarse, fine) = (tilted_arm(0.0075, 0.05), tilted_arm(0.001, 0.05));
    let rel = |a: f64, b: f64| (a - b).abs() / b;
    println!("default: {coarse:?}\ntight: {fine:?}");
    assert!(
        fine.peak_tilt > 2.0 * C / L * 0.1,
        "the arm hardly tilts: {fine:?}"
    );
    for (name, a, b) in [
        ("tilt", coarse.peak_tilt, fine.peak_tilt),
        ("first peak", coarse.first_peak, fine.first_peak),
        ("edge", coarse.peak_edge, fine.peak_edge),
        (
            "edge line load",
            coarse.peak_edge_pressure,
            fine.peak_edge_pressure,
        ),
    ] {
        println!("{name}: {:.3e}", rel(a, b));
        assert!(rel(a, b) < 0.01, "{name}: {a} against {b}");
    }
}

/// Broken on purpose: a fixed step too long for the steel bore is refused with the step-size
/// error (naming the joint), not run into a wrong result.
#[test]
fn coarse_fixed_step_is_refused() {
    let clearance = steel_spatial().name("spatial pin");
    let mut world = arm(clearance, 0.05, StepControl::fixed(5e-4)).world;
    let e = loop {
        match world.step(0.2) {
            Ok(_) if world.time() < 0.2 => continue,
            Ok(_) => panic!("a 0.5 ms step through steel impacts was accepted"),
            Err(e) => break e,
        }
    };
    assert!(matches!(e, Error::StepTooLarge(_)), "{e}");
    assert!(e.to_string().contains("spatial pin"), "{e}");
}

/// Broken on purpose: a face law so soft that an axial knock sinks the shoulder millimetres
/// into the face leaves the model's validity; the penetration guard says so, with the worst
/// depth.
#[test]
fn soft_face_trips_the_penetration_guard() {
    let model = SpatialModel::steel(PLAY, COLLAR).face(FaceLaw {
        stiffness: 1e3,
        restitution: 0.9,
    });
    let clearance = steel_liu()
        .unwrap()
        .model(ClearanceModel::Spatial(model))
        .name("soft faces");
    let (mut world, pin, _) = fixed_bearing(&clearance, StepControl::adaptive(1e-3, 0.02));
    world.rapier.bodies[pin].set_linvel(Vector::new(0.0, 0.0, 0.2), true);
    world.step_to(0.2).unwrap();
    let guards = world.guards();
    let v = guards
        .violations
        .iter()
        .find(|v| v.kind == GuardKind::Penetration)
        .unwrap_or_else(|| panic!("no penetration guard: {guards:?}"));
    assert_eq!(v.joint.as_deref(), Some("soft faces"));
    // 0.2 m/s into 1e3 N/m with 0.5 kg: 4.5 mm deep, far past the 98 um of validity.
    assert!(v.worst > 1e-3 && v.worst > 10.0 * v.limit, "{v:?}");
}

/// The step control on the tilted arm against finer tolerances (the docs' figures):
/// `cargo test --release --test spatial -- --ignored --nocapture tilted_arm_tolerance_table`.
#[test]
#[ignore]
fn tilted_arm_tolerance_table() {
    let run = |tol: f64| {
        let clearance = steel_liu()
            .unwrap()
            .friction(FrictionModel::Bai(Bai::DRY))
            .model(ClearanceModel::Spatial(SpatialModel::steel(PLAY, COLLAR)));
        arm(clearance, 0.05, StepControl::adaptive(1e-3, tol)).run(0.05)
    };
    let fine = run(2.5e-4);
    println!(
        "| tolerance | steps | first-impact peak, N | peak tilt, mrad | peak edge pressure, N | arm from the finest, um |"
    );
    println!("|---|---|---|---|---|---|");
    for tol in [0.0075, 0.00375, 0.001, 2.5e-4] {
        let r = if tol == 2.5e-4 { &fine } else { &run(tol) };
        println!(
            "| {tol} | {} | {:.3} | {:.5} | {:.2} | {:.3} |",
            r.steps,
            r.first_peak,
            r.peak_tilt * 1e3,
            r.peak_edge_pressure,
            (r.position - fine.position).length() * 1e6
        );
    }
}
