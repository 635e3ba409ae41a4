//! Non-interference with a rigid obstacle (eq. 16), for a rod of radius `r`:
//! `c = (r + margin)/L − d/L ≤ 0` at every sample point, where `d` is the signed distance
//! (negative inside). Its gradient is `−n · ∂x/∂a` with `n` the outward normal. The multiplier
//! `λ ≥ 0` of a row is the contact force magnitude at that sample, pushing along `n`.
//!
//! With `chords` (`discretisation.contact: "chords"`; never the path optimiser's rows), `d` is
//! the smallest signed distance over the point and the half-chords from it towards its
//! neighbouring sample points, so that the rows together keep the whole polyline through the
//! sample points clear: a rod pressed on an obstacle's corner, or wrapped round it, no longer
//! dips between its sample points. The row's witness is the
//! point of the half-chord `x_b + t (x_n − x_b)`, `t ∈ [0, ½]`, nearest the obstacle; its
//! gradient is `−n ((1 − t) ∂x_b/∂a + t ∂x_n/∂a)` (the distance's derivative along the chord
//! vanishes at an interior minimum), and its contact force acts there, split between the two
//! sample points in those proportions. Half-chords that cannot come within the required
//! clearance plus their own half-length (the distance is 1-Lipschitz) are not searched.

use super::{Adjoint, Rows};
use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;
use crate::scene::obstacle::Obstacle;
use std::sync::Arc;

/// One obstacle, checked at a set of mesh boundaries.
#[derive(Clone, Debug)]
pub struct ObstacleConstraint {
    /// The obstacle.
    pub obstacle: Arc<Obstacle>,
    /// Sample boundaries, in increasing arc length.
    pub samples: Vec<usize>,
    /// Required clearance `(r + margin)/L`.
    pub clearance: f64,
    /// Rod length `L` (to convert positions).
    pub length: f64,
    /// Each row also keeps its half-chords to the neighbouring sample points clear (static
    /// solves); `false`: the point alone (the path optimiser's sampled rows).
    pub chords: bool,
}

/// Where a row's distance is smallest: the boundary towards which the witness lies (the row's
/// own when `t = 0`), the fraction `t ∈ [0, ½]` of the way, and the signed distance and the
/// normal there (case units).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Witness {
    pub(crate) towards: usize,
    pub(crate) t: f64,
    pub(crate) distance: f64,
    pub(crate) normal: [f64; 3],
}

impl ObstacleConstraint {
    /// The witness of row `j` for dimensionless boundary `positions`.
    pub(crate) fn witness(&self, positions: &[[f64; 3]], j: usize) -> Witness {
        let l = self.length;
        let b = self.samples[j];
        let x = positions[b].map(|v| v * l);
        let (d0, n0) = self.obstacle.signed_distance(x);
        let mut best = Witness {
            towards: b,
            t: 0.0,
            distance: d0,
            normal: n0,
        };
        if !self.chords {
            return best;
        }
        let need = self.clearance * l;
        for nb in [j.checked_sub(1), Some(j + 1)].into_iter().flatten() {
            let Some(&bn) = self.samples.get(nb) else {
                continue;
            };
            let y = positions[bn].map(|v| v * l);
            let e = [y[0] - x[0], y[1] - x[1], y[2] - x[2]];
            let half = 0.5 * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
            // The half-chord comes no closer than d0 − half: far from the required clearance,
            // the point decides.
            if d0 - half - need > half {
                continue;
            }
            let at = |t: f64| {
                self.obstacle
                    .signed_distance([x[0] + t * e[0], x[1] + t * e[1], x[2] + t * e[2]])
            };
            let slope = |n: [f64; 3]| n[0] * e[0] + n[1] * e[1] + n[2] * e[2];
            // The distance along the chord: its minimum over [0, ½] by bisection on the sign
            // of its derivative `n · e` (convex obstacles: a convex function of t).
            if slope(n0) >= 0.0 {
                continue;
            }
            let (dh, nh) = at(0.5);
            let w = if slope(nh) <= 0.0 {
                // Still falling at the middle: where it falls all the way to the neighbour, the
                // chord comes closest at the neighbour itself, which its own row keeps clear
                // (a chord along a flat face: the row stays the point's, smooth, instead of
                // switching to the midpoint as the chord tilts); otherwise its minimum lies in
                // the neighbour's half, and the middle joins this row to that one continuously.
                if slope(at(1.0).1) <= 0.0 {
                    continue;
                }
                (0.5, dh, nh)
            } else {
                let (mut lo, mut hi) = (0.0, 0.5);
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    if slope(at(mid).1) < 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let t = 0.5 * (lo + hi);
                let (d, _) = at(t);
                // The normals just before and after the minimum, combined so that the result
                // is orthogonal to the chord: the distance's gradient at a minimum on a kink
                // (a cuboid's edge), and the normal there where it is smooth.
                let (dt, eps) = (hi - lo, 1e-7);
                let (nm, np) = (at((t - eps - dt).max(0.0)).1, at((t + eps + dt).min(0.5)).1);
                let (sm, sp) = (slope(nm), slope(np));
                let mu = if sp - sm > 0.0 && sm < 0.0 && sp > 0.0 {
                    sp / (sp - sm)
                } else {
                    0.5
                };
                let n: [f64; 3] = std::array::from_fn(|i| mu * nm[i] + (1.0 - mu) * np[i]);
                (t, d, n)
            };
            if w.1 < best.distance {
                best = Witness {
                    towards: bn,
                    t: w.0,
                    distance: w.1,
                    normal: w.2,
                };
            }
        }
        best
    }
}

