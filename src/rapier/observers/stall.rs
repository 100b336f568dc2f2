//! Why the step control stalled, read from the numbers of the contact that stopped it: the
//! message of [`Error::Stalled`](crate::Error::Stalled) names the joint, its contact state
//! (penetration, approach speed `delta_dot0`, damping ratio, stable step) and the cause, chosen by
//! from those numbers rather than guessed:
//!
//! 1. a body whose inertia makes the effective mass at the contact tiny;
//! 2. an approach speed that presses the contact past its law's validity;
//! 3. a slow re-contact of a hysteresis law (its damping grows as `1/delta_dot0`, floored at
//!    `min_impact_speed`);
//! 4. a damping parameter that over-damps the contact;
//! 5. a friction law too steep near zero slip for the normal force;
//! 6. a stiffness too high for the bodies' masses.

use crate::error::sig4;
use crate::model::laws::LawKind;
use crate::rapier::pipeline::protocol::{BodyShare, StalledContact};
use rapier3d_f64::prelude::RigidBodyHandle;

/// The cause read from the numbers of a stalled contact.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum StallCause {
    /// A body's inertia makes the effective mass at the contact tiny against its mass.
    TinyInertia(BodyShare),
    /// The approach presses the contact past its law's validity.
    Speed,
    /// A hysteresis law's damping `~ 1/delta_dot0` at a re-contact as slow as the floor.
    SlowRecontact,
    /// The law's damping over-damps the contact.
    Damping,
    /// Friction's slope near zero slip under this normal force.
    Friction,
    /// The contact is too stiff for the bodies' masses.
    Stiffness,
    /// No joint was in contact: nothing the contact laws do explains it.
    NoContact,
    /// The turn bound, not a contact: the fastest-turning movable body may turn `per_step` rad
    /// a step (`tolerance/8`), which at its rate needs steps of `step` s, at the floor.
    TurnBound {
        /// The body.
        body: RigidBodyHandle,
        /// Its angular speed, rad/s.
        rate: f64,
        /// The turn a step may take, rad.
        per_step: f64,
        /// The step that turn allows, s.
        step: f64,
    },
}

/// Why the step control stalled: what it saw, the contact that stopped it (the one whose step
/// limit is the shortest) and the cause found from its numbers. Its `Display` is the message of
/// [`Error::Stalled`](crate::Error::Stalled).
#[derive(Clone, Debug, PartialEq)]
pub struct Stall {
    /// What the step control saw (`12 steps in a row at the floor`).
    pub seen: String,
    /// The step floor `min_dt`, s.
    pub min_dt: f64,
    /// The contact that stopped the step control, with its numbers; `None` when no clearance
    /// joint was in contact, or the turn bound stopped it.
    pub contact: Option<StalledContact>,
    /// The cause: read from the contact's numbers, [`StallCause::NoContact`] without a
    /// contact, or [`StallCause::TurnBound`].
    pub cause: StallCause,
    /// Bodies named in the message, by handle (see [`name_body`](Self::name_body)).
    body_names: Vec<(RigidBodyHandle, String)>,
}

impl Stall {
    /// A stall seen as `seen` under the step floor `min_dt` (s) at `contact`, its cause
    /// read from the contact's numbers.
    pub(crate) fn at_contact(seen: String, contact: Option<StalledContact>, min_dt: f64) -> Stall {
        let cause = contact
            .as_ref()
            .map_or(StallCause::NoContact, |c| diagnose(c, min_dt));
        Stall {
            seen,
            min_dt,
            contact,
            cause,
            body_names: Vec::new(),
        }
    }

    /// A stall seen as `seen` under the step floor `min_dt` (s) that the turn bound explains
    /// (`cause` a [`StallCause::TurnBound`]).
    pub(crate) fn turn_bound(seen: String, min_dt: f64, cause: StallCause) -> Stall {
        Stall {
            seen,
            min_dt,
            contact: None,
            cause,
            body_names: Vec::new(),
        }
    }

    /// Names body `handle` `label` in the message (a scene's `` body `crank` ``): the step
    /// control knows only Rapier's handles, `body (0, 0)`. The first label given for a handle
    /// is used.
    pub(crate) fn name_body(&mut self, handle: RigidBodyHandle, label: impl Into<String>) {
        self.body_names.push((handle, label.into()));
    }
}

