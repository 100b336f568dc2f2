#!/usr/bin/env python3
"""Independent RK45 reference for the project's default scene (the deployable solar panel).

What it models
--------------
The paper's scene (Wang & Liu, APISAT2014), as specified in /work/shared/MODEL.md sections 1-4 and
the scene file assets/solar_panel.ron; written from those texts, not from the Rust code:

* a free-floating 768 kg satellite (body 1, carries the bearing) and a 7.68 kg panel (body 2, carries
  the journal), no gravity, at rest at t = 0;
* a revolute hinge with radial clearance c = 0.5 mm (R_b = 10 mm, R_j = 9.5 mm, width L = 16 mm,
  steel E = 207 GPa, nu = 0.3 on both sides), journal centred at t = 0;
* normal law: the paper's improved Liu law with n = 1,
      F_N = max(0, F_K + D_imp * delta_dot),  F_K = (pi/2) E* L delta sqrt(delta / (2 (c + delta))),
      D_imp = STEP(delta, 0, 0, delta_max, D_max),  D_max = eta * dF_K/d delta (at delta_max),
      delta_max = 0.1 mm, eta = 0.01 s;
  (this law does not use delta_dot0, so the delta_dot0 floor/raise conventions do not enter);
* friction: Bai / Adams stiction, "Dry" (mu_s = 0.3, mu_d = 0.25, v_s = 0.1 mm/s, v_d = 10 mm/s);
* contact force on the journal F = -F_N n - mu(|v_t|) F_N v_t/|v_t| at the midpoint of the two surface
  points, equal and opposite on the bearing (momentum-exact);
* torsion spring T = T0 - k theta (T0 = 0.135 N m, k = 0.0015 N m/deg, theta = hinge angle in deg),
  +T on the panel, -T on the satellite.

The motion is planar. In-plane coordinates (u, w) = (world x, world z); since x cross z = -y = the
hinge axis, a positive angle in this 2-D frame is a positive rotation about the hinge axis
(deployment). Rotational inertias about the hinge axis: satellite Jy = 81.92, panel Jy = 0.4156 kg m^2.

State and why
-------------
A change of variables of the 6-DOF planar state [x1, z1, th1, x2, z2, th2] (exact, no reduction):
    y = [x1, z1, th1, e_u, e_w, theta,  and their rates]
with e = P_j - P_i the eccentricity (journal centre minus bearing centre, world) and
theta = th2 - th1 the hinge angle. The panel's pose follows from P_j = P_i + e and th2 = th1 + theta.
Reason: RK45's error test uses max(atol, rtol |y_k|) per component. With absolute panel coordinates
(|x2| ~ 0.4 m) rtol = 1e-4 would accept ~40 um of local error in the very quantity whose difference
gives the penetration (a few um); with e as a state the tolerance on it is ~rtol * 0.5 mm = 0.05 um.

Integration: scipy.integrate.solve_ivp(method="RK45", rtol=1e-4, atol=ATOL) over 0..5 s in one call,
atol = 1e-10 m for e, 1e-9 m for x1, z1, 1e-9 rad for th1, theta, and 1e-8 m/s or rad/s for the rates
(all well below the smallest physical scales: 1 um penetrations, ~mm/s approach speeds).
Events (located by scipy on the RK45 interpolant, all smooth functions of the state):
  * delta = 0 upward (contact onset) and downward (lift-off);
  * delta_dot = 0 downward with delta > 0 (local maximum penetration);
  * dF_N/dt = 0 downward with F_N > 0 (local maximum of the normal force; dF_N/dt is computed exactly
    from the state and the equations of motion).
A contact's peak force / depth is the largest of these local maxima between its onset and lift-off.

Run:  python3 benches/reference/solar_panel_rk45.py        (needs numpy and scipy; ~minutes of CPU)
"""

import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

