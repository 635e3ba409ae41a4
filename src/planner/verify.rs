//! Verification of a path on a grid of `(s, k)` the optimiser never saw: the true maximum
//! energy and the worst clearance to every obstacle. A path that tunnels through an obstacle
//! between the optimiser's samples shows up here as a negative clearance.

use crate::planner::path::DeformationPath;
use crate::planner::workers::{JOB_VERIFY, Workers};
use crate::rod::energy::Objective;
use crate::rod::kinematics::Shape;
use crate::rod::model::{Discretisation, Model};
use crate::scene::obstacle::Obstacle;
use serde::Serialize;
use std::sync::Arc;

/// The verification model: the case's rod with `s_intervals` uniform sample points as panel
/// boundaries (a finer quadrature than the optimiser's as well), in the same angles' frame.
pub fn fine_model(model: &Model, s_intervals: usize, gauss_points: usize) -> Model {
    let pts: Vec<f64> = (0..=s_intervals)
        .map(|j| j as f64 / s_intervals as f64)
        .collect();
    let fine = Model::new(
        model.rod.clone(),
        model.layout,
        Discretisation {
            panels: s_intervals,
            gauss_points,
        },
        model.base,
        model.loads.clone(),
        &pts,
    );
    match model.angle_frame() {
        Some(r) => fine
            .with_frame(r)
            .expect("the case's model took this frame"),
        None => fine,
    }
}

/// Worst clearance to one obstacle.
#[derive(Clone, Debug, Serialize)]
pub struct ObstacleClearance {
    /// Obstacle name.
    pub obstacle: String,
    /// Smallest surface gap `d − r` (case units; negative = penetration).
    pub clearance: f64,
    /// Where along the path.
    pub k: f64,
    /// Where along the rod (case units).
    pub s: f64,
}

/// Result of [`verify`].
#[derive(Clone, Debug, Serialize)]
pub struct Verification {
    /// Largest energy on the grid (case units).
    pub u_max: f64,
    /// `k` where it occurs.
    pub k_at_u_max: f64,
    /// Energy at every grid `k` (case units).
    #[serde(skip)]
    pub energies: Vec<f64>,
    /// Grid `k`.
    #[serde(skip)]
    pub ks: Vec<f64>,
    /// Per obstacle.
    pub obstacles: Vec<ObstacleClearance>,
    /// Smallest over obstacles (case units), `None` without obstacles.
    pub min_clearance: Option<f64>,
    /// With self-contact: the smallest gap `d − 2r` between chords of the rod at least `2r`
    /// apart along it (case units; 64 chords per shape), and the `k` where it occurs.
    pub self_contact: Option<(f64, f64)>,
}

impl Verification {
    /// Whether no obstacle is penetrated (within `tol`, case units).
    pub fn collision_free(&self, tol: f64) -> bool {
        self.min_clearance.is_none_or(|c| c >= -tol)
            && self.self_contact.is_none_or(|(g, _)| g >= -tol)
    }

    /// Whether the grid's largest energy is an end shape's (at `k = 0` or `k = 1`, to
    /// rounding, [`attains_end_energy`]): the path attains the lower bound on every path's
    /// `U_max` (the larger end energy), since every path passes through both end shapes.
    pub fn peaks_at_an_end(&self) -> bool {
        match (self.energies.first(), self.energies.last()) {
            (Some(&first), Some(&last)) => attains_end_energy(self.u_max, first.max(last)),
            _ => self.k_at_u_max == 0.0 || self.k_at_u_max == 1.0,
        }
    }
}

/// Relative rounding within which a path's largest energy counts as its larger end energy.
/// The energies inside a path whose shapes do not change (start and goal the same pose) differ
/// from the ends' in their last bits (the samples' coefficients are `(1−k)a₀ + k·a₁`), and such
/// a path attains the lower bound on `U_max` all the same.
pub const END_ENERGY_ROUNDING: f64 = 1e-12;

/// Whether `top`, the largest energy along a path, is `ends`, its larger end energy, to
/// [`END_ENERGY_ROUNDING`]: the path then attains the lower bound on every path's `U_max`.
pub fn attains_end_energy(top: f64, ends: f64) -> bool {
    top <= ends + END_ENERGY_ROUNDING * ends.abs().max(top.abs())
}

/// A shape's points in case units and, per obstacle, every point's surface gap `d − r`.
type ShapeGaps = (Vec<[f64; 3]>, Vec<Vec<f64>>);

