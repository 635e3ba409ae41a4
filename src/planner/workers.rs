//! The threads a path optimisation splits its sampled shapes over: the calling thread and
//! helper threads the planner owns ([`super::PlanSettings::threads`]). Work is cut into fixed
//! chunks of samples whatever the number of threads, every sample's results are written to its
//! own slots, and whatever adds samples together runs afterwards on the calling thread in
//! sample order: a plan is the same bit for bit on any number of threads. A planar
//! evaluation takes a tenth of a millisecond, about what waking a sleeping thread costs, so an
//! idle helper keeps looking for work for a while before it sleeps, and each thread takes the
//! same share of the samples at every call (their data stays in its core's cache). Each kind of
//! job runs shared or on the calling thread alone by what it has lately cost each way: small
//! jobs (a rod with few nodes, most samples left out) go faster alone.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::SeqCst};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Samples per chunk: a multiple of the four shapes the planar kinematics advance side by side.
pub const CHUNK: usize = 4;

/// How long an idle helper keeps looking for the next piece of work before it sleeps: longer
/// than the optimiser's own work between two evaluations, so that a helper is awake when the
/// next one starts (waking a sleeping thread costs about as much as a planar evaluation).
const SPIN: Duration = Duration::from_micros(100);

/// The kinds of job the planner tells apart ([`Workers::for_each_chunk3`]'s `kind`), each run
/// shared or alone by what its own calls cost: the path optimisation's sampled values,
/// gradients and Hessians ([`super::minimax::MinimaxProblem`]), the verification's shapes
/// ([`super::verify`]), and equilibrium tracking's stretches of static solves
/// ([`super::replay::equilibria_from`], each element milliseconds of work and a chunk of its
/// own).
pub const JOB_VALUES: usize = 0;
/// See [`JOB_VALUES`].
pub const JOB_GRADIENT: usize = 1;
/// See [`JOB_VALUES`].
pub const JOB_HESSIAN: usize = 2;
/// See [`JOB_VALUES`].
pub const JOB_VERIFY: usize = 3;
/// See [`JOB_VALUES`].
pub const JOB_EQUILIBRIA: usize = 4;
/// How many kinds of job there are.
pub const KINDS: usize = JOB_EQUILIBRIA + 1;

/// Whether a kind of job runs shared or on the calling thread alone, by what each has cost
/// lately. Sharing costs a hand-over, and a helper that looks for work slows a calling thread
/// that shares its core's resources; where a job is small (a rod with few nodes, one obstacle,
/// most samples left out) the calling thread alone is faster. The choice changes only who runs
/// a chunk, never what it computes.
#[derive(Clone, Copy, Debug, Default)]
struct Choice {
    calls: u64,
    /// Moving averages of a call's wall time (ns): alone, shared (0: not measured yet).
    alone: f64,
    shared: f64,
    /// Whether the probes start shared: for the kinds whose calls are large from the first
    /// (the verification grid, [`JOB_VERIFY`], and tracking's equilibria, [`JOB_EQUILIBRIA`]).
    shared_first: bool,
}

impl Choice {
    /// Calls of each way tried first, and how often the way not chosen is tried again.
    const PROBE: u64 = 4;
    const REPROBE: u64 = 32;

    /// A call that takes this long (ns) is worth sharing whatever a hand-over costs: ten times
    /// the wake-up of a sleeping helper.
    const LARGE: f64 = 1e6;

    /// The choice of a kind of job: its probes start shared for [`JOB_VERIFY`] and
    /// [`JOB_EQUILIBRIA`].
    fn of(kind: usize) -> Choice {
        Choice {
            shared_first: kind == JOB_VERIFY || kind == JOB_EQUILIBRIA,
            ..Choice::default()
        }
    }

    fn shared_next(&self) -> bool {
        let c = self.calls;
        if c < 2 * Self::PROBE {
            // A job too large for a hand-over to matter (a verification grid, a few calls per
            // plan) runs shared from its second call, whichever way it was probed first.
            if c >= 1 && self.alone.max(self.shared) >= Self::LARGE {
                return true;
            }
            return (c >= Self::PROBE) != self.shared_first;
        }
        let cost = |v: f64| if v > 0.0 { v } else { f64::INFINITY };
        let better = cost(self.shared) < cost(self.alone);
        if c.is_multiple_of(Self::REPROBE) {
            !better
        } else {
            better
        }
    }

    fn record(&mut self, shared: bool, ns: f64) {
        let avg = if shared {
            &mut self.shared
        } else {
            &mut self.alone
        };
        *avg = if self.calls < 2 * Self::PROBE && *avg == 0.0 {
            ns
        } else {
            0.75 * *avg + 0.25 * ns
        };
        self.calls += 1;
    }
}

