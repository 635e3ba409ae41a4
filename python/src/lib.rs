//! `dlo_planner._dlo`: the Python bindings of dlo-planner. The domain types (rod, obstacles,
//! static problem, end poses, case files) are classes here; results are the pure-Python
//! classes of `dlo_planner.results`, built from the same JSON reports the CLI prints plus
//! NumPy arrays. Every solve releases the GIL.

mod case;
mod errors;
mod grasp;
mod logs;
mod model;
mod observer;
mod plan;
mod settings;
mod shape;

use pyo3::prelude::*;

/// The Rust core of `dlo_planner`; use the package, not this module.
#[pymodule]
fn _dlo(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("InputError", m.py().get_type::<errors::InputError>())?;
    m.add(
        "UnreachableError",
        m.py().get_type::<errors::UnreachableError>(),
    )?;
    m.add_class::<model::Rod>()?;
    m.add_class::<model::Obstacle>()?;
    m.add_class::<model::StaticProblem>()?;
    m.add_class::<model::End>()?;
    m.add_class::<case::Case>()?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(grasp::grasp_margin, m)?)?;
    m.add_function(wrap_pyfunction!(shape::solve_repeatedly, m)?)?;
    Ok(())
}
