//! The spatial clearance joint in scenes: the format (`clearance.model: Spatial(..)`, its
//! defaults, its errors, its overrides), the planar limit on the paper's scene, and the door and
//! spatial-panel scenes (assets/door_hinge.ron, assets/solar_panel_spatial.ron) at short ends.
//! Runs optimised (`[profile.test] opt-level = 3`).

use clearance_joint::model::laws::{Material, effective_modulus};
use clearance_joint::model::spatial::{FaceLaw, SpatialModel};
use clearance_joint::rapier::hinge::design::ClearanceModel;
use clearance_joint::rapier::observers::metrics::SpatialMetrics;
use clearance_joint::scene::Scene;
use clearance_joint::scene::report::TwinSummary;
use clearance_joint::scene::runner::{RunOptions, RunResult, Simulation, Twins};
use std::path::Path;

fn asset(name: &str) -> Scene {
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("assets")
            .join(name),
    )
    .unwrap()
}

fn run(scene: &Scene, twins: Twins) -> RunResult {
    Simulation::new(
        scene,
        RunOptions {
            twins,
            skip_rows: true,
        },
    )
    .unwrap()
    .run()
    .unwrap()
}

fn clearance(r: &RunResult) -> TwinSummary {
    r.summary().twins["clearance"].clone()
}

fn spatial(s: &TwinSummary) -> SpatialMetrics {
    s.hinges["hinge"]
        .spatial
        .clone()
        .expect("a spatial hinge's metrics")
}

/// The paper's scene with its clearance hinge spatial (aligned, so nothing tilts and the axial
/// play is never used).
const SPATIAL: &str =
    r#"hinge.model={"Spatial":{"geometry":{"axial_play":1e-4,"collar_radius":0.015}}}"#;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

/// The spatial joint's aligned limit is the planar joint. On the paper's scene (5 s) the two
/// runs take the same steps to one (20,570 and 20,571: the two edge regions carry their rates
/// to the state together, which rounds differently from the planar joint's one force, and a step
/// in contact follows the contact's energy) and count the same impacts, the first at the same
/// instant to rounding. The rest is that rounding, grown over the rattle's 281 impacts and read
/// at states a rounding apart (measured): the first peak agrees to 1.8e-6, the final angles to
/// 1.1e-7, the steps in contact to 2 of 12,910.
#[test]
fn spatial_joint_aligned_is_the_planar_joint_on_the_paper_scene() {
    // The explicit joints (the figures above are theirs).
    let planar = Scene::solar_panel()
        .with_overrides(&["run.contact_integration=Explicit"])
        .unwrap();
    let spatial_scene = planar.with_overrides(&[SPATIAL]).unwrap();
    let (p, s) = (
        run(&planar, Twins::ClearanceOnly),
        run(&spatial_scene, Twins::ClearanceOnly),
    );
    assert!(p.is_complete() && s.is_complete());
    assert!(p.guards.is_clean() && s.guards.is_clean(), "{:?}", s.guards);
    println!("steps {} vs {}", p.steps, s.steps);
    assert!(
        p.steps.abs_diff(s.steps) <= 2,
        "step count {} vs {}",
        p.steps,
        s.steps
    );
    let (p, s) = (clearance(&p), clearance(&s));
    let (hp, hs) = (&p.hinges["hinge"], &s.hinges["hinge"]);
    assert_eq!(hp.onsets, hs.onsets, "onsets");
    assert_eq!(hp.impacts, hs.impacts, "impacts");
    assert!(hp.onsets > 200, "the paper's scene rattles: {}", hp.onsets);
    let (tp, ts) = (hp.first_impact_t_s.unwrap(), hs.first_impact_t_s.unwrap());
    assert!(rel(tp, ts) < 1e-12, "first impact at {tp} vs {ts} s");
    for (name, a, b, bound) in [
        ("peak force", hp.peak_force_n, hs.peak_force_n, 1e-5),
        (
            "first impact peak",
            hp.first_impact_peak_n.unwrap(),
            hs.first_impact_peak_n.unwrap(),
            1e-5,
        ),
        (
            "max penetration",
            hp.max_penetration_um,
            hs.max_penetration_um,
            2e-4,
        ),
        ("RMS force", hp.rms_force_n, hs.rms_force_n, 2e-4),
        ("restitution", hp.max_restitution, hs.max_restitution, 2e-4),
    ] {
        println!("{name}: {a} vs {b}, {:.2e}", rel(a, b));
        assert!(rel(a, b) < bound, "{name}: {a} vs {b}");
    }
    for (body, a) in &p.final_angles_deg {
        let b = s.final_angles_deg[body];
        println!("final angle of {body}: {a} vs {b}, {:.2e}", rel(*a, b));
        assert!(rel(*a, b) < 2e-7, "final angle of {body}: {a} vs {b}");
    }
    println!("contact steps {} vs {}", hp.contact_steps, hs.contact_steps);
    assert!(hp.contact_steps.abs_diff(hs.contact_steps) <= 10);
    // Nothing tilted, nothing slid, no face touched; each end's region carried half the bore.
    let m = spatial(&s);
    assert!(
        m.max_tilt_deg < 1e-12 && m.max_axial_offset_mm < 1e-12,
        "{m:?}"
    );
    assert_eq!(m.face_contacts, [0, 0]);
    assert_eq!(m.edge_loaded_fraction, 0.0);
    assert!(rel(m.peak_edge_force_n[0], hp.peak_force_n / 2.0) < 0.01);
    assert!(
        p.hinges["hinge"].spatial.is_none(),
        "a planar hinge has none"
    );
}

