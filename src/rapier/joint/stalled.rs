//! The numbers of a compliant joint's contact for a stall's diagnosis ([`StalledContact`]).

use super::*;
use crate::rapier::pipeline::protocol::{BodyShare, StalledContact};

/// The numbers of `joint` (with handle `handle`) in `bodies` at its last evaluation, for a
/// stall's diagnosis.
pub(super) fn stalled_contact_of(
    handle: ClearanceJointHandle,
    joint: &ClearanceJoint,
    bodies: &RigidBodySet,
) -> StalledContact {
    let r = joint.report();
    let s = &r.state;
    let law = joint.governing_law();
    let m = r.effective_mass;
    let shares = [joint.body1(), joint.body2()]
        .into_iter()
        .filter_map(|h| {
            let rb = bodies.get(h).filter(|rb| rb.is_dynamic())?;
            let mp = &rb.mass_properties().local_mprops;
            let rn = (s.contact_point - world_center_of_mass(rb)).cross(s.normal);
            let p = mp.principal_inertia();
            Some(BodyShare {
                handle: h,
                mass: mp.mass(),
                inertia: p.x.min(p.y).min(p.z),
                rotational_inverse_mass: rn.dot(mp.world_inv_inertia(rb.rotation()) * rn),
            })
        })
        .collect();
    let energy =
        0.5 * m * s.penetration_rate.max(0.0).powi(2) + law.elastic_energy(s.penetration.max(0.0));
    let reach = penetration_for_energy(law, energy, 1e-6).max(s.penetration);
    let valid = joint.max_valid_penetration();
    let at_valid = NormalContact {
        penetration: valid,
        penetration_rate: s.penetration_rate.max(0.0),
        impact_rate: r.impact_rate.max(joint.min_impact_speed_floor()),
    };
    // A sub-cycled joint has no step limit of its own (its report's is infinite): the message
    // reads the contact's damped stability limit here, the scale its sub-steps follow.
    let here = NormalContact {
        penetration: s.penetration.max(0.0),
        penetration_rate: s.penetration_rate,
        impact_rate: r.impact_rate.max(joint.min_impact_speed_floor()),
    };
    let stable_dt = match r.max_stable_dt.is_finite() {
        true => r.max_stable_dt,
        false => {
            let k = law.tangent_stiffness(here.penetration);
            stable_step(k, law.damping_coefficient(&here), m).0
        }
    };
    let (stable_dt_at_valid, _, _) = stable_step(
        law.tangent_stiffness(valid),
        law.damping_coefficient(&at_valid),
        m,
    );
    StalledContact {
        joint: joint.name().to_string(),
        handle: Some(handle.id()),
        law: law.kind(),
        penetration: s.penetration,
        rate: s.penetration_rate,
        impact_rate: r.impact_rate,
        min_impact_speed: joint.min_impact_speed_floor(),
        zeta: r.zeta,
        omega: r.omega,
        elastic_stiffness: law.tangent_stiffness(s.penetration),
        face: r.spatial.is_some_and(|sp| sp.governed_by_face),
        stable_dt,
        friction_dt: r.friction_stable_dt,
        normal_force: r.force.normal_force,
        effective_mass: m,
        bodies: shares,
        max_valid_penetration: valid,
        reachable_penetration: reach,
        stable_dt_at_valid,
    }
}
