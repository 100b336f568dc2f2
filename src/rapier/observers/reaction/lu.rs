//! Dense LU factorisation and solve of the constraint matrix, regularised when singular.

/// Relative size of a pivot below which a matrix is singular to working precision.
const PIVOT_TOLERANCE: f64 = 1e-12;

/// Relative regularisation added to the diagonal of a singular matrix (the least-norm share it
/// gives is exact to about this relative size).
const REGULARISATION: f64 = 1e-12;

/// Relative pivot tolerance of the regularised matrix: well below the regularisation, since a
/// redundant row's pivot after elimination is about the regularisation itself (the same
/// tolerance for both made every redundant system fail).
const REGULARISED_PIVOT_TOLERANCE: f64 = 1e-2 * REGULARISATION;

/// LU factors of the `n x n` row-major `a` into `lu`, with a relative regularisation
/// ([`REGULARISATION`]) on the diagonal when `a` is singular (redundant constraints: a
/// least-norm share). False when even that fails (a non-finite entry).
pub(crate) fn factor_regularised(
    a: &[f64],
    lu: &mut Vec<f64>,
    piv: &mut Vec<usize>,
    n: usize,
) -> bool {
    lu.clear();
    lu.extend_from_slice(a);
    if lu_factor(lu, piv, n, PIVOT_TOLERANCE) {
        return true;
    }
    lu.clear();
    lu.extend_from_slice(a);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        lu[i * n + i] += REGULARISATION * scale;
    }
    lu_factor(lu, piv, n, REGULARISED_PIVOT_TOLERANCE)
}

/// LU factorisation with partial pivoting of the `n x n` row-major `a` in place (`piv` the row
/// order). False when a pivot is below `tolerance` times the largest entry (singular to working
/// precision) or an entry is not finite.
pub(super) fn lu_factor(a: &mut [f64], piv: &mut Vec<usize>, n: usize, tolerance: f64) -> bool {
    piv.clear();
    piv.extend(0..n);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) && n > 0 {
        return false;
    }
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &k| a[i * n + col].abs().total_cmp(&a[k * n + col].abs()))
            .unwrap_or(col);
        if !(a[pivot * n + col].abs() > tolerance * scale) {
            return false;
        }
        if pivot != col {
            for k in 0..n {
                a.swap(pivot * n + k, col * n + k);
            }
            piv.swap(pivot, col);
        }
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            a[i * n + col] = f;
            if f != 0.0 {
                for k in col + 1..n {
                    a[i * n + k] -= f * a[col * n + k];
                }
            }
        }
    }
    true
}

/// Solves `A x = b` from the factors of [`lu_factor`]; the solution replaces `b`.
pub(crate) fn lu_solve(lu: &[f64], piv: &[usize], b: &mut [f64], scratch: &mut Vec<f64>, n: usize) {
    scratch.clear();
    scratch.extend(piv.iter().map(|&p| b[p]));
    b.copy_from_slice(scratch);
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= lu[i * n + k] * b[k];
        }
        b[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= lu[i * n + k] * b[k];
        }
        b[i] = s / lu[i * n + i];
    }
}
