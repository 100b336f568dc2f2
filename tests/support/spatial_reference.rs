//! Independent references for the spatial clearance joint, shared by `tests/spatial_exact.rs`
//! (included with `#[path]`). Written from the model's statement (below), never from the crate's
//! code: nothing here calls the crate, the vectors are plain `[f64; 3]`.
//!
//! # The model
//!
//! Bearing: a bore of radius `R_b` and width `L` about the axis `a_i` through the centre `P_i`;
//! its faces are the planes `(X - P_i) . a_i = +-L/2`. Journal: a cylinder of radius
//! `R_j = R_b - c` about the axis `a_j` through `P_j`; its shoulders are flat annuli (radii `R_j`
//! to `R_o`) square to `a_j` at `+-(L + a)/2` along `a_j` from `P_j`.
//!
//! **Bore.** In the bearing's plane at `s` (`(X - P_i) . a_i = s`, `|s| <= L/2`) the journal's
//! section is an ellipse. With `cos = a_i . a_j`, the journal's axis crosses the plane at
//! `C = P_j + t a_j`, `t = (P_i + s a_i - P_j) . a_i / cos`; the bore's axis at `O = P_i + s a_i`;
//! `E = C - O` is the eccentricity in the plane. With `p = (a_j - cos a_i)/|..|` (the tilt's
//! direction in the plane) and `q = a_i x p`, the section is
//! `C + (R_j/cos) cos(phi) p + R_j sin(phi) q` (its points are `R_j` from the journal's axis:
//! `|v|^2 - (v . a_j)^2 = alpha^2 cos^2 + beta^2`). The penetration is
//! `delta(s) = max_phi |E + v(phi)| - R_b`, found by Newton on `phi` from the direction of `E`
//! (the maximum is unique when `|E|` is large against the ellipse's excess `R_j (1/cos - 1)`,
//! else 64 samples first).
//!
//! The energy is `U = (1/L) int E(delta(s)) ds` (`E' = F`, the law's force for the whole width
//! at uniform penetration). Its gradient: move the journal rigidly by a virtual `dX`; its surface
//! at the deepest point `X*` moves by `w = dX . N` along the journal's outward normal `N`
//! (square to `a_j`). To stay in the plane `s` the point also slides along the surface by
//! `tau = -w (N . a_i)/(a_j . a_i) a_j` (plus any motion along the section's curve, which does not
//! change `rho` at its maximum), so `d delta = w k`,
//!
//! `k = r . N - (N . a_i)(r . a_j)/(a_i . a_j)`, `r` the bore's radial unit vector at `X*`.
//!
//! So the force on the journal per unit `s` is `-(F(delta)/L) k N` at `X*`, on the bearing the
//! opposite at the same point: exactly `-grad U` (checked by finite differences in
//! `self_checks`). For a journal tilted by `theta` in the plane of its eccentricity
//! `k = 1/cos(theta)`.
//!
//! **Faces.** A shoulder point `X = P_j + h a_j + w` (`w` square to `a_j`, `R_j <= |w| <= R_o`)
//! intrudes past its face by `delta = L/2 - sigma (X - P_i) . a_i` (`sigma = -1` lower shoulder
//! and face, `+1` upper; `h = sigma (L + a)/2`): linear in `w`, `delta = delta_c + g xi` with
//! `xi = w . e`, `e` the unit vector along `G = -sigma (a_i - (a_i . a_j) a_j)`, `g = |G|`.
//! The pressure `K delta / A` (`A = pi (R_o^2 - R_j^2)`) acts along `sigma a_i` on the
//! journal wherever `delta > 0`. All the forces are parallel, so the resultant is
//! `(K/A) I_1 sigma a_i` at `X_c + (I_xi / I_1) e`, with `I_m = int max(delta, 0) xi^m dA`
//! over the annulus: the disc of `R_o` less the disc of `R_j`, and for a disc of radius `R`
//! `int_{xi_lo}^{R} f(xi) 2 sqrt(R^2 - xi^2) dxi = int_0^{t_hi} f(R cos t) 2 R^2 sin^2 t dt`,
//! `xi_lo = max(-R, -delta_c/g)`, smooth in `t`, so Gauss-Legendre converges fast. The energy
//! is `(K/A) int max(delta, 0)^2/2 dA`.
//!
//! **Quadrature.** Along the width: `delta(s)` is sampled at 64 + 1 planes (it is convex in `s`,
//! `|E(s)|` being the norm of an affine function, so every stretch in contact touches an end of
//! the width and there are at most two sign changes), each sign change is refined to the last
//! bit, and each stretch in contact is integrated by 24 panels of
//! 10-point Gauss-Legendre (exact for the linear law, whose `delta(s)` is linear in a plane of
//! symmetry, and converged to rounding for the others: `int_0^x t^1.5` at 240 points is good to
//! 1e-9 relative even at the root, see `self_checks`).
//!
//! # The closed forms used to check the quadrature
//!
//! A journal whose axis stays in the bearing's `y-z` plane, the journal fixed along `z`, the
//! bearing tilted by `theta` about `x` (`a_i = (0, -sin, cos)`) and sunk by `e0` along `-y`
//! (`P_i = (0, -e0, u)`). In the plane `s` the journal's axis is `eps(s) = (e0 + s sin)/cos`
//! above the bore's (along `(0, cos, sin)`), the ellipse's half axis along it `R_j / cos`, so
//!
//! `delta(s) = |eps(s)| - c + R_j (1/cos - 1)`,
//!
//! piecewise linear in `s`; the deepest point is on the journal's top (`eps > 0`) or bottom
//! (`eps < 0`), `X* = (0, sgn R_j, (s + e0 sin + sgn R_j sin)/cos)`, `N = (0, sgn, 0)`, `k = 1/cos`.
//! The forces on the bearing are `sgn F(delta)/(L cos)` along `y` at `X*`. For the linear law
//! every integral is a polynomial's; [`hanging_pin_closed_form`] solves the two equations (the
//! vertical force and the moment about `x`) from them, independently of the general code.

#![allow(dead_code)]

use std::f64::consts::PI;

pub type V3 = [f64; 3];

pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
pub fn unit(a: V3) -> V3 {
    scale(a, 1.0 / norm(a))
}
/// `a` rotated by `angle` about the unit axis `k` (Rodrigues).
pub fn rotate(a: V3, k: V3, angle: f64) -> V3 {
    let (s, c) = angle.sin_cos();
    add(
        add(scale(a, c), scale(cross(k, a), s)),
        scale(k, dot(k, a) * (1.0 - c)),
    )
}
/// A unit vector square to the unit `a`.
pub fn perpendicular(a: V3) -> V3 {
    let t = if a[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    unit(sub(t, scale(a, dot(a, t))))
}

/// The `n`-point Gauss-Legendre rule on [-1, 1]: (node, weight).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    if n == POINTS {
        static RULE: std::sync::OnceLock<Vec<(f64, f64)>> = std::sync::OnceLock::new();
        return RULE.get_or_init(|| legendre_rule(n)).clone();
    }
    legendre_rule(n)
}