/// The door (assets/door_hinge.ron, first 0.06 s): its weight's moment across the axis tilts
/// the journal in its bore onto the bore's edges, and it falls through its axial play onto the
/// bearing's upper face (the bearing's end at +L/2 along the upward axis).
#[test]
fn door_sags_edge_loads_and_knocks_on_a_face() {
    let scene = asset("door_hinge.ron")
        .with_overrides(&["run.end_s=0.06"])
        .unwrap();
    let r = run(&scene, Twins::Both);
    assert!(r.is_complete());
    assert!(r.guards.is_clean(), "{:?}", r.guards);
    let s = clearance(&r);
    let m = spatial(&s);
    // Edge contact at both ends needs a tilt of about 2c/L = 0.2/20 rad = 0.57 deg.
    assert!(m.max_tilt_deg > 0.4, "tilt {} deg", m.max_tilt_deg);
    // The static couple alone is M/L = 2 kg 9.81 m/s^2 0.2 m / 0.02 m = 196 N at each edge.
    for (k, f) in m.peak_edge_force_n.iter().enumerate() {
        assert!(*f > 196.0, "edge {k}: {f} N");
    }
    // Rattling at first, then bearing on the edges (a third of the time by 0.06 s, measured
    // 0.33; 0.96 over the whole second).
    assert!(m.edge_loaded_fraction > 0.2, "{m:?}");
    // Free fall through 0.3 mm (7.8 ms) onto the upper face: a knock well above the weight.
    assert!(m.face_contacts[1] >= 1, "{m:?}");
    assert!(m.peak_face_force_n[1] > 10.0 * 2.0 * 9.81, "{m:?}");
    let t = s.hinges["hinge"].first_impact_t_s.unwrap();
    assert!(
        (t - (2.0 * 0.3e-3 / 9.81f64).sqrt()).abs() < 1e-3,
        "first impact at {t} s"
    );
    assert!(m.max_axial_offset_mm > 0.149, "{m:?}");
    // The ideal twin's hinge is an ideal revolute: no spatial figures.
    assert!(r.summary().twins["ideal"].hinges["hinge"].spatial.is_none());
}

/// The paper's panel with a real hinge width (assets/solar_panel_spatial.ron, first 0.5 s): the
/// panel's centre of mass off the hinge's mid-plane tilts the journal at the impacts.
#[test]
fn spatial_panel_runs_clean_and_tilts() {
    let scene = asset("solar_panel_spatial.ron")
        .with_overrides(&["run.end_s=0.5"])
        .unwrap();
    let r = run(&scene, Twins::ClearanceOnly);
    assert!(r.is_complete());
    assert!(r.guards.is_clean(), "{:?}", r.guards);
    let s = clearance(&r);
    let m = spatial(&s);
    assert!(s.onsets > 0);
    assert!(m.max_tilt_deg > 1e-3, "{m:?}");
    assert!(m.peak_edge_force_n.iter().any(|&f| f > 0.0), "{m:?}");
    assert!(s.linear_momentum_drift.unwrap() < 1e-9, "{s:?}");
}

