//! Self-interference (eq. 17): chords between consecutive sample points must stay at least
//! `2r` apart, `c = 2r/L − dist(segᵢ, segⱼ) ≤ 0`, for every pair of chords separated along the
//! rod by at least `2r` of arc length (the paper's condition `|sᵢ − sⱼ| ≥ r(sᵢ) + r(sⱼ)`).
//! Chord–chord distance (not point–point) keeps a strand from slipping between two samples.

use super::{Adjoint, Rows};
use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;

/// Self-contact among chords through sample boundaries.
#[derive(Clone, Debug)]
pub struct SelfContactConstraint {
    /// Sample boundaries in increasing arc length.
    pub samples: Vec<usize>,
    /// Chord pairs `(i, j)` (chord `i` joins samples `i` and `i+1`).
    pub pairs: Vec<(usize, usize)>,
    /// Required distance `2r/L`.
    pub min_distance: f64,
}

impl SelfContactConstraint {
    /// Pairs of chords whose arc-length gap is at least `2r/L`; `ts` are the samples' `t`.
    pub fn new(samples: Vec<usize>, ts: &[f64], min_distance: f64) -> Self {
        let k = samples.len().saturating_sub(1);
        let mut pairs = Vec::new();
        for i in 0..k {
            for j in i + 2..k {
                if ts[j] - ts[i + 1] >= min_distance - 1e-12 {
                    pairs.push((i, j));
                }
            }
        }
        SelfContactConstraint {
            samples,
            pairs,
            min_distance,
        }
    }
}

/// Closest points of segments `p1q1`, `p2q2` (Ericson, *Real-Time Collision Detection* §5.1.9):
/// returns `(s, t, distance)` with the closest points `p1 + s(q1−p1)`, `p2 + t(q2−p2)`.
pub fn segment_distance(p1: [f64; 3], q1: [f64; 3], p2: [f64; 3], q2: [f64; 3]) -> (f64, f64, f64) {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (d1, d2, r) = (sub(q1, p1), sub(q2, p2), sub(p1, p2));
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let eps = 1e-300;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = dot(d1, r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = dot(d1, d2);
            let denom = a * e - b * b;
            let mut s = if denom > 1e-14 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    let c1 = [p1[0] + d1[0] * s, p1[1] + d1[1] * s, p1[2] + d1[2] * s];
    let c2 = [p2[0] + d2[0] * t, p2[1] + d2[1] * t, p2[2] + d2[2] * t];
    let d = sub(c1, c2);
    (s, t, dot(d, d).sqrt())
}

impl SelfContactConstraint {
    /// The contact forces of the multipliers `lambda` (one per pair, dimensionless forces): for
    /// every pair that pushes, the dimensionless arc lengths `(t_a, t_b)`, `t_a < t_b`, of its
    /// closest points and the force on the strand at `t_a`, along the line from the closest
    /// point at `t_b` to it (the strand at `t_b` takes the opposite force).
    pub fn contacts(&self, m: &Model, shape: &Shape, lambda: &[f64]) -> Vec<([f64; 2], [f64; 3])> {
        let t = |b: usize| m.mesh.boundaries[b];
        let mut out = Vec::new();
        for (&li, &(i, j)) in lambda.iter().zip(&self.pairs) {
            if li <= 0.0 {
                continue;
            }
            let Some((s, u, n)) = self.closest(shape, i, j) else {
                continue;
            };
            let along = |c: usize, f: f64| {
                let (a, b) = (t(self.samples[c]), t(self.samples[c + 1]));
                a + f * (b - a)
            };
            out.push(([along(i, s), along(j, u)], n.map(|v| li * v)));
        }
        out
    }

    /// The closest points of chords `i` and `j` as their parameters along each chord, and the
    /// unit vector from the point on `j` to the point on `i` (`None` where the chords meet).
    fn closest(&self, shape: &Shape, i: usize, j: usize) -> Option<(f64, f64, [f64; 3])> {
        let (p1, q1) = self.chord(shape, i);
        let (p2, q2) = self.chord(shape, j);
        let (s, t, d) = segment_distance(p1, q1, p2, q2);
        if d < 1e-300 {
            return None;
        }
        let c1: [f64; 3] = std::array::from_fn(|k| p1[k] + s * (q1[k] - p1[k]));
        let c2: [f64; 3] = std::array::from_fn(|k| p2[k] + t * (q2[k] - p2[k]));
        Some((s, t, std::array::from_fn(|k| (c1[k] - c2[k]) / d)))
    }

    fn chord(&self, shape: &Shape, i: usize) -> ([f64; 3], [f64; 3]) {
        (
            shape.positions[self.samples[i]],
            shape.positions[self.samples[i + 1]],
        )
    }
}

impl Rows for SelfContactConstraint {
    fn label(&self) -> String {
        "self contact".into()
    }
    fn rows(&self) -> usize {
        self.pairs.len()
    }
    fn sense(&self, _i: usize) -> Sense {
        Sense::LessEq
    }
    fn values(&self, _m: &Model, _a: &[f64], shape: &Shape, out: &mut [f64]) {
        for (o, &(i, j)) in out.iter_mut().zip(&self.pairs) {
            let (p1, q1) = self.chord(shape, i);
            let (p2, q2) = self.chord(shape, j);
            *o = self.min_distance - segment_distance(p1, q1, p2, q2).2;
        }
    }
    fn add_gradient(&self, _m: &Model, _a: &[f64], shape: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (&wi, &(i, j)) in w.iter().zip(&self.pairs) {
            if wi == 0.0 {
                continue;
            }
            let Some((s, t, n)) = self.closest(shape, i, j) else {
                continue;
            };
            // c = min − d: ∂c/∂x = −∂d/∂x.
            adj.add_pos(self.samples[i], -wi * (1.0 - s), n);
            adj.add_pos(self.samples[i + 1], -wi * s, n);
            adj.add_pos(self.samples[j], wi * (1.0 - t), n);
            adj.add_pos(self.samples[j + 1], wi * t, n);
        }
    }
}
