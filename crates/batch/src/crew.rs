//! A crew of persistent helper threads for a batch that steps many times
//! a second in short calls (a vector environment's step: about a
//! millisecond of work per call).
//!
//! A rayon pool costs such a call the hand-off of the job to a sleeping
//! worker, the worker's wake-up, and the caller's own wake-up when the job
//! is done: some 50 µs a call on the 2-core machine here, a tenth of a
//! 256-lander step on two threads. The crew keeps the calling thread at
//! work (it takes the first run of items itself) and its helpers awake
//! between calls for a short while (spinning on a flag, yielding), so a
//! call costs a flag and a lock per helper.
//!
//! Items move, they are not shared: each call hands helper `k` its own
//! `Vec` of items (a pointer move) with the task, and takes it back when
//! the task is done. No item is ever seen by two threads at once, so the
//! crew needs no `unsafe` and the items only `Send`.

use janus2d::WorldError;
use std::any::Any;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What a task does to a run of items: the first error, with the index
/// of its item in the whole batch.
pub(crate) type Task<T> = Box<dyn FnOnce(&mut [T]) -> Failure + Send>;

/// A task's first error, with its item's index in the whole batch.
pub(crate) type Failure = Option<(usize, WorldError)>;

/// A helper's panic, handed to the caller.
pub(crate) type Panic = Box<dyn Any + Send>;

/// A helper thread: its slot and its handle (taken when it is joined).
struct Helper<T> {
    shared: Arc<Shared<T>>,
    handle: Option<JoinHandle<()>>,
}

/// How long a helper keeps watching for the next task before it sleeps.
const STAY_AWAKE: Duration = Duration::from_micros(300);

enum Slot<T> {
    Empty,
    Work(Vec<T>, Task<T>),
    Done(Vec<T>, Failure),
    Panicked(Panic),
    Quit,
}

struct Shared<T> {
    slot: Mutex<Slot<T>>,
    /// The helper waits here for work.
    wake: Condvar,
    /// The caller waits here for the result.
    back: Condvar,
    /// Work is in the slot (read while spinning, without the lock).
    posted: AtomicBool,
    /// A result is in the slot.
    finished: AtomicBool,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Helper threads, each with a slot the caller posts work into.
pub(crate) struct Crew<T: Send + 'static> {
    helpers: Vec<Helper<T>>,
}

impl<T: Send + 'static> Crew<T> {
    /// A crew of `helpers` threads.
    pub(crate) fn new(helpers: usize) -> Result<Crew<T>, std::io::Error> {
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
            });
            let mine = Arc::clone(&shared);
            // On an error the crew built so far is dropped: its threads quit.
            let handle = std::thread::Builder::new()
                .name(format!("janus2d-crew-{}", k + 1))
                .spawn(move || helper_loop(&mine))?;
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

    /// Hands `items` and `task` to helper `k`.
    pub(crate) fn post(&self, k: usize, items: Vec<T>, task: Task<T>) {
        let shared = &self.helpers[k].shared;
        let mut slot = lock(&shared.slot);
        *slot = Slot::Work(items, task);
        shared.finished.store(false, Ordering::Relaxed);
        shared.posted.store(true, Ordering::Release);
        drop(slot);
        shared.wake.notify_one();
    }

    /// Waits for helper `k`'s result: its items back and the task's
    /// first error, or the panic its task raised (the items are lost).
    pub(crate) fn collect(&self, k: usize) -> Result<(Vec<T>, Failure), Panic> {
        let shared = &self.helpers[k].shared;
        let start = Instant::now();
        while !shared.finished.load(Ordering::Acquire) && start.elapsed() < STAY_AWAKE {
            std::thread::yield_now();
        }
        let mut slot = lock(&shared.slot);
        loop {
            match std::mem::replace(&mut *slot, Slot::Empty) {
                Slot::Done(items, error) => return Ok((items, error)),
                Slot::Panicked(payload) => return Err(payload),
                other => {
                    *slot = other;
                    slot = shared
                        .back
                        .wait(slot)
                        .unwrap_or_else(PoisonError::into_inner);
                }
            }
        }
    }
}

impl<T: Send + 'static> Drop for Crew<T> {
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

fn helper_loop<T>(shared: &Shared<T>) {
    loop {
        let start = Instant::now();
        while !shared.posted.load(Ordering::Acquire) && start.elapsed() < STAY_AWAKE {
            std::thread::yield_now();
        }
        let (mut items, task) = {
            let mut slot = lock(&shared.slot);
            loop {
                match std::mem::replace(&mut *slot, Slot::Empty) {
                    Slot::Work(items, task) => {
                        shared.posted.store(false, Ordering::Relaxed);
                        break (items, task);
                    }
                    Slot::Quit => return,
                    other => {
                        *slot = other;
                        slot = shared
                            .wake
                            .wait(slot)
                            .unwrap_or_else(PoisonError::into_inner);
                    }
                }
            }
        };
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| task(&mut items)));
        let mut slot = lock(&shared.slot);
        *slot = match result {
            Ok(error) => Slot::Done(items, error),
            Err(payload) => Slot::Panicked(payload),
        };
        shared.finished.store(true, Ordering::Release);
        drop(slot);
        shared.back.notify_one();
    }
}