/// Where chunks of work run: on the calling thread alone, or also on helper threads that live
/// as long as the planner.
#[derive(Clone, Default)]
pub struct Workers {
    team: Option<Arc<Team>>,
}

impl std::fmt::Debug for Workers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Workers({})", self.threads())
    }
}

/// A job as the helpers see it: the calling thread's closure, which outlives every call a
/// helper makes (see [`Workers::run`]).
#[derive(Clone, Copy)]
struct JobPtr(*const (dyn Fn(usize) + Sync));
// SAFETY: the pointee is `Sync`, and `Workers::run` keeps it alive while any helper may call it.
unsafe impl Send for JobPtr {}

#[derive(Default)]
struct Shared {
    /// The job, while `open`.
    job: Mutex<Option<JobPtr>>,
    /// Bumped for every job posted.
    epoch: AtomicU64,
    /// Whether helpers may still enter the current job.
    open: AtomicBool,
    /// Helpers inside the current job.
    active: AtomicUsize,
    /// A helper's job panicked.
    panicked: AtomicBool,
    shutdown: AtomicBool,
}

struct Team {
    /// Held while a job runs: one job at a time (a second caller runs its chunks alone); it
    /// holds what each kind of job has cost alone and shared ([`Choice`]).
    busy: Mutex<[Choice; KINDS]>,
    shared: Arc<Shared>,
    helpers: Vec<(std::thread::JoinHandle<()>, Arc<AtomicBool>)>,
}

impl Drop for Team {
    fn drop(&mut self) {
        self.shared.shutdown.store(true, SeqCst);
        for (h, _) in self.helpers.drain(..) {
            h.thread().unpark();
            let _ = h.join();
        }
    }
}

fn helper(index: usize, shared: Arc<Shared>, sleeping: Arc<AtomicBool>) {
    let mut seen = shared.epoch.load(SeqCst);
    loop {
        // Wait for a new job: look for it for a while, then sleep until woken.
        let since = Instant::now();
        loop {
            if shared.shutdown.load(SeqCst) {
                return;
            }
            if shared.epoch.load(SeqCst) != seen {
                break;
            }
            if since.elapsed() < SPIN {
                std::hint::spin_loop();
                continue;
            }
            sleeping.store(true, SeqCst);
            if shared.epoch.load(SeqCst) == seen && !shared.shutdown.load(SeqCst) {
                std::thread::park();
            }
            sleeping.store(false, SeqCst);
        }
        seen = shared.epoch.load(SeqCst);
        // Enter only while the job is open: the calling thread, once it has closed the job,
        // waits for every helper that entered before it may drop the closure.
        shared.active.fetch_add(1, SeqCst);
        if shared.open.load(SeqCst) {
            let job = *shared.job.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(JobPtr(f)) = job {
                // SAFETY: the job is open and this helper is counted in `active`, so the
                // closure is alive until this helper leaves (see `Workers::run`).
                let f = unsafe { &*f };
                if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(index))).is_err() {
                    shared.panicked.store(true, SeqCst);
                }
            }
        }
        shared.active.fetch_sub(1, SeqCst);
    }
}

impl Workers {
    /// The calling thread alone.
    pub fn serial() -> Workers {
        Workers { team: None }
    }

    /// The calling thread and `threads − 1` helpers (the calling thread alone for 0 or 1, or
    /// when no thread can be started).
    pub fn new(threads: usize) -> Workers {
        if threads <= 1 {
            return Workers::serial();
        }
        let shared = Arc::new(Shared::default());
        let helpers: Vec<_> = (1..threads)
            .filter_map(|i| {
                let sleeping = Arc::new(AtomicBool::new(false));
                let (sh, sl) = (shared.clone(), sleeping.clone());
                std::thread::Builder::new()
                    .name(format!("dlo-plan-{i}"))
                    .spawn(move || helper(i, sh, sl))
                    .ok()
                    .map(|h| (h, sleeping))
            })
            .collect();
        if helpers.is_empty() {
            return Workers::serial();
        }
        Workers {
            team: Some(Arc::new(Team {
                busy: Mutex::new(std::array::from_fn(Choice::of)),
                shared,
                helpers,
            })),
        }
    }

    /// Threads that take part, the calling one included.
    pub fn threads(&self) -> usize {
        1 + self.team.as_ref().map_or(0, |t| t.helpers.len())
    }

