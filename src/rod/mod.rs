//! The rod model (paper §2–§3.1): the material ([`Rod`]), the Ritz basis, the layout of the
//! coefficients, the quadrature mesh, the discretised [`Model`], the kinematics that turn
//! coefficients into positions and frames, and the energy with its gradient and Hessian.

pub mod basis;
pub mod energy;
pub mod hessian;
pub mod kinematics;
pub mod layout;
pub mod material;
pub mod model;
pub mod quadrature;

pub use material::{Profile, Rod};
pub use model::{Discretisation, Model};