/// [`ShapeGaps`] of the shape with dimensionless boundary `positions`.
fn gaps_at(fine: &Model, obstacles: &[Arc<Obstacle>], positions: &[[f64; 3]]) -> ShapeGaps {
    let (l, r) = (fine.rod.length, fine.rod.radius);
    let pts: Vec<[f64; 3]> = positions.iter().map(|p| p.map(|v| v * l)).collect();
    let gaps = obstacles
        .iter()
        .map(|o| {
            let mut d = vec![0.0; pts.len()];
            o.signed_distance_values(&pts, &mut d);
            d.iter_mut().for_each(|d| *d -= r);
            d
        })
        .collect();
    (pts, gaps)
}

/// Records the gaps of the shape at `k` in each obstacle's worst clearance.
fn record(fine: &Model, gaps: &[Vec<f64>], k: f64, worst: &mut [ObstacleClearance]) {
    for (g, w) in gaps.iter().zip(worst.iter_mut()) {
        for (b, &gap) in g.iter().enumerate() {
            if gap < w.clearance {
                w.clearance = gap;
                w.k = k;
                w.s = fine.mesh.boundaries[b] * fine.rod.length;
            }
        }
    }
}

/// The smallest chord bound `(g(p) + g(q) − |q − p|)/2` of any point and obstacle between two
/// shapes (case units); with `skip_inside`, leaving out points inside the obstacle in either
/// shape (their collision is on the grid already; bisecting only measures its depth).
fn chord_bound(a: &ShapeGaps, b: &ShapeGaps, skip_inside: bool) -> f64 {
    let mut lo = f64::INFINITY;
    for (ga, gb) in a.1.iter().zip(&b.1) {
        for j in 0..a.0.len() {
            if skip_inside && (ga[j] < 0.0 || gb[j] < 0.0) {
                continue;
            }
            let (p, q) = (a.0[j], b.0[j]);
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            lo = lo.min(0.5 * (ga[j] + gb[j] - d));
        }
    }
    lo
}

/// Bisects `(k0, k1)` while the chord bound between its ends is negative (see
/// [`chord_bound`] for `skip_inside`), up to `depth` times, recording every evaluated shape's
/// clearances in `worst`.
#[allow(clippy::too_many_arguments)]
fn between(
    fine: &Model,
    path: &DeformationPath,
    z: &[f64],
    obstacles: &[Arc<Obstacle>],
    lo: (f64, &ShapeGaps),
    hi: (f64, &ShapeGaps),
    depth: usize,
    skip_inside: bool,
    worst: &mut [ObstacleClearance],
) {
    if depth == 0 || chord_bound(lo.1, hi.1, skip_inside) >= 0.0 {
        return;
    }
    let k = 0.5 * (lo.0 + hi.0);
    let mut a = vec![0.0; path.n()];
    path.shape_at(z, k, &mut a);
    let mid = gaps_at(fine, obstacles, &fine.evaluate(&a).positions);
    record(fine, &mid.1, k, worst);
    between(
        fine,
        path,
        z,
        obstacles,
        lo,
        (k, &mid),
        depth - 1,
        skip_inside,
        worst,
    );
    between(
        fine,
        path,
        z,
        obstacles,
        (k, &mid),
        hi,
        depth - 1,
        skip_inside,
        worst,
    );
}

/// Each obstacle's worst clearance before any shape is seen (infinite).
fn unseen(obstacles: &[Arc<Obstacle>]) -> Vec<ObstacleClearance> {
    obstacles
        .iter()
        .map(|o| ObstacleClearance {
            obstacle: o.name.clone(),
            clearance: f64::INFINITY,
            k: 0.0,
            s: 0.0,
        })
        .collect()
}

/// The fine grid's self-contact chords: 64 through every fourth-or-so boundary, and the pairs
/// of them at least `2r` apart along the rod (none without self-contact).
fn self_contact_chords(fine: &Model, self_contact: bool) -> (Vec<usize>, Vec<(usize, usize)>) {
    let nb = fine.mesh.boundaries.len();
    let stride = ((nb - 1) / 64).max(1);
    let chord_pts: Vec<usize> = (0..nb).step_by(stride).collect();
    let chord_t: Vec<f64> = chord_pts.iter().map(|&b| fine.mesh.boundaries[b]).collect();
    let pairs = if self_contact {
        crate::constraints::SelfContactConstraint::new(
            chord_pts.clone(),
            &chord_t,
            2.0 * fine.rod.radius / fine.rod.length,
        )
        .pairs
    } else {
        Vec::new()
    };
    (chord_pts, pairs)
}

