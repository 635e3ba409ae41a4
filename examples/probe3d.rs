use dlo_planner::planner::{Planner, clearance};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let case = dlo_planner::case::load(std::path::Path::new(&path)).unwrap();
    let pl = Planner::from_case(&case).unwrap();
    let m = &pl.base.model;
    for (n, s) in [("start", &pl.start), ("goal", &pl.goal)] {
        let sh = m.evaluate(&s.a);
        println!(
            "{n}: {:?} U {:.4} clearance {:?}",
            s.status,
            s.energy.potential(),
            clearance(&pl.base, &sh.positions)
        );
    }
}
