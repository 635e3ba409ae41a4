//! The `grasp` section of a case file: the case's static problem as a [`GraspProblem`] and the
//! section as [`GraspSettings`].

use crate::case::Case;
use crate::error::Error;
use crate::grasp::Grasp;
use crate::grasp::margin::{GraspProblem, GraspSettings};

impl Grasp {
    /// Validates the case's `grasp` section and solves the undisturbed grasp: the case file as
    /// a [`GraspProblem`] and [`GraspSettings`] for [`Grasp::new`].
    pub fn from_case(case: &Case) -> Result<Grasp, Error> {
        let err = |field: String, message: String| Error::invalid(&case.path, field, message);
        let Some(raw) = &case.grasp else {
            return Err(err(
                "grasp".into(),
                "missing: `dlo margin` needs a `grasp` section".into(),
            ));
        };
        let settings: GraspSettings = super::field_path::read_in("grasp", raw.clone())
            .map_err(|(field, message)| err(field, message))?;
        let problem = GraspProblem {
            statics: case.builder.clone(),
            initial: case.initial.clone(),
            static_settings: case.file.solver,
        };
        Grasp::new(problem, settings).map_err(|e| {
            let field = if e.field == "constraints" {
                e.field
            } else {
                format!("grasp.{}", e.field)
            };
            err(field, e.message)
        })
    }
}
