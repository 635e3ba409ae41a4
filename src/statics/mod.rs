//! Static shapes (paper §4): the problem (energy and constraints as a nonlinear program), its
//! solve by the multiplier method, the reactions its multipliers give, the moment balance that
//! checks them, the stability verdict, and the reports.

pub mod balance;
pub mod builder;
pub mod problem;
pub mod reactions;
pub mod report;
pub mod settings;
mod solve;
pub mod stability;

pub use builder::{BuildError, StaticProblemBuilder};
pub use problem::StaticProblem;
pub use reactions::{Reaction, SelfContactForce, reactions, self_contacts};
pub use settings::StaticSettings;
pub use solve::*;
