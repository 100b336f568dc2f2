use super::*;
use crate::scene::Scene;

#[test]
fn from_a_scene_spec() {
    let scene = Scene::solar_panel();
    let spec = scene.hinges[0].clearance.as_ref().unwrap();
    let c = spec.clearance().unwrap();
    assert!((c.geometry.clearance() - 0.5e-3).abs() < 1e-15);
    assert_eq!(
        c.friction,
        crate::model::laws::FrictionModel::Bai(crate::model::laws::Bai::DRY)
    );
    assert_eq!(
        c.normal,
        HingeDesign::steel_improved_liu(0.010, 0.5e-3, 0.016)
            .unwrap()
            .normal
    );
}