fn legendre_rule(n: usize) -> Vec<(f64, f64)> {
    assert!(n >= 2);
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let k = k as f64;
            let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
            p0 = p1;
            p1 = p2;
        }
        // P_n and its derivative.
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `int_a^b` by `panels` panels of the rule `rule`: calls `f(x, w)` at each point `x` with its
/// weight `w`.
pub fn integrate(rule: &[(f64, f64)], panels: usize, a: f64, b: f64, mut f: impl FnMut(f64, f64)) {
    let h = (b - a) / panels as f64;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for &(x, w) in rule {
            f(mid + 0.5 * h * x, w * 0.5 * h);
        }
    }
}

/// A root of `f` between `a` and `b` (`f(a)`, `f(b)` of opposite signs or one zero) by the
/// Illinois variant of regula falsi, to `xtol`.
pub fn root(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64, xtol: f64) -> f64 {
    let (mut fa, mut fb) = (f(a), f(b));
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    assert!(
        fa.signum() != fb.signum(),
        "no sign change: f({a}) = {fa}, f({b}) = {fb}"
    );
    let mut side = 0;
    for _ in 0..400 {
        let mut x = (a * fb - b * fa) / (fb - fa);
        if !(x > a.min(b) && x < a.max(b)) {
            x = 0.5 * (a + b);
        }
        let fx = f(x);
        if fx == 0.0 {
            return x;
        }
        if fx.signum() == fb.signum() {
            b = x;
            fb = fx;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = x;
            fa = fx;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if (b - a).abs() <= xtol.max(4.0 * f64::EPSILON * a.abs().max(b.abs())) {
            break;
        }
    }
    if fa.abs() < fb.abs() { a } else { b }
}

/// Newton's method on `f(x) = 0` in three unknowns with a central-difference Jacobian (steps
/// 1e-7 of `scales`), until the step is below 1e-14 of `scales`.
pub fn newton(f: impl Fn([f64; 3]) -> [f64; 3], mut x: [f64; 3], scales: [f64; 3]) -> [f64; 3] {
    for _ in 0..20 {
        let r = f(x);
        let mut j = [[0.0; 3]; 3];
        for k in 0..3 {
            let hk = 1e-7 * scales[k];
            let (mut xp, mut xm) = (x, x);
            xp[k] += hk;
            xm[k] -= hk;
            let (fp, fm) = (f(xp), f(xm));
            for i in 0..3 {
                j[i][k] = (fp[i] - fm[i]) / (2.0 * hk);
            }
        }
        let dx = solve3(j, r);
        let mut small = true;
        for k in 0..3 {
            x[k] -= dx[k];
            small &= dx[k].abs() < 1e-14 * scales[k];
        }
        if small {
            break;
        }
    }
    x
}

/// `A^-1 b` by Cramer's rule.
pub fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let mut out = [0.0; 3];
    for k in 0..3 {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        out[k] = det(m) / d;
    }
    out
}

/// Extends `hi` away from `lo` (doubling the distance) until `f(hi)` has the sign `sign`.
pub fn expand(mut f: impl FnMut(f64) -> f64, lo: f64, mut hi: f64, sign: f64) -> f64 {
    for _ in 0..200 {
        if f(hi).signum() == sign {
            return hi;
        }
        hi = lo + 2.0 * (hi - lo);
    }
    panic!("no bracket from {lo} towards {hi}");
}

/// A power law `F = K delta^n` (n = 1: the linear law; its energy `K delta^(n+1)/(n+1)`).
#[derive(Clone, Copy, Debug)]
pub struct PowerLaw {
    pub stiffness: f64,
    pub exponent: f64,
}

impl PowerLaw {
    pub fn force(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            0.0
        } else {
            self.stiffness * delta.powf(self.exponent)
        }
    }
    pub fn energy(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            0.0
        } else {
            self.stiffness * delta.powf(self.exponent + 1.0) / (self.exponent + 1.0)
        }
    }
}

/// The hinge's geometry and its laws.
#[derive(Clone, Copy, Debug)]
pub struct Hinge {
    /// Bore radius `R_b`, radial clearance `c`, width `L`, m.
    pub bore_radius: f64,
    pub clearance: f64,
    pub width: f64,
    /// Axial play `a` and shoulder radius `R_o`, m.
    pub play: f64,
    pub collar: f64,
    /// The bore's law (for the whole width at uniform penetration).
    pub bore: PowerLaw,
    /// The face law's stiffness for the whole annulus, N/m.
    pub face_stiffness: f64,
}

impl Hinge {
    pub fn journal_radius(&self) -> f64 {
        self.bore_radius - self.clearance
    }
    pub fn annulus_area(&self) -> f64 {
        let rj = self.journal_radius();
        PI * (self.collar * self.collar - rj * rj)
    }
}

/// Where the bore and the journal are (world).
#[derive(Clone, Copy, Debug)]
pub struct Pose {
    pub bearing_center: V3,
    pub bearing_axis: V3,
    pub journal_center: V3,
    pub journal_axis: V3,
}

/// The journal's section by the bearing's plane at `s`.
#[derive(Clone, Copy, Debug)]
pub struct Section {
    /// Penetration `delta(s)`, m.
    pub depth: f64,
    /// The deepest point `X*` (world).
    pub point: V3,
    /// The journal's outward normal `N` there.
    pub normal: V3,
    /// `k = d delta / d w`.
    pub gain: f64,
}