/// The smallest gap `d − 2r` (case units) between the chord `pairs` of a shape with
/// dimensionless boundary `positions` (`None` without pairs).
fn self_gap(
    fine: &Model,
    chord_pts: &[usize],
    pairs: &[(usize, usize)],
    positions: &[[f64; 3]],
) -> Option<f64> {
    let (l, r) = (fine.rod.length, fine.rod.radius);
    pairs
        .iter()
        .map(|&(i, j)| {
            let x = |q: usize| positions[chord_pts[q]].map(|v| v * l);
            let (_, _, d) = crate::constraints::segment_distance(x(i), x(i + 1), x(j), x(j + 1));
            d - 2.0 * r
        })
        .reduce(f64::min)
}

/// Clearances of given shapes (not a path) on the fine grid: each obstacle's worst, and the
/// worst self-contact gap with `self_contact` (`(gap, k)`), over `shapes` (`k` and Ritz
/// coefficients).
pub fn shapes_clearance<'a>(
    fine: &Model,
    obstacles: &[Arc<Obstacle>],
    self_contact: bool,
    shapes: impl IntoIterator<Item = (f64, &'a [f64])>,
) -> (Vec<ObstacleClearance>, Option<(f64, f64)>) {
    let (chord_pts, pairs) = self_contact_chords(fine, self_contact);
    let mut worst = unseen(obstacles);
    let mut worst_self: Option<(f64, f64)> = None;
    let mut shape = Shape::default();
    for (k, a) in shapes {
        fine.evaluate_into(a, &mut shape);
        let g = gaps_at(fine, obstacles, &shape.positions);
        record(fine, &g.1, k, &mut worst);
        if let Some(gap) = self_gap(fine, &chord_pts, &pairs, &shape.positions)
            && worst_self.is_none_or(|(w, _)| gap < w)
        {
            worst_self = Some((gap, k));
        }
    }
    (worst, worst_self)
}

/// The worst obstacle clearance of the shape of coefficients `a` on the fine grid (the first
/// obstacle among equals; `None` without obstacles).
pub fn shape_worst_clearance(
    fine: &Model,
    obstacles: &[Arc<Obstacle>],
    a: &[f64],
) -> Option<ObstacleClearance> {
    let (worst, _) = shapes_clearance(fine, obstacles, false, [(0.0, a)]);
    worst
        .into_iter()
        .min_by(|p, q| p.clearance.total_cmp(&q.clearance))
}

/// Evaluates `path(z)` on `k_samples` uniform values of `k` with the fine model, and between
/// them wherever a point could reach an obstacle (see [`verify_with`]).
pub fn verify(
    fine: &Model,
    path: &DeformationPath,
    z: &[f64],
    k_samples: usize,
    obstacles: &[Arc<Obstacle>],
    objective: Objective,
) -> Verification {
    verify_with(fine, path, z, k_samples, obstacles, objective, false)
}

/// [`verify`], also checking self-contact when `self_contact` is set.
pub fn verify_with(
    fine: &Model,
    path: &DeformationPath,
    z: &[f64],
    k_samples: usize,
    obstacles: &[Arc<Obstacle>],
    objective: Objective,
    self_contact: bool,
) -> Verification {
    verify_grid(
        fine,
        path,
        z,
        k_samples,
        obstacles,
        objective,
        self_contact,
        false,
        &Workers::serial(),
    )
}

/// One grid shape's verification: its energy (case units), points and gaps, each obstacle's
/// worst clearance on it, and its self-contact gap.
struct GridShape {
    energy: f64,
    gaps: ShapeGaps,
    worst: Vec<ObstacleClearance>,
    self_gap: Option<f64>,
}

/// Takes `part`'s worst clearances into `worst`, `part` coming after everything `worst` has
/// seen: the first of equal minima stays, as if every shape had been recorded in order.
fn merge(worst: &mut [ObstacleClearance], part: &[ObstacleClearance]) {
    for (w, p) in worst.iter_mut().zip(part) {
        if p.clearance < w.clearance {
            *w = p.clone();
        }
    }
}

