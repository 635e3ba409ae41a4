//! Grasp stability (paper §6): fingers as contact constraints with friction cones
//! ([`fingers`]) and the disturbance force margin ([`margin`]).

pub mod fingers;
pub mod margin;

pub use margin::{Directions, Grasp, GraspProblem, GraspSettings, Limit, Margin, MarginReport};
