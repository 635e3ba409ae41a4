use dlo_planner::planner::{Planner, observer::Silent};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let case = dlo_planner::case::load(std::path::Path::new(&path)).unwrap();
    let t = std::time::Instant::now();
    let pl = Planner::from_case(&case).unwrap();
    println!(
        "endpoints {:?} U0 {} U1 {}",
        t.elapsed(),
        pl.start.energy.potential(),
        pl.goal.energy.potential()
    );
    let _ = time_eval;
    let r = pl.run(&mut Silent);
    let mut v = serde_json::to_value(&r).unwrap();
    v["replay"]["steps"] = serde_json::Value::Null;
    println!("{}", serde_json::to_string_pretty(&v).unwrap());
    for s in r.replay.steps.iter() {
        println!(
            "k {:.3} d {:.4} uo {:.3} uf {:.3} st {:?} conv {}",
            s.k, s.deviation, s.u_optimal, s.u_feasible, s.stable, s.converged
        );
    }
}
#[allow(dead_code)]
fn dbg_start(pl: &Planner) {
    use dlo_planner::planner::endpoints::EndPose;
    let m = &pl.base.model;
    let sh = m.evaluate(&pl.start.a);
    let pose = EndPose::of(m, &pl.start.a, &sh.positions);
    println!("pose {:?}", pose);
    let sol = dlo_planner::planner::endpoints::solve_end(
        &pl.base,
        &pose,
        &pl.start.a,
        &pl.static_options,
    );
    println!("a0 {:?}\nsol {:?} {:?}", pl.start.a, sol.a, sol.status);
}
#[allow(dead_code)]
pub fn time_eval(pl: &Planner) {
    use dlo_planner::optim::Nlp;
    let mut p = pl.minimax_problem();
    p.beta = 10.0;
    let n = p.n();
    let z: Vec<f64> = (0..n).map(|i| 0.01 * (i as f64).sin()).collect();
    let mut c = vec![0.0; p.m()];
    let y = vec![0.1; p.m()];
    let mut g = vec![0.0; n];
    let t = std::time::Instant::now();
    for _ in 0..1000 {
        p.values(&z, &mut c);
    }
    println!("values {:?}/eval (m = {})", t.elapsed() / 1000, p.m());
    let t = std::time::Instant::now();
    for _ in 0..1000 {
        p.gradient(&z, &y, &mut g);
    }
    println!("gradient {:?}/eval", t.elapsed() / 1000);
}
