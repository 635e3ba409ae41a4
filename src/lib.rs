//! # dlo-planner
//!
//! Static modelling and deformation path planning of deformable linear objects (cables, wires,
//! threads, thin strips) after Wakamatsu & Hirai, *Static Modeling of Linear Object Deformation
//! Based on Differential Geometry* (IJRR 2004).
//!
//! A shape is four functions of arc length — Euler angles `φ, θ, ψ` and strain `ε` — each a
//! Ritz combination of basis functions. The crate is layered:
//!
//! - [`rod`]: the material, the basis, the discretised [`rod::Model`], the kinematics that turn
//!   coefficients into positions and frames, and the energy of eq. (7)–(13) with its
//!   derivatives;
//! - [`scene`]: obstacles (parry3d shapes) and triangle meshes;
//! - [`constraints`]: the constraint kinds of §3.2, one closed enum;
//! - [`optim`]: the generic multiplier method, BFGS and Newton steps;
//! - [`statics`]: static shapes — [`statics::StaticProblem::builder`] builds a problem in code,
//!   [`statics::solve_static`] solves it and reports reactions, moment balance and stability;
//! - [`planner`]: deformation paths (§7) — [`planner::Planner::new`] (or
//!   [`planner::Planner::with_contact_samples`], as `dlo plan` makes it) takes a
//!   [`planner::PlanProblem`] and [`planner::PlanSettings`], plans, verifies and replays;
//! - [`grasp`]: the disturbance force margin of a grasp (§6);
//! - [`case`]: case files, an adapter from JSON to the types above;
//! - [`output`]: MCAP logs for Foxglove and SVG plots.
//!
//! The library prints nothing. Its default feature `cli` builds the `dlo` tool and with it
//! `mcap` (MCAP logs for Foxglove, [`output`]) and `plot` (SVG pictures of logs); a
//! library user who needs neither depends on it with `default-features = false`.

pub mod case;
pub mod constraints;
pub mod error;
pub mod grasp;
mod kernels;
pub mod optim;
pub mod output;
pub mod planner;
pub mod rod;
pub mod scene;
pub mod statics;

pub use error::Error;
