//! The MCAP topic names, in one place: the log writer ([`super::mcap_log`]) writes them and the
//! plots read them. A plan's shapes go to one topic per kind of path (`/rod/optimal`, …), with
//! the controlled end's pose and the shape's metrics beside them.

/// The transform tree (gravity's frame).
pub const TRANSFORMS: &str = "/tf";
/// The obstacles, once per log.
pub const OBSTACLES: &str = "/scene/obstacles";

/// The start and goal shapes of a plan.
pub const ROD_ENDPOINTS: &str = "/rod/endpoints";
/// The straight-line path `c = 0`.
pub const ROD_STRAIGHT: &str = "/rod/straight";
/// The optimiser's iterates.
pub const ROD_ITERATE: &str = "/rod/iterate";
/// The optimal path on the verification grid.
pub const ROD_OPTIMAL: &str = "/rod/optimal";
/// The replay driven by the controlled end.
pub const ROD_FEASIBLE: &str = "/rod/feasible";
/// The controlled end's pose along the optimal path.
pub const END_POSE_OPTIMAL: &str = "/end_pose/optimal";
/// The controlled end's pose along the replay.
pub const END_POSE_FEASIBLE: &str = "/end_pose/feasible";
/// Energy, clearance and deviation of the start and goal shapes.
pub const METRICS_ENDPOINTS: &str = "/metrics/endpoints";
/// Metrics of the straight-line path.
pub const METRICS_STRAIGHT: &str = "/metrics/straight";
/// Metrics of the optimiser's iterates.
pub const METRICS_ITERATE: &str = "/metrics/iterate";
/// Metrics of the optimal path.
pub const METRICS_OPTIMAL: &str = "/metrics/optimal";
/// Metrics of the replay.
pub const METRICS_FEASIBLE: &str = "/metrics/feasible";
/// The reactions along the replay.
pub const REACTIONS_FEASIBLE: &str = "/reactions/feasible";
/// The optimiser's progress, one message per outer iteration.
pub const OPTIMISER_PROGRESS: &str = "/optimiser/progress";
/// The optimiser's worst sampled shape at each outer iteration.
pub const OPTIMISER_WORST: &str = "/optimiser/worst";

/// A static shape (`dlo shape`).
pub const SHAPE: &str = "/rod/shape";
/// Its free end's pose.
pub const END_POSE_SHAPE: &str = "/end_pose/shape";
/// Its report.
pub const METRICS_SHAPE: &str = "/metrics/shape";

/// The fingers of a grasp (`dlo margin`).
pub const GRASP_FINGERS: &str = "/grasp/fingers";
/// The held shape at each disturbance direction.
pub const GRASP_HELD_SHAPE: &str = "/grasp/held_shape";
/// The limit force at each disturbance direction.
pub const GRASP_LIMITS: &str = "/grasp/limits";
