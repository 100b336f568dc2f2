//! Independent reference ODEs for a journal in a bearing with radial clearance, shared by
//! `tests/references.rs` (included with `#[path]`). Written from MODEL.md §1-§3 (the laws'
//! table and Ambrosio's friction, written out here) and from each mechanism's own equations of
//! motion in reduced coordinates (Newton-Euler, the ideal joints' reactions eliminated by taking
//! moments about the pins), integrated by an own adaptive Dormand-Prince 5(4) that ends a step on
//! every switch of the contact (onset, separation, the clamp `F_N >= 0`, the law's and the
//! friction's kinks) and on the extrema of the penetration and of the force, so the approach
//! speed `delta_dot0`, the peak force and the deepest penetration are exact to its tolerance.
//! Nothing here calls the crate.

#![allow(dead_code)]

use std::f64::consts::PI;

/// A planar vector (x, y) in the mechanism's plane; the hinge axis is z.
pub type V2 = [f64; 2];
/// A state of at most two generalised coordinates and their rates (unused slots stay 0).
pub type State = [f64; 4];

fn add(a: V2, b: V2) -> V2 {
    [a[0] + b[0], a[1] + b[1]]
}
fn sub(a: V2, b: V2) -> V2 {
    [a[0] - b[0], a[1] - b[1]]
}
fn scale(a: V2, s: f64) -> V2 {
    [a[0] * s, a[1] * s]
}
fn dot(a: V2, b: V2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
/// The z component of `a x b`.
fn cross(a: V2, b: V2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
/// `z x a`: `a` turned a quarter turn counter-clockwise.
fn perp(a: V2) -> V2 {
    [-a[1], a[0]]
}
fn norm(a: V2) -> f64 {
    a[0].hypot(a[1])
}
/// The unit vector at angle `q`.
fn unit(q: f64) -> V2 {
    [q.cos(), q.sin()]
}

// ---------------------------------------------------------------------------------------------
// Material and geometric constants (MODEL.md §2)
// ---------------------------------------------------------------------------------------------

/// `sigma_l = (1 - nu_l^2)/E_l`.
pub fn sigma(youngs: f64, poisson: f64) -> f64 {
    (1.0 - poisson * poisson) / youngs
}

/// Lankarani-Nikravesh's geometric stiffness of a journal in a bearing:
/// `K = 4/(3(sigma_i + sigma_j)) sqrt(R_b R_j/(R_b - R_j))`.
pub fn lankarani_nikravesh_stiffness(sigma_i: f64, sigma_j: f64, r_b: f64, r_j: f64) -> f64 {
    4.0 / (3.0 * (sigma_i + sigma_j)) * (r_b * r_j / (r_b - r_j)).sqrt()
}

/// MSC Adams' cubic STEP: `h0` below `x0`, `h1` above `x1`, `h0 + (h1-h0) s^2 (3-2s)` between.
pub fn adams_step(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> f64 {
    if x <= x0 {
        h0
    } else if x >= x1 {
        h1
    } else {
        let s = (x - x0) / (x1 - x0);
        h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    }
}

/// The improved model's elastic term (paper eq. 14):
/// `F_K = (pi/2) E* L sqrt(delta/(2(c+delta))) delta^n`.
pub fn improved_elastic(e_star: f64, l: f64, c: f64, n: f64, delta: f64) -> f64 {
    if delta <= 0.0 {
        return 0.0;
    }
    0.5 * PI * e_star * l * (delta / (2.0 * (c + delta))).sqrt() * delta.powf(n)
}

/// The tangent stiffness `K_N = dF_K/d delta` of the improved model's elastic term (paper eq. 17),
/// differentiated by hand: with `g = sqrt(delta/(2(c+delta)))`, `g' = g c/(2 delta (c+delta))`,
/// so `K_N = (pi/2) E* L g delta^(n-1) (n + c/(2(c+delta)))`.
pub fn improved_tangent_stiffness(e_star: f64, l: f64, c: f64, n: f64, delta: f64) -> f64 {
    let g = (delta / (2.0 * (c + delta))).sqrt();
    0.5 * PI * e_star * l * g * delta.powf(n - 1.0) * (n + c / (2.0 * (c + delta)))
}

// ---------------------------------------------------------------------------------------------
// Normal force laws (MODEL.md §2, the table)
// ---------------------------------------------------------------------------------------------

/// One normal force law of MODEL.md §2 with its constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Law {
    /// Hertz: `K delta^n`.
    Hertz { k: f64, n: f64 },
    /// Kelvin-Voigt: `K delta + D delta_dot`.
    KelvinVoigt { k: f64, d: f64 },
    /// Hunt-Crossley: `K delta^n (1 + 3(1-cr)/2 delta_dot/delta_dot0)`.
    HuntCrossley { k: f64, n: f64, cr: f64 },
    /// Lankarani-Nikravesh: `K delta^1.5 (1 + 3(1-cr^2)/4 delta_dot/delta_dot0)`.
    LankaraniNikravesh { k: f64, cr: f64 },
    /// Flores et al. 2011: `K delta^n (1 + 8(1-cr)/(5 cr) delta_dot/delta_dot0)`.
    Flores { k: f64, n: f64, cr: f64 },
    /// Gonthier et al. 2004: `K delta^n (1 + (1-cr^2)/cr delta_dot/delta_dot0)`.
    Gonthier { k: f64, n: f64, cr: f64 },
    /// Liu et al. 2007 (cylindrical): `(pi/2) E* L delta sqrt(delta/(2(c+delta)))`.
    Liu { e_star: f64, l: f64, c: f64 },
    /// The paper's improved model: `F_K + STEP(delta, 0, 0, delta_max, D_max) delta_dot`.
    Improved {
        e_star: f64,
        l: f64,
        c: f64,
        n: f64,
        delta_max: f64,
        d_max: f64,
    },
}

impl Law {
    /// The paper's improved model with `D_max = eta K_N(delta_max)` (paper eq. 17, MODEL.md).
    pub fn improved(e_star: f64, l: f64, c: f64, n: f64, delta_max: f64, eta: f64) -> Law {
        let d_max = eta * improved_tangent_stiffness(e_star, l, c, n, delta_max);
        Law::Improved {
            e_star,
            l,
            c,
            n,
            delta_max,
            d_max,
        }
    }

    /// The law's expression before the clamp `F_N >= 0`, at penetration `delta > 0`, normal rate
    /// `rate` (positive approaching) and impact rate `rate0`.
    pub fn unclamped(&self, delta: f64, rate: f64, rate0: f64) -> f64 {
        match *self {
            Law::Hertz { k, n } => k * delta.powf(n),
            Law::KelvinVoigt { k, d } => k * delta + d * rate,
            Law::HuntCrossley { k, n, cr } => {
                k * delta.powf(n) * (1.0 + 1.5 * (1.0 - cr) * rate / rate0)
            }
            Law::LankaraniNikravesh { k, cr } => {
                k * delta.powf(1.5) * (1.0 + 0.75 * (1.0 - cr * cr) * rate / rate0)
            }
            Law::Flores { k, n, cr } => {
                k * delta.powf(n) * (1.0 + 8.0 * (1.0 - cr) / (5.0 * cr) * rate / rate0)
            }
            Law::Gonthier { k, n, cr } => {
                k * delta.powf(n) * (1.0 + (1.0 - cr * cr) / cr * rate / rate0)
            }
            Law::Liu { e_star, l, c } => {
                0.5 * PI * e_star * l * delta * (delta / (2.0 * (c + delta))).sqrt()
            }
            Law::Improved {
                e_star,
                l,
                c,
                n,
                delta_max,
                d_max,
            } => {
                improved_elastic(e_star, l, c, n, delta)
                    + adams_step(delta, 0.0, 0.0, delta_max, d_max) * rate
            }
        }
    }

    /// The normal force `F_N = max(0, law)` for `delta > 0`, zero otherwise (MODEL.md §1).
    pub fn force(&self, delta: f64, rate: f64, rate0: f64) -> f64 {
        if delta <= 0.0 {
            0.0
        } else {
            self.unclamped(delta, rate, rate0).max(0.0)
        }
    }

    /// The elastic energy `K delta^(n+1)/(n+1)` stored at `delta` by the laws that divide by
    /// `delta_dot0` (the hysteresis laws), `None` for the others.
    pub fn hysteresis_energy(&self, delta: f64) -> Option<f64> {
        match *self {
            Law::HuntCrossley { k, n, .. }
            | Law::Flores { k, n, .. }
            | Law::Gonthier { k, n, .. } => Some(k * delta.powf(n + 1.0) / (n + 1.0)),
            Law::LankaraniNikravesh { k, .. } => Some(k * delta.powf(2.5) / 2.5),
            _ => None,
        }
    }

    /// The penetration at which the law's damping changes form (the STEP's end), if any.
    pub fn kink(&self) -> Option<f64> {
        match *self {
            Law::Improved { delta_max, .. } => Some(delta_max),
            _ => None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Friction (MODEL.md §3)
// ---------------------------------------------------------------------------------------------

/// A friction law of MODEL.md §3 (the two the references need).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Friction {
    /// No friction.
    None,
    /// Ambrosio: `mu = mu_d c_d`, `c_d` 0 below `v0`, linear to 1 at `v1`, 1 above.
    Ambrosio { mu_d: f64, v0: f64, v1: f64 },
}

impl Friction {
    /// The friction coefficient at slip speed `v >= 0`.
    pub fn mu(&self, v: f64) -> f64 {
        match *self {
            Friction::None => 0.0,
            Friction::Ambrosio { mu_d, v0, v1 } => {
                if v <= v0 {
                    0.0
                } else if v <= v1 {
                    mu_d * (v - v0) / (v1 - v0)
                } else {
                    mu_d
                }
            }
        }
    }

    /// The slip speeds at which the coefficient has a kink.
    pub fn kinks(&self) -> [Option<f64>; 2] {
        match *self {
            Friction::None => [None, None],
            Friction::Ambrosio { v0, v1, .. } => [Some(v0), Some(v1)],
        }
    }
}

/// One clearance pin: its normal law, friction, radial clearance and radii.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pin {
    pub law: Law,
    pub friction: Friction,
    /// Radial clearance `c = R_b - R_j`, m.
    pub c: f64,
    pub r_b: f64,
    pub r_j: f64,
    /// The library's documented conventions for the laws that divide by `delta_dot0`
    /// (docs/MODEL.md §2 of the project, not the published laws): `delta_dot0` floored at this
    /// speed (m/s; 0: no floor) ...
    pub min_impact_speed: f64,
    /// ... and raised at each state to the speed of a free impact reaching the current depth,
    /// `sqrt(2 E(delta)/m_eff)` (`m_eff` along the normal, the ideal joints included).
    pub free_impact_raise: bool,
}

impl Pin {
    /// A pin with the published law alone (no floor, no raise of `delta_dot0`).
    pub fn published(law: Law, friction: Friction, c: f64, r_b: f64) -> Pin {
        Pin {
            law,
            friction,
            c,
            r_b,
            r_j: r_b - c,
            min_impact_speed: 0.0,
            free_impact_raise: false,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Mechanisms in reduced coordinates
// ---------------------------------------------------------------------------------------------

/// The pin's kinematics at a state (MODEL.md §1, planar).
#[derive(Clone, Copy, Debug)]
pub struct Kin {
    /// The bearing centre `P_i` in the world.
    pub bearing: V2,
    /// The eccentricity `e = P_j - P_i` and its rate.
    pub e: V2,
    pub e_dot: V2,
    /// The angular rates of the journal's body and the bearing's body about z.
    pub w_j: f64,
    pub w_i: f64,
}

/// A mechanism in reduced coordinates carrying one clearance pin.
pub trait Mechanism {
    /// The pin's kinematics at time `t` and state `y`.
    fn kin(&self, t: f64, y: &State) -> Kin;
    /// The state's rate with the force `f` on the journal applied at the world point `p` (and
    /// `-f` on the bearing at `p`).
    fn deriv(&self, t: f64, y: &State, f: V2, p: V2) -> State;
    /// The absolute error allowed in each state component per unit of tolerance.
    fn scales(&self) -> State;
    /// `1/m_eff` along the unit normal `n`: `n^T G M^-1 G^T n` with `G = de/dq` and `M` the
    /// mass matrix of the reduced coordinates (the mechanism's ideal joints included).
    fn inverse_mass(&self, t: f64, y: &State, n: V2) -> f64;
}

/// A body turning about a fixed pivot at the origin (moment of inertia `i_pivot` about it),
/// its journal `l` from the pivot, in a bearing fixed at `(l, 0)`; state `[phi, phi_dot]`.
#[derive(Clone, Copy, Debug)]
pub struct Arm {
    pub i_pivot: f64,
    pub l: f64,
    /// Scales of the angle (rad) and of the rate (rad/s) for the error control.
    pub angle_scale: f64,
    pub rate_scale: f64,
}

impl Mechanism for Arm {
    fn kin(&self, _t: f64, y: &State) -> Kin {
        let (phi, w) = (y[0], y[1]);
        let half = (0.5 * phi).sin();
        Kin {
            bearing: [self.l, 0.0],
            // J - B = l (cos phi - 1, sin phi), with cos phi - 1 = -2 sin^2(phi/2) (no cancellation).
            e: [-2.0 * self.l * half * half, self.l * phi.sin()],
            e_dot: scale(perp(unit(phi)), self.l * w),
            w_j: w,
            w_i: 0.0,
        }
    }
    fn deriv(&self, _t: f64, y: &State, f: V2, p: V2) -> State {
        // I_pivot phi'' = ((p - O) x f).z
        [y[1], cross(p, f) / self.i_pivot, 0.0, 0.0]
    }
    fn scales(&self) -> State {
        [self.angle_scale, self.rate_scale, 1.0, 1.0]
    }
    fn inverse_mass(&self, _t: f64, y: &State, n: V2) -> f64 {
        let g = self.l * dot(perp(unit(y[0])), n);
        g * g / self.i_pivot
    }
}

/// A free body of mass `m` that only translates along x (no rotation), its journal at
/// `(x, 0)` in a bearing fixed at the origin; state `[x, x_dot]`: the one-dimensional impact.
#[derive(Clone, Copy, Debug)]
pub struct Slide {
    pub m: f64,
    pub length_scale: f64,
    pub speed_scale: f64,
}

impl Mechanism for Slide {
    fn kin(&self, _t: f64, y: &State) -> Kin {
        Kin {
            bearing: [0.0, 0.0],
            e: [y[0], 0.0],
            e_dot: [y[1], 0.0],
            w_j: 0.0,
            w_i: 0.0,
        }
    }
    fn deriv(&self, _t: f64, y: &State, f: V2, _p: V2) -> State {
        [y[1], f[0] / self.m, 0.0, 0.0]
    }
    fn scales(&self) -> State {
        [self.length_scale, self.speed_scale, 1.0, 1.0]
    }
    fn inverse_mass(&self, _t: f64, _y: &State, n: V2) -> f64 {
        n[0] * n[0] / self.m
    }
}

/// Flores & Ambrosio's slider-crank: a crank `l1` turning at the prescribed rate `omega` about
/// the origin (crank pin `A = l1 (cos omega t, sin omega t)`), a rod `l2` (mass `m2`, inertia
/// `i2` about its mid-length centre of mass) pinned ideally at A, its far end the journal, and a
/// slider (mass `m3`) on an ideal guide along x carrying the bearing at `(x, 0)`; gravity `g`.
/// State `[theta, x, theta_dot, x_dot]` (rod angle, slider position).
#[derive(Clone, Copy, Debug)]
pub struct SliderCrank {
    pub omega: f64,
    pub l1: f64,
    pub l2: f64,
    pub m2: f64,
    pub i2: f64,
    pub m3: f64,
    pub g: V2,
    pub angle_scale: f64,
    pub length_scale: f64,
    pub rate_scale: f64,
    pub speed_scale: f64,
}

/// The crank pin's position, velocity and acceleration on its prescribed circle.
fn crank_pin(l1: f64, omega: f64, t: f64) -> (V2, V2, V2) {
    let u = unit(omega * t);
    (
        scale(u, l1),
        scale(perp(u), l1 * omega),
        scale(u, -l1 * omega * omega),
    )
}

impl Mechanism for SliderCrank {
    fn kin(&self, t: f64, y: &State) -> Kin {
        let (a, va, _) = crank_pin(self.l1, self.omega, t);
        let u = unit(y[0]);
        let p = add(a, scale(u, self.l2));
        let vp = add(va, scale(perp(u), self.l2 * y[2]));
        Kin {
            bearing: [y[1], 0.0],
            e: sub(p, [y[1], 0.0]),
            e_dot: sub(vp, [y[3], 0.0]),
            w_j: y[2],
            w_i: 0.0,
        }
    }
    fn deriv(&self, t: f64, y: &State, f: V2, p: V2) -> State {
        let (a, _, acc) = crank_pin(self.l1, self.omega, t);
        let u = unit(y[0]);
        let half = 0.5 * self.l2;
        // Moments about the crank pin A (Newton-Euler with the pin force eliminated):
        // (I_G + m2 l2^2/4) theta'' = -m2 (l2/2) u x A'' + m2 (l2/2) u x g + (p - A) x f.
        let i_a = self.i2 + self.m2 * half * half;
        let theta_dd = (-self.m2 * half * cross(u, acc)
            + self.m2 * half * cross(u, self.g)
            + cross(sub(p, a), f))
            / i_a;
        // The slider along the guide: m3 x'' = -f.x (gravity is the guide's).
        [y[2], y[3], theta_dd, -f[0] / self.m3]
    }
    fn scales(&self) -> State {
        [
            self.angle_scale,
            self.length_scale,
            self.rate_scale,
            self.speed_scale,
        ]
    }
    fn inverse_mass(&self, _t: f64, y: &State, n: V2) -> f64 {
        let half = 0.5 * self.l2;
        let g = self.l2 * dot(perp(unit(y[0])), n);
        g * g / (self.i2 + self.m2 * half * half) + n[0] * n[0] / self.m3
    }
}

/// A crank-rocker four-bar: a crank `l1` at the prescribed rate `omega` about the origin, a
/// coupler `lc` (mass `mc`, inertia `ic` about its mid-length centre of mass) pinned ideally at
/// the crank pin, its far end the journal, and a rocker `lr` (mass `mr`, inertia `ir` about its
/// middle) pivoted ideally at `o4`, its far end the bearing; gravity `g`.
/// State `[alpha, beta, alpha_dot, beta_dot]` (coupler and rocker angles).
#[derive(Clone, Copy, Debug)]
pub struct FourBar {
    pub omega: f64,
    pub l1: f64,
    pub lc: f64,
    pub mc: f64,
    pub ic: f64,
    pub o4: V2,
    pub lr: f64,
    pub mr: f64,
    pub ir: f64,
    pub g: V2,
    pub angle_scale: f64,
    pub rate_scale: f64,
}

impl Mechanism for FourBar {
    fn kin(&self, t: f64, y: &State) -> Kin {
        let (a, va, _) = crank_pin(self.l1, self.omega, t);
        let (ua, ub) = (unit(y[0]), unit(y[1]));
        let p = add(a, scale(ua, self.lc));
        let vp = add(va, scale(perp(ua), self.lc * y[2]));
        let b = add(self.o4, scale(ub, self.lr));
        let vb = scale(perp(ub), self.lr * y[3]);
        Kin {
            bearing: b,
            e: sub(p, b),
            e_dot: sub(vp, vb),
            w_j: y[2],
            w_i: y[3],
        }
    }
    fn deriv(&self, t: f64, y: &State, f: V2, p: V2) -> State {
        let (a, _, acc) = crank_pin(self.l1, self.omega, t);
        let (ua, ub) = (unit(y[0]), unit(y[1]));
        let (hc, hr) = (0.5 * self.lc, 0.5 * self.lr);
        // Coupler, moments about the crank pin A (its prescribed acceleration A''):
        // (I_c + mc lc^2/4) alpha'' = -mc (lc/2) u x A'' + mc (lc/2) u x g + (p - A) x f.
        let alpha_dd = (-self.mc * hc * cross(ua, acc)
            + self.mc * hc * cross(ua, self.g)
            + cross(sub(p, a), f))
            / (self.ic + self.mc * hc * hc);
        // Rocker, moments about its fixed pivot: (I_r + mr lr^2/4) beta'' = mr (lr/2) u x g
        // + (p - O4) x (-f).
        let beta_dd = (self.mr * hr * cross(ub, self.g) - cross(sub(p, self.o4), f))
            / (self.ir + self.mr * hr * hr);
        [y[2], y[3], alpha_dd, beta_dd]
    }
    fn scales(&self) -> State {
        [
            self.angle_scale,
            self.angle_scale,
            self.rate_scale,
            self.rate_scale,
        ]
    }
    fn inverse_mass(&self, _t: f64, y: &State, n: V2) -> f64 {
        let (hc, hr) = (0.5 * self.lc, 0.5 * self.lr);
        let ga = self.lc * dot(perp(unit(y[0])), n);
        let gb = self.lr * dot(perp(unit(y[1])), n);
        ga * ga / (self.ic + self.mc * hc * hc) + gb * gb / (self.ir + self.mr * hr * hr)
    }
}

// ---------------------------------------------------------------------------------------------
// The contact at a state
// ---------------------------------------------------------------------------------------------

/// Whether the journal is in contact, and the normal rate at which this contact began.
#[derive(Clone, Copy, Debug)]
pub struct Mode {
    pub in_contact: bool,
    pub rate0: f64,
}

/// The contact's quantities at one state (MODEL.md §1).
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// Penetration `delta = |e| - c` and normal rate `delta_dot`.
    pub delta: f64,
    pub rate: f64,
    /// The free-impact speed `sqrt(2 E(delta)/m_eff)` when the pin raises `delta_dot0` to it.
    pub free_speed: f64,
    /// The law before the clamp, and `F_N` after it.
    pub unclamped: f64,
    pub f_n: f64,
    /// Signed tangential slip of the surface points along `z x n`.
    pub slip: f64,
    /// The force on the journal and its point (the midpoint of the two surface points).
    pub force: V2,
    pub point: V2,
}

/// The contact force of `pin` at the kinematics `k`: `F = -F_N n - mu F_N v_t/|v_t|` on the
/// journal at the midpoint of `Q_i = P_i + R_b n` and `Q_j = P_j + R_j n` (MODEL.md §1).
pub fn contact<M: Mechanism>(mech: &M, pin: &Pin, mode: &Mode, t: f64, y: &State) -> Contact {
    let k = mech.kin(t, y);
    let r = norm(k.e);
    if r == 0.0 {
        return Contact {
            delta: -pin.c,
            rate: 0.0,
            free_speed: 0.0,
            unclamped: 0.0,
            f_n: 0.0,
            slip: 0.0,
            force: [0.0, 0.0],
            point: k.bearing,
        };
    }
    let n = scale(k.e, 1.0 / r);
    let tangent = perp(n);
    let delta = r - pin.c;
    let rate = dot(n, k.e_dot);
    // v(Q_j) - v(Q_i) = e_dot + (w_j R_j - w_i R_b) z x n; its part along z x n.
    let slip = dot(k.e_dot, tangent) + k.w_j * pin.r_j - k.w_i * pin.r_b;
    let mut free_speed = 0.0;
    let (unclamped, f_n) = if mode.in_contact && delta > 0.0 {
        let mut rate0 = mode.rate0.max(pin.min_impact_speed);
        if pin.free_impact_raise
            && let Some(energy) = pin.law.hysteresis_energy(delta)
        {
            free_speed = (2.0 * energy * mech.inverse_mass(t, y, n)).sqrt();
            rate0 = rate0.max(free_speed);
        }
        let u = pin.law.unclamped(delta, rate, rate0);
        (u, u.max(0.0))
    } else {
        (0.0, 0.0)
    };
    let friction = if f_n > 0.0 && slip != 0.0 {
        -pin.friction.mu(slip.abs()) * f_n * slip.signum()
    } else {
        0.0
    };
    Contact {
        delta,
        rate,
        free_speed,
        unclamped,
        f_n,
        slip,
        force: add(scale(n, -f_n), scale(tangent, friction)),
        // Q_i = P_i + R_b n and Q_j = P_i + (c + delta + R_j) n = P_i + (R_b + delta) n.
        point: add(k.bearing, scale(n, pin.r_b + 0.5 * delta)),
    }
}

/// The state's rate with the contact of `pin` in `mode`.
pub fn rate_of<M: Mechanism>(mech: &M, pin: &Pin, mode: &Mode, t: f64, y: &State) -> State {
    let c = contact(mech, pin, mode, t, y);
    mech.deriv(t, y, c.force, c.point)
}

// ---------------------------------------------------------------------------------------------
// Dormand-Prince 5(4)
// ---------------------------------------------------------------------------------------------

/// One Dormand-Prince 5(4) step of `h` from `(t, y)`: the fifth-order state and the difference
/// of the embedded pair (the local error estimate).
pub fn dopri_step<F: Fn(f64, &State) -> State>(f: &F, t: f64, y: &State, h: f64) -> (State, State) {
    const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
    const A: [[f64; 6]; 7] = [
        [0.0; 6],
        [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ];
    // Fifth-order weights minus the embedded fourth-order ones.
    const E: [f64; 7] = [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ];
    let mut k = [[0.0; 4]; 7];
    for s in 0..7 {
        let mut ys = *y;
        for (j, kj) in k.iter().enumerate().take(s) {
            for i in 0..4 {
                ys[i] += h * A[s][j] * kj[i];
            }
        }
        k[s] = f(t + C[s] * h, &ys);
    }
    let mut y5 = *y;
    let mut err = [0.0; 4];
    for i in 0..4 {
        for s in 0..6 {
            y5[i] += h * A[6][s] * k[s][i];
        }
    }
    // The last stage is evaluated at y5 (FSAL); recompute it there for the error estimate.
    let k7 = f(t + h, &y5);
    for i in 0..4 {
        for s in 0..6 {
            err[i] += h * E[s] * k[s][i];
        }
        err[i] += h * E[6] * k7[i];
    }
    (y5, err)
}

// ---------------------------------------------------------------------------------------------
// Impacts
// ---------------------------------------------------------------------------------------------

/// One contact from onset to separation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Impact {
    /// Time at which `delta` crosses 0 upwards, and `delta_dot0` there.
    pub onset_t: f64,
    pub approach_speed: f64,
    /// The largest `F_N` of the contact and its time.
    pub peak_force: f64,
    pub peak_t: f64,
    /// The deepest `delta` of the contact.
    pub max_penetration: f64,
    /// Time at which `delta` crosses 0 downwards (NaN while in contact), and `-delta_dot` there.
    pub end_t: f64,
    pub separation_speed: f64,
    /// The largest `|F|` of the contact (normal and friction together).
    pub peak_total_force: f64,
    /// The largest `sqrt(2 E(delta)/m_eff)/delta_dot0` over the contact's states (hysteresis
    /// laws): above 1, the mechanism loaded the contact deeper than a free impact at the
    /// approach speed would reach.
    pub free_impact_ratio: f64,
    /// The most negative `delta` of the free flight before this contact.
    pub gap_before: f64,
}

/// The settings of one reference run.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Local error tolerance (per unit of each component's scale).
    pub tol: f64,
    /// Longest step, s (so that no grazing contact is stepped over).
    pub h_max: f64,
    /// First step, s.
    pub h0: f64,
    /// Half-width of the central difference that gives `dF_N/dt` along the motion, s.
    pub eps_t: f64,
    /// Stop at this time, or after this many completed impacts.
    pub t_end: f64,
    pub max_impacts: usize,
}

/// A reference run's impacts, end state and cost.
#[derive(Clone, Debug)]
pub struct Run {
    pub impacts: Vec<Impact>,
    pub t: f64,
    pub y: State,
    pub steps: usize,
}

/// Number of switching functions watched by the integrator.
const EVENTS: usize = 8;

/// The switching functions at a state: 0 `delta` (onset/separation), 1 the law before its clamp,
/// 2 `delta - delta_max` (the STEP's end), 3-4 `|v_t|` minus the friction's kinks, 5
/// `delta_dot` (deepest penetration), 6 `dF_N/dt` (peak force), 7 the free-impact speed minus
/// `delta_dot0` (where its raise begins). The integrator ends a step on
/// each sign change, so no step straddles a switch of the force's form or an extremum.
fn events<M: Mechanism>(
    mech: &M,
    pin: &Pin,
    mode: &Mode,
    eps_t: f64,
    t: f64,
    y: &State,
) -> [f64; EVENTS] {
    let c = contact(mech, pin, mode, t, y);
    let mut g = [c.delta, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    if mode.in_contact && c.delta > 0.0 {
        g[1] = c.unclamped;
        if let Some(dm) = pin.law.kink() {
            g[2] = c.delta - dm;
        }
        let kinks = pin.friction.kinks();
        for (slot, kink) in [3, 4].into_iter().zip(kinks) {
            if let Some(v) = kink {
                g[slot] = c.slip.abs() - v;
            }
        }
        g[5] = c.rate;
        // dF_N/dt along the motion, by a central difference along the state's rate.
        let f = mech.deriv(t, y, c.force, c.point);
        let at = |s: f64| {
            let mut ys = *y;
            for i in 0..4 {
                ys[i] += s * f[i];
            }
            contact(mech, pin, mode, t + s, &ys).f_n
        };
        g[6] = (at(eps_t) - at(-eps_t)) / (2.0 * eps_t);
        if pin.free_impact_raise {
            g[7] = c.free_speed - mode.rate0.max(pin.min_impact_speed);
        }
    }
    g
}

/// Integrates `mech` with the clearance `pin` from `(t0, y0)`, journal not in contact, and
/// returns every impact (onset, approach speed, peak force, deepest penetration, separation).
pub fn simulate<M: Mechanism>(mech: &M, pin: &Pin, y0: State, t0: f64, s: &Settings) -> Run {
    let scales = mech.scales();
    let mut mode = Mode {
        in_contact: false,
        rate0: 0.0,
    };
    let (mut t, mut y) = (t0, y0);
    let mut h = s.h0;
    let mut impacts: Vec<Impact> = Vec::new();
    let mut steps = 0;
    let mut gap = 0.0f64;
    let done = |impacts: &Vec<Impact>| {
        impacts.len() >= s.max_impacts && impacts.last().is_some_and(|i| !i.end_t.is_nan())
    };
    while t < s.t_end && !done(&impacts) {
        let h_try = h.min(s.h_max).min(s.t_end - t);
        let m = mode;
        let f = |tt: f64, yy: &State| rate_of(mech, pin, &m, tt, yy);
        let (y1, err) = dopri_step(&f, t, &y, h_try);
        let err_norm = (0..4)
            .map(|i| (err[i] / (s.tol * scales[i])).abs())
            .fold(0.0, f64::max);
        let factor = if err_norm == 0.0 {
            5.0
        } else {
            (0.9 * err_norm.powf(-0.2)).clamp(0.2, 5.0)
        };
        // A NaN error (a blown-up trial) is rejected too.
        if err_norm.is_nan() || err_norm > 1.0 {
            h = h_try * factor.min(0.9);
            assert!(h > 1e-22, "step size underflow at t = {t}");
            continue;
        }
        steps += 1;
        let g0 = events(mech, pin, &m, s.eps_t, t, &y);
        let g1 = events(mech, pin, &m, s.eps_t, t + h_try, &y1);
        // The earliest switch inside the step, located by the Illinois method on the step length
        // (each trial a single step from the step's start).
        let mut first: Option<(usize, f64)> = None;
        for k in 0..EVENTS {
            if (g0[k] > 0.0) == (g1[k] > 0.0) {
                continue;
            }
            let g =
                |hh: f64| events(mech, pin, &m, s.eps_t, t + hh, &dopri_step(&f, t, &y, hh).0)[k];
            let (mut lo, mut hi) = (0.0, h_try);
            let (mut glo, mut ghi) = (g0[k], g1[k]);
            let mut side = 0;
            for _ in 0..200 {
                if hi - lo <= 1e-15 * (t.abs() + hi) {
                    break;
                }
                let mut mid = hi - ghi * (hi - lo) / (ghi - glo);
                if !(mid > lo && mid < hi) {
                    mid = 0.5 * (lo + hi);
                }
                let gm = g(mid);
                if (gm > 0.0) == (glo > 0.0) {
                    lo = mid;
                    glo = gm;
                    if side == -1 {
                        ghi *= 0.5;
                    }
                    side = -1;
                } else {
                    hi = mid;
                    ghi = gm;
                    if side == 1 {
                        glo *= 0.5;
                    }
                    side = 1;
                }
            }
            if first.is_none_or(|(_, h0)| hi < h0) {
                first = Some((k, hi));
            }
        }
        let (t_new, y_new) = match first {
            Some((_, hh)) => (t + hh, dopri_step(&f, t, &y, hh).0),
            None => (t + h_try, y1),
        };
        // Bookkeeping on the new state, in the step's mode.
        let k_new = mech.kin(t_new, &y_new);
        let c = contact(mech, pin, &m, t_new, &y_new);
        if m.in_contact {
            let imp = impacts.last_mut().expect("a contact has its impact");
            if c.f_n > imp.peak_force {
                imp.peak_force = c.f_n;
                imp.peak_t = t_new;
            }
            imp.max_penetration = imp.max_penetration.max(c.delta);
            imp.peak_total_force = imp.peak_total_force.max(norm(c.force));
            if let Some(energy) = pin.law.hysteresis_energy(c.delta.max(0.0)) {
                let n = scale(k_new.e, 1.0 / norm(k_new.e));
                let speed = (2.0 * energy * mech.inverse_mass(t_new, &y_new, n)).sqrt();
                imp.free_impact_ratio = imp.free_impact_ratio.max(speed / m.rate0);
            }
        } else {
            gap = gap.min(c.delta);
        }
        // The mode follows the sign of delta at the new state: a step ends on the earliest
        // switch, so delta changed sign only if this is the located onset or separation.
        let switched = m.in_contact != (c.delta > 0.0);
        if switched {
            if m.in_contact {
                let imp = impacts.last_mut().expect("a contact has its impact");
                imp.end_t = t_new;
                imp.separation_speed = -c.rate;
                mode = Mode {
                    in_contact: false,
                    rate0: 0.0,
                };
            } else {
                impacts.push(Impact {
                    onset_t: t_new,
                    approach_speed: c.rate,
                    end_t: f64::NAN,
                    gap_before: gap,
                    ..Impact::default()
                });
                gap = 0.0;
                mode = Mode {
                    in_contact: true,
                    rate0: c.rate,
                };
            }
        }
        h = h_try * factor;
        if switched {
            // A contact begins or ends: restart from the first step (the force's form changes).
            h = h.min(s.h0);
        }
        t = t_new;
        y = y_new;
    }
    Run {
        impacts,
        t,
        y,
        steps,
    }
}