impl Rows for ObstacleConstraint {
    fn label(&self) -> String {
        format!("obstacle {}", self.obstacle.name)
    }
    fn rows(&self) -> usize {
        self.samples.len()
    }
    fn sense(&self, _i: usize) -> Sense {
        Sense::LessEq
    }
    fn values(&self, _m: &Model, _a: &[f64], shape: &Shape, out: &mut [f64]) {
        clearances(self, &shape.positions, out);
    }
    fn add_gradient(&self, _m: &Model, _a: &[f64], shape: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (j, (&wi, &b)) in w.iter().zip(&self.samples).enumerate() {
            if wi == 0.0 {
                continue;
            }
            let wt = self.witness(&shape.positions, j);
            adj.add_pos(b, -wi * (1.0 - wt.t), wt.normal);
            if wt.t > 0.0 {
                adj.add_pos(wt.towards, -wi * wt.t, wt.normal);
            }
        }
    }
    /// The distance function's Hessian by central differences of its normal (step `1e-6 L`).
    fn add_curvature(&self, m: &Model, _a: &[f64], shape: &Shape, w: &[f64], h: &mut [f64]) {
        let n = m.n();
        let step = 1e-6 * self.length;
        for (j, (&wi, &b)) in w.iter().zip(&self.samples).enumerate() {
            if wi == 0.0 {
                continue;
            }
            // At the witness, whose position is (1 − t) x_b + t x_n.
            let wt = self.witness(&shape.positions, j);
            let (xb, xn) = (shape.positions[b], shape.positions[wt.towards]);
            let x: [f64; 3] =
                std::array::from_fn(|i| ((1.0 - wt.t) * xb[i] + wt.t * xn[i]) * self.length);
            // D = ∂n/∂X (world units); ∇²ₓc = −L D for dimensionless x.
            let mut d = [[0.0; 3]; 3];
            for k in 0..3 {
                let (mut xp, mut xm) = (x, x);
                xp[k] += step;
                xm[k] -= step;
                let (_, np) = self.obstacle.signed_distance(xp);
                let (_, nm) = self.obstacle.signed_distance(xm);
                for r in 0..3 {
                    d[r][k] = (np[r] - nm[r]) / (2.0 * step);
                }
            }
            if d.iter().all(|r| r.iter().all(|v| v.abs() < 1e-9)) {
                continue;
            }
            let mut jac = m.position_jacobian(shape, b);
            if wt.t > 0.0 {
                let jn = m.position_jacobian(shape, wt.towards);
                if wt.t < 0.5 {
                    // The witness moves along the chord as the ends move: the minimum's
                    // Hessian loses `v vᵀ / (eᵀ D e)`, with `v` the derivative of the
                    // distance's slope along the chord with respect to the ends.
                    let l = self.length;
                    let e: [f64; 3] = std::array::from_fn(|i| (xn[i] - xb[i]) * l);
                    let sym = |r: usize, k: usize| 0.5 * (d[r][k] + d[k][r]);
                    let de: [f64; 3] =
                        std::array::from_fn(|r| (0..3).map(|k| sym(r, k) * e[k]).sum());
                    let denom: f64 = (0..3).map(|r| e[r] * de[r]).sum();
                    if denom > 1e-12 * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) {
                        let nn = wt.normal;
                        let vb: [f64; 3] = std::array::from_fn(|r| (1.0 - wt.t) * de[r] - nn[r]);
                        let vn: [f64; 3] = std::array::from_fn(|r| wt.t * de[r] + nn[r]);
                        let q: Vec<f64> = (0..n)
                            .map(|i| (0..3).map(|r| jac[r][i] * vb[r] + jn[r][i] * vn[r]).sum())
                            .collect();
                        let scale = wi * l / denom;
                        for i in 0..n {
                            let v = scale * q[i];
                            if v != 0.0 {
                                for (hv, qj) in h[i * n..(i + 1) * n].iter_mut().zip(&q) {
                                    *hv += v * qj;
                                }
                            }
                        }
                    }
                }
                for (row, rn) in jac.iter_mut().zip(&jn) {
                    for (v, vn) in row.iter_mut().zip(rn) {
                        *v = (1.0 - wt.t) * *v + wt.t * vn;
                    }
                }
            }
            for r in 0..3 {
                for k in 0..3 {
                    let dk = -wi * self.length * 0.5 * (d[r][k] + d[k][r]);
                    if dk == 0.0 {
                        continue;
                    }
                    for i in 0..n {
                        let v = dk * jac[r][i];
                        if v != 0.0 {
                            for (hv, jv) in h[i * n..(i + 1) * n].iter_mut().zip(&jac[k]) {
                                *hv += v * jv;
                            }
                        }
                    }
                }
            }
        }
    }
}