    /// Runs `f(0)` on the calling thread and `f(i)` on every helper `i` that joins in before
    /// the calling thread's own call returns; returns once no helper is inside `f` any more.
    fn run(&self, team: &Team, f: &(dyn Fn(usize) + Sync)) {
        let shared = &team.shared;
        // SAFETY (lifetime): the pointer is erased to `'static` for the helpers; they call it
        // only while the job is open or they are counted in `active`, and this function
        // closes the job and waits for `active` to reach zero before it returns.
        let ptr: *const (dyn Fn(usize) + Sync + '_) = f;
        let ptr: *const (dyn Fn(usize) + Sync) = unsafe { std::mem::transmute(ptr) };
        *shared.job.lock().unwrap_or_else(|e| e.into_inner()) = Some(JobPtr(ptr));
        shared.open.store(true, SeqCst);
        shared.epoch.fetch_add(1, SeqCst);
        for (h, sleeping) in &team.helpers {
            if sleeping.load(SeqCst) {
                h.thread().unpark();
            }
        }
        let mine = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(0)));
        shared.open.store(false, SeqCst);
        let mut spins = 0u32;
        while shared.active.load(SeqCst) != 0 {
            spins += 1;
            if spins < 1 << 12 {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
        *shared.job.lock().unwrap_or_else(|e| e.into_inner()) = None;
        if let Err(p) = mine {
            std::panic::resume_unwind(p);
        }
        if shared.panicked.swap(false, SeqCst) {
            panic!("a planner thread panicked");
        }
    }

    /// Calls `f(j0, a_chunk)` on every chunk of [`CHUNK`] items of `a`, `j0` being the chunk's
    /// first index; the calling thread takes part and returns when every chunk is done.
    pub fn for_each_chunk<A: Send>(
        &self,
        kind: usize,
        a: &mut [A],
        f: impl Fn(usize, &mut [A]) + Sync,
    ) {
        let mut b = vec![(); a.len()];
        let mut c = vec![(); a.len()];
        self.for_each_chunk3(kind, a, &mut b, &mut c, |j0, a, _, _| f(j0, a));
    }

    /// [`Workers::for_each_chunk`] on the same chunks of three slices of the same length.
    /// `kind` (below [`KINDS`]) names the job, whose calls run shared or alone by what they
    /// have cost each way; a [`JOB_EQUILIBRIA`] job's chunks are single elements.
    pub fn for_each_chunk3<A: Send, B: Send, C: Send>(
        &self,
        kind: usize,
        a: &mut [A],
        b: &mut [B],
        c: &mut [C],
        f: impl Fn(usize, &mut [A], &mut [B], &mut [C]) + Sync,
    ) {
        debug_assert!(a.len() == b.len() && a.len() == c.len());
        // The team runs one job at a time: a clone of these workers used on another thread
        // meanwhile runs its chunks alone.
        let size = if kind == JOB_EQUILIBRIA { 1 } else { CHUNK };
        let team = self.team.as_ref().filter(|_| a.len() > size);
        let mut busy = team.and_then(|t| t.busy.try_lock().ok());
        let choice = busy.as_mut().map(|b| &mut b[kind.min(KINDS - 1)]);
        let shared = choice.as_ref().is_some_and(|c| c.shared_next());
        let t0 = Instant::now();
        let (Some(team), true) = (team, shared) else {
            let chunks = a.chunks_mut(size).zip(b.chunks_mut(size));
            for (i, ((x, y), z)) in chunks.zip(c.chunks_mut(size)).enumerate() {
                f(i * size, x, y, z);
            }
            if let Some(choice) = choice {
                choice.record(false, t0.elapsed().as_nanos() as f64);
            }
            return;
        };
        type Piece<'a, A, B, C> = Mutex<Option<((&'a mut [A], &'a mut [B]), &'a mut [C])>>;
        let pieces: Vec<Piece<A, B, C>> = a
            .chunks_mut(size)
            .zip(b.chunks_mut(size))
            .zip(c.chunks_mut(size))
            .map(|p| Mutex::new(Some(p)))
            .collect();
        // Thread `t` of `n` takes its own share of the chunks first (the same share at every
        // call, so that a sample's data stays in one core's cache), then whatever is left.
        let (n, len) = (self.threads(), pieces.len());
        let work = |t: usize| {
            let own = (t * len / n).min(len)..((t + 1) * len / n).min(len);
            for i in own.chain(0..pieces.len()) {
                let taken = pieces[i].lock().map(|mut p| p.take());
                if let Ok(Some(((x, y), z))) = taken {
                    f(i * size, x, y, z);
                }
            }
        };
        self.run(team, &work);
        if let Some(choice) = choice {
            choice.record(true, t0.elapsed().as_nanos() as f64);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_chunk_runs_once_with_its_first_index() {
        for threads in [1, 2, 3] {
            let w = Workers::new(threads);
            for n in [0, 1, 4, 5, 41] {
                let mut a: Vec<usize> = vec![0; n];
                let mut b: Vec<usize> = vec![0; n];
                let mut c: Vec<usize> = vec![0; n];
                w.for_each_chunk3(0, &mut a, &mut b, &mut c, |j0, x, y, z| {
                    for (i, u) in x.iter_mut().enumerate() {
                        *u += j0 + i;
                    }
                    y.iter_mut().for_each(|v| *v += 1);
                    z.iter_mut().for_each(|v| *v += 2);
                });
                assert_eq!(a, (0..n).collect::<Vec<_>>(), "threads {threads}, n {n}");
                assert!(b.iter().all(|&v| v == 1) && c.iter().all(|&v| v == 2));
            }
        }
    }

    #[test]
    fn equilibrium_jobs_run_each_element_as_a_chunk_of_its_own() {
        for threads in [1, 2, 3] {
            let w = Workers::new(threads);
            for n in [0, 1, 2, 5] {
                let mut a: Vec<Vec<usize>> = vec![Vec::new(); n];
                w.for_each_chunk(JOB_EQUILIBRIA, &mut a, |j0, x| {
                    assert_eq!(x.len(), 1);
                    x[0].push(j0);
                });
                let want: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
                assert_eq!(a, want, "threads {threads}, n {n}");
            }
        }
    }

    #[test]
    fn a_panic_on_any_thread_reaches_the_caller_and_the_workers_go_on() {
        let w = Workers::new(2);
        for bad in [0, 40] {
            let mut a = vec![0usize; 41];
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                w.for_each_chunk(0, &mut a, |j0, x| {
                    if (j0..j0 + x.len()).contains(&bad) {
                        panic!("chunk with {bad}");
                    }
                    x.iter_mut().for_each(|v| *v = 1);
                })
            }));
            assert!(r.is_err(), "the panic at sample {bad} is lost");
        }
        let mut a = vec![0usize; 41];
        w.for_each_chunk(0, &mut a, |_, x| x.iter_mut().for_each(|v| *v = 1));
        assert!(a.iter().all(|&v| v == 1));
    }

    #[test]
    fn clones_used_on_several_threads_at_once_each_get_every_chunk() {
        let w = Workers::new(2);
        std::thread::scope(|sc| {
            for t in 0..4 {
                let w = w.clone();
                sc.spawn(move || {
                    for _ in 0..200 {
                        let mut a = vec![0usize; 41];
                        w.for_each_chunk(0, &mut a, |j0, x| {
                            for (i, v) in x.iter_mut().enumerate() {
                                *v = t + j0 + i;
                            }
                        });
                        assert!(a.iter().enumerate().all(|(i, &v)| v == t + i));
                    }
                });
            }
        });
    }

    #[test]
    fn a_kind_of_job_runs_the_way_that_has_cost_less_and_tries_the_other_now_and_then() {
        for (alone, shared) in [(100.0, 60.0), (50.0, 80.0)] {
            let mut c = Choice::default();
            let mut ways = Vec::new();
            for _ in 0..200 {
                let s = c.shared_next();
                ways.push(s);
                c.record(s, if s { shared } else { alone });
            }
            let p = Choice::PROBE as usize;
            assert!(ways[..p].iter().all(|&s| !s) && ways[p..2 * p].iter().all(|&s| s));
            let cheaper = shared < alone;
            let other = ways[2 * p..].iter().filter(|&&s| s != cheaper).count();
            assert_eq!(
                other,
                (2 * p..200)
                    .filter(|i| (*i as u64).is_multiple_of(Choice::REPROBE))
                    .count()
            );
        }
    }

    #[test]
    fn a_job_that_takes_over_a_millisecond_alone_shares_from_its_second_call() {
        let mut c = Choice::default();
        let mut ways = Vec::new();
        for _ in 0..3 {
            let s = c.shared_next();
            ways.push(s);
            c.record(
                s,
                if s {
                    0.6 * Choice::LARGE
                } else {
                    Choice::LARGE
                },
            );
        }
        assert_eq!(ways, [false, true, true]);
    }

    #[test]
    fn the_verification_probes_shared_first_and_a_large_job_stays_shared() {
        for (cost, want) in [
            (2.0 * Choice::LARGE, [true, true, true, true, true, true]),
            (0.1 * Choice::LARGE, [true, true, true, true, false, false]),
        ] {
            let mut c = Choice::of(JOB_VERIFY);
            let mut ways = Vec::new();
            for _ in 0..6 {
                let s = c.shared_next();
                ways.push(s);
                c.record(s, cost);
            }
            assert_eq!(ways, want, "cost {cost}");
        }
        assert!(!Choice::of(JOB_VALUES).shared_next());
    }
}