/// [`verify_with`], its shapes shared out over `workers` (each grid shape, then each interval
/// between grid values, on its own; the parts are merged in `k` order, so that the result is
/// the same bit for bit on any number of threads); with `skip_inside`, for a report (the
/// straight-line path's): where a point lies inside an obstacle at either of two consecutive
/// grid values, the collision is reported on the grid, and the interval between them is not
/// bisected for that point to measure its depth (or where it enters) there.
#[allow(clippy::too_many_arguments)]
pub(crate) fn verify_grid(
    fine: &Model,
    path: &DeformationPath,
    z: &[f64],
    k_samples: usize,
    obstacles: &[Arc<Obstacle>],
    objective: Objective,
    self_contact: bool,
    skip_inside: bool,
    workers: &Workers,
) -> Verification {
    let (chord_pts, pairs) = self_contact_chords(fine, self_contact);
    let unit = fine.rod.energy_unit();
    let ks: Vec<f64> = (0..k_samples)
        .map(|j| j as f64 / (k_samples - 1) as f64)
        .collect();
    let mut slots: Vec<Option<GridShape>> = (0..k_samples).map(|_| None).collect();
    workers.for_each_chunk(JOB_VERIFY, &mut slots, |j0, chunk| {
        let mut a = vec![0.0; path.n()];
        let mut shape = Shape::default();
        for (i, slot) in chunk.iter_mut().enumerate() {
            let k = ks[j0 + i];
            path.shape_at(z, k, &mut a);
            fine.evaluate_into(&a, &mut shape);
            let t = fine.energy(&a, &shape, objective, None);
            let gaps = gaps_at(fine, obstacles, &shape.positions);
            let mut worst = unseen(obstacles);
            record(fine, &gaps.1, k, &mut worst);
            *slot = Some(GridShape {
                energy: unit * t.value(objective),
                gaps,
                worst,
                self_gap: self_gap(fine, &chord_pts, &pairs, &shape.positions),
            });
        }
    });
    let grid: Vec<GridShape> = slots
        .into_iter()
        .map(|g| g.expect("every grid shape is evaluated"))
        .collect();
    let mut worst = unseen(obstacles);
    let mut worst_self: Option<(f64, f64)> = None;
    for (g, &k) in grid.iter().zip(&ks) {
        merge(&mut worst, &g.worst);
        if let Some(gap) = g.self_gap
            && worst_self.is_none_or(|(w, _)| gap < w)
        {
            worst_self = Some((gap, k));
        }
    }
    let energies: Vec<f64> = grid.iter().map(|g| g.energy).collect();
    // Between grid values: a point moving from p to q keeps at least (g(p) + g(q) − |q − p|)/2
    // from an obstacle along the chord (the gap g is 1-Lipschitz). Where that bound goes below
    // zero, the interval is bisected (to 1/64 of it) and every shape evaluated there counts, so
    // that a path tunnelling between grid values is found instead of called collision-free.
    if !obstacles.is_empty() {
        let mut parts: Vec<Vec<ObstacleClearance>> = (0..k_samples.saturating_sub(1))
            .map(|_| Vec::new())
            .collect();
        workers.for_each_chunk(JOB_VERIFY, &mut parts, |j0, chunk| {
            for (i, part) in chunk.iter_mut().enumerate() {
                let w = j0 + i;
                *part = unseen(obstacles);
                between(
                    fine,
                    path,
                    z,
                    obstacles,
                    (ks[w], &grid[w].gaps),
                    (ks[w + 1], &grid[w + 1].gaps),
                    6,
                    skip_inside,
                    part,
                );
            }
        });
        for part in &parts {
            merge(&mut worst, part);
        }
    }
    let (jmax, &u_max) = energies
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .expect("at least one sample");
    let min_clearance = worst.iter().map(|w| w.clearance).reduce(f64::min);
    Verification {
        u_max,
        k_at_u_max: ks[jmax],
        energies,
        ks,
        obstacles: worst,
        min_clearance,
        self_contact: worst_self,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's straight path runs 0.205 deep through the block, and a bent path near it
    /// grazes the block's corner: the verification shared over three threads (six calls, so
    /// that both ways of running its jobs are taken, [`Workers`]) gives the serial one bit for
    /// bit, grid energies, each obstacle's worst clearance and where it lies, with and without
    /// `skip_inside`.
    #[test]
    fn verification_is_the_same_on_any_number_of_threads() {
        let p = crate::planner::paper_planner();
        let fine = fine_model(&p.base.model, 256, 4);
        let path = p.path();
        let bent: Vec<f64> = (0..path.n_vars())
            .map(|i| 0.3 * ((i as f64) * 0.7).sin())
            .collect();
        let straight = vec![0.0; path.n_vars()];
        let team = Workers::new(3);
        for (z, skip_inside) in [(&straight, true), (&straight, false), (&bent, false)] {
            let run = |w: &Workers| {
                verify_grid(
                    &fine,
                    &path,
                    z,
                    201,
                    &p.obstacles,
                    p.base.objective,
                    true,
                    skip_inside,
                    w,
                )
            };
            let serial = run(&Workers::serial());
            assert!(serial.min_clearance.is_some_and(|c| c.is_finite()));
            for _ in 0..6 {
                assert_eq!(format!("{:?}", run(&team)), format!("{serial:?}"));
            }
        }
    }
}