pub fn section(h: &Hinge, p: &Pose, s: f64) -> Section {
    let (ai, aj) = (p.bearing_axis, p.journal_axis);
    let cos = dot(ai, aj);
    assert!(cos > 0.5, "the journal is crosswise: a_i . a_j = {cos}");
    let o = add(p.bearing_center, scale(ai, s));
    let t = dot(sub(o, p.journal_center), ai) / cos;
    let c = add(p.journal_center, scale(aj, t));
    let e = sub(c, o);
    let rj = h.journal_radius();
    let pv = sub(aj, scale(ai, cos));
    let sin = norm(pv);
    let (ph, qh) = if sin > 1e-300 {
        let ph = scale(pv, 1.0 / sin);
        (ph, cross(ai, ph))
    } else {
        let ph = perpendicular(ai);
        (ph, cross(ai, ph))
    };
    let b = rj / cos;
    let (ep, eq) = (dot(e, ph), dot(e, qh));
    // f(phi) = (ep + b cos)^2 + (eq + rj sin)^2 and its derivatives.
    let df = |phi: f64| {
        let (sn, cs) = phi.sin_cos();
        let d1 = -2.0 * ep * b * sn + 2.0 * eq * rj * cs + 2.0 * (rj * rj - b * b) * sn * cs;
        let d2 =
            -2.0 * ep * b * cs - 2.0 * eq * rj * sn + 2.0 * (rj * rj - b * b) * (2.0 * phi).cos();
        (d1, d2)
    };
    let f = |phi: f64| {
        let (sn, cs) = phi.sin_cos();
        (ep + b * cs).powi(2) + (eq + rj * sn).powi(2)
    };
    let excess = b - rj;
    let mut phi = if ep.hypot(eq) > 4.0 * excess && ep.hypot(eq) > 0.0 {
        (eq * b).atan2(ep * rj)
    } else {
        (0..64)
            .map(|i| i as f64 * PI / 32.0)
            .fold((0.0, f64::MIN), |(bp, bf), x| {
                let v = f(x);
                if v > bf { (x, v) } else { (bp, bf) }
            })
            .0
    };
    for _ in 0..50 {
        let (d1, d2) = df(phi);
        if d2 >= 0.0 || d1 == 0.0 {
            break;
        }
        let step = d1 / d2;
        phi -= step;
        if step.abs() < 1e-16 {
            break;
        }
    }
    let (sn, cs) = phi.sin_cos();
    let v = add(scale(ph, b * cs), scale(qh, rj * sn));
    let point = add(c, v);
    let r = add(e, v);
    let rho = norm(r);
    let rhat = scale(r, 1.0 / rho);
    let normal = unit(sub(v, scale(aj, dot(v, aj))));
    let gain = dot(rhat, normal) - dot(normal, ai) * dot(rhat, aj) / cos;
    Section {
        depth: rho - h.bore_radius,
        point,
        normal,
        gain,
    }
}

/// A stretch of the width in contact, or a part of one.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stretch {
    pub from: f64,
    pub to: f64,
    /// Force on the journal, N, and its moment about the world origin, N m.
    pub force: V3,
    pub moment: V3,
    /// `int |f| ds` and `int |f| X* ds`: the resultant's size when the forces are parallel and
    /// its point.
    pub magnitude: f64,
    pub weighted_point: V3,
    /// Elastic energy, J.
    pub energy: f64,
}

impl Stretch {
    pub fn point(&self) -> V3 {
        scale(self.weighted_point, 1.0 / self.magnitude)
    }
    fn plus(mut self, o: &Stretch) -> Stretch {
        self.force = add(self.force, o.force);
        self.moment = add(self.moment, o.moment);
        self.magnitude += o.magnitude;
        self.weighted_point = add(self.weighted_point, o.weighted_point);
        self.energy += o.energy;
        self.from = self.from.min(o.from);
        self.to = self.to.max(o.to);
        self
    }
}

/// What one end of the bore carries.
#[derive(Clone, Copy, Debug, Default)]
pub struct Edge {
    /// `|resultant|`, N (0 if no region touches that end).
    pub force: f64,
    /// Its point (the centre of its forces), world; `None` if it carries nothing.
    pub point: Option<V3>,
    /// Length of its region along the width, m.
    pub length: f64,
}

/// The bore's whole contact.
#[derive(Clone, Debug, Default)]
pub struct Bore {
    pub force: V3,
    pub moment: V3,
    pub energy: f64,
    /// Largest `delta(s)` over the width (negative: a gap).
    pub deepest: f64,
    pub stretches: Vec<Stretch>,
    /// The two ends' regions (lower `-L/2`, upper `+L/2`), when asked for.
    pub edges: [Edge; 2],
    /// True when the whole width touches with the same penetration (to 1e-9 of it): the split
    /// between the ends is then a matter of convention.
    pub uniform: bool,
}

/// Planes sampled along the width to find where the contact starts and ends.
pub const WIDTH_SAMPLES: usize = 64;
/// Panels and points of Gauss-Legendre per stretch.
pub const PANELS: usize = 24;
pub const POINTS: usize = 10;

fn stretch(h: &Hinge, p: &Pose, rule: &[(f64, f64)], from: f64, to: f64) -> Stretch {
    let mut out = Stretch {
        from,
        to,
        ..Default::default()
    };
    if to <= from {
        return out;
    }
    integrate(rule, PANELS, from, to, |s, w| {
        let sec = section(h, p, s);
        let load = h.bore.force(sec.depth) / h.width;
        let f = scale(sec.normal, -load * sec.gain * w);
        out.force = add(out.force, f);
        out.moment = add(out.moment, cross(sec.point, f));
        let m = norm(f);
        out.magnitude += m;
        out.weighted_point = add(out.weighted_point, scale(sec.point, m));
        out.energy += h.bore.energy(sec.depth) / h.width * w;
    });
    out
}

/// The bore's contact integrals; with `edges`, also the two ends' regions (split at the plane
/// of least penetration when the whole width touches).
pub fn bore(h: &Hinge, p: &Pose, edges: bool) -> Bore {
    let rule = gauss_legendre(POINTS);
    let half = 0.5 * h.width;
    let depth = |s: f64| section(h, p, s).depth;
    let n = WIDTH_SAMPLES;
    let samples: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let s = -half + h.width * i as f64 / n as f64;
            (s, depth(s))
        })
        .collect();
    let deepest = samples.iter().map(|x| x.1).fold(f64::MIN, f64::max);
    // Ends of the stretches in contact.
    let mut cuts = vec![-half];
    for w in samples.windows(2) {
        let ((s0, d0), (s1, d1)) = (w[0], w[1]);
        if (d0 > 0.0) != (d1 > 0.0) && d0 != 0.0 && d1 != 0.0 {
            cuts.push(root(depth, s0, s1, 0.0));
        }
    }
    cuts.push(half);
    let mut out = Bore {
        deepest,
        ..Default::default()
    };
    for c in cuts.windows(2) {
        let (a, b) = (c[0], c[1]);
        if b > a && depth(0.5 * (a + b)) > 0.0 {
            out.stretches.push(stretch(h, p, &rule, a, b));
        }
    }
    for st in &out.stretches {
        out.force = add(out.force, st.force);
        out.moment = add(out.moment, st.moment);
        out.energy += st.energy;
    }
    // The deepest point may lie between samples (a region shorter than a sample spacing at an
    // end): the ends are sampled, and in a plane of symmetry delta(s) is piecewise linear.
    if !edges {
        return out;
    }
    let whole =
        out.stretches.len() == 1 && out.stretches[0].from == -half && out.stretches[0].to == half;
    let edge = |st: &Stretch| Edge {
        force: norm(st.force),
        point: Some(st.point()),
        length: st.to - st.from,
    };
    if whole {
        // delta(s) is |affine| less a near constant: convex, so golden section finds its least.
        let (mut a, mut b) = (-half, half);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            let (x1, x2) = (b - g * (b - a), a + g * (b - a));
            if depth(x1) < depth(x2) {
                b = x2;
            } else {
                a = x1;
            }
        }
        let split = 0.5 * (a + b);
        let (lo, hi) = (depth(-half), depth(half));
        out.uniform = (lo - hi).abs() <= 1e-9 * lo.abs().max(hi.abs());
        let split = if (split + half).abs() < 1e-12 * h.width {
            -half
        } else if (split - half).abs() < 1e-12 * h.width {
            half
        } else {
            split
        };
        let lower = stretch(h, p, &rule, -half, split);
        let upper = stretch(h, p, &rule, split, half);
        out.edges = [
            if lower.magnitude > 0.0 {
                edge(&lower)
            } else {
                Edge::default()
            },
            if upper.magnitude > 0.0 {
                edge(&upper)
            } else {
                Edge::default()
            },
        ];
    } else {
        for st in &out.stretches {
            if st.from == -half {
                out.edges[0] = edge(st);
            }
            if st.to == half {
                out.edges[1] = edge(st);
            }
        }
    }
    out
}

