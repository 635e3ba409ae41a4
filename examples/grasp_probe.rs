use dlo_planner::grasp::Grasp;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let sa: f64 = std::env::args().nth(2).unwrap().parse().unwrap();
    let case = dlo_planner::case::load(std::path::Path::new(&path)).unwrap();
    let g = Grasp::from_case(&case).unwrap();
    println!("initial forces {:?} f_max {}", g.initial_forces, g.f_max);
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let t = std::time::Instant::now();
    let lim = g.limit(sa, [h, 0.0, -h]).unwrap();
    println!("{:?} in {:?}", lim, t.elapsed());
}
