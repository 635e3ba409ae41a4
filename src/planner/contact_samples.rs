//! The contact samples a plan is made with: more than the problem's own where an end shape
//! dips into an obstacle between them, and twice as many kept ready for replayed equilibria
//! that dip between the chords of those ([`Planner::with_contact_samples`]).

use super::result::{ContactRefinement, ContactTry};
use super::{PlanProblem, PlanSettings, PlanSetupError, Planner};
use crate::rod::model::{MAX_SAMPLES, MAX_SELF_CONTACT_SAMPLES};
use crate::statics::StaticProblemBuilder;
use crate::statics::problem::StaticProblem;
use std::sync::Arc;

/// Times the contact samples may be doubled where an end shape dips between them.
const CONTACT_DOUBLINGS: u32 = 2;

impl Planner {
    /// The planner of `problem` (whose static problem `builder` builds) with `settings`
    /// ([`Planner::new`]). Where an end shape dips into an obstacle between the contact points
    /// its solve holds clear, on a grid four times finer in s than the verification grid
    /// ([`Planner::end_dip`]: a rod wrapped round an obstacle whose radius is not much larger
    /// than the points' spacing), the problem is made again with twice the contact samples
    /// ([`StaticProblemBuilder::samples`]), and again with four times (with self-contact,
    /// whose rows grow as the samples squared, twice only), within their limits, its end
    /// solves started from the shapes solved before. The first whose end shapes rest clear on
    /// that grid is the planner, and says so ([`Planner::contact_refinement`]); where none
    /// does, the problem's own (whose plan then reports the end inside the obstacle). Either
    /// way the planner lists the tries whose end shapes still dipped, or did not solve
    /// ([`Planner::contact_tries`]), and keeps the static problem with twice its samples for
    /// replayed equilibria that dip between the chords of its own
    /// ([`Planner::finer_contacts`]).
    ///
    /// `dlo plan` and the Python package make every plan so; [`Planner::new`] keeps the
    /// problem's samples throughout.
    pub fn with_contact_samples(
        builder: &StaticProblemBuilder,
        problem: PlanProblem,
        settings: PlanSettings,
    ) -> Result<Planner, PlanSetupError> {
        let mut own = Planner::new(problem.clone(), settings.clone())?;
        let own_samples = builder.sample_count();
        let Some(dipped) = own.end_dip() else {
            own.finer_contacts = finer_contacts(builder, &own, own_samples);
            return Ok(own);
        };
        let most = most_samples(&own);
        let doublings = if own.has_self_contact() {
            1
        } else {
            CONTACT_DOUBLINGS
        };
        let mut seeded = problem;
        seeded.start.shape = Some(own.start.a.clone());
        seeded.goal.shape = Some(own.goal.a.clone());
        let mut tries = Vec::new();
        for n in (1..=doublings).map(|d| own_samples << d) {
            if n > most {
                break;
            }
            let Ok(statics) = builder.clone().samples(n).build() else {
                break;
            };
            seeded.statics = statics;
            let Ok(mut p) = Planner::new(seeded.clone(), settings.clone()) else {
                tries.push(ContactTry {
                    samples: n,
                    dipped: None,
                });
                break;
            };
            match p.end_dip() {
                None => {
                    p.finer_contacts = finer_contacts(builder, &p, n);
                    p.contact_refinement = Some(ContactRefinement {
                        case_samples: own_samples,
                        samples: n,
                        dipped,
                    });
                    p.contact_tries = tries;
                    // Its end solves started from the shapes solved before, not from a shape
                    // the problem gave.
                    p.goal_by_pose = own.goal_by_pose;
                    return Ok(p);
                }
                still => tries.push(ContactTry {
                    samples: n,
                    dipped: still,
                }),
            }
            seeded.start.shape = Some(p.start.a.clone());
            seeded.goal.shape = Some(p.goal.a.clone());
        }
        own.contact_tries = tries;
        own.finer_contacts = finer_contacts(builder, &own, own_samples);
        Ok(own)
    }
}

/// The static problem `builder` makes with twice `samples` contact samples, for `planner`'s
/// replayed equilibria that dip between the chords of its own ([`Planner::finer_contacts`]);
/// `None` where that is beyond the limits (with self-contact, whose rows grow as the samples
/// squared, its own limit), or where the problem has no obstacle.
fn finer_contacts(
    builder: &StaticProblemBuilder,
    planner: &Planner,
    samples: usize,
) -> Option<Arc<(usize, StaticProblem)>> {
    let n = 2 * samples;
    (!planner.obstacles.is_empty() && n <= most_samples(planner))
        .then(|| builder.clone().samples(n).build().ok())
        .flatten()
        .map(|p| Arc::new((n, p)))
}

/// The most contact samples `planner`'s problem may be made with: with self-contact, whose
/// rows grow as the samples squared, fewer.
fn most_samples(planner: &Planner) -> usize {
    if planner.has_self_contact() {
        MAX_SELF_CONTACT_SAMPLES
    } else {
        MAX_SAMPLES
    }
}
