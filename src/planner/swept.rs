//! Swept clearance between consecutive `k` samples: a guard against tunnelling.
//!
//! A point that moves on the segment from `p` to `q` keeps at least
//! `(d(p) + d(q) − |q − p|) / 2` from any obstacle, where `d` is the distance to it: for `y` on
//! the segment and `o` the obstacle point nearest to `y`, `d(p) ≤ |p − y| + d(y)` and
//! `d(q) ≤ |q − y| + d(y)`, and `|p − y| + |q − y| = |q − p|`. So for every obstacle sample
//! point `b` and every pair of consecutive interior samples `k_i`, `k_{i+1}` the row
//!
//! `c = c_i + c_{i+1} + |x_{i+1}(b) − x_i(b)|  ≤ 0`, halved,
//!
//! with `c_i = (r + margin)/L − d(x_i(b))/L` the obstacle row of sample `i`, keeps the straight
//! chord between the two samples' positions of `b` clear by the required clearance. It needs no
//! distance query of its own, implies both samples' rows (`d` is 1-Lipschitz; up to `δ/2` with
//! the smoothing below), and stops the
//! optimiser from moving a point across a thin obstacle between two samples. The chord is not the
//! path's exact motion, which curves in `k`, and the first and last intervals, next to the fixed
//! end shapes (which carry no rows), have no swept row: the verification grid checks both. `|Δ|` is
//! smoothed as `√(|Δ|² + δ²) − δ` with `δ = 1e-4` (units of `L`), so rows stay differentiable
//! where a point does not move (the clamped base).

use crate::constraints::{Adjoint, Constraint};
use crate::planner::path::DeformationPath;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;

/// Smoothing length of `|Δ|` (units of `L`).
pub const DELTA: f64 = 1e-4;

/// The swept rows of a minimax problem: one per obstacle sample point and pair of consecutive
/// interior samples, laid out pair-major after the per-sample rows.
#[derive(Clone, Debug)]
pub struct Swept {
    /// Obstacle blocks: the block's index among the problem's blocks and its sample
    /// boundaries.
    pub obstacles: Vec<(usize, Vec<usize>)>,
    /// Row offset of each obstacle inside a pair's rows (one more entry than `obstacles`).
    pub offsets: Vec<usize>,
    /// Number of pairs (interior samples − 1).
    pub pairs: usize,
}

impl Swept {
    /// The swept rows for the obstacle blocks among `blocks`, over `interior` samples; `None`
    /// when there is no obstacle or fewer than two interior samples.
    pub fn new(blocks: &[Constraint], interior: usize) -> Option<Swept> {
        let obstacles: Vec<(usize, Vec<usize>)> = blocks
            .iter()
            .enumerate()
            .filter_map(|(i, b)| match b {
                Constraint::Obstacle(o) => Some((i, o.samples.clone())),
                _ => None,
            })
            .collect();
        if obstacles.is_empty() || interior < 2 {
            return None;
        }
        let mut offsets = vec![0];
        for (_, s) in &obstacles {
            offsets.push(offsets.last().unwrap() + s.len());
        }
        Some(Swept {
            obstacles,
            offsets,
            pairs: interior - 1,
        })
    }

    /// Rows per pair.
    pub fn rows_per_pair(&self) -> usize {
        *self.offsets.last().unwrap()
    }

    /// Total rows.
    pub fn rows(&self) -> usize {
        self.pairs * self.rows_per_pair()
    }

