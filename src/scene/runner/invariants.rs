//! Conservation checks over every step: momentum drift and the energy balance.

use crate::rapier::pipeline::stepper::StepInfo;
use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::RigidBody;
use serde::Serialize;

/// Conservation checks over every step.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Invariants {
    /// A prescribed motion drives the scene: it does work the balance does not know, so the
    /// energy figures are null. (A joint motor's work is in the balance: `motor_work_j`.)
    #[serde(skip)]
    pub driven: bool,
    /// Largest `|P(t) - P(0)|` over the largest single-body linear momentum seen; null when the
    /// scene is not free-floating (gravity or a fixed body: momentum is not conserved).
    pub linear_momentum_drift: Option<f64>,
    /// Largest `|L(t) - L(0)|` (about the origin) over the largest single-body angular momentum
    /// seen; null when the scene is not free-floating.
    pub angular_momentum_drift: Option<f64>,
    /// Largest growth of the energy balance `E(t) + D(t) - W(t) - E(0)` (E: kinetic, gravity,
    /// spring and contact elastic energy; D: the work dissipated so far by contact damping and
    /// friction; W: the joint motors' work) over the energy scale. Fixed supports and ideal joints do no work, so the balance holds with
    /// gravity and grounds too, and energy gained by the integration shows even in a run that
    /// dissipates. Null when nothing moved (an energy scale below 1e-9 J: no scale to judge by),
    /// and when a prescribed motion drives the scene (its work is not in the balance).
    pub energy_growth: Option<f64>,
    /// Largest `|E(t) + D(t) - E(0)|` over the energy scale (null when nothing moved).
    pub energy_error: Option<f64>,
    /// The energy scale: the larger of the peak kinetic energy and the largest change of the
    /// potential energy, J.
    pub energy_scale_j: f64,
    /// Peak kinetic energy, J.
    pub peak_kinetic_energy_j: f64,
    /// Work dissipated by contact damping and friction over the run, J.
    pub dissipated_j: f64,
    /// Work done by the joint motors on the bodies over the run, J: at each step, the impulse
    /// Rapier's motor row applied times the joint's speed at the step's start. The energy
    /// balance counts it as energy put in: `E(t) + D(t) - W(t) - E(0)`.
    pub motor_work_j: f64,
    /// Largest `|speed - target| / |target|` (the target floored at 1e-3) of the velocity motors,
    /// which are reported as holding their speed exactly (their torques and the reactions are
    /// solved so): how far that holds. Null without velocity motors.
    pub motor_speed_error: Option<f64>,
    /// The velocity motor where `motor_speed_error` was largest, and when, s.
    #[serde(skip)]
    pub motor_speed_error_at: Option<(String, f64)>,
    /// States at which a velocity motor missed its speed by more than
    /// [`MOTOR_SPEED_ERROR_LIMIT`].
    #[serde(skip)]
    pub motor_speed_violations: u64,
    /// When a velocity motor first missed its speed by more than the limit, s.
    #[serde(skip)]
    pub motor_speed_first_violation_at: Option<f64>,
    /// When the energy balance grew the most, s.
    #[serde(skip)]
    pub energy_growth_at: f64,
    /// There: the speed's miss `|speed - target|` and the target, in the motor's unit (rad/s
    /// or m/s, the third field): a zero target's miss is reported as it is, not relative to the
    /// floor.
    #[serde(skip)]
    pub motor_speed_miss: Option<(f64, f64, &'static str)>,
    /// A velocity motor whose bodies start off its target (beyond the motor guard's limit): its
    /// joint, the initial speed and the target. Rapier's motor then jumps them to speed in the
    /// first steps, work the energy balance does not see: the initial velocities do not match
    /// the motor.
    #[serde(skip)]
    pub motor_start_mismatch: Option<(String, f64, f64, &'static str)>,
    #[serde(skip)]
    free_floating: bool,
    #[serde(skip)]
    p0: Option<(Vector, Vector, f64, f64)>,
    #[serde(skip)]
    max_p: f64,
    #[serde(skip)]
    max_l: f64,
    #[serde(skip)]
    max_dp: f64,
    #[serde(skip)]
    max_dl: f64,
    #[serde(skip)]
    max_de: f64,
    #[serde(skip)]
    max_abs_de: f64,
    #[serde(skip)]
    max_dpe: f64,
}

impl Invariants {
    /// Empty checks for a scene that is free-floating (no gravity, no fixed or driven body:
    /// momentum is conserved) or driven by a prescribed motion (its work is not in the balance).
    pub(super) fn new(free_floating: bool, driven: bool) -> Invariants {
        Invariants {
            free_floating,
            driven,
            ..Invariants::default()
        }
    }
}

/// Below this energy scale (J) nothing moved enough for the energy balance to be judged.
const MIN_ENERGY_SCALE_J: f64 = 1e-9;

/// A velocity motor's speed error above this fraction of its target is a guard violation: its
/// torque and the reactions are solved as if it held its speed.
pub const MOTOR_SPEED_ERROR_LIMIT: f64 = 1e-2;

/// Energy growth above this fraction of the energy scale is a guard violation.
pub const ENERGY_GROWTH_LIMIT: f64 = 1e-2;

/// A moving body at the state before a step, as the balances need it: the twin passes these
/// in (the invariants know no twin).
pub(super) struct BodyBefore<'a> {
    /// Mass, kg.
    pub(super) mass: f64,
    /// Centre of mass (world), m.
    pub(super) com: Vector,
    /// Rotation.
    pub(super) rotation: Rotation,
    /// Stored (half-step) linear and angular velocities.
    pub(super) linvel: Vector,
    pub(super) angvel: Vector,
    /// The body after the step: its velocities are the next half-step's.
    pub(super) after: &'a RigidBody,
    /// The velocity (linear, angular) the state has beyond the Verlet reading of the stored
    /// ones: sub-cycled contacts' impulses inside the steps around it
    /// ([`ClearanceJoint::start_velocity_correction`](crate::rapier::joint::ClearanceJoint::start_velocity_correction)).
    pub(super) beyond: (Vector, Vector),
}