/// A shoulder against its face.
#[derive(Clone, Copy, Debug, Default)]
pub struct Face {
    /// Force on the journal, N, and its moment about the world origin.
    pub force: V3,
    pub moment: V3,
    /// `|force|`, N, and its point (world; the shoulder's centre when nothing touches).
    pub magnitude: f64,
    pub point: V3,
    pub energy: f64,
    /// The deepest intrusion (at the rim), m; negative: a gap.
    pub deepest: f64,
}

/// `int over the disc of radius r of max(dc + g xi, 0)^m xi^k dA`.
pub fn disc_integral(dc: f64, g: f64, r: f64, m: i32, k: i32) -> f64 {
    let lo = if g > 0.0 {
        (-dc / g).max(-r)
    } else if dc > 0.0 {
        -r
    } else {
        r
    };
    if lo >= r {
        return 0.0;
    }
    let t_hi = (lo / r).clamp(-1.0, 1.0).acos();
    let rule = gauss_legendre(POINTS);
    let mut sum = 0.0;
    integrate(&rule, PANELS, 0.0, t_hi, |t, w| {
        let (sn, cs) = t.sin_cos();
        let xi = r * cs;
        let d = (dc + g * xi).max(0.0);
        sum += w * d.powi(m) * xi.powi(k) * 2.0 * r * r * sn * sn;
    });
    sum
}

pub fn faces(h: &Hinge, p: &Pose) -> [Face; 2] {
    let (ai, aj) = (p.bearing_axis, p.journal_axis);
    let rj = h.journal_radius();
    let k_over_a = h.face_stiffness / h.annulus_area();
    [-1.0, 1.0].map(|sigma: f64| {
        let center = add(
            p.journal_center,
            scale(aj, sigma * 0.5 * (h.width + h.play)),
        );
        let dc = 0.5 * h.width - sigma * dot(sub(center, p.bearing_center), ai);
        let gv = scale(sub(ai, scale(aj, dot(ai, aj))), -sigma);
        let g = norm(gv);
        let e = if g > 0.0 {
            scale(gv, 1.0 / g)
        } else {
            perpendicular(aj)
        };
        let annulus = |m, k| disc_integral(dc, g, h.collar, m, k) - disc_integral(dc, g, rj, m, k);
        let i1 = annulus(1, 0);
        let mut face = Face {
            deepest: dc + g * h.collar,
            point: center,
            ..Default::default()
        };
        if i1 > 0.0 {
            let ixi = annulus(1, 1);
            face.magnitude = k_over_a * i1;
            face.force = scale(ai, sigma * face.magnitude);
            face.point = add(center, scale(e, ixi / i1));
            face.moment = cross(face.point, face.force);
            face.energy = 0.5 * k_over_a * annulus(2, 0);
        }
        face
    })
}

/// Everything the joint does at a pose: the bore, the two faces, their sum on the journal.
#[derive(Clone, Debug)]
pub struct Contact {
    pub bore: Bore,
    pub faces: [Face; 2],
    pub force: V3,
    pub moment: V3,
    pub energy: f64,
    pub deepest: f64,
}

pub fn contact(h: &Hinge, p: &Pose, edges: bool) -> Contact {
    let bore = bore(h, p, edges);
    let faces = faces(h, p);
    let force = add(bore.force, add(faces[0].force, faces[1].force));
    let moment = add(bore.moment, add(faces[0].moment, faces[1].moment));
    let energy = bore.energy + faces[0].energy + faces[1].energy;
    let deepest = bore.deepest.max(faces[0].deepest).max(faces[1].deepest);
    Contact {
        bore,
        faces,
        force,
        moment,
        energy,
        deepest,
    }
}

/// The static equilibrium of a body hung on a fixed horizontal pin (journal fixed along `z`
/// through the origin), the body carrying the bearing, its weight `weight` (N, along `-y`)
/// acting on the bearing's axis `d` (m) from the bearing's mid-plane. By symmetry the bearing
/// only sinks (`e0`, along `-y`) and tilts (`theta`, about `x`):
/// `P_i = (0, -e0, 0)`, `a_i = (0, -sin theta, cos theta)`; its axial place does not matter (no
/// force along `z` acts: the journal's normals are square to `z`). Solved nested: `e0` for the
/// vertical force at each `theta`, `theta` for the moment about `x`, both by Illinois to the
/// last bits.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    pub e0: f64,
    pub tilt: f64,
    pub pose: Pose,
    pub contact: Contact,
    /// Residual force and moment on the body (contact + weight), N and N m.
    pub residual_force: V3,
    pub residual_moment: V3,
}

pub fn hanging_pin_pose(e0: f64, tilt: f64) -> Pose {
    Pose {
        bearing_center: [0.0, -e0, 0.0],
        bearing_axis: [0.0, -tilt.sin(), tilt.cos()],
        journal_center: [0.0; 3],
        journal_axis: [0.0, 0.0, 1.0],
    }
}