impl std::fmt::Display for Stall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut text = match &self.cause {
            StallCause::TurnBound {
                body,
                rate,
                per_step,
                step,
            } => format!(
                "{} (the floor `min_dt` is {} s); cause: the turn bound, not a contact: body {:?} \
                 turns at {} rad/s and may turn at most tolerance/8 = {} rad a step, which needs \
                 steps of {} s; raise `tolerance`, or check what spins the body so fast (a motor, \
                 a drive, a prescribed motion, an initial velocity)",
                self.seen,
                sig4(self.min_dt),
                body.into_raw_parts(),
                sig4(*rate),
                sig4(*per_step),
                sig4(*step)
            ),
            cause => explain(&self.seen, self.contact.as_ref(), cause, self.min_dt),
        };
        for (handle, label) in &self.body_names {
            let raw = format!("body {:?}", handle.into_raw_parts());
            if text.contains(&raw) {
                text = text.replace(&raw, label);
            }
        }
        f.write_str(&text)
    }
}

/// Below this fraction of the lighter moving body's mass, an effective mass is the sign of a
/// body whose inertia is out of proportion (a rotation too easy to excite).
const TINY_MASS_FRACTION: f64 = 1e-3;

/// The cause of a stall at contact `c` under the step floor `min_dt` (s), from its numbers (see
/// the module docs for the order).
pub(crate) fn diagnose(c: &StalledContact, min_dt: f64) -> StallCause {
    if !(c.penetration > 0.0) {
        return StallCause::NoContact;
    }
    let lightest = c
        .bodies
        .iter()
        .map(|b| b.mass)
        .fold(f64::INFINITY, f64::min);
    if c.effective_mass < TINY_MASS_FRACTION * lightest
        && let Some(b) = c
            .bodies
            .iter()
            .filter(|b| b.rotational_inverse_mass > 1.0 / b.mass)
            .max_by(|a, b| {
                a.rotational_inverse_mass
                    .total_cmp(&b.rotational_inverse_mass)
            })
    {
        return StallCause::TinyInertia(*b);
    }
    if c.reachable_penetration > c.max_valid_penetration {
        return StallCause::Speed;
    }
    // Damping that alone needs steps below the floor comes first: its force also loads
    // friction, whose limit then falls with it.
    let damped = c.zeta > 1.0;
    if damped && (c.stable_dt < min_dt || c.friction_dt >= c.stable_dt) {
        if is_hysteresis(c.law) && c.impact_rate <= 1.01 * c.min_impact_speed {
            return StallCause::SlowRecontact;
        }
        return StallCause::Damping;
    }
    if c.friction_dt < c.stable_dt {
        return StallCause::Friction;
    }
    if damping_stiffens(c) {
        return StallCause::Damping;
    }
    StallCause::Stiffness
}

/// Whether a hysteresis law's damping, not its spring, sets the contact's frequency: the damping
/// grows with the penetration (`D = chi K delta^n`), so its slope times the rate adds to the
/// stiffness; a tiny restitution makes that term dominate while the damping ratio stays small.
/// Only a factor of 100 counts: a spatial joint's frequency sums its regions' over their own
/// masses, which can reach a few times the law's spring without any damping.
fn damping_stiffens(c: &StalledContact) -> bool {
    is_hysteresis(c.law) && c.omega * c.omega * c.effective_mass > 100.0 * c.elastic_stiffness
}

/// The laws whose damping is `chi K delta^n delta_dot` (it grows with the penetration and is
/// divided by the approach speed `delta_dot0`).
fn is_hysteresis(law: LawKind) -> bool {
    matches!(
        law,
        LawKind::HuntCrossley
            | LawKind::LankaraniNikravesh
            | LawKind::FloresEtAl
            | LawKind::GonthierEtAl
    )
}