    /// Smoothed chord `(|Δ|_δ, Δ/√(|Δ|² + δ²), √(|Δ|² + δ²))` from `p` to `q`.
    fn chord(p: [f64; 3], q: [f64; 3]) -> (f64, [f64; 3], f64) {
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let s = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + DELTA * DELTA).sqrt();
        (s - DELTA, [d[0] / s, d[1] / s, d[2] / s], s)
    }

    /// Writes the swept rows into `out` from the per-sample rows `c` (`per` rows per interior
    /// sample, obstacle blocks at `block_offsets`) and the interior samples' `shapes`.
    pub fn values(
        &self,
        c: &[f64],
        per: usize,
        block_offsets: &[usize],
        shapes: &[&Shape],
        out: &mut [f64],
    ) {
        let rp = self.rows_per_pair();
        for p in 0..self.pairs {
            for (o, (blk, samples)) in self.obstacles.iter().enumerate() {
                for (r, &b) in samples.iter().enumerate() {
                    let ci = c[p * per + block_offsets[*blk] + r];
                    let cj = c[(p + 1) * per + block_offsets[*blk] + r];
                    let (len, _, _) =
                        Self::chord(shapes[p].positions[b], shapes[p + 1].positions[b]);
                    out[p * rp + self.offsets[o] + r] = 0.5 * (ci + cj + len);
                }
            }
        }
    }

    /// Calls `f(block, row in block, boundary, pair, sign, yᵣ)` for every swept row with a
    /// non-zero multiplier `yᵣ` that involves interior sample `i` (`sign` is `+1` where the
    /// sample ends the pair, `−1` where it starts it).
    fn touching(
        &self,
        i: usize,
        y: &[f64],
        mut f: impl FnMut(usize, usize, usize, usize, f64, f64),
    ) {
        let rp = self.rows_per_pair();
        for (p, sign) in [(i.checked_sub(1), 1.0), (Some(i), -1.0)] {
            let Some(p) = p.filter(|&p| p < self.pairs) else {
                continue;
            };
            for (o, (blk, samples)) in self.obstacles.iter().enumerate() {
                for (r, &b) in samples.iter().enumerate() {
                    let yr = y[p * rp + self.offsets[o] + r];
                    if yr != 0.0 {
                        f(*blk, r, b, p, sign, yr);
                    }
                }
            }
        }
    }

    /// For interior sample `i`: adds the swept rows' share `½ yᵣ` of its obstacle rows'
    /// weights to `w` (the sample's `per` weights), for swept multipliers `y` (all swept rows).
    /// Returns whether any swept multiplier touching the sample is non-zero.
    pub fn add_sample_weights(
        &self,
        i: usize,
        y: &[f64],
        block_offsets: &[usize],
        w: &mut [f64],
    ) -> bool {
        let mut any = false;
        self.touching(i, y, |blk, r, _, _, _, yr| {
            any = true;
            w[block_offsets[blk] + r] += 0.5 * yr;
        });
        any
    }

    /// For interior sample `i`: adds the swept rows' chord terms `±½ yᵣ u` (u the chord's unit
    /// direction) at their boundaries to `adj`.
    pub fn add_chord_cotangents(&self, i: usize, y: &[f64], shapes: &[&Shape], adj: &mut Adjoint) {
        self.touching(i, y, |_, _, b, p, sign, yr| {
            let (_, u, _) = Self::chord(shapes[p].positions[b], shapes[p + 1].positions[b]);
            adj.add_pos(b, sign * 0.5 * yr, u);
        });
    }

    /// Adds the parts of the swept rows' Hessian that couple two samples to `h` (`z` space):
    /// the chord's curvature `½ yᵣ DᵀH D` (D = ∂(x_{i+1} − x_i)/∂z, H the Hessian of `|Δ|_δ`),
    /// and the penalty's Gauss–Newton part `sᵣ ∇cᵣ∇cᵣᵀ`. The per-sample parts (the obstacle
    /// distance's and the positions' curvature) come through [`Swept::add_sample_weights`] and
    /// [`Swept::add_chord_cotangents`].
    /// `kin`, `a` and `shapes` hold the interior samples only.
    #[allow(clippy::too_many_arguments)]
    pub fn add_coupling_hessian(
        &self,
        model: &Model,
        path: &DeformationPath,
        blocks: &[Constraint],
        kin: &[f64],
        a: &[&[f64]],
        shapes: &[&Shape],
        y: &[f64],
        s: &[f64],
        h: &mut [f64],
    ) {
        let rp = self.rows_per_pair();
        let nv = path.n_vars();
        let n = model.n();
        let mut adj = Adjoint::new(model);
        let mut ga = vec![0.0; n];
        let mut g = vec![0.0; nv];
        for p in 0..self.pairs {
            for (o, (blk, samples)) in self.obstacles.iter().enumerate() {
                for (r, &b) in samples.iter().enumerate() {
                    let row = p * rp + self.offsets[o] + r;
                    let (yr, sr) = (y[row], s[row]);
                    if yr == 0.0 && sr == 0.0 {
                        continue;
                    }
                    let (_, u, len) =
                        Self::chord(shapes[p].positions[b], shapes[p + 1].positions[b]);
                    // D: rows ∂(x_{p+1}(b) − x_p(b))/∂z.
                    let mut dz = [vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]];
                    for (q, sign) in [(p, -1.0), (p + 1, 1.0)] {
                        let jac = model.position_jacobian(shapes[q], b);
                        for (d, row_a) in dz.iter_mut().zip(&jac) {
                            let scaled: Vec<f64> = row_a.iter().map(|v| sign * v).collect();
                            path.add_chain(&scaled, kin[q], d);
                        }
                    }
                    if yr != 0.0 {
                        // H = (I − u uᵀ)/√(|Δ|² + δ²).
                        for r1 in 0..3 {
                            for r2 in 0..3 {
                                let hv = (f64::from(u8::from(r1 == r2)) - u[r1] * u[r2]) / len;
                                let w = 0.5 * yr * hv;
                                if w == 0.0 {
                                    continue;
                                }
                                for (i, &di) in dz[r1].iter().enumerate() {
                                    let wi = w * di;
                                    if wi != 0.0 {
                                        for (hv, dj) in
                                            h[i * nv..(i + 1) * nv].iter_mut().zip(&dz[r2])
                                        {
                                            *hv += wi * dj;
                                        }
                                    }
                                }
                            }
                        }
                    }
                    if sr != 0.0 {
                        // ∇c = ½ (∇c_p + ∇c_{p+1} + uᵀD).
                        g.iter_mut().for_each(|v| *v = 0.0);
                        let mut unit = vec![0.0; blocks[*blk].rows()];
                        unit[r] = 1.0;
                        for q in [p, p + 1] {
                            adj.clear();
                            blocks[*blk].add_gradient(model, a[q], shapes[q], &unit, &mut adj);
                            ga.iter_mut().for_each(|v| *v = 0.0);
                            adj.finish(model, shapes[q], &mut ga);
                            path.add_chain(&ga, kin[q], &mut g);
                        }
                        for (k, d) in dz.iter().enumerate() {
                            for (gv, dv) in g.iter_mut().zip(d) {
                                *gv += u[k] * dv;
                            }
                        }
                        g.iter_mut().for_each(|v| *v *= 0.5);
                        crate::rod::hessian::add_rank_one(h, sr, &g);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::obstacle::{Obstacle, ObstacleShape};
    use parry3d_f64::shape::Cuboid;

    /// The bound behind the rows: wherever `(d(p) + d(q) − |q − p|)/2 ≥ c`, every point of the
    /// chord from `p` to `q` keeps at least `c` from the obstacle (checked at 201 points of each
    /// of 400 pseudo-random chords around a rotated box, with `c` the bound itself).
    #[test]
    fn chord_bound_holds_along_the_chord() {
        let ob = Obstacle::new(
            "box".into(),
            ObstacleShape::Cuboid(Cuboid::new([0.2, 0.1, 0.3].into())),
            [0.1, -0.2, 0.4],
            [0.3, -0.5, 0.2],
        );
        let mut s: u64 = 0x2545_F491_4F6C_DD1D;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut checked = 0;
        for _ in 0..400 {
            let p = [0.1 + 0.8 * rnd(), -0.2 + 0.8 * rnd(), 0.4 + 0.8 * rnd()];
            let q = [0.1 + 0.8 * rnd(), -0.2 + 0.8 * rnd(), 0.4 + 0.8 * rnd()];
            let (dp, _) = ob.signed_distance(p);
            let (dq, _) = ob.signed_distance(q);
            let len =
                ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt();
            let bound = 0.5 * (dp + dq - len);
            if bound <= 0.0 {
                continue;
            }
            checked += 1;
            for i in 0..=200 {
                let t = i as f64 / 200.0;
                let y = [0, 1, 2].map(|k| p[k] + t * (q[k] - p[k]));
                let (dy, _) = ob.signed_distance(y);
                assert!(dy >= bound - 1e-12, "chord point {t}: {dy} < {bound}");
            }
        }
        assert!(checked > 50, "only {checked} chords with a positive bound");
    }
}
