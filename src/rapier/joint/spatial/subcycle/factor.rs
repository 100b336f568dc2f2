//! The spatial sub-cycle's state and linear algebra: the impulses, the load's Jacobian and the
//! factorisation each Rosenbrock stage solves with.

use super::*;

/// The sub-cycle's state: `Pi` and `Gamma` beyond the held load's (`Q` and `G` of
/// `SpatialCycle`'s held load).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Impulses {
    pub(super) pi: Pair12,
    pub(super) gamma: Pair12,
}

/// The Jacobian of the load: `dL/dx`, `dL/dv` (over the pair's coordinates) and the same through
/// the mobility, `A = dL/dx P`, `B = dL/dv P`.
pub(super) struct Slopes {
    pub(super) lx: Square,
    pub(super) lv: Square,
    pub(super) a: Square,
    pub(super) b: Square,
}

/// `l p` for 12 x 12 matrices: a load's slope through a mobility.
pub(super) fn through(l: &Square, p: &Square) -> Square {
    std::array::from_fn(|i| {
        let (r, c) = (i / 12, i % 12);
        (0..12).map(|k| l[r * 12 + k] * p[k * 12 + c]).sum()
    })
}

/// An LU factorisation of `I - gamma s B - (gamma s)^2 A` with its row order, over the
/// `12 n` coordinates of a group's `n` pairs: `A` and `B` hold each pair's slopes through the
/// mobilities from every pair's load (`A_ab = dL_a/dx_a P_ab`), so a contact's stiffness on a
/// body two pairs share is implicit in both.
pub(super) struct Factor {
    lu: Vec<f64>,
    order: Vec<usize>,
    /// `A`, row-major over the `12 n` coordinates (for the stages' right-hand sides).
    a: Vec<f64>,
    n: usize,
    gs: f64,
}

impl Factor {
    /// `None` when the matrix is singular (the sub-step is then halved). `a` and `b` are
    /// `12 n` square, row-major.
    pub(super) fn of(a: Vec<f64>, b: &[f64], s: f64) -> Option<Self> {
        let n = (a.len() as f64).sqrt().round() as usize;
        let gs = GAMMA * s;
        let mut m: Vec<f64> = (0..n * n)
            .map(|i| {
                let id = if i / n == i % n { 1.0 } else { 0.0 };
                id - gs * b[i] - gs * gs * a[i]
            })
            .collect();
        let mut order: Vec<usize> = (0..n).collect();
        for col in 0..n {
            let pivot = (col..n)
                .max_by(|&x, &y| m[x * n + col].abs().total_cmp(&m[y * n + col].abs()))
                .unwrap_or(col);
            if !(m[pivot * n + col].abs() > 0.0) {
                return None;
            }
            if pivot != col {
                for c in 0..n {
                    m.swap(col * n + c, pivot * n + c);
                }
                order.swap(col, pivot);
            }
            let d = m[col * n + col];
            for r in col + 1..n {
                let f = m[r * n + col] / d;
                m[r * n + col] = f;
                for c in col + 1..n {
                    m[r * n + c] -= f * m[col * n + c];
                }
            }
        }
        Some(Factor {
            lu: m,
            order,
            a,
            n,
            gs,
        })
    }

    /// `(I - gamma s J) k = r` for the system `dPi/dt = Gamma`, `dGamma/dt = L` of every pair:
    /// `k_Gamma = M^-1 (r_Gamma + gamma s A r_Pi)`, `k_Pi = r_Pi + gamma s k_Gamma`.
    pub(super) fn solve(&self, r: &[Impulses]) -> Vec<Impulses> {
        let n = self.n;
        let flat = |f: fn(&Impulses) -> &Pair12| -> Vec<f64> {
            r.iter().flat_map(|i| f(i).iter().copied()).collect()
        };
        let (pi, mut rhs) = (flat(|i| &i.pi), flat(|i| &i.gamma));
        for (row, x) in rhs.iter_mut().enumerate() {
            let a_pi: f64 = (0..n).map(|k| self.a[row * n + k] * pi[k]).sum();
            *x += self.gs * a_pi;
        }
        let mut x: Vec<f64> = (0..n).map(|i| rhs[self.order[i]]).collect();
        for i in 0..n {
            for c in 0..i {
                x[i] -= self.lu[i * n + c] * x[c];
            }
        }
        for i in (0..n).rev() {
            for c in i + 1..n {
                x[i] -= self.lu[i * n + c] * x[c];
            }
            x[i] /= self.lu[i * n + i];
        }
        r.iter()
            .enumerate()
            .map(|(m, ri)| {
                let gamma: Pair12 = std::array::from_fn(|i| x[12 * m + i]);
                let mut pi = ri.pi;
                axpy(&mut pi, self.gs, &gamma);
                Impulses { pi, gamma }
            })
            .collect()
    }
}
