//! Verification and sample refinement of one start's plan: where the verification grid finds
//! tunnelling, or an energy peak the optimiser's samples missed, the grid's worst `k` (and its
//! neighbours) join the samples and the sharpest stage runs again from the current path. Every
//! start refines its own plan, so that the starts compete on verified paths.

use super::Planner;
use super::observer::Progress;
use super::optimise::StartRun;
use super::verify::Verification;

/// One start's plan after its verification and sample refinement.
#[derive(Clone)]
pub(super) struct Verified {
    /// The optimiser's outcome (evaluations include the refinement rounds').
    pub(super) run: StartRun,
    /// The plan on the verification grid.
    pub(super) verification: Verification,
    /// Samples of `k` added by the refinement rounds.
    pub(super) added: Vec<f64>,
}

impl Planner {
    /// Verifies start `start`'s plan `run` (optimised on the samples `uniform`) with `check`
    /// and refines its samples while the grid finds tunnelling or a missed peak, keeping the
    /// best verified path (collision-free first, then the lower true U_max).
    pub(super) fn refine(
        &self,
        start: usize,
        run: StartRun,
        uniform: &[f64],
        check: &(dyn Fn(&[f64]) -> Verification + Sync),
        sink: &mut dyn FnMut(Progress, Vec<f64>),
    ) -> Verified {
        let tol = self.collision_tolerance();
        let h = 1.0 / (self.settings.verify_k_samples - 1) as f64;
        let gap = self.settings.energy_gap_tolerance;
        let missed_peak = |r: &StartRun, v: &Verification| {
            v.u_max - r.sampled_max > gap * r.sampled_max.abs().max(v.u_max.abs())
        };
        let better = |a: &Verification, b: &Verification| {
            (a.collision_free(tol), -a.u_max) > (b.collision_free(tol), -b.u_max)
        };
        let mut chosen = run;
        let mut ver = check(&chosen.z);
        let mut ks = uniform.to_vec();
        let mut added = Vec::new();
        let mut kept: Option<(StartRun, Verification)> = None;
        for _ in 0..self.settings.sample_refinements {
            let tunnels = !ver.collision_free(tol);
            let peak = missed_peak(&chosen, &ver);
            if (!tunnels && !peak) || self.stopped() {
                break;
            }
            let worst_k: Vec<f64> = ver
                .obstacles
                .iter()
                .filter(|o| o.clearance < -tol)
                .map(|o| o.k)
                .chain(ver.self_contact.filter(|(g, _)| *g < -tol).map(|(_, k)| k))
                .chain(peak.then_some(ver.k_at_u_max))
                .collect();
            for kw in worst_k {
                // The grid's worst k and its grid neighbours, and the midpoints of the
                // optimiser's interval holding it and of the intervals on either side: the
                // sample spacing halves where the path tunnels or peaks.
                let mut cand = vec![kw - h, kw, kw + h];
                let i = ks
                    .iter()
                    .rposition(|&q| q <= kw)
                    .unwrap_or(0)
                    .min(ks.len() - 2);
                for j in i.saturating_sub(1)..(i + 2).min(ks.len() - 1) {
                    cand.push(0.5 * (ks[j] + ks[j + 1]));
                }
                for k in cand {
                    if k > 0.0 && k < 1.0 && !ks.iter().any(|&q| (q - k).abs() < 0.25 * h) {
                        ks.push(k);
                        added.push(k);
                    }
                }
            }
            ks.sort_by(f64::total_cmp);
            if kept.as_ref().is_none_or(|(_, kv)| better(&ver, kv)) {
                kept = Some((chosen.clone(), ver.clone()));
            }
            // Warm: only the sharpest stage again.
            let last = self.settings.sharpness.len() - 1;
            let r = self.optimise_from(start, chosen.z.clone(), &ks, last, sink);
            chosen = StartRun {
                evaluations: chosen.evaluations + r.evaluations,
                ..r
            };
            ver = check(&chosen.z);
        }
        if let Some((kr, kv)) = kept
            && better(&kv, &ver)
        {
            chosen = StartRun {
                evaluations: chosen.evaluations,
                ..kr
            };
            ver = kv;
        }
        Verified {
            run: chosen,
            verification: ver,
            added,
        }
    }
}