impl Invariants {
    /// Momentum and energy at the state before the step just taken, from its moving bodies
    /// and the sources' elastic energy there (J), with its synchronous velocities: the
    /// half-step velocities around it weighted by the steps,
    /// `(h v_before + h_prev v_after)/(h_prev + h)` (second order, where the stored half-step
    /// velocities alone would make the energy balance first order).
    pub(super) fn update<'a>(
        &mut self,
        bodies: impl IntoIterator<Item = BodyBefore<'a>>,
        source_energy: f64,
        gravity: Vector,
        info: &StepInfo,
    ) {
        let (h, h_prev) = (info.dt, (2.0 * info.kick - info.dt).max(0.0));
        let sync = |before: Vector, after: Vector| (h * before + h_prev * after) / (h_prev + h);
        let (mut p, mut l, mut ke, mut pe) = (Vector::ZERO, Vector::ZERO, 0.0, 0.0);
        for b in bodies {
            let rb = b.after;
            let com = b.com;
            let v = sync(b.linvel, rb.linvel()) + b.beyond.0;
            let w = sync(b.angvel, rb.angvel()) + b.beyond.1;
            let mp = &rb.mass_properties().local_mprops;
            // I w in world: R I_principal R^T w.
            let rot = b.rotation * mp.principal_inertia_local_frame;
            let iw = rot * (mp.principal_inertia() * (rot.inverse() * w));
            let pb = b.mass * v;
            let lb = com.cross(pb) + iw;
            p += pb;
            l += lb;
            ke += 0.5 * b.mass * v.length_squared() + 0.5 * w.dot(iw);
            pe -= b.mass * gravity.dot(com);
            self.max_p = self.max_p.max(pb.length());
            self.max_l = self.max_l.max(lb.length());
        }
        pe += source_energy;
        self.record(p, l, ke, pe, info.t0);
    }

    /// Folds the momenta and energies of one state into the drifts and the balance.
    fn record(&mut self, p: Vector, l: Vector, ke: f64, pe: f64, t: f64) {
        let inv = self;
        let e = ke + pe + inv.dissipated_j - inv.motor_work_j;
        let (p0, l0, e0, pe0) = *inv.p0.get_or_insert((p, l, e, pe));
        inv.max_dp = inv.max_dp.max((p - p0).length());
        inv.max_dl = inv.max_dl.max((l - l0).length());
        if e - e0 > inv.max_de {
            inv.max_de = e - e0;
            inv.energy_growth_at = t;
        }
        inv.max_abs_de = inv.max_abs_de.max((e - e0).abs());
        inv.max_dpe = inv.max_dpe.max((pe - pe0).abs());
        inv.peak_kinetic_energy_j = inv.peak_kinetic_energy_j.max(ke);
        inv.energy_scale_j = inv.peak_kinetic_energy_j.max(inv.max_dpe);
        let rel = |d: f64, scale: f64| if scale > 0.0 { d / scale } else { 0.0 };
        if inv.free_floating {
            inv.linear_momentum_drift = Some(rel(inv.max_dp, inv.max_p));
            inv.angular_momentum_drift = Some(rel(inv.max_dl, inv.max_l));
        }
        if inv.energy_scale_j >= MIN_ENERGY_SCALE_J && !inv.driven {
            inv.energy_growth = Some(inv.max_de / inv.energy_scale_j);
            inv.energy_error = Some(inv.max_abs_de / inv.energy_scale_j);
        }
    }
}
