//! A crew of persistent helper threads for a batch that steps many times
//! a second in short calls (a vector environment's step: from some 20 µs
//! to a millisecond of work per call).
//!
//! A rayon pool costs such a call the hand-off of the job to a sleeping
//! worker, the worker's wake-up, and the caller's own wake-up when the job
//! is done: some 50 µs a call on the 2-core machine here, a tenth of a
//! 256-lander step on two threads. The crew keeps the calling thread at
//! work (it runs the job as worker 0) and its helpers awake between calls
//! for a short while (watching a flag, yielding), so a call costs a lock
//! and a flag per helper; a condition variable is signalled only when the
//! other side has gone to sleep on it.
//!
//! The crew runs one job on every thread; what the job works on is its own
//! business (the lander batch hands out runs of landers from a board of
//! mutexes, see `lander`). The crew needs no `unsafe`: a job is an
//! `Arc<dyn Fn(usize)>`, called with the worker's number.

use std::any::Any;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What every worker runs, with its number (0: the caller, 1..: the
/// helpers).
pub(crate) type Job = Arc<dyn Fn(usize) + Send + Sync>;

/// A helper's panic, handed to the caller.
pub(crate) type Panic = Box<dyn Any + Send>;

/// A helper thread: its slot and its handle (taken when it is joined).
struct Helper {
    shared: Arc<Shared>,
    handle: Option<JoinHandle<()>>,
}

/// How long a helper keeps watching for the next job before it sleeps,
/// and how long the caller watches for a helper's end before it sleeps.
const STAY_AWAKE: Duration = Duration::from_micros(300);

enum Slot {
    Empty,
    Work(Job),
    Done,
    Panicked(Panic),
    Quit,
}

struct Shared {
    slot: Mutex<Slot>,
    /// The helper waits here for work.
    wake: Condvar,
    /// The caller waits here for the result.
    back: Condvar,
    /// Work is in the slot (read while watching, without the lock).
    posted: AtomicBool,
    /// A result is in the slot.
    finished: AtomicBool,
    /// The helper sleeps on `wake` (written under the slot's lock).
    helper_asleep: AtomicBool,
    /// The caller sleeps on `back` (written under the slot's lock).
    caller_asleep: AtomicBool,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Watches `flag` for up to [`STAY_AWAKE`], yielding the core between
/// looks; whether it came up.
fn watch(flag: &AtomicBool) -> bool {
    let start = Instant::now();
    loop {
        if flag.load(Ordering::Acquire) {
            return true;
        }
        if start.elapsed() >= STAY_AWAKE {
            return false;
        }
        std::thread::yield_now();
    }
}

/// Helper threads, each with a slot the caller posts a job into.
pub(crate) struct Crew {
    helpers: Vec<Helper>,
}

impl Crew {
    /// A crew of `helpers` threads.
    pub(crate) fn new(helpers: usize) -> Result<Crew, std::io::Error> {
        let mut crew = Crew {
            helpers: Vec::with_capacity(helpers),
        };
        for k in 0..helpers {
            let shared = Arc::new(Shared {
                slot: Mutex::new(Slot::Empty),
                wake: Condvar::new(),
                back: Condvar::new(),
                posted: AtomicBool::new(false),
                finished: AtomicBool::new(false),
                helper_asleep: AtomicBool::new(false),
                caller_asleep: AtomicBool::new(false),
            });
            let mine = Arc::clone(&shared);
            // On an error the crew built so far is dropped: its threads quit.
            let handle = std::thread::Builder::new()
                .name(format!("janus2d-crew-{}", k + 1))
                .spawn(move || helper_loop(&mine, k + 1))?;
            crew.helpers.push(Helper {
                shared,
                handle: Some(handle),
            });
        }
        Ok(crew)
    }

    /// Helpers in the crew.
    pub(crate) fn len(&self) -> usize {
        self.helpers.len()
    }

    /// Runs `job` on every helper (worker `k + 1` on helper `k`) and on
    /// the calling thread (worker 0), and returns when all are done. A
    /// panic of the caller's part is resumed once the helpers are done;
    /// otherwise the first helper's panic is returned.
    pub(crate) fn run(&self, job: &Job) -> Result<(), Panic> {
        for k in 0..self.helpers.len() {
            self.post(k, Arc::clone(job));
        }
        let own = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(0)));
        let mut first = None;
        for k in 0..self.helpers.len() {
            if let Err(payload) = self.collect(k) {
                first = first.or(Some(payload));
            }
        }
        if let Err(payload) = own {
            std::panic::resume_unwind(payload);
        }
        first.map_or(Ok(()), Err)
    }

    /// Hands `job` to helper `k`.
    fn post(&self, k: usize, job: Job) {
        let shared = &self.helpers[k].shared;
        let mut slot = lock(&shared.slot);
        *slot = Slot::Work(job);
        shared.finished.store(false, Ordering::Relaxed);
        shared.posted.store(true, Ordering::Release);
        let asleep = shared.helper_asleep.load(Ordering::Relaxed);
        drop(slot);
        if asleep {
            shared.wake.notify_one();
        }
    }

    /// Waits for helper `k`'s job to end: Ok, or the panic it raised.
    fn collect(&self, k: usize) -> Result<(), Panic> {
        let shared = &self.helpers[k].shared;
        watch(&shared.finished);
        let mut slot = lock(&shared.slot);
        loop {
            match std::mem::replace(&mut *slot, Slot::Empty) {
                Slot::Done => return Ok(()),
                Slot::Panicked(payload) => return Err(payload),
                other => {
                    *slot = other;
                    shared.caller_asleep.store(true, Ordering::Relaxed);
                    slot = shared
                        .back
                        .wait(slot)
                        .unwrap_or_else(PoisonError::into_inner);
                    shared.caller_asleep.store(false, Ordering::Relaxed);
                }
            }
        }
    }
}

impl Drop for Crew {
    fn drop(&mut self) {
        for helper in &self.helpers {
            let shared = &helper.shared;
            *lock(&shared.slot) = Slot::Quit;
            shared.posted.store(true, Ordering::Release);
            shared.wake.notify_one();
        }
        for helper in &mut self.helpers {
            if let Some(h) = helper.handle.take() {
                // A helper's panic was already handed to the caller.
                let _ = h.join();
            }
        }
    }
}

/// Helper `worker - 1`'s life: watch for a job, run it as `worker`,
/// report, until told to quit.
fn helper_loop(shared: &Shared, worker: usize) {
    loop {
        watch(&shared.posted);
        let job = {
            let mut slot = lock(&shared.slot);
            loop {
                match std::mem::replace(&mut *slot, Slot::Empty) {
                    Slot::Work(job) => {
                        shared.posted.store(false, Ordering::Relaxed);
                        break job;
                    }
                    Slot::Quit => return,
                    other => {
                        *slot = other;
                        shared.helper_asleep.store(true, Ordering::Relaxed);
                        slot = shared
                            .wake
                            .wait(slot)
                            .unwrap_or_else(PoisonError::into_inner);
                        shared.helper_asleep.store(false, Ordering::Relaxed);
                    }
                }
            }
        };
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(worker)));
        // The job's captures (the caller's board) are released before the
        // caller hears that the job is done.
        drop(job);
        let mut slot = lock(&shared.slot);
        *slot = match result {
            Ok(()) => Slot::Done,
            Err(payload) => Slot::Panicked(payload),
        };
        shared.finished.store(true, Ordering::Release);
        let asleep = shared.caller_asleep.load(Ordering::Relaxed);
        drop(slot);
        if asleep {
            shared.back.notify_one();
        }
    }
}