pub fn hanging_pin(h: &Hinge, weight: f64, d: f64) -> Equilibrium {
    // On the bearing: minus the contact's force and moment on the journal, plus the weight.
    let load = |e0: f64, tilt: f64| {
        let p = hanging_pin_pose(e0, tilt);
        let c = contact(h, &p, false);
        let com = add(p.bearing_center, scale(p.bearing_axis, d));
        let w = [0.0, -weight, 0.0];
        (
            add(scale(c.force, -1.0), w),
            add(scale(c.moment, -1.0), cross(com, w)),
        )
    };
    let sink = |tilt: f64| {
        let fy = |e0: f64| load(e0, tilt).0[1];
        let hi = expand(fy, 0.0, h.clearance * 1.01, 1.0);
        root(fy, 0.0, hi, 1e-22)
    };
    let mx = |tilt: f64| load(sink(tilt), tilt).1[0];
    let tilt = if d == 0.0 {
        0.0
    } else {
        let free = 2.0 * h.clearance / h.width;
        let hi = expand(mx, 0.0, free * d.signum(), -d.signum());
        root(mx, 0.0, hi, 1e-20)
    };
    let e0 = sink(tilt);
    let pose = hanging_pin_pose(e0, tilt);
    let (residual_force, residual_moment) = load(e0, tilt);
    Equilibrium {
        e0,
        tilt,
        pose,
        contact: contact(h, &pose, true),
        residual_force,
        residual_moment,
    }
}

