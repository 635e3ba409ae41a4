//! Grasp stability (paper §6): fingers as contact constraints with friction cones
//! ([`fingers`]) and the disturbance force margin ([`margin`]).

pub mod fingers;
pub mod margin;

pub use margin::{Grasp, Limit, Margin};
