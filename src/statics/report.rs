//! Machine-readable summaries of solves, shared by the CLI's `--json` output and tests.

use crate::rod::energy::EnergyTerms;
use crate::rod::kinematics::angles_of;
use crate::statics::problem::StaticProblem;
use crate::statics::{Reaction, StaticSolution};
use serde::Serialize;

/// Energy terms in the case's units, with their total `U` and the internal energy `V = U − W`.
#[derive(Clone, Debug, Serialize)]
pub struct EnergyReport {
    /// `U = U_flex + U_tor + U_ext + U_grav`.
    pub total: f64,
    /// `U_flex`.
    pub flexural: f64,
    /// `U_tor`.
    pub torsional: f64,
    /// `U_ext`.
    pub extensional: f64,
    /// `U_grav`.
    pub gravitational: f64,
    /// `ΣW` of point loads.
    pub work: f64,
    /// `V = U − ΣW`.
    pub internal: f64,
}

impl From<EnergyTerms> for EnergyReport {
    fn from(t: EnergyTerms) -> Self {
        EnergyReport {
            total: t.potential(),
            flexural: t.flexural,
            torsional: t.torsional,
            extensional: t.extensional,
            gravitational: t.gravitational,
            work: t.work,
            internal: t.internal(),
        }
    }
}

/// A pose of the rod's cross-section frame.
#[derive(Clone, Debug, Serialize)]
pub struct PoseReport {
    /// Arc length.
    pub s: f64,
    /// Position (case units).
    pub position: [f64; 3],
    /// The frame's rotation matrix (rows) in the case's axes, columns `ξ, η, ζ`.
    pub rotation: [[f64; 3]; 3],
    /// Euler angles `[φ, θ, ψ]` of `rotation` (radians): the fields' own values, or, where
    /// the rod's angles have their own reference frame, the principal angles of `rotation`.
    pub euler_zyz: [f64; 3],
}

/// Pose at arc length `s` (case units).
pub fn pose(p: &StaticProblem, a: &[f64], s: f64) -> PoseReport {
    let m = &p.model;
    let l = m.rod.length;
    let t = s / l;
    let ang = m.angles_at(a, t);
    let rotation = m.frame_at(a, t);
    PoseReport {
        s,
        position: m.position_at(a, t).map(|c| c * l),
        rotation,
        // With an angles' frame the fields' angles are not the case's: these are.
        euler_zyz: if m.frame.is_some() {
            angles_of(rotation)
        } else {
            ang
        },
    }
}

/// Summary of a static solve or evaluation.
#[derive(Clone, Debug, Serialize)]
pub struct ShapeReport {
    /// Case name.
    pub case: String,
    /// `converged`, `iteration_limit`, `infeasible`, `numerical_failure`, or `evaluated`.
    pub status: String,
    /// Energy terms (case units).
    pub energy: EnergyReport,
    /// Reactions at each constraint (force and moment on the rod, case units).
    pub reactions: Vec<Reaction>,
    /// Global moment balance of the reactions, loads and gravity (left out where not
    /// computed: [`crate::statics::StaticOptions::balance`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balance: Option<crate::statics::balance::Balance>,
    /// Where the rod touches itself, largest force first (empty without self-contact).
    pub self_contacts: Vec<crate::statics::SelfContactForce>,
    /// Largest constraint violation (positions in units of `L`).
    pub max_violation: f64,
    /// KKT residual (units of `Rf/L`); `null` for an evaluation.
    pub kkt_residual: Option<f64>,
    /// `true` stable, `false` unstable, `null` marginal or not computed.
    pub stable: Option<bool>,
    /// `"stable"`, `"unstable"` or `"marginal"`; `null` if not computed.
    pub stability: Option<crate::statics::stability::Verdict>,
    /// Smallest reduced-Hessian eigenvalue against the fields' Gram matrix (units of `Rf/L`).
    pub min_reduced_eigenvalue: Option<f64>,
    /// Eigenvalues within the verdict's resolution of zero.
    pub neutral_modes: Option<usize>,
    /// Exact gauge directions removed before judging.
    pub gauge_modes: Option<usize>,
    /// Pose of the `s = L` frame.
    pub end_pose: PoseReport,
    /// Poses at the report points.
    pub points: Vec<PoseReport>,
    /// Ritz coefficients by field, of the angles measured from `angle_frame`.
    pub coefficients: serde_json::Value,
    /// The frame `R` (row-major; columns the angles' x, y, z axes in the case's) from which a
    /// 3D rod's angles are measured; `null` for the case's own axes.
    pub angle_frame: Option<[[f64; 3]; 3]>,
    /// Outer iterations of the multiplier method.
    pub outer_iterations: Option<usize>,
    /// Wall-clock seconds.
    pub timing_s: f64,
}

/// Coefficients as a JSON object keyed by field, in the case file's `shape` format.
pub fn coefficients_json(p: &StaticProblem, a: &[f64]) -> serde_json::Value {
    use crate::rod::layout::Field;
    let lay = &p.model.layout;
    let mut m = serde_json::Map::new();
    for (nm, f) in [
        ("phi", Field::Phi),
        ("theta", Field::Theta),
        ("psi", Field::Psi),
        ("eps", Field::Eps),
    ] {
        if let Some(c) = lay.field(a, f) {
            m.insert(nm.into(), serde_json::json!(c));
        }
    }
    serde_json::Value::Object(m)
}

impl ShapeReport {
    /// Report of a solved shape.
    pub fn solved(
        name: &str,
        p: &StaticProblem,
        sol: &StaticSolution,
        points: &[f64],
        secs: f64,
    ) -> Self {
        let status = serde_json::to_value(sol.status)
            .ok()
            .and_then(|v| v.as_str().map(String::from));
        ShapeReport {
            case: name.into(),
            status: status.unwrap_or_default(),
            energy: sol.energy.into(),
            reactions: sol.reactions.clone(),
            balance: sol.balance,
            self_contacts: sol.self_contacts.clone(),
            max_violation: sol.max_violation,
            kkt_residual: Some(sol.kkt_residual),
            stable: sol.stable,
            stability: sol.stability,
            min_reduced_eigenvalue: sol.min_reduced_eigenvalue,
            neutral_modes: sol.neutral_modes,
            gauge_modes: sol.gauge_modes,
            end_pose: pose(p, &sol.a, p.model.rod.length),
            points: points.iter().map(|&s| pose(p, &sol.a, s)).collect(),
            coefficients: coefficients_json(p, &sol.a),
            angle_frame: p.model.frame,
            outer_iterations: Some(sol.outer_iterations),
            timing_s: secs,
        }
    }

    /// Report of coefficients `a` evaluated without optimising (`dlo energy`).
    pub fn evaluated(
        name: &str,
        p: &StaticProblem,
        ev: crate::statics::Evaluation,
        a: &[f64],
        points: &[f64],
        secs: f64,
    ) -> Self {
        ShapeReport {
            case: name.into(),
            status: "evaluated".into(),
            energy: ev.energy.into(),
            reactions: ev.reactions,
            balance: Some(ev.balance),
            self_contacts: ev.self_contacts,
            max_violation: ev.max_violation,
            kkt_residual: Some(ev.kkt_residual),
            stable: None,
            stability: None,
            min_reduced_eigenvalue: None,
            neutral_modes: None,
            gauge_modes: None,
            end_pose: pose(p, a, p.model.rod.length),
            points: points.iter().map(|&s| pose(p, a, s)).collect(),
            coefficients: coefficients_json(p, a),
            angle_frame: p.model.angle_frame(),
            outer_iterations: None,
            timing_s: secs,
        }
    }
}