/// The stall message: what was seen (`seen`), the contact state, the cause and what to change.
/// `min_dt` is the step floor, s.
fn explain(
    seen: &str,
    contact: Option<&StalledContact>,
    cause: &StallCause,
    min_dt: f64,
) -> String {
    let Some(c) = contact else {
        return format!(
            "{seen}, with no clearance joint in contact: no contact law explains it (a body moved \
             by hand or by a kinematic position target, which any step reaches at once, or a step \
             floor `min_dt` = {} s too high)",
            sig4(min_dt)
        );
    };
    let cause = match *cause {
        StallCause::NoContact | StallCause::TurnBound { .. } => format!(
            "no contact law explains it (the joint is not in contact: a body moved by hand or by \
             a kinematic position target, which any step reaches at once, or a step floor \
             `min_dt` = {} s too high)",
            sig4(min_dt)
        ),
        StallCause::TinyInertia(b) => format!(
            "body {:?} has a smallest moment of inertia of {} kg m^2 for a mass of {} kg: turning \
             it about its centre of mass at the contact is so easy that the effective mass there is \
             {} kg, and any contact stiffness oscillates faster than the floor {} s resolves; \
             check its inertia (kg m^2, about its centre of mass)",
            b.handle.into_raw_parts(),
            sig4(b.inertia),
            sig4(b.mass),
            sig4(c.effective_mass),
            sig4(min_dt)
        ),
        StallCause::Speed => format!(
            "the approach is out of the contact law's range: at {} m/s the contact would be pressed \
             to {} um, {} times its validity limit {} um (a contact that stayed valid would need \
             steps of {} s); check the bodies' initial velocities and the loads that drive them",
            sig4(c.rate.max(c.impact_rate)),
            sig4(c.reachable_penetration * 1e6),
            sig4(c.reachable_penetration / c.max_valid_penetration),
            sig4(c.max_valid_penetration * 1e6),
            sig4(c.stable_dt_at_valid)
        ),
        StallCause::SlowRecontact => format!(
            "a slow re-contact: its approach speed delta_dot0 = {} m/s sits at the floor \
             `min_impact_speed` = {} m/s, and this hysteresis law's damping grows as \
             1/delta_dot0, so the contact is over-damped (damping ratio {}) and stable only below \
             {} s; raise `min_impact_speed`",
            sig4(c.impact_rate),
            sig4(c.min_impact_speed),
            sig4(c.zeta),
            sig4(c.stable_dt)
        ),
        StallCause::Damping if c.zeta <= 1.0 => format!(
            "the law's damping: it grows with the penetration, and its slope stiffens the contact \
             to {} N/m against the spring's {} N/m (natural frequency {} rad/s), so it is stable \
             only below {} s; lower the {} damping ({})",
            sig4(c.omega * c.omega * c.effective_mass),
            sig4(c.elastic_stiffness),
            sig4(c.omega),
            sig4(c.stable_dt),
            law_name(c.face),
            damping_field(c.law, c.face)
        ),
        StallCause::Damping => format!(
            "the contact is over-damped: damping ratio {} (the damping is {} times the critical \
             damping 2 sqrt(K m) of the effective mass {} kg), so it is stable only below {} s; \
             lower the {} damping ({})",
            sig4(c.zeta),
            sig4(c.zeta),
            sig4(c.effective_mass),
            sig4(c.stable_dt),
            law_name(c.face),
            damping_field(c.law, c.face)
        ),
        StallCause::Friction => format!(
            "friction: under a normal force of {} N its law is so steep near zero slip that a step \
             must stay below {} s; use a friction law with a larger stiction speed",
            sig4(c.normal_force),
            sig4(c.friction_dt)
        ),
        StallCause::Stiffness => format!(
            "the contact is too stiff for the effective mass {} kg: natural frequency {} rad/s, \
             stable only below {} s; check the {}",
            sig4(c.effective_mass),
            sig4(c.omega),
            sig4(c.stable_dt),
            if c.face {
                "face law's `stiffness` (`spatial.face`)"
            } else {
                "law's stiffness (or the materials' Young's moduli)"
            }
        ),
    };
    format!(
        "{seen} (the floor `min_dt` is {} s); {}. Cause: {cause}",
        sig4(min_dt),
        c
    )
}

/// Which law, in words: the face law of a spatial joint's shoulders, or the joint's own.
fn law_name(face: bool) -> &'static str {
    if face { "face law's" } else { "law's" }
}

