//! The scene layer's names in the library's errors: an error raised by the plain API names the
//! API's parameters (`dt`, a law's `stiffness`); passing through a scene run it names the scene's
//! field paths (`run.dt_s`, `hinges[NAME].clearance.contact.eta_s`), the ones a scene file or an
//! override sets.

use crate::error::{ContactParameter, Error, ParameterNames};

/// `e` in the scene's words: a step-limit error names `step_field` (the scene's field that set
/// the step), how a scene turns adaptive stepping on, and the fields of the hinge's clearance
/// that make its contact stiff (the clearance joint of a scene hinge bears the hinge's name).
/// Other errors pass through.
pub(crate) fn in_scene(e: Error, step_field: &str) -> Error {
    let Error::StepTooLarge(limit) = &e else {
        return e;
    };
    let names = ParameterNames {
        adaptive: "run.step = Adaptive".into(),
        contact: contact_fields(limit.joint(), limit.parameter()),
    };
    e.named(step_field, names)
}

/// The scene's fields behind `parameter` for hinge `hinge`, in the order of
/// [`ContactParameter::api_names`].
fn contact_fields(hinge: &str, parameter: ContactParameter) -> Vec<String> {
    let p = format!("hinges[{hinge}].clearance");
    match parameter {
        ContactParameter::Stiffness => {
            vec![format!("{p}.contact.stiffness"), "youngs_modulus_pa".into()]
        }
        ContactParameter::ModulusAndWidth => vec![
            format!("{p}.bearing_material.youngs_modulus_pa"),
            format!("{p}.journal_material.youngs_modulus_pa"),
            format!("{p}.width_mm"),
        ],
        ContactParameter::Damping => vec![format!("{p}.contact.damping")],
        ContactParameter::MaxDamping => {
            vec![format!("{p}.contact.eta_s"), "d_max_n_s_per_m".into()]
        }
        ContactParameter::Restitution => vec![format!("{p}.contact.restitution")],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(parameter: ContactParameter, zeta: f64, adaptive: Option<bool>) -> Error {
        let mut limit = crate::error::StepLimit::new(
            "hinge",
            1e-3,
            1.3122521820485098e-4,
            11.333333333333334,
            15241.234567890123,
            zeta,
            parameter,
        );
        limit.t = Some(0.08800000000000001);
        limit.adaptive = adaptive;
        Error::StepTooLarge(Box::new(limit))
    }

    /// The step-limit message in a scene names the scene's field
    /// that sets the stiffness (or the damping), the step field and the scene's switch to
    /// adaptive steps, and no option of the app.
    #[test]
    fn step_limit_messages_name_the_scene_fields() {
        use crate::model::laws::LawKind;
        let p = "hinges[hinge].clearance";
        let cases = [
            (
                LawKind::ImprovedLiu,
                0.1234567890123,
                Some(false),
                format!("{p}.bearing_material.youngs_modulus_pa"),
                "adaptive stepping (`run.step = Adaptive`)",
            ),
            (
                LawKind::ImprovedLiu,
                4.2,
                Some(false),
                format!("{p}.contact.eta_s` (or `d_max_n_s_per_m`)"),
                "`run.dt_s` below 1.05e-4 s",
            ),
            (
                LawKind::Hertz,
                0.0,
                Some(true),
                format!("{p}.contact.stiffness"),
                "Adaptive stepping is on",
            ),
            (
                LawKind::KelvinVoigt,
                3.0,
                Some(true),
                format!("{p}.contact.damping"),
                "too stiff (or too damped)",
            ),
            (
                LawKind::HuntCrossley,
                0.3,
                None,
                format!("{p}.contact.stiffness"),
                "smaller `run.dt_s`",
            ),
            (
                LawKind::LankaraniNikravesh,
                2.0,
                Some(false),
                format!("{p}.contact.restitution"),
                "a lower restitution damps harder",
            ),
        ];
        for (law, zeta, adaptive, field, advice) in cases {
            let e = in_scene(error(law.stiff_parameter(zeta), zeta, adaptive), "run.dt_s");
            let e = e.to_string();
            assert!(e.contains("1.312e-4 s") && e.contains("t = 0.088 s"), "{e}");
            assert!(e.contains(&field) && e.contains(advice), "{law:?}: {e}");
            assert!(e.contains("`run.dt_s` = 0.001 s"), "{e}");
            assert!(!e.contains("--"), "{e}");
            if adaptive == Some(true) {
                assert!(!e.contains("run.step = Adaptive"), "{e}");
            }
        }
    }
}