/// The spatial panel's first impact (at 0.0875 s) sub-cycled at the default tolerance against
/// the explicit joint at fixed 2e-6 s steps (178.188 N; 178.194 N at 5e-7 s): within 1 %. The
/// sub-steps of an impact are bounded to `tol` of the contact's period (measured 177.914 N,
/// -0.15 %); bounded by ROS2's error estimate alone, its L-stable damping took the peak 3.2 % low
/// over this span (172.551 N).
#[test]
fn spatial_panel_first_impact_sub_cycled_matches_the_explicit_joint() {
    let first = |overrides: &[&str]| {
        let scene = asset("solar_panel_spatial.ron")
            .with_overrides(&[&["run.end_s=0.12"], overrides].concat())
            .unwrap();
        let r = run(&scene, Twins::ClearanceOnly);
        assert!(r.is_complete() && r.guards.is_clean(), "{:?}", r.guards);
        let s = clearance(&r);
        (
            s.hinges["hinge"].first_impact_peak_n.unwrap(),
            s.hinges["hinge"].first_impact_t_s,
        )
    };
    let (reference, t_ref) = first(&["run.step=Fixed", "run.dt_s=2e-6"]);
    let (sub_cycled, t) = first(&["run.contact_integration=SubCycled"]);
    println!(
        "first impact: sub-cycled {sub_cycled:.3} N at {t:?} s, explicit {reference:.3} N at {t_ref:?} s"
    );
    assert!(reference > 100.0, "{reference}");
    assert!(
        (t.unwrap() - t_ref.unwrap()).abs() < 1e-3,
        "{t:?} against {t_ref:?}"
    );
    assert!(
        rel(sub_cycled, reference) < 0.01,
        "{sub_cycled} against {reference}"
    );
}

fn door_with(model: &str) -> Result<Scene, String> {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/door_hinge.ron"),
    )
    .unwrap();
    let i = text.find("model: Spatial(").unwrap();
    let end = i + text[i..].find('\n').unwrap();
    let text = format!("{}{model}{}", &text[..i], &text[end..]);
    let scene = Scene::from_ron(&text, "door").map_err(|e| e.to_string())?;
    scene.validate().map_err(|e| e.to_string())?;
    Ok(scene)
}

fn door_model(scene: &Scene) -> SpatialModel {
    let v = scene.validated().unwrap();
    match v.clearance(0).unwrap().model {
        ClearanceModel::Spatial(m) => m,
        other => panic!("{other:?}"),
    }
}

#[test]
fn spatial_model_reads_in_full_and_with_defaults() {
    let full = door_with(
        "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 0.010), \
         face: (stiffness: 1e9, restitution: 0.8))),",
    )
    .unwrap();
    let m = door_model(&full);
    assert_eq!(
        m.face,
        FaceLaw {
            stiffness: 1e9,
            restitution: 0.8
        }
    );
    assert_eq!(m.geometry.axial_play, 0.3e-3);
    // Left out: a flat steel punch of the collar's radius, restitution 0.9.
    let m = door_model(&asset("door_hinge.ron"));
    let steel = effective_modulus(&Material::STEEL, &Material::STEEL);
    assert_eq!(m, SpatialModel::steel(0.3e-3, 0.010));
    assert_eq!(
        m.face,
        FaceLaw::flat_punch(steel, 0.010, FaceLaw::DEFAULT_RESTITUTION)
    );
    // Written back and read again: the same scene (the defaults stay left out).
    let door = asset("door_hinge.ron");
    let again = Scene::from_ron(&door.to_ron(), "written").unwrap();
    assert_eq!(again, door);
    assert!(!door.to_ron().contains("face"), "{}", door.to_ron());
}