# ----------------------------------------------------------------------------- scene parameters
M1, J1 = 768.0, 81.92          # satellite mass (kg), inertia about the hinge axis (Jy, kg m^2)
M2, J2 = 7.68, 0.4156          # panel
C1_0 = (0.0, 0.0)              # centres of mass at t = 0, (u, w) = (x, z), m
C2_0 = (0.4, 0.0)
H = (0.4, 0.4)                 # hinge point (x, z) = (0.4, 0.4)
S1 = (H[0] - C1_0[0], H[1] - C1_0[1])   # bearing centre in satellite frame (body axes = world at t=0)
S2 = (H[0] - C2_0[0], H[1] - C2_0[1])   # journal centre in panel frame

R_B = 10.0e-3                  # bearing radius (diameter 20 mm)
CLR = 0.5e-3                   # radial clearance
R_J = R_B - CLR
L_W = 16.0e-3                  # width
E_MOD, NU = 207e9, 0.3
E_STAR = 1.0 / (2.0 * (1.0 - NU ** 2) / E_MOD)
N_EXP = 1.0                    # improved-law exponent (scene: exponent 1.0)
DELTA_MAX = 0.1e-3             # delta_max_mm 0.1
ETA = 0.01                     # eta_s

MU_S, MU_D = 0.3, 0.25         # Dry (paper table 3)
V_S, V_D = 0.1e-3, 10.0e-3     # m/s

T0 = 0.135                     # N m
K_SPRING = 0.0015              # N m per degree
END_T = 5.0

PREF = 0.5 * math.pi * E_STAR * L_W


def f_elastic(d):
    """F_K of the improved law (n = N_EXP), d > 0."""
    return PREF * math.sqrt(d / (2.0 * (CLR + d))) * d ** N_EXP


def k_tangent(d):
    """dF_K/d delta, analytic."""
    g = math.sqrt(d / (2.0 * (CLR + d)))
    # d/dd sqrt(d/(2(c+d))) = (1/(2g)) * c / (2 (c+d)^2)
    dg = CLR / (4.0 * g * (CLR + d) ** 2)
    return PREF * (dg * d ** N_EXP + g * N_EXP * d ** (N_EXP - 1.0))


D_MAX = ETA * k_tangent(DELTA_MAX)


