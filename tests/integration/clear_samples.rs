//! The planner keeps the rows, and where it can leaves out the shapes, of sampled paths that
//! certainly keep clear of every obstacle (`MinimaxProblem::set_skip_clear_samples`): the
//! displacement bound it relies on, and that the optimisation is the same bit for bit with and
//! without it.

use dlo_planner::case;
use dlo_planner::optim::{AlOutcome, Nlp, augmented_lagrangian};
use dlo_planner::planner::Planner;
use std::path::Path;

fn planner(name: &str) -> Planner {
    let c = case::load(&Path::new("planning_cases").join(name)).unwrap();
    Planner::from_case(&c).unwrap()
}

/// Deterministic numbers in [−1, 1].
fn wave(n: usize, seed: f64) -> Vec<f64> {
    (0..n).map(|i| ((i as f64 + 1.0) * seed).sin()).collect()
}

/// `|x_b(a) − x_b(a′)| ≤ Σᵢ ωᵢ |aᵢ − a′ᵢ|` at every boundary, for 300 pairs of planar shapes
/// at distances from 1e-6 to 3 in coefficients; and the weights exist only for rods whose
/// positions depend on θ alone.
#[test]
fn position_bound_weights_bound_the_displacement() {
    let pl = planner("plan_paper_planar.json");
    let m = &pl.base.model;
    let omega = m
        .position_bound_weights()
        .expect("a planar inextensible rod");
    let n = m.n();
    let mut tightest: f64 = 0.0;
    for t in 0..300 {
        let scale = 10f64.powf(-6.0 + 6.5 * (t as f64) / 299.0);
        let a: Vec<f64> = wave(n, 0.7 + 0.01 * t as f64)
            .iter()
            .map(|v| 2.0 * v)
            .collect();
        let d = wave(n, 1.3 + 0.017 * t as f64);
        let b: Vec<f64> = a.iter().zip(&d).map(|(x, y)| x + scale * y).collect();
        let (xa, xb) = (m.evaluate(&a).positions, m.evaluate(&b).positions);
        let moved = xa
            .iter()
            .zip(&xb)
            .map(|(p, q)| {
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        let bound: f64 = omega
            .iter()
            .zip(a.iter().zip(&b))
            .map(|(w, (x, y))| w * (x - y).abs())
            .sum();
        assert!(
            moved <= bound * (1.0 + 1e-12),
            "pair {t}: moved {moved} > bound {bound}"
        );
        tightest = tightest.max(moved / bound);
    }
    // Not vacuous: some pair moves a boundary by more than a tenth of the bound.
    assert!(tightest > 0.1, "{tightest}");
    let bar = planner("plan_cable_under_bar.json");
    assert!(bar.base.model.position_bound_weights().is_none());
}

/// The multiplier method on the paper's planning problem with the paper's objective (no travel
/// term, which reads every sample's shape; the first sharpness stage, from a perturbed straight
/// path) ends at the same path, multipliers and objective bit for bit
/// whether the problem leaves out the shapes of samples clear of the block or not — and it
/// does leave out most of them.
/// The first sharpness stage of the paper's planning problem, from a perturbed straight path,
/// with the travel term's weight `travel`, keeping clear samples' rows (and shapes) or not:
/// the path, the outcome, the shapes left out, the rows kept and the number of samples.
fn first_stage(
    pl: &Planner,
    skip: bool,
    travel: f64,
) -> (Vec<f64>, AlOutcome, usize, usize, usize) {
    let mut p = pl.minimax_problem();
    p.set_skip_clear_samples(skip);
    p.mean_weight = 1.0;
    p.travel_weight = travel;
    p.beta = 10.0 / 2.5466;
    let mut z: Vec<f64> = wave(p.n(), 0.9).iter().map(|v| 0.01 * v).collect();
    let out = augmented_lagrangian(&mut p, &mut z, None, pl.stage_options());
    (z, out, p.shapes_left_out(), p.rows_kept(), p.ks.len())
}

/// The same path, multipliers, objective, violation, status and evaluations to the bit.
fn assert_same_run(z_on: &[f64], on: &AlOutcome, z_off: &[f64], off: &AlOutcome) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(z_on), bits(z_off));
    assert_eq!(bits(&on.lambda), bits(&off.lambda));
    assert_eq!(on.f.to_bits(), off.f.to_bits());
    assert_eq!(on.max_violation.to_bits(), off.max_violation.to_bits());
    assert_eq!(on.status, off.status);
    assert_eq!(on.evaluations, off.evaluations);
}

#[test]
fn leaving_out_clear_samples_changes_nothing() {
    let pl = planner("plan_paper_planar.json");
    let (z_on, on, left_out, _, nk) = first_stage(&pl, true, 0.0);
    let (z_off, off, none, _, _) = first_stage(&pl, false, 0.0);
    assert_eq!(none, 0);
    assert_same_run(&z_on, &on, &z_off, &off);
    assert!(
        left_out * 2 > on.evaluations * nk,
        "{left_out} of {} sampled shapes left out",
        on.evaluations * nk
    );
}

/// With the travel term, which reads every sample's end position, every shape is evaluated,
/// but the rows of samples clear of the block are still kept from their last evaluation: the
/// multiplier method ends at the same path, multipliers and objective bit for bit, and most
/// samples keep their rows.
#[test]
fn keeping_clear_rows_with_the_travel_term_changes_nothing() {
    let pl = planner("plan_paper_planar.json");
    let (z_on, on, left_out, kept, nk) = first_stage(&pl, true, 0.5);
    let (z_off, off, _, none, _) = first_stage(&pl, false, 0.5);
    assert_eq!((left_out, none), (0, 0));
    assert_same_run(&z_on, &on, &z_off, &off);
    assert!(
        kept * 2 > on.evaluations * (nk - 2),
        "{kept} of {} samples' rows kept",
        on.evaluations * (nk - 2)
    );
}
