//! What the rod meets: rigid obstacles (parry3d shapes with poses, and their signed distance)
//! and the triangle meshes some of them are made of.

pub mod mesh;
pub mod obstacle;

pub use obstacle::Obstacle;
