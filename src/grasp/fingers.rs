//! Fingers as contact constraints (paper §6.2). A finger is a position constraint with exactly
//! one unilateral row — its normal: the finger can push but not pull — and equality rows for the
//! other coordinates (the contact sticks). Its multipliers are the contact force: the normal
//! force and the tangential (friction) force, which must stay inside the friction cone
//! `|f_t| ≤ μ f_n`.
//!
//! Two fingers at the same point with opposite normals form a *pinch* (grasp (b)). Rigid fingers
//! leave the squeeze indeterminate, so a pinch carries a preload `r0`: its fingers' normal forces
//! are `r0 ± P/2`, where `P` is the net normal force the pair exerts, and each carries half the
//! tangential force.

use crate::constraints::{Bound, Constraint};
use crate::statics::problem::StaticProblem;
use serde::Serialize;

/// One finger of a grasp.
#[derive(Clone, Debug)]
pub struct Finger {
    /// Label.
    pub name: String,
    /// Index of its constraint block in the problem.
    pub block: usize,
    /// Mesh boundary of the contact point.
    pub boundary: usize,
    /// Row of the normal within the block.
    pub normal_row: usize,
    /// Component of the normal.
    pub normal_component: usize,
    /// `+1` when the finger pushes towards `+component` (`≥` bound), `−1` otherwise.
    pub normal_sign: f64,
    /// Rows of the tangential (stick) equalities within the block.
    pub tangential_rows: Vec<usize>,
    /// The other finger of its pinch, if any.
    pub pinch_with: Option<usize>,
}

/// Contact force of one finger (case force units).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ContactForce {
    /// Normal force (≥ 0 while the contact holds).
    pub normal: f64,
    /// Magnitude of the tangential force.
    pub tangential: f64,
}

/// Finds the fingers among `p`'s constraints.
pub fn fingers(p: &StaticProblem) -> Vec<Finger> {
    let mut out: Vec<Finger> = Vec::new();
    for (block, con) in p.constraints.iter().enumerate() {
        let Constraint::Position(pc) = con else {
            continue;
        };
        let unilateral: Vec<usize> = (0..pc.rows.len())
            .filter(|&i| !matches!(pc.rows[i].1, Bound::Equal(_)))
            .collect();
        if unilateral.len() != 1 {
            continue;
        }
        let r = unilateral[0];
        let (comp, bound) = pc.rows[r];
        out.push(Finger {
            name: pc.name.clone(),
            block,
            boundary: pc.boundary,
            normal_row: r,
            normal_component: comp,
            normal_sign: if matches!(bound, Bound::AtLeast(_)) {
                1.0
            } else {
                -1.0
            },
            tangential_rows: (0..pc.rows.len()).filter(|&i| i != r).collect(),
            pinch_with: None,
        });
    }
    for i in 0..out.len() {
        for j in 0..out.len() {
            if i != j
                && out[i].boundary == out[j].boundary
                && out[i].normal_component == out[j].normal_component
                && out[i].normal_sign == -out[j].normal_sign
            {
                out[i].pinch_with = Some(j);
            }
        }
    }
    out
}

/// Contact forces of `fingers` from multipliers `lambda` (dimensionless) of problem `p`;
/// `preload` is the pinch squeeze (case force units).
pub fn contact_forces(
    p: &StaticProblem,
    fingers: &[Finger],
    lambda: &[f64],
    preload: f64,
) -> Vec<ContactForce> {
    let fu = p.model.rod.force_unit();
    let raw: Vec<(f64, f64)> = fingers
        .iter()
        .map(|f| {
            let rows = p.rows_of(f.block);
            let lam = &lambda[rows];
            let n = lam[f.normal_row].max(0.0) * fu;
            let t = f
                .tangential_rows
                .iter()
                .map(|&r| (lam[r] * fu).powi(2))
                .sum::<f64>()
                .sqrt();
            (n, t)
        })
        .collect();
    fingers
        .iter()
        .enumerate()
        .map(|(i, f)| match f.pinch_with {
            None => ContactForce {
                normal: raw[i].0,
                tangential: raw[i].1,
            },
            Some(j) => {
                // Net force of the pair on the rod along this finger's normal.
                let net = raw[i].0 - raw[j].0;
                ContactForce {
                    normal: preload + 0.5 * net,
                    tangential: 0.5 * (raw[i].1 + raw[j].1),
                }
            }
        })
        .collect()
}

/// The largest `|f_t|/f_n` over the fingers, `∞` when a normal force is not positive
/// (contact lost).
pub fn friction_ratio(forces: &[ContactForce], scale: f64) -> f64 {
    forces.iter().fold(0.0, |m, c| {
        if c.normal <= 1e-9 * scale {
            f64::INFINITY
        } else {
            m.max(c.tangential / c.normal)
        }
    })
}
