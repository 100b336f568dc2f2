use crate::rapier::hinge::design::ClearanceModel;
use crate::scene::Scene;
use crate::scene::runner::{RunOptions, Simulation, Twins};

fn error_of(scene: &Scene, twins: Twins) -> Option<String> {
    let options = RunOptions {
        twins,
        ..RunOptions::default()
    };
    Simulation::new(scene, options).err().map(|e| e.to_string())
}

#[test]
fn a_large_step_hinge_runs_in_the_runner() {
    let base = Scene::solar_panel();
    let name = base.hinges[0].name.clone();
    // The format may choose the model, and the runner steps it.
    let mut scene = base
        .with_overrides(&[format!("{name}.model=LargeStep"), "run.end_s=0.5".into()])
        .unwrap();
    scene.run.output_interval_s = 1e-3;
    let spec = scene.hinges[0].clearance.as_ref().unwrap();
    assert_eq!(spec.model, crate::scene::ModelSpec::LargeStep);
    let v = scene.validated().unwrap();
    assert_eq!(v.clearance(0).unwrap().model, ClearanceModel::LargeStep);
    assert_eq!(error_of(&scene, Twins::IdealOnly), None);
    let sim = Simulation::new(&scene, RunOptions::default()).unwrap();
    assert_eq!(sim.world.large_step.len(), 1);
    assert!(sim.world.clearance.is_empty());
    let run = sim.run().unwrap();
    let clear = &run.twins[1];
    assert_eq!(clear.clearance_hinges(), vec![name.as_str()]);
    // The panel's first swing closes the play: contacts recorded, the journal kept within
    // its bearing (the eccentricity columns, mm, against c = 0.5 mm), the guards clean.
    let m = &clear.hinge_metrics()[&name];
    assert!(m.onsets > 0, "{m:?}");
    let t = &clear.table;
    let (u, w) = (
        t.column(&format!("{name}_ecc_u_mm")).unwrap(),
        t.column(&format!("{name}_ecc_v_mm")).unwrap(),
    );
    let worst = u
        .iter()
        .zip(&w)
        .map(|(a, b)| a.hypot(*b))
        .fold(0.0, f64::max);
    assert!(
        worst > 0.4 && worst < 0.55,
        "largest |e| {worst} mm, c = 0.5 mm"
    );
    assert!(run.guards.is_clean(), "{:?}", run.guards);
}

#[test]
fn the_models_settings_are_checked_at_the_scene() {
    let base = Scene::solar_panel();
    let name = base.hinges[0].name.clone();
    // A restitution is the large-step model's only.
    let e = base
        .with_overrides(&[format!("{name}.clearance.restitution=0.5")])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("`hinges[{name}].clearance.restitution`")) && e.contains("large-step"),
        "{e}"
    );
    let e = base
        .with_overrides(&[
            format!("{name}.model=LargeStep"),
            format!("{name}.clearance.restitution=1.5"),
        ])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("`hinges[{name}].clearance.restitution`")),
        "{e}"
    );
    let ok = base
        .with_overrides(&[
            format!("{name}.model=LargeStep"),
            format!("{name}.clearance.restitution=0.5"),
        ])
        .unwrap();
    assert_eq!(
        ok.validated().unwrap().clearance(0).unwrap().restitution,
        Some(0.5)
    );
    // Written back, the choice reads the same; the default is not written (old scenes
    // and their files read as before).
    assert_eq!(Scene::from_ron(&ok.to_ron(), "round trip").unwrap(), ok);
    assert!(ok.to_ron().contains("LargeStep"));
    assert!(!base.to_ron().contains("model"), "{}", base.to_ron());
    // An unknown model is a parse error naming the variants.
    let text = crate::scene::SOLAR_PANEL_RON.replacen(
        "clearance: Some((",
        "clearance: Some((model: Rigid, ",
        1,
    );
    assert!(text.contains("model: Rigid"), "the asset's hinge moved");
    let e = Scene::from_ron(&text, "test").unwrap_err().to_string();
    assert!(e.contains("Rigid"), "{e}");
}
