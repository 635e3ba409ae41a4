//! Generic optimisers. They know nothing of rods: a problem provides values and gradients
//! through closures or the [`Nlp`] trait.

pub mod augmented_lagrangian;
pub mod bfgs;
pub mod line_search;
pub mod newton;
pub mod nlp;
pub mod second_order;

pub use augmented_lagrangian::{
    AlOptions, AlOutcome, AlStatus, OuterIterate, augmented_lagrangian,
    augmented_lagrangian_observed, augmented_lagrangian_warm,
};
pub use bfgs::{BfgsOptions, BfgsOutcome, BfgsStatus, bfgs};
pub use newton::{NewtonOptions, newton};
pub use nlp::{Nlp, Sense};