def step(x, x0, h0, x1, h1):
    """MSC Adams cubic STEP."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    s = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


def dstep(x, x0, h0, x1, h1):
    """d STEP / dx."""
    if x <= x0 or x >= x1:
        return 0.0
    s = (x - x0) / (x1 - x0)
    return (h1 - h0) * 6.0 * s * (1.0 - s) / (x1 - x0)


def mu_bai(v):
    """Bai / Adams stiction coefficient, paper eq. 19."""
    if v >= V_D:
        return MU_D
    if v >= V_S:
        return step(v, V_S, MU_S, V_D, MU_D)
    return step(v, -V_S, -MU_S, V_S, MU_S)


def rot(th, p):
    c, s = math.cos(th), math.sin(th)
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


# ----------------------------------------------------------------------------- dynamics
def kinematics(y):
    """Positions/velocities of both bodies from the state."""
    x1, z1, th1, eu, ew, th = y[0], y[1], y[2], y[3], y[4], y[5]
    vx1, vz1, w1, deu, dew, dth = y[6], y[7], y[8], y[9], y[10], y[11]
    th2, w2 = th1 + th, w1 + dth
    r1 = rot(th1, S1)                       # COM1 -> bearing centre
    r2 = rot(th2, S2)                       # COM2 -> journal centre
    pi = (x1 + r1[0], z1 + r1[1])
    pj = (pi[0] + eu, pi[1] + ew)
    c2 = (pj[0] - r2[0], pj[1] - r2[1])
    return th2, w2, r1, r2, pi, pj, c2


def contact(y):
    """Normal force, its parts, and the contact force on the journal and its point of application.

    Returns (delta, delta_dot, F_N, n, Fvec, point, Fk, D) ; Fvec = (0,0) and point = None if no contact.
    """
    eu, ew = y[3], y[4]
    deu, dew = y[9], y[10]
    em = math.hypot(eu, ew)
    delta = em - CLR
    if em > 0.0:
        n = (eu / em, ew / em)
        ddot = deu * n[0] + dew * n[1]
    else:
        n = (1.0, 0.0)
        ddot = math.hypot(deu, dew)
    if delta <= 0.0:
        return delta, ddot, 0.0, n, (0.0, 0.0), None, 0.0, 0.0
    fk = f_elastic(delta)
    dmp = step(delta, 0.0, 0.0, DELTA_MAX, D_MAX)
    fn = max(0.0, fk + dmp * ddot)
    th2, w2, r1, r2, pi, pj, c2 = kinematics(y)
    w1 = y[8]
    t = (-n[1], n[0])                       # k x n
    # v_rel = v(Q_j on panel) - v(Q_i on satellite) = e_dot + (w2 R_j - w1 R_b) k x n
    a = w2 * R_J - w1 * R_B
    vr = (deu + a * t[0], dew + a * t[1])
    vn = vr[0] * n[0] + vr[1] * n[1]
    vt = (vr[0] - vn * n[0], vr[1] - vn * n[1])
    vts = math.hypot(vt[0], vt[1])
    fx, fz = -fn * n[0], -fn * n[1]
    if vts > 0.0 and fn > 0.0:
        mu = mu_bai(vts)
        fx -= mu * fn * vt[0] / vts
        fz -= mu * fn * vt[1] / vts
    qi = (pi[0] + R_B * n[0], pi[1] + R_B * n[1])
    qj = (pj[0] + R_J * n[0], pj[1] + R_J * n[1])
    point = (0.5 * (qi[0] + qj[0]), 0.5 * (qi[1] + qj[1]))
    return delta, ddot, fn, n, (fx, fz), point, fk, dmp


NFEV = [0, 0]   # rhs calls, dynamics evaluations (rhs + force-peak event root-finding)


def accelerations(y):
    """Second derivatives of (x1, z1, th1, e_u, e_w, theta)."""
    NFEV[1] += 1
    th1, th = y[2], y[5]
    w1, dth = y[8], y[11]
    th2, w2, r1, r2, pi, pj, c2 = kinematics(y)
    _, _, _, _, F, p, _, _ = contact(y)
    T = T0 - K_SPRING * math.degrees(th)     # spring torque, + on panel, - on satellite
    c1 = (y[0], y[1])
    if p is not None:
        tau2 = cross((p[0] - c2[0], p[1] - c2[1]), F)
        tau1 = -cross((p[0] - c1[0], p[1] - c1[1]), F)
    else:
        tau2 = tau1 = 0.0
    a1 = (-F[0] / M1, -F[1] / M1)
    al1 = (tau1 - T) / J1
    a2 = (F[0] / M2, F[1] / M2)
    al2 = (tau2 + T) / J2
    # accelerations of the bearing and journal centres: a_c + alpha k x r - w^2 r
    api = (a1[0] - al1 * r1[1] - w1 * w1 * r1[0], a1[1] + al1 * r1[0] - w1 * w1 * r1[1])
    apj = (a2[0] - al2 * r2[1] - w2 * w2 * r2[0], a2[1] + al2 * r2[0] - w2 * w2 * r2[1])
    return (a1[0], a1[1], al1, apj[0] - api[0], apj[1] - api[1], al2 - al1)


def rhs(t, y):
    NFEV[0] += 1
    a = accelerations(y)
    return [y[6], y[7], y[8], y[9], y[10], y[11], a[0], a[1], a[2], a[3], a[4], a[5]]


# ----------------------------------------------------------------------------- events
def ev_onset(t, y):
    return math.hypot(y[3], y[4]) - CLR


ev_onset.direction = 1.0


def ev_liftoff(t, y):
    return math.hypot(y[3], y[4]) - CLR


ev_liftoff.direction = -1.0


def ev_maxpen(t, y):
    """delta_dot (= d|e|/dt); a downward zero with delta > 0 is a local maximum penetration."""
    em = math.hypot(y[3], y[4])
    if em == 0.0:
        return 1.0
    return (y[3] * y[9] + y[4] * y[10]) / em


ev_maxpen.direction = -1.0


def fn_rate(y):
    """d/dt of the unclamped normal force F_K + D delta_dot, inside contact."""
    eu, ew, deu, dew = y[3], y[4], y[9], y[10]
    em = math.hypot(eu, ew)
    delta = em - CLR
    n = (eu / em, ew / em)
    ddot = deu * n[0] + dew * n[1]
    acc = accelerations(y)
    # delta_ddot = e_ddot . n + (|e_dot|^2 - delta_dot^2)/|e|
    dd2 = acc[3] * n[0] + acc[4] * n[1] + (deu * deu + dew * dew - ddot * ddot) / em
    dmp = step(delta, 0.0, 0.0, DELTA_MAX, D_MAX)
    ddmp = dstep(delta, 0.0, 0.0, DELTA_MAX, D_MAX)
    return k_tangent(delta) * ddot + ddmp * ddot * ddot + dmp * dd2


def ev_maxforce(t, y):
    if math.hypot(y[3], y[4]) - CLR <= 0.0:
        return 1.0
    return fn_rate(y)


ev_maxforce.direction = -1.0

EVENTS = [ev_onset, ev_liftoff, ev_maxpen, ev_maxforce]

ATOL = np.array([1e-9, 1e-9, 1e-9, 1e-10, 1e-10, 1e-9,
                 1e-8, 1e-8, 1e-8, 1e-8, 1e-8, 1e-8])
RTOL = 1e-4


def run(t_end, rtol=RTOL, atol=ATOL):
    y0 = np.zeros(12)
    NFEV[0] = NFEV[1] = 0
    c0 = time.process_time()
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="RK45", rtol=rtol, atol=atol, events=EVENTS)
    cpu = time.process_time() - c0
    return sol, cpu


def contacts_from(sol):
    """Group event records into contacts: list of dicts (onset, liftoff, peak F_N, max delta)."""
    on_t = sol.t_events[0]
    off_t = sol.t_events[1]
    pen_t, pen_y = sol.t_events[2], sol.y_events[2]
    frc_t, frc_y = sol.t_events[3], sol.y_events[3]
    out = []
    for k, t0 in enumerate(on_t):
        later = off_t[off_t > t0]
        t1 = later[0] if later.size else math.inf
        peak, depth, t_peak = 0.0, 0.0, None
        for t, y in zip(frc_t, frc_y):
            if t0 < t < t1:
                f = contact(y)[2]
                if f > peak:
                    peak, t_peak = f, t
        for t, y in zip(pen_t, pen_y):
            if t0 < t < t1:
                d = math.hypot(y[3], y[4]) - CLR
                depth = max(depth, d)
        out.append(dict(onset=t0, liftoff=t1, peak=peak, t_peak=t_peak, depth=depth))
    return out


def momentum(y):
    """Total linear and angular momentum (about the origin); both start at 0."""
    th2, w2, r1, r2, pi, pj, c2 = kinematics(y)
    w1 = y[8]
    v1 = (y[6], y[7])
    vpi = (v1[0] - w1 * r1[1], v1[1] + w1 * r1[0])
    vpj = (vpi[0] + y[9], vpi[1] + y[10])
    v2 = (vpj[0] + w2 * r2[1], vpj[1] - w2 * r2[0])
    p = (M1 * v1[0] + M2 * v2[0], M1 * v1[1] + M2 * v2[1])
    h = J1 * w1 + J2 * w2 + M1 * cross((y[0], y[1]), v1) + M2 * cross(c2, v2)
    return p, h


def main():
    wall0 = time.process_time()
    print("Solar-panel clearance-joint reference: scipy solve_ivp RK45, rtol = %g" % RTOL)
    print("  atol: e 1e-10 m, x1/z1 1e-9 m, angles 1e-9 rad, rates 1e-8 (m/s, rad/s)")
    print("  E* = %.5g Pa, (pi/2)E*L = %.5g N/m, K_N(delta_max) = %.5g N/m, D_max = %.5g N s/m"
          % (E_STAR, PREF, k_tangent(DELTA_MAX), D_MAX))
    sys.stdout.flush()

    sol, cpu = run(END_T)
    print("\nsolver status: %d (%s)" % (sol.status, sol.message))
    cs = contacts_from(sol)
    yend = sol.y[:, -1]
    th1, th = yend[2], yend[5]
    p, h = momentum(yend)
    first = cs[0] if cs else None
    print("RK45 accepted steps (sol.t.size - 1): %d" % (sol.t.size - 1))
    print("RHS evaluations: solve_ivp nfev = %d; dynamics evaluations incl. force-peak event root-finding = %d"
          % (sol.nfev, NFEV[1]))
    print("CPU time of solve_ivp (process_time): %.2f s" % cpu)
    if first:
        print("first impact onset: %.6f s" % first["onset"])
        print("first impact peak normal force: %.3f N (at t = %.6f s)" % (first["peak"], first["t_peak"]))
        print("first impact max penetration: %.4f um" % (first["depth"] * 1e6))
        print("first impact lift-off: %.6f s (duration %.3f ms)"
              % (first["liftoff"], (first["liftoff"] - first["onset"]) * 1e3))
    allpk = max(cs, key=lambda c: c["peak"]) if cs else None
    alldp = max(cs, key=lambda c: c["depth"]) if cs else None
    if cs:
        print("largest peak over 5 s: %.3f N at t = %.5f s; max penetration over 5 s: %.4f um at onset %.5f s"
              % (allpk["peak"], allpk["t_peak"], alldp["depth"] * 1e6, alldp["onset"]))
    print("contact onsets in 0..%g s: %d (lift-offs: %d)" % (END_T, len(sol.t_events[0]), len(sol.t_events[1])))
    in_contact = math.hypot(yend[3], yend[4]) > CLR
    print("in contact at t = %g s: %s" % (END_T, in_contact))
    print("final hinge (relative) angle: %.4f deg" % math.degrees(th))
    print("final panel angle: %.4f deg; satellite angle: %.4f deg" % (math.degrees(th1 + th), math.degrees(th1)))
    print("momentum check at t_end: |p| = %.3e kg m/s, h = %.3e kg m^2/s" % (math.hypot(*p), h))

    # onsets per second, to compare with the library's onset count in shape
    edges = np.arange(0.0, END_T + 1e-9, 1.0)
    hist, _ = np.histogram(sol.t_events[0], bins=edges)
    print("onsets per 1 s bin: %s" % list(hist))

    # tolerance check on the first impact only (cheap): does rtol = 1e-4 resolve it?
    print("\nfirst-impact tolerance check (integrating to 0.12 s only):")
    for rt, scale in ((1e-4, 1.0), (1e-6, 1e-2), (1e-8, 1e-4)):
        s2, c2 = run(0.12, rtol=rt, atol=ATOL * scale)
        cc = contacts_from(s2)
        print("  rtol %.0e atol x%.0e: onset %.6f s, peak %.3f N, max penetration %.4f um, steps %d"
              % (rt, scale, cc[0]["onset"], cc[0]["peak"], cc[0]["depth"] * 1e6, s2.t.size - 1))
    print("\nCPU time of the whole script (process_time): %.2f s" % (time.process_time() - wall0))


if __name__ == "__main__":
    main()