crate::kernels::wide::dispatch! {
    fn clearances(c: &ObstacleConstraint, positions: &[[f64; 3]], out: &mut [f64]) => clearances_body
}

/// The rows' values from the positions (compiled twice, see [`crate::kernels::wide`]).
#[inline(always)]
fn clearances_body(c: &ObstacleConstraint, positions: &[[f64; 3]], out: &mut [f64]) {
    if c.chords {
        for (j, o) in out.iter_mut().enumerate() {
            *o = c.clearance - c.witness(positions, j).distance / c.length;
        }
        return;
    }
    // The sample points gathered a batch at a time, their distances side by side.
    use crate::kernels::written;
    use crate::scene::obstacle::BATCH;
    // Left uninitialised beyond the batch's points.
    let mut pts = [std::mem::MaybeUninit::<[f64; 3]>::uninit(); BATCH];
    for (o, samples) in out.chunks_mut(BATCH).zip(c.samples.chunks(BATCH)) {
        for (p, &b) in pts.iter_mut().zip(samples) {
            p.write(positions[b].map(|v| v * c.length));
        }
        // SAFETY: the first `samples.len()` are written just above.
        let pts = unsafe { written(&pts[..samples.len()]) };
        // The distances in place, then the rows.
        c.obstacle.signed_distance_values(pts, o);
        for o in o.iter_mut() {
            *o = c.clearance - *o / c.length;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ObstacleConstraint;
    use crate::scene::obstacle::{Obstacle, ObstacleShape};
    use std::sync::Arc;

    /// Rows on the chords of three sample points `xs` (case units, `L = 1`) near `shape`.
    fn witnesses(shape: ObstacleShape, xs: [[f64; 3]; 3]) -> Vec<super::Witness> {
        let c = ObstacleConstraint {
            obstacle: Arc::new(Obstacle::new("o".into(), shape, [0.0; 3], [0.0; 3])),
            samples: vec![0, 1, 2],
            clearance: 0.01,
            length: 1.0,
            chords: true,
        };
        (0..3).map(|j| c.witness(&xs, j)).collect()
    }

    /// Along a flat face a chord comes closest at one of its ends, which that end's own row
    /// keeps clear: each row is its own point's distance, however the chords tilt (a rod lying
    /// on a table has smooth rows, none switching to a chord's middle as it slides).
    #[test]
    fn rows_along_a_flat_face_are_their_points() {
        let table = || ObstacleShape::half_space([0.0, 0.0, 1.0]).unwrap();
        for tilt in [-1e-3, 0.0, 1e-3] {
            let xs = [
                [0.0, 0.0, 0.011],
                [0.05, 0.0, 0.011 + tilt],
                [0.1, 0.0, 0.011],
            ];
            for (j, w) in witnesses(table(), xs).iter().enumerate() {
                assert_eq!(w.t, 0.0, "row {j}, tilt {tilt}");
                assert_eq!(w.towards, j);
                assert!((w.distance - xs[j][2]).abs() < 1e-15);
            }
        }
    }

    /// Across a ball a chord dips below both its ends: the row whose half holds the chord's
    /// lowest point takes it, so that the polyline keeps clear.
    #[test]
    fn a_chord_across_a_ball_keeps_its_lowest_point() {
        let (r, h) = (0.1, 0.105);
        let xs = [[-0.2, 0.0, 0.0], [-0.03, 0.0, h], [0.05, 0.0, h]];
        let w = witnesses(ObstacleShape::ball(r), xs);
        // Between points 1 and 2 the chord passes over the ball's top at x = 0, three eighths
        // of the way from 1 towards 2: in point 1's half.
        let from_1 = w[1];
        assert_eq!(from_1.towards, 2);
        assert!((from_1.t - 0.375).abs() < 1e-9, "{}", from_1.t);
        assert!((from_1.distance - (h - r)).abs() < 1e-9);
        // Point 2's row, whose half does not hold it, keeps the chord's middle, which joins
        // the two rows continuously as the lowest point crosses it.
        assert_eq!((w[2].towards, w[2].t), (1, 0.5));
        assert!(w[2].distance > from_1.distance);
    }
}