/// The same equilibrium from the closed forms of the linear law in the plane of symmetry
/// (module docs), by a 2-D Newton: independent of [`section`], [`bore`] and their quadrature.
/// Returns `(e0, theta, [F_lower, F_upper], [z_lower, z_upper], deepest)`: the ends' resultants
/// and the axial coordinates of their points (the whole width touching: all of it on the
/// deeper end, the least penetration being at the other end).
pub fn hanging_pin_closed_form(
    h: &Hinge,
    weight: f64,
    d: f64,
) -> (f64, f64, [f64; 2], [f64; 2], f64) {
    assert_eq!(h.bore.exponent, 1.0);
    let (rj, c, l) = (h.journal_radius(), h.clearance, h.width);
    let kl = h.bore.stiffness / l;
    // Stretches where sgn eps = sigma and delta > 0 on [-L/2, L/2], with delta = sigma eps - c',
    // eps = eps0 + s tan: each is [s0, s1] with delta linear; integrals exact.
    struct Piece {
        sigma: f64,
        s0: f64,
        s1: f64,
    }
    let pieces = |e0: f64, th: f64| -> (Vec<Piece>, f64, f64, f64) {
        let (sn, cs) = th.sin_cos();
        let tn = sn / cs;
        let eps0 = e0 / cs;
        let cp = c - rj * (1.0 / cs - 1.0);
        let mut out = Vec::new();
        for sigma in [1.0, -1.0] {
            // sigma (eps0 + s tn) - cp > 0.
            let (a, b) = (sigma * eps0 - cp, sigma * tn);
            let (mut s0, mut s1) = (-0.5 * l, 0.5 * l);
            if b == 0.0 {
                if a <= 0.0 {
                    continue;
                }
            } else if b > 0.0 {
                s0 = s0.max(-a / b);
            } else {
                s1 = s1.min(-a / b);
            }
            if s1 > s0 {
                out.push(Piece { sigma, s0, s1 });
            }
        }
        (out, eps0, cp, tn)
    };
    // Vertical force and moment about x on the bearing (contact + weight) and the ends.
    let eval = |e0: f64, th: f64| {
        let (sn, cs) = th.sin_cos();
        let (ps, eps0, cp, tn) = pieces(e0, th);
        let (mut fy, mut mx) = (-weight, 0.0);
        // Weight at (0, -e0 - d sn, d cs): moment x = -z F_y = d cs weight.
        mx += d * cs * weight;
        let mut ends = [(0.0, 0.0); 2];
        for pc in &ps {
            // delta(s) = a + b s; G = kl delta; force on bearing sigma G / cs at
            // z = (s + e0 sn + sigma rj sn)/cs.
            let (a, b) = (pc.sigma * eps0 - cp, pc.sigma * tn);
            let m0 = |s: f64| a * s + 0.5 * b * s * s;
            let m1 = |s: f64| 0.5 * a * s * s + b * s * s * s / 3.0;
            let i0 = kl * (m0(pc.s1) - m0(pc.s0));
            let i1 = kl * (m1(pc.s1) - m1(pc.s0));
            let f = i0 / cs;
            let zf = (i1 + (e0 * sn + pc.sigma * rj * sn) * i0) / (cs * cs);
            fy += pc.sigma * f;
            mx -= pc.sigma * zf;
            let end = if pc.s0 == -0.5 * l && pc.s1 == 0.5 * l {
                // Whole width: the least penetration is at the end where delta is smaller.
                if b > 0.0 { 1 } else { 0 }
            } else if pc.s0 == -0.5 * l {
                0
            } else {
                1
            };
            ends[end] = (f, zf / f);
        }
        (fy, mx, ends, cp, eps0, tn)
    };
    let (mut e0, mut th) = (c + weight / h.bore.stiffness, 0.0);
    if d != 0.0 {
        th = d.signum() * 2.0 * c / l;
    }
    for _ in 0..100 {
        let (fy, mx, ..) = eval(e0, th);
        let (de, dt) = (1e-12, 1e-10);
        let (fy1, mx1, ..) = eval(e0 + de, th);
        let (fy2, mx2, ..) = eval(e0, th + dt);
        let j = [
            [(fy1 - fy) / de, (fy2 - fy) / dt],
            [(mx1 - mx) / de, (mx2 - mx) / dt],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let (mut x, mut y) = (
            (fy * j[1][1] - mx * j[0][1]) / det,
            (j[0][0] * mx - j[1][0] * fy) / det,
        );
        if d == 0.0 {
            x = fy / j[0][0];
            y = 0.0;
        }
        // Damped: never more than half the clearance at once.
        let lim = 0.25 * c;
        let sc = (lim / x.abs().max(lim)).min(lim / l / y.abs().max(lim / l));
        e0 -= x * sc;
        th -= y * sc;
        if x.abs() < 1e-20 && y.abs() < 1e-18 {
            break;
        }
    }
    let (_, _, ends, cp, eps0, tn) = eval(e0, th);
    let deepest = (eps0 - 0.5 * l * tn).abs().max((eps0 + 0.5 * l * tn).abs()) - cp;
    (
        e0,
        th,
        [ends[0].0, ends[1].0],
        [ends[0].1, ends[1].1],
        deepest,
    )
}

/// The rigid Winkler beam, the textbook's small-tilt limit of [`hanging_pin_closed_form`]
/// (no ellipse, the contact on the bearing's axis): the ends' forces for a load `W` at `d`,
/// linear foundation `k = K/L`, clearance `c`, width `L`.
/// - `|d| <= L/6`: the whole width, `q(s) = (W/L)(1 + 12 d s/L^2)`: one region, all of it at the
///   deeper end.
/// - `L/6 < |d|` and the far end clear: a triangle of length `l = 3 (L/2 - |d|)` (its resultant
///   a third of it from the end).
/// - otherwise both ends, on opposite sides: triangles `l1`, `l2` with the same slope `tau`,
///   `F_i = k tau l_i^2 / 2`, `F_2 - F_1 = W`, `F_2 (L/2 - l_2/3) + F_1 (L/2 - l_1/3) = W d`,
///   `tau (L - l_1 - l_2) = 2 c` (the gap between them is where `|eps| < c`).
///
/// Returns `([F_lower, F_upper], tilt)` for `d >= 0`.
pub fn rigid_winkler(k: f64, weight: f64, d: f64, c: f64, l: f64) -> ([f64; 2], f64) {
    assert!(d >= 0.0);
    if d <= l / 6.0 {
        let tau = 12.0 * d * weight / (k * l * l * l);
        return ([0.0, weight], tau);
    }
    // One triangle: q_max = 2 W / len, tau = q_max / (k len).
    let len = 3.0 * (0.5 * l - d);
    if len > 0.0 {
        let tau = 2.0 * weight / (k * len * len);
        // The far end is clear while the eccentricity there stays above -c: the triangle's
        // foot at depth 0 is c above it... the penetration at the far end is
        // -(L - len) tau; clear if (L - len) tau < 2 c.
        if (l - len) * tau < 2.0 * c {
            return ([0.0, weight], tau);
        }
    }
    // Both ends: unknowns l1, l2 (tau from the gap).
    let resid = |l1: f64, l2: f64| {
        let tau = 2.0 * c / (l - l1 - l2);
        let (f1, f2) = (0.5 * k * tau * l1 * l1, 0.5 * k * tau * l2 * l2);
        (
            f2 - f1 - weight,
            f2 * (0.5 * l - l2 / 3.0) + f1 * (0.5 * l - l1 / 3.0) - weight * d,
        )
    };
    let (mut l1, mut l2) = (0.05 * l, 0.1 * l);
    for _ in 0..200 {
        let (r1, r2) = resid(l1, l2);
        let h = 1e-12 * l;
        let (a1, a2) = resid(l1 + h, l2);
        let (b1, b2) = resid(l1, l2 + h);
        let j = [
            [(a1 - r1) / h, (b1 - r1) / h],
            [(a2 - r2) / h, (b2 - r2) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let dx = (r1 * j[1][1] - r2 * j[0][1]) / det;
        let dy = (j[0][0] * r2 - j[1][0] * r1) / det;
        let sc = (0.02 * l / dx.abs().max(0.02 * l)).min(0.02 * l / dy.abs().max(0.02 * l));
        l1 = (l1 - dx * sc).max(1e-9 * l);
        l2 = (l2 - dy * sc).max(1e-9 * l);
        if dx.abs() < 1e-18 && dy.abs() < 1e-18 {
            break;
        }
    }
    let tau = 2.0 * c / (l - l1 - l2);
    ([0.5 * k * tau * l1 * l1, 0.5 * k * tau * l2 * l2], tau)
}

/// The door: a body carrying the journal (axis `a_j`, the body's own `y`) on a fixed vertical
/// bearing (`a_i = y` through the origin), its weight `weight` (N, along `-y`) acting `arm` m
/// off the journal's axis along the body's `x`. In the `x-y` plane: the journal shifts by `e0`
/// (along `x`) and `u` (along `y`) and tilts by `theta` about `z`:
/// `P_j = (e0, u, 0)`, `a_j = (-sin theta, cos theta, 0)`, centre of mass
/// `P_j + arm (cos theta, sin theta, 0)`. Solved nested (`u` for the vertical force, `e0` for the
/// horizontal, `theta` for the moment about `z`).
pub fn door_pose(e0: f64, u: f64, tilt: f64) -> Pose {
    Pose {
        bearing_center: [0.0; 3],
        bearing_axis: [0.0, 1.0, 0.0],
        journal_center: [e0, u, 0.0],
        journal_axis: [-tilt.sin(), tilt.cos(), 0.0],
    }
}

#[derive(Clone, Debug)]
pub struct DoorEquilibrium {
    pub e0: f64,
    pub u: f64,
    pub tilt: f64,
    pub pose: Pose,
    pub contact: Contact,
    pub residual_force: V3,
    pub residual_moment: V3,
}

pub fn door(h: &Hinge, weight: f64, arm: f64) -> DoorEquilibrium {
    let load = |e0: f64, u: f64, tilt: f64| {
        let p = door_pose(e0, u, tilt);
        let c = contact(h, &p, false);
        let com = add(p.journal_center, scale([tilt.cos(), tilt.sin(), 0.0], arm));
        let w = [0.0, -weight, 0.0];
        (add(c.force, w), add(c.moment, cross(com, w)))
    };
    let lift = |e0: f64, tilt: f64| {
        // Lower u: the upper shoulder sinks into the upper face, the vertical force grows. (Far
        // from the equilibrium the bore's tilted normals alone may hold the weight: then no
        // face contact, u = 0.)
        let fy = |u: f64| load(e0, u, tilt).0[1];
        let top = 0.0;
        if fy(top) >= 0.0 {
            return top;
        }
        let lo = expand(fy, top, -0.5 * h.play, 1.0);
        root(fy, lo, top, 1e-13)
    };
    let shift = |tilt: f64| {
        let fx = |e0: f64| load(e0, lift(e0, tilt), tilt).0[0];
        let lo = expand(fx, 0.0, -0.1 * h.clearance, 1.0);
        let hi = expand(fx, 0.0, 0.1 * h.clearance, -1.0);
        root(fx, lo, hi, 1e-12)
    };
    let mz = |tilt: f64| {
        let e0 = shift(tilt);
        load(e0, lift(e0, tilt), tilt).1[2]
    };
    // Nested to about 1e-7 (of the tilt, and the e0 and u a few 1e-8 of theirs), then Newton on all three (the residual is smooth near
    // the equilibrium: the regions keep their ends).
    let free = 2.0 * h.clearance / h.width;
    let lo = expand(mz, 0.0, -free, 1.0);
    let tilt = root(mz, lo, 0.0, 1e-7 * free);
    let e0 = shift(tilt);
    let u = lift(e0, tilt);
    let scales = [h.clearance, h.clearance, free];
    let [e0, u, tilt] = newton(
        |x: [f64; 3]| {
            let (f, m) = load(x[0], x[1], x[2]);
            [f[0], f[1], m[2] / h.width]
        },
        [e0, u, tilt],
        scales,
    );
    let pose = door_pose(e0, u, tilt);
    let (residual_force, residual_moment) = load(e0, u, tilt);
    DoorEquilibrium {
        e0,
        u,
        tilt,
        pose,
        contact: contact(h, &pose, true),
        residual_force,
        residual_moment,
    }
}

/// The rim strike's pose: the bearing fixed along `z` at the origin, the journal at `(0, 0, z)`
/// tilted by `th` about `x`.
pub fn rim_pose(z: f64, th: f64) -> Pose {
    Pose {
        bearing_center: [0.0; 3],
        bearing_axis: [0.0, 0.0, 1.0],
        journal_center: [0.0, 0.0, z],
        journal_axis: [0.0, -th.sin(), th.cos()],
    }
}

/// Where the rim strike starts: the journal's `z` at which the upper shoulder's rim is 1 um off
/// the upper face.
pub fn rim_start(h: &Hinge, tilt: f64) -> f64 {
    let rim_gap = |z: f64| faces(h, &rim_pose(z, tilt))[1].deepest + 1e-6;
    root(
        rim_gap,
        -(0.5 * h.play + h.collar * tilt.abs() + 1e-5),
        0.0,
        1e-18,
    )
}

/// The rim strike: a free journal (mass `mass`, spherical inertia `inertia`, its centre of mass
/// at `P_j`) tilted by `tilt` about `x`, moving along the fixed bearing's axis `z` at `speed`
/// towards `-z`, its upper shoulder (outside the bearing at `+z`) onto the upper face, no bore contact (checked), the face law elastic. The face force is
/// along `z` at the sliver's centre, so the centre of mass moves along `z` only and the journal
/// turns about `x` only: two degrees of freedom `(z, theta)`,
/// `m z'' = F_z`, `I theta'' = M_x` (about the centre of mass), integrated by the classical
/// Runge-Kutta with `dt` (s) until the shoulder leaves the face. Returns the peak face force
/// (sampled every step, refined by a parabola through the three samples about the peak), the
/// time of the peak and of separation, and the journal's velocity after it (free flight: its
/// axial speed along `z`, m/s, and its spin about `x`, rad/s).
pub fn rim_strike(
    h: &Hinge,
    mass: f64,
    inertia: f64,
    tilt: f64,
    speed: f64,
    dt: f64,
) -> (f64, f64, f64, [f64; 2]) {
    let pose = rim_pose;
    let accel = |y: [f64; 4]| {
        let p = pose(y[0], y[1]);
        let fs = faces(h, &p);
        let f = fs[1];
        let m = cross(sub(f.point, p.journal_center), f.force);
        ([y[2], y[3], f.force[2] / mass, m[0] / inertia], f.magnitude)
    };
    let z0 = rim_start(h, tilt);
    let mut y = [z0, tilt, -speed, 0.0];
    let mut t = 0.0;
    let mut hist: Vec<(f64, f64)> = Vec::new();
    let mut touched = false;
    loop {
        let (k1, f) = accel(y);
        hist.push((t, f));
        if f > 0.0 {
            touched = true;
        } else if touched {
            break;
        }
        let ys = |k: [f64; 4], s: f64| {
            let mut o = y;
            for i in 0..4 {
                o[i] += s * k[i];
            }
            o
        };
        let (k2, _) = accel(ys(k1, 0.5 * dt));
        let (k3, _) = accel(ys(k2, 0.5 * dt));
        let (k4, _) = accel(ys(k3, dt));
        for i in 0..4 {
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        t += dt;
        assert!(t < 1.0, "the rim strike did not end");
        let b = bore(h, &pose(y[0], y[1]), false);
        assert!(b.deepest < 0.0, "the bore touched: {}", b.deepest);
    }
    let (i, _) =
        hist.iter().enumerate().fold(
            (0, f64::MIN),
            |(bi, bf), (i, &(_, f))| if f > bf { (i, f) } else { (bi, bf) },
        );
    let (f0, f1, f2) = (hist[i - 1].1, hist[i].1, hist[i + 1].1);
    let den = f0 - 2.0 * f1 + f2;
    let x = if den != 0.0 {
        0.5 * (f0 - f2) / den
    } else {
        0.0
    };
    let peak = f1 - 0.25 * (f0 - f2) * x;
    (peak, hist[i].0 + x * dt, t, [y[2], y[3]])
}

/// Checks of the reference against closed forms and brute force (panics on a failure; returns
/// what it measured, for printing).
pub fn self_checks() -> Vec<String> {
    let mut log = Vec::new();
    let close = |a: f64, b: f64, tol: f64, what: &str| {
        assert!(
            (a - b).abs() <= tol * b.abs().max(1e-300),
            "{what}: {a} against {b} (tolerance {tol})"
        );
    };
    // Quadrature: exact for degree 19 on one panel; the root's t^1.5.
    let rule = gauss_legendre(POINTS);
    let mut s = 0.0;
    integrate(&rule, 1, 0.0, 1.0, |x, w| s += w * x.powi(19));
    close(s, 0.05, 1e-14, "int x^19");
    let mut s = 0.0;
    integrate(&rule, PANELS, 0.0, 1e-3, |x, w| s += w * x.powf(1.5));
    close(s, 0.4 * 1e-3f64.powf(2.5), 1e-9, "int x^1.5");
    log.push(format!(
        "quadrature: int_0^1e-3 x^1.5 off by {:.1e}",
        s / (0.4 * 1e-3f64.powf(2.5)) - 1.0
    ));

    let h = Hinge {
        bore_radius: 0.006,
        clearance: 0.1e-3,
        width: 0.020,
        play: 0.3e-3,
        collar: 0.010,
        bore: PowerLaw {
            stiffness: 1e8,
            exponent: 1.0,
        },
        face_stiffness: 2.27e9,
    };
    let rj = h.journal_radius();
    // The tilted plane of symmetry: delta(s) = |eps| - c + R_j (1/cos - 1), k = 1/cos.
    let (e0, th) = (0.08e-3, 0.006);
    let p = hanging_pin_pose(e0, th);
    for s in [-0.01, -0.003, 0.0, 0.007, 0.01] {
        let sec = section(&h, &p, s);
        let eps = (e0 + s * th.sin()) / th.cos();
        let want = eps.abs() - h.clearance + rj * (1.0 / th.cos() - 1.0);
        close(sec.depth, want, 1e-12, "tilted section's depth");
        close(sec.gain, 1.0 / th.cos(), 1e-13, "tilted section's gain");
        let sg = eps.signum();
        let z = (s + e0 * th.sin() + sg * rj * th.sin()) / th.cos();
        let off = norm(sub(sec.point, [0.0, sg * rj, z]));
        assert!(off < 1e-15, "deepest point {off} m off");
    }
    // A skew pose (tilt about both axes, eccentricity off the tilt's plane) against a brute
    // search of the ellipse: the section's points are R_j from the journal's axis.
    let skew = Pose {
        bearing_center: [1e-5, -2e-5, 3e-4],
        bearing_axis: unit([0.001, -0.002, 1.0]),
        journal_center: [0.06e-3, 0.07e-3, 0.0],
        journal_axis: unit([-0.004, 0.007, 1.0]),
    };
    for s in [-0.01, -0.004, 0.0, 0.005, 0.01] {
        let sec = section(&h, &skew, s);
        let (ai, aj) = (skew.bearing_axis, skew.journal_axis);
        let o = add(skew.bearing_center, scale(ai, s));
        let u = perpendicular(ai);
        let v = cross(ai, u);
        // Points of the plane at angle psi from the bore's axis, at the journal's surface.
        let mut best = f64::MIN;
        let n = 200_000;
        for i in 0..n {
            let psi = 2.0 * PI * i as f64 / n as f64;
            let dir = add(scale(u, psi.cos()), scale(v, psi.sin()));
            // Largest rho with the point on the journal's surface: the surface is met where
            // dist(o + rho dir, journal axis) = R_j; outer root by bisection.
            let dist = |rho: f64| {
                let x = sub(add(o, scale(dir, rho)), skew.journal_center);
                let along = dot(x, aj);
                norm(sub(x, scale(aj, along))) - rj
            };
            if dist(h.bore_radius) > 0.0 && dist(0.0) > 0.0 {
                continue;
            }
            let r = root(dist, 0.5 * h.bore_radius, 2.0 * h.bore_radius, 1e-16);
            best = best.max(r);
        }
        close(
            sec.depth,
            best - h.bore_radius,
            1e-6,
            "skew section against brute force",
        );
        // The point is on the journal's surface and in the plane.
        let x = sub(sec.point, skew.journal_center);
        close(
            norm(sub(x, scale(aj, dot(x, aj)))),
            rj,
            1e-12,
            "point on the surface",
        );
        let off = dot(sub(sec.point, o), ai).abs();
        assert!(off < 1e-15, "point {off} m off the plane");
    }
    log.push("sections: tilted plane exact, skew pose = brute force (2e5 directions)".into());

    // Faces: full contact gives K delta_c and the first moment g pi (R_o^4 - R_j^4)/4;
    // a sliver against a polar brute-force grid.
    let (ro, a) = (h.collar, h.annulus_area());
    let ann =
        |dc: f64, g: f64, m, k| disc_integral(dc, g, ro, m, k) - disc_integral(dc, g, rj, m, k);
    close(ann(1e-6, 1e-5, 1, 0), 1e-6 * a, 1e-13, "full annulus force");
    close(
        ann(1e-6, 1e-5, 1, 1),
        1e-5 * PI * (ro.powi(4) - rj.powi(4)) / 4.0,
        1e-12,
        "full annulus moment",
    );
    for (dc, g) in [(-0.95e-4, 0.01), (-0.5e-4, 0.006), (2e-6, 0.003)] {
        let (mut f, mut m, mut e) = (0.0, 0.0, 0.0);
        let (nr, nt) = (4000, 4000);
        for i in 0..nr {
            let r = rj + (ro - rj) * (i as f64 + 0.5) / nr as f64;
            for j in 0..nt {
                let t = 2.0 * PI * (j as f64 + 0.5) / nt as f64;
                let xi = r * t.cos();
                let d = (dc + g * xi).max(0.0);
                let da = r * (ro - rj) / nr as f64 * 2.0 * PI / nt as f64;
                f += d * da;
                m += d * xi * da;
                e += d * d * da;
            }
        }
        close(ann(dc, g, 1, 0), f, 2e-5, "sliver force");
        close(ann(dc, g, 1, 1), m, 2e-5, "sliver moment");
        close(ann(dc, g, 2, 0), e, 2e-5, "sliver energy");
    }
    log.push("faces: full contact exact, slivers = 4000 x 4000 polar grid to 2e-5".into());

    // -grad U against the forces, by central differences over rigid motions of the journal, at
    // a skew pose touching both ends of the bore on opposite sides and the upper face, with a
    // Hertz bore law (F ~ delta^1.5).
    let hz = Hinge {
        bore: PowerLaw {
            stiffness: 1e10,
            exponent: 1.5,
        },
        ..h
    };
    let touching = Pose {
        bearing_center: [0.0; 3],
        bearing_axis: [0.0, 0.0, 1.0],
        journal_center: [0.003e-3, -0.002e-3, -0.049e-3],
        journal_axis: unit([0.0028, 0.00978, 1.0]),
    };
    let c0 = contact(&hz, &touching, false);
    assert!(
        c0.bore.stretches.len() == 2 && c0.faces[1].magnitude > 0.0,
        "{c0:?}"
    );
    let moved = |dx: V3, dr: V3| {
        let ang = norm(dr);
        let (pc, ax) = if ang > 0.0 {
            let k = scale(dr, 1.0 / ang);
            (
                rotate(touching.journal_center, k, ang),
                rotate(touching.journal_axis, k, ang),
            )
        } else {
            (touching.journal_center, touching.journal_axis)
        };
        let p = Pose {
            journal_center: add(pc, dx),
            journal_axis: ax,
            ..touching
        };
        let c = contact(&hz, &p, false);
        [c.bore.energy, c.faces[0].energy + c.faces[1].energy]
    };
    let (hx, hr) = (1e-10, 1e-8);
    let parts = [
        ("bore", c0.bore.force, c0.bore.moment),
        (
            "faces",
            add(c0.faces[0].force, c0.faces[1].force),
            add(c0.faces[0].moment, c0.faces[1].moment),
        ),
    ];
    let mut worst: f64 = 0.0;
    for (k, (name, force, moment)) in parts.iter().enumerate() {
        let (fs, ms) = (norm(*force), norm(*moment));
        for i in 0..3 {
            let mut e = [0.0; 3];
            e[i] = hx;
            let f = -(moved(e, [0.0; 3])[k] - moved(scale(e, -1.0), [0.0; 3])[k]) / (2.0 * hx);
            e[i] = hr;
            let m = -(moved([0.0; 3], e)[k] - moved([0.0; 3], scale(e, -1.0))[k]) / (2.0 * hr);
            assert!(
                (f - force[i]).abs() < 1e-5 * fs,
                "{name} force {i}: -dU/dx {f}, {force:?}"
            );
            assert!(
                (m - moment[i]).abs() < 1e-5 * ms,
                "{name} moment {i}: -dU/da {m}, {moment:?}"
            );
            worst = worst
                .max((f - force[i]).abs() / fs)
                .max((m - moment[i]).abs() / ms);
        }
    }
    let ends: Vec<f64> = c0.bore.stretches.iter().map(|s| norm(s.force)).collect();
    log.push(format!(
        "-grad U = the forces (central differences, worst {worst:.1e} of each part's size): bore ends {ends:.3?} N, face {:.3} N",
        c0.faces[1].magnitude
    ));
    log
}