/// The parameter that sets a law's damping, in words (`face`: the face law's restitution).
fn damping_field(law: LawKind, face: bool) -> &'static str {
    if face {
        return "`spatial.face.restitution`: a higher restitution damps less";
    }
    match law {
        LawKind::KelvinVoigt => "`damping`, N s/m",
        LawKind::ImprovedLiu => "`eta_s`, or `d_max_n_s_per_m`",
        LawKind::HuntCrossley
        | LawKind::LankaraniNikravesh
        | LawKind::FloresEtAl
        | LawKind::GonthierEtAl => "a higher `restitution` damps less",
        _ => "its damping parameter",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact() -> StalledContact {
        StalledContact {
            joint: "pin".into(),
            handle: Some(crate::rapier::pipeline::protocol::ElementId::from_raw_parts(0, 0)),
            law: LawKind::LankaraniNikravesh,
            penetration: 1e-6,
            rate: 1e-3,
            impact_rate: 0.1,
            min_impact_speed: 1e-4,
            zeta: 0.1,
            omega: 1e6,
            elastic_stiffness: 1e11,
            face: false,
            stable_dt: 2e-10 * 0.5,
            friction_dt: f64::INFINITY,
            normal_force: 10.0,
            effective_mass: 0.1,
            bodies: vec![BodyShare {
                handle: RigidBodyHandle::from_raw_parts(1, 0),
                mass: 0.14,
                inertia: 1e-4,
                rotational_inverse_mass: 2.0,
            }],
            max_valid_penetration: 95e-6,
            reachable_penetration: 2e-6,
            stable_dt_at_valid: 1e-7,
        }
    }

    #[test]
    fn each_cause_from_its_numbers() {
        assert_eq!(diagnose(&contact(), 1e-10), StallCause::Stiffness);
        let c = StalledContact {
            zeta: 50.0,
            impact_rate: 1e-4,
            ..contact()
        };
        assert_eq!(diagnose(&c, 1e-10), StallCause::SlowRecontact);
        assert_eq!(
            diagnose(
                &StalledContact {
                    law: LawKind::KelvinVoigt,
                    ..c.clone()
                },
                1e-10
            ),
            StallCause::Damping
        );
        assert_eq!(
            diagnose(
                &StalledContact {
                    impact_rate: 0.5,
                    ..c
                },
                1e-10
            ),
            StallCause::Damping
        );
        assert_eq!(
            diagnose(
                &StalledContact {
                    friction_dt: 1e-12,
                    ..contact()
                },
                1e-10
            ),
            StallCause::Friction
        );
        assert_eq!(
            diagnose(
                &StalledContact {
                    reachable_penetration: 7e-3,
                    ..contact()
                },
                1e-10
            ),
            StallCause::Speed
        );
        let tiny = StalledContact {
            effective_mass: 6e-12,
            bodies: vec![BodyShare {
                inertia: 1e-12,
                rotational_inverse_mass: 1.6e11,
                ..contact().bodies[0]
            }],
            ..contact()
        };
        assert!(matches!(diagnose(&tiny, 1e-10), StallCause::TinyInertia(b) if b.inertia == 1e-12));
        // Damping that needs steps below the floor is the cause even when friction's limit,
        // loaded by the damping force, is lower still.
        assert_eq!(
            diagnose(
                &StalledContact {
                    law: LawKind::KelvinVoigt,
                    zeta: 1e7,
                    stable_dt: 4e-12,
                    friction_dt: 4e-15,
                    ..contact()
                },
                1e-10
            ),
            StallCause::Damping
        );
        assert_eq!(
            diagnose(
                &StalledContact {
                    penetration: -1e-6,
                    ..contact()
                },
                1e-10
            ),
            StallCause::NoContact
        );
    }

    #[test]
    fn the_message_names_the_joint_the_state_and_the_cause() {
        let c = StalledContact {
            zeta: 50.0,
            impact_rate: 1e-4,
            ..contact()
        };
        let m = Stall::at_contact(
            "no step resolves the contact".into(),
            Some(c.clone()),
            1e-10,
        )
        .to_string();
        for part in [
            "joint `pin`",
            "penetration 1 um",
            "delta_dot0 1e-4 m/s",
            "damping ratio 50",
            "stable step 1e-10 s",
            "slow re-contact",
            "raise `min_impact_speed`",
        ] {
            assert!(m.contains(part), "{part:?} not in {m}");
        }
        assert!(!m.contains("out of its physical range"), "{m}");
    }

    /// A face law with a restitution of 1e-6: its damping's slope makes the contact 10^6 times
    /// stiffer than its spring while the damping ratio stays small. The cause is the damping, and
    /// the message names the face law's restitution, not a stiffness.
    #[test]
    fn a_steep_hysteresis_damping_on_a_face_names_the_face_restitution() {
        let c = StalledContact {
            law: LawKind::FloresEtAl,
            zeta: 0.0037,
            omega: 8.4e7,
            elastic_stiffness: 3e9,
            effective_mass: 0.68,
            face: true,
            ..contact()
        };
        assert_eq!(diagnose(&c, 1e-10), StallCause::Damping);
        let m = Stall::at_contact(
            "no step resolves the contact".into(),
            Some(c.clone()),
            1e-10,
        )
        .to_string();
        for part in [
            "a shoulder on a bearing face",
            "its slope stiffens the contact",
            "lower the face law's damping",
            "`spatial.face.restitution`",
        ] {
            assert!(m.contains(part), "{part:?} not in {m}");
        }
        assert!(!m.contains("check the law's stiffness"), "{m}");
        // The same numbers on the bore's own law name that law's damping.
        let bore = StalledContact { face: false, ..c };
        let m = Stall::at_contact(
            "no step resolves the contact".into(),
            Some(bore.clone()),
            1e-10,
        )
        .to_string();
        assert!(
            m.contains("lower the law's damping (a higher `restitution`"),
            "{m}"
        );
    }
}
