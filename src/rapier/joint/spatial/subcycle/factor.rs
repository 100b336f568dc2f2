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

/// An LU factorisation of `I - gamma s B - (gamma s)^2 A` with its row order.
pub(super) struct Factor {
    pub(super) lu: Square,
    pub(super) order: [usize; 12],
    pub(super) gs: f64,
}

impl Factor {
    /// `None` when the matrix is singular (the sub-step is then halved).
    pub(super) fn of(slopes: &Slopes, s: f64) -> Option<Self> {
        let gs = GAMMA * s;
        let mut m: Square = std::array::from_fn(|i| {
            let id = if i / 12 == i % 12 { 1.0 } else { 0.0 };
            id - gs * slopes.b[i] - gs * gs * slopes.a[i]
        });
        let mut order: [usize; 12] = std::array::from_fn(|i| i);
        for col in 0..12 {
            let pivot = (col..12)
                .max_by(|&x, &y| m[x * 12 + col].abs().total_cmp(&m[y * 12 + col].abs()))
                .unwrap_or(col);
            if !(m[pivot * 12 + col].abs() > 0.0) {
                return None;
            }
            if pivot != col {
                for c in 0..12 {
                    m.swap(col * 12 + c, pivot * 12 + c);
                }
                order.swap(col, pivot);
            }
            let d = m[col * 12 + col];
            for r in col + 1..12 {
                let f = m[r * 12 + col] / d;
                m[r * 12 + col] = f;
                for c in col + 1..12 {
                    m[r * 12 + c] -= f * m[col * 12 + c];
                }
            }
        }
        Some(Factor { lu: m, order, gs })
    }

    /// `(I - gamma s J) k = r` for the system `dPi/dt = Gamma`, `dGamma/dt = L`:
    /// `k_Gamma = M^-1 (r_Gamma + gamma s A r_Pi)`, `k_Pi = r_Pi + gamma s k_Gamma`.
    pub(super) fn solve(&self, slopes: &Slopes, r: &Impulses) -> Impulses {
        let mut rhs = r.gamma;
        axpy(&mut rhs, self.gs, &mul(&slopes.a, &r.pi));
        let mut x: Pair12 = std::array::from_fn(|i| rhs[self.order[i]]);
        for i in 0..12 {
            for c in 0..i {
                x[i] -= self.lu[i * 12 + c] * x[c];
            }
        }
        for i in (0..12).rev() {
            for c in i + 1..12 {
                x[i] -= self.lu[i * 12 + c] * x[c];
            }
            x[i] /= self.lu[i * 12 + i];
        }
        let mut pi = r.pi;
        axpy(&mut pi, self.gs, &x);
        Impulses { pi, gamma: x }
    }
}
