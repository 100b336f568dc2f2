use super::*;

/// A step-limit error as the plain API raises it (field `dt`, no caller names).
fn step_error(parameter: ContactParameter, adaptive: Option<bool>) -> Error {
    let mut limit = StepLimit::new(
        "pin",
        1e-3,
        1.3122521820485098e-4,
        11.333333333333334,
        15241.234567890123,
        0.1234567890123,
        parameter,
    );
    limit.t = Some(0.08800000000000001);
    limit.adaptive = adaptive;
    Error::StepTooLarge(Box::new(limit))
}

#[test]
fn step_limit_messages_speak_the_api() {
    use ContactParameter as P;
    let cases = [
        (
            P::ModulusAndWidth,
            Some(false),
            "`Material::youngs_modulus_pa` and `length`",
        ),
        (
            P::MaxDamping,
            Some(false),
            "`MaxDamping::Eta` (or `MaxDamping::Explicit`)",
        ),
        (P::Stiffness, Some(true), "`stiffness` (or the materials'"),
        (P::Damping, Some(true), "check `damping`"),
        (
            P::Restitution,
            None,
            "`restitution` (a lower restitution damps harder)",
        ),
    ];
    for (parameter, adaptive, names) in cases {
        let e = step_error(parameter, adaptive).to_string();
        assert!(e.contains("1.312e-4 s") && e.contains("t = 0.088 s"), "{e}");
        assert!(e.contains("joint `pin`") && e.contains(names), "{e}");
        match adaptive {
            Some(true) => assert!(e.contains("Adaptive stepping is on"), "{e}"),
            Some(false) => assert!(
                e.contains("`dt` below 1.05e-4 s")
                    && e.contains("adaptive stepping (`StepControl::adaptive`)"),
                "{e}"
            ),
            None => assert!(e.contains("smaller `dt`"), "{e}"),
        }
        for word in ["--", "run.", "hinges["] {
            assert!(!e.contains(word), "{word:?} in {e}");
        }
    }
    assert_eq!(
        step_error(P::Stiffness, Some(false)).suggested_step(),
        Some(0.8 * 1.3122521820485098e-4)
    );
    assert_eq!(step_error(P::Stiffness, Some(true)).suggested_step(), None);
}

#[test]
fn a_caller_puts_its_own_names() {
    let names = ParameterNames {
        adaptive: "my.adaptive".into(),
        contact: vec!["my.eta".into(), "my.d_max".into()],
    };
    let e = step_error(ContactParameter::MaxDamping, Some(false))
        .named("my.step", names)
        .to_string();
    assert!(
        e.contains("`my.step` = 0.001 s")
            && e.contains("`my.step` below")
            && e.contains("(`my.adaptive`)")
            && e.contains("`my.eta` (or `my.d_max`)")
            && !e.contains("MaxDamping"),
        "{e}"
    );
}