#[test]
fn spatial_model_errors_name_the_field_and_the_reason() {
    let p = "hinges[hinge].clearance.model";
    let cases = [
        (
            "model: Spatial((geometry: (axial_play: -1e-4, collar_radius: 0.010))),",
            format!("{p}.geometry.axial_play"),
            "> 0",
        ),
        (
            "model: Spatial((geometry: (axial_play: 0.3, collar_radius: 0.010))),",
            format!("{p}.geometry.axial_play"),
            "metres",
        ),
        (
            "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 0.005))),",
            format!("{p}.geometry.collar_radius"),
            "journal radius",
        ),
        (
            "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 10.0))),",
            format!("{p}.geometry.collar_radius"),
            "metres",
        ),
        (
            "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 0.010), \
             face: (stiffness: 1e9, restitution: 1.5))),",
            format!("{p}.face.restitution"),
            "(0, 1]",
        ),
        (
            "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 0.010), \
             face: (stiffness: -1.0, restitution: 0.9))),",
            format!("{p}.face.stiffness"),
            "between",
        ),
        (
            "model: Spatial((geometry: (axial_play: 0.2e-3, collar_radius: 0.010))),",
            "hinges[hinge].journal_offset_mm".to_string(),
            "half the axial play",
        ),
        // The planar model cannot hang the door: gravity along its axis, no axial play.
        (
            "model: Compliant,",
            "hinges[hinge].journal_offset_mm".into(),
            "spatial model",
        ),
    ];
    for (model, field, reason) in cases {
        let e = door_with(model).unwrap_err();
        assert!(
            e.contains(&format!("`{field}`")) && e.contains(reason),
            "{model}: {e}"
        );
    }
    // Unknown fields are refused by name.
    let e = door_with(
        "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 0.010, slice: 4))),",
    )
    .unwrap_err();
    assert!(e.contains("slice"), "{e}");
    // Centred, the planar door is refused for its axial load, naming gravity and the way out.
    let e = asset("door_hinge.ron")
        .with_overrides(&["hinge.model=Compliant", "hinge.journal_offset_mm=[0,0,0]"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("`gravity`") && e.contains("Spatial"), "{e}");
    // A radial start outside the clearance.
    let e = asset("door_hinge.ron")
        .with_overrides(&["hinge.journal_offset_mm=[0.2,0.1,0]"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`hinges[hinge].journal_offset_mm`") && e.contains("radial clearance"),
        "{e}"
    );
}

#[test]
fn spatial_settings_take_overrides() {
    let door = asset("door_hinge.ron");
    let o = door.with_overrides(&["hinge.axial_play=0.5e-3"]).unwrap();
    let m = door_model(&o);
    assert_eq!(m.geometry.axial_play, 0.5e-3);
    assert_eq!(
        door.override_field("hinge.collar_radius").unwrap(),
        "hinges[hinge].clearance.model.Spatial.geometry.collar_radius"
    );
    // A face law written in the scene is overridden by its path; a left-out one with the model.
    let full = door_with(
        "model: Spatial((geometry: (axial_play: 0.3e-3, collar_radius: 0.010), \
         face: (stiffness: 1e9, restitution: 0.8))),",
    )
    .unwrap();
    let m = door_model(&full.with_overrides(&["hinge.face.stiffness=2e9"]).unwrap());
    assert_eq!(m.face.stiffness, 2e9);
    let e = door
        .with_overrides(&["hinge.face.stiffness=2e9"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("no field `face`"), "{e}");
    // The planar scene switched to spatial by one override.
    let m = door_model(&Scene::solar_panel().with_overrides(&[SPATIAL]).unwrap());
    assert_eq!(m, SpatialModel::steel(1e-4, 0.015));
}

/// `journal_offset_mm` starts a planar hinge's journal off-centre too: the pendulum
/// (assets/pendulum.ron, 0.2 mm of play) started resting on the bottom of its bearing takes its
/// weight without the 2.45 kN knock of the drop from the centre.
#[test]
fn journal_offset_starts_a_planar_journal_resting_on_its_bearing() {
    let first_peak = |offset: &str| {
        let scene = asset("pendulum.ron")
            .with_overrides(&[
                format!("pivot.journal_offset_mm={offset}"),
                "run.end_s=0.01".into(),
                "run.step=Adaptive".into(),
            ])
            .unwrap();
        let r = run(&scene, Twins::ClearanceOnly);
        assert!(r.guards.violations.is_empty(), "{:?}", r.guards);
        let m = clearance(&r).hinges["pivot"].clone();
        (m.first_impact_t_s.unwrap(), m.peak_force_n)
    };
    let (t_drop, drop) = first_peak("[0,0,0]");
    let (t_rest, rest) = first_peak("[0,-0.2,0]");
    assert!(t_drop > 5e-3 && drop > 1000.0, "{t_drop} s, {drop} N");
    assert!(
        t_rest < 1e-3 && rest < 3.0 * 2.0 * 9.81,
        "{t_rest} s, {rest} N"
    );
}
