//! Composite Gauss–Legendre quadrature on `[0, 1]` over panels whose boundaries include every
//! point where a position is needed (constraint points, obstacle samples), so that positions at
//! those points are exact cumulative sums of panel integrals (eq. 6).

/// The 8-point Gauss–Legendre rule on `[-1, 1]` ([`gauss_legendre`]`(8)`), computed once: the
/// positions between mesh boundaries integrate with it.
pub fn gauss_legendre_8() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: std::sync::OnceLock<(Vec<f64>, Vec<f64>)> = std::sync::OnceLock::new();
    RULE.get_or_init(|| gauss_legendre(8))
}

/// Gauss–Legendre nodes and weights on `[-1, 1]` with `n` points (Newton on `Pₙ`).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 1 { z } else { p1 };
            let pnm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * pn - pnm1) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        if n == 1 {
            z = 0.0;
            dp = 1.0;
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = if n == 1 {
            2.0
        } else {
            2.0 / ((1.0 - z * z) * dp * dp)
        };
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// Panels on `[0, 1]` and the quadrature nodes inside them.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Panel boundaries `0 = b₀ < b₁ < … < b_P = 1`.
    pub boundaries: Vec<f64>,
    /// Node positions `t`.
    pub nodes: Vec<f64>,
    /// Node weights (sum to 1).
    pub weights: Vec<f64>,
    /// `panel_start[j]..panel_start[j+1]` are the nodes of panel `j`.
    pub panel_start: Vec<usize>,
}

impl Mesh {
    /// `panels` uniform panels, refined so that every `extra` point is a boundary, with `gauss`
    /// points per panel. Points closer than `1e-9` are merged.
    pub fn new(panels: usize, gauss: usize, extra: &[f64]) -> Mesh {
        let mut b: Vec<f64> = (0..=panels).map(|j| j as f64 / panels as f64).collect();
        b.extend(extra.iter().copied().filter(|t| (0.0..=1.0).contains(t)));
        b.sort_by(f64::total_cmp);
        b.dedup_by(|x, y| (*x - *y).abs() < 1e-9);
        let (gx, gw) = gauss_legendre(gauss);
        let mut nodes = Vec::with_capacity((b.len() - 1) * gauss);
        let mut weights = Vec::with_capacity(nodes.capacity());
        let mut panel_start = vec![0];
        for p in b.windows(2) {
            let (a, c) = (p[0], p[1]);
            let h = c - a;
            for (x, w) in gx.iter().zip(&gw) {
                nodes.push(a + 0.5 * h * (x + 1.0));
                weights.push(0.5 * h * w);
            }
            panel_start.push(nodes.len());
        }
        Mesh {
            boundaries: b,
            nodes,
            weights,
            panel_start,
        }
    }

    /// Index of the boundary closest to `t`.
    pub fn boundary_index(&self, t: f64) -> usize {
        let mut best = 0;
        for (i, b) in self.boundaries.iter().enumerate() {
            if (b - t).abs() < (self.boundaries[best] - t).abs() {
                best = i;
            }
        }
        best
    }

    /// Number of panels.
    pub fn panels(&self) -> usize {
        self.boundaries.len() - 1
    }

    /// Nodes per panel (every panel has the same number, [`Mesh::new`]'s `gauss`).
    pub fn gauss(&self) -> usize {
        self.panel_start[1] - self.panel_start[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in 1..=8 {
            let (x, w) = gauss_legendre(n);
            for deg in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!((q - exact).abs() < 1e-13, "n={n} deg={deg} {q} {exact}");
            }
        }
    }

    #[test]
    fn mesh_contains_extra_points() {
        let m = Mesh::new(4, 3, &[0.3, 0.3 + 1e-12, 1.0]);
        assert_eq!(m.boundaries, vec![0.0, 0.25, 0.3, 0.5, 0.75, 1.0]);
        let total: f64 = m.weights.iter().sum();
        assert!((total - 1.0).abs() < 1e-14);
    }
}
