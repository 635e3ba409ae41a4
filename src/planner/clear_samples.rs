//! Which sampled shapes' obstacle rows the planning objective may keep from their last
//! evaluation (and, where nothing else reads them, leave the shapes out): samples that certainly
//! keep clear of every obstacle, by a bound on how far their positions can have moved since
//! their rows were last evaluated (see
//! [`crate::planner::minimax::MinimaxProblem::set_skip_clear_samples`]).

/// Below this (in the rows' units, dimensionless lengths) a row counts as certainly below
/// zero: above the multiplier method's boundary band (1e-9) and the planner's active-row
/// tolerance (1e-7), so that every decision the method takes on such a row is the same for any
/// value below it.
const CLEAR_MARGIN: f64 = 1e-6;

/// What lets [`crate::planner::minimax::MinimaxProblem`] skip a sample's rows (and shape); each
/// sample keeps its own last rows ([`LastRows`]), so that the thread evaluating it records and
/// tests them. On a rod whose positions depend on θ alone (planar, inextensible, fixed base),
/// with obstacle rows only, a row value `c = clearance − d(x)/L` changes by at most the boundary's displacement,
/// which is at most `Σᵢ ωᵢ |aᵢ − a′ᵢ|` ([`crate::rod::model::Model::position_bound_weights`]).
/// A sample whose rows all have zero multipliers and whose largest row, at the coefficients of
/// its last evaluated rows, plus that bound is below `−CLEAR_MARGIN` keeps its last rows. Where
/// the energy is the constant quadratic form (weightless, no loads) and nothing else reads the
/// shape, it skips its shape too.
#[derive(Debug)]
pub(super) struct ClearSamples {
    /// `ωᵢ`.
    omega: Vec<f64>,
    /// Per interior sample: whether all its rows' multipliers are zero.
    free: Vec<bool>,
    /// Per sample: whether its shape is older than its coefficients.
    pub(super) stale: Vec<bool>,
    /// Shapes left out so far.
    pub(super) left_out: usize,
    /// Samples whose recorded rows stood in for their rows so far.
    pub(super) rows_kept: usize,
    /// Whether the energy needs no shape (a weightless rod without loads), so that a kept
    /// sample's shape may be left out too.
    pub(super) shapes_optional: bool,
}

/// A sample's rows at the coefficients of its last evaluated shape.
#[derive(Clone, Debug)]
pub(super) struct LastRows {
    a: Vec<f64>,
    rows: Vec<f64>,
    /// The largest row.
    max: f64,
}

impl ClearSamples {
    /// Nothing recorded yet, for `samples` samples of which `interior` carry rows.
    pub(super) fn new(
        omega: Vec<f64>,
        samples: usize,
        interior: usize,
        shapes_optional: bool,
    ) -> Self {
        ClearSamples {
            omega,
            free: vec![false; interior],
            stale: vec![false; samples],
            left_out: 0,
            rows_kept: 0,
            shapes_optional,
        }
    }

    /// Takes in the multipliers: interior sample `i` owns rows `i·per .. (i+1)·per`.
    pub(super) fn set_free(&mut self, lambda: &[f64], per: usize) {
        for (i, f) in self.free.iter_mut().enumerate() {
            *f = lambda
                .get(i * per..(i + 1) * per)
                .is_some_and(crate::kernels::all_zero);
        }
    }

    /// Whether interior sample `i`, whose last recorded rows are `last`, may keep them at
    /// coefficients `a`.
    pub(super) fn clear(&self, i: usize, last: Option<&LastRows>, a: &[f64]) -> bool {
        if !self.free[i] {
            return false;
        }
        let Some(last) = last else {
            return false;
        };
        let moved: f64 = self
            .omega
            .iter()
            .zip(a.iter().zip(&last.a))
            .map(|(w, (x, y))| w * (x - y).abs())
            .sum();
        last.max + moved < -CLEAR_MARGIN
    }
}

impl LastRows {
    /// Records a sample's rows at coefficients `a` (its shape just evaluated) in `slot`.
    pub(super) fn record(slot: &mut Option<LastRows>, a: &[f64], rows: &[f64]) {
        let max = rows.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        match slot {
            Some(last) => {
                last.a.copy_from_slice(a);
                last.rows.copy_from_slice(rows);
                last.max = max;
            }
            none => {
                *none = Some(LastRows {
                    a: a.to_vec(),
                    rows: rows.to_vec(),
                    max,
                })
            }
        }
    }

    /// The recorded rows.
    pub(super) fn rows(&self) -> &[f64] {
        &self.rows
    }
}
