//! Gauss-Legendre rules for the spatial joint's contact regions, and the change of variable that
//! keeps them accurate where a region ends at a root of the penetration.

/// A Gauss-Legendre rule on [-1, 1] by its positive nodes (the others are their negatives) and
/// their weights (summing to 1: half the rule's).
#[derive(Clone, Copy, Debug)]
pub struct Rule {
    nodes: &'static [f64],
    weights: &'static [f64],
}

/// 4 points, exact for polynomials up to degree 7.
pub const GAUSS_4: Rule = Rule {
    nodes: &[0.339_981_043_584_856_3, 0.861_136_311_594_052_6],
    weights: &[0.652_145_154_862_546_1, 0.347_854_845_137_453_9],
};

/// 8 points, exact for polynomials up to degree 15.
pub const GAUSS_8: Rule = Rule {
    nodes: &NODES_8,
    weights: &WEIGHTS_8,
};

const NODES_8: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];

const WEIGHTS_8: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

impl Rule {
    /// Its points.
    pub fn points(self) -> usize {
        2 * self.nodes.len()
    }

    /// The rule on `[a, b]`: `(x_k, w_k)` with `sum w_k f(x_k)` the integral of `f` (the weights
    /// sum to `b - a`).
    pub fn on(self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        self.nodes
            .iter()
            .zip(self.weights)
            .flat_map(move |(x, w)| [(mid - half * x, half * w), (mid + half * x, half * w)])
    }

    /// The rule on the interval from `root` to `end` (either order) for an integrand that
    /// vanishes like a power of the distance from `root` (a penetration crossing zero there):
    /// with `x = root + (end - root) t^2` the integrand `(x - root)^p dx` becomes
    /// `t^(2p + 1) dt`, smooth for the contact laws' exponents (`p` from 1 to 2.5), where the
    /// plain rule would converge only algebraically. The weights sum to `|end - root|`.
    pub fn from_root(self, root: f64, end: f64) -> impl Iterator<Item = (f64, f64)> {
        let length = end - root;
        self.on(0.0, 1.0)
            .map(move |(t, w)| (root + length * t * t, w * 2.0 * t * length.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_is_exact_to_degree_15() {
        for (rule, degree) in [(GAUSS_4, 7), (GAUSS_8, 15)] {
            exact_to(rule, degree);
        }
    }

    fn exact_to(rule: Rule, degree: i32) {
        for p in 0..=degree {
            let sum: f64 = rule.on(-0.3, 1.1).map(|(x, w)| w * x.powi(p)).sum();
            let exact = (1.1f64.powi(p + 1) - (-0.3f64).powi(p + 1)) / f64::from(p + 1);
            assert!((sum - exact).abs() < 1e-14 * exact.abs().max(1.0), "{p}");
        }
        // One degree more is not integrated exactly.
        let p = degree + 1;
        let sum: f64 = rule.on(-0.3, 1.1).map(|(x, w)| w * x.powi(p)).sum();
        let exact = (1.1f64.powi(p + 1) - (-0.3f64).powi(p + 1)) / f64::from(p + 1);
        assert!((sum - exact).abs() > 1e-12, "{p}");
    }

    #[test]
    fn a_root_power_is_integrated_exactly() {
        // (x - r)^1.5 from r to e: t^4 after the change of variable.
        let (r, e) = (0.2, -0.7);
        let sum: f64 = GAUSS_8
            .from_root(r, e)
            .map(|(x, w)| w * (r - x).powf(1.5))
            .sum();
        let exact = 0.9f64.powf(2.5) / 2.5;
        assert!((sum - exact).abs() < 1e-15, "{sum} {exact}");
    }
}
