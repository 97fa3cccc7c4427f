//! The step's worker team: one rayon broadcast per step, stages split into
//! blocks that the workers claim through atomics.
//!
//! ```text
//! World::step ── with_team ── rayon::broadcast (once per step) ────────────┐
//!   thread 0 (leader)                  threads 1..n (followers)            │
//!   runs the stage sequence            wait for a job (spin, then yield)   │
//!   ├ team.run(blocks, job) ─publish─▶ claim block i (swap) → job(i)       │
//!   │   claims blocks itself            … until every block is claimed     │
//!   │   waits: done == blocks                                              │
//!   │   retires the job, waits until no follower holds it                  │
//!   ├ serial work (merges, colourings, overflows): followers spin          │
//!   ├ team.run(...) …                                                      │
//!   └ stop ─────────────────────────▶ return to rayon ─────────────────────┘
//! ```
//!
//! A stage is one job: no fork–join per colour, one atomic swap per
//! claimed block. Thread `t` of `n` starts claiming at block `t · blocks /
//! n` (forward, then backward from there, see `Shared::work`), so a thread
//! tends to run the same share of every stage and its data stays in that
//! thread's cache. Whatever a job computes for block `i` must not depend on
//! which thread runs it; the solver's jobs write disjoint data per block, so
//! results are bit-identical for any thread count.
//!
//! Without the `parallel` feature, or in a pool of one thread, the team is
//! serial: [`Team::run`] calls the job for blocks `0, 1, …` in order on the
//! caller.
//!
//! # Safety
//!
//! This and [`hint`](crate::hint) are the modules of `janus2d-core` that
//! use `unsafe` (the rest of the crate denies it). It does what safe Rust
//! cannot express here:
//!
//! 1. **A borrowed job handed to threads that outlive the call.** The
//!    followers are started once per step, but every job borrows stage data
//!    that lives only during [`Team::run`]. The job's reference is stored
//!    with its lifetime erased; [`Team::run`] does not return before (a)
//!    every block has finished (`done == blocks`) and (b) no follower holds
//!    the job any more (`active == 0` after the job was retired). A follower
//!    increments `active` *before* re-reading the epoch and reads the job
//!    only if the epoch still names it; all these operations are `SeqCst`,
//!    so in their single total order either the follower's increment comes
//!    before the leader's check of `active` (and the leader waits for the
//!    matching decrement, which the follower makes after its last use of
//!    the job), or the follower's re-read comes after the retiring store
//!    and it never touches the job. So no job is used after `run` returns.
//!    The job cell itself is written only by the leader while the epoch is
//!    idle and `active == 0`, when no follower reads it.
//! 2. **Disjoint mutable blocks of one slice** ([`Team::for_each_chunk_mut`],
//!    and of two or three equally long slices at once,
//!    [`Team::for_each_chunk_pair_mut`], [`Team::for_each_chunk_triple_mut_beside`]).
//!    Block `i` is the sub-slice `[i·len, min((i+1)·len, n))`; a block is
//!    run by the one thread whose swap of the job's epoch into the block's
//!    claim flag returned another value (epochs never repeat within a team,
//!    and the flags start at 0), blocks past the flags by the one thread
//!    the claim counter hands them to, so each block index runs exactly
//!    once per job: the `&mut` sub-slices never alias, and they do not
//!    outlive the job (hence not the `&mut` borrow `for_each_chunk_mut`
//!    holds).
//! 3. **Body states written by several threads at once**
//!    ([`Team::for_each_planned`]). A [`StatePlan`] lists, per item of a
//!    group (a colour's chunk), the state indices it reads and the subset
//!    it writes; [`StatePlan::verify`] checks once that they are in bounds,
//!    that no state is written by two slots of a group, and that no state
//!    written by one item is read by another. A job runs one group, each
//!    item by exactly one thread (point 2), through [`PlannedStates`],
//!    which reaches only that item's slots. So every state is either
//!    written by one item and touched by no other, or only read, during the
//!    job: no data race. Two plans' groups run as one job
//!    ([`Team::for_each_planned_pair`]) only after a [`CrossPlan`] checked
//!    that no state written by an item of either group is a slot of an
//!    item of the other, for exactly these two verifications (ids) and
//!    this state count: the same argument then covers the items of both. A plan runs on threads only if it was verified
//!    against the very slice length it is given; otherwise it runs
//!    serially.
//! 4. **Items made in place** ([`Team::extend_mapped`]). The new items
//!    are written into the vector's spare capacity, item `i` by the one
//!    block that holds index `i` (point 2: every block runs exactly once,
//!    and the blocks cover `0..count`), and the length is set only after
//!    [`Team::run`] returned normally, which it does only when every block
//!    finished; a block that panics makes `run` panic first (on the leader
//!    directly, on a follower through the `panicked` flag), so the length
//!    never covers a slot left unwritten. Items written before such a
//!    panic are leaked, never read or dropped.
//!
//! Memory ordering of the data: a block's writes happen before its
//! `done.fetch_add` (a release RMW); the leader's acquire load that sees the
//! final count synchronises with every such RMW (they form one release
//! sequence), and the next job is published with a release store that the
//! followers acquire. So each stage sees all writes of the stage before.

#![allow(unsafe_code)]

use std::cell::UnsafeCell;

use crate::body::BodyState;
use crate::math::{Real, Vec2};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::SeqCst};

/// A stage's job: called once for every block index.
type Job<'a> = &'a (dyn Fn(usize) + Sync + 'a);

/// The epoch value that tells followers to leave.
#[cfg_attr(not(feature = "parallel"), allow(dead_code))]
const STOP: u64 = u64::MAX;

/// What the leader shares with the followers. The epoch is odd while a job
/// is published and even while the team is idle.
struct Shared {
    epoch: AtomicU64,
    /// The published job, lifetime erased (see the module's safety proof).
    job: UnsafeCell<Option<Job<'static>>>,
    blocks: AtomicUsize,
    /// The claim counter (blocks past the claim flags), the finished count
    /// and the holders each on a cache line of their own: claims do not
    /// slow the followers' polling.
    next: Line<AtomicUsize>,
    done: Line<AtomicUsize>,
    /// Followers currently holding the published job.
    active: Line<AtomicUsize>,
    /// Set when a block panicked on a follower.
    panicked: AtomicBool,
    /// Per block (the first [`CLAIM_FLAGS`] of a job): the epoch of the
    /// last job in which a thread claimed it.
    claims: Box<[AtomicU64]>,
    /// Threads of the team (the leader is thread 0).
    threads: usize,
}

/// Blocks of a job claimed through per-block flags, each thread starting at
/// its own share (see [`Shared::work`]); a job with more blocks claims the
/// rest through the counter.
const CLAIM_FLAGS: usize = 4096;

/// A value alone on its cache line (128 bytes: two lines on x86, whose
/// prefetcher pairs them).
#[repr(align(128))]
struct Line<T>(T);

impl<T> std::ops::Deref for Line<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.0
    }
}

// SAFETY: `job` is written only by the leader while no follower can read it
// and read by followers only while the leader does not write it (module
// docs, point 1); every other field is atomic.
unsafe impl Sync for Shared {}

impl Shared {
    #[cfg_attr(not(feature = "parallel"), allow(dead_code))]
    fn new(threads: usize) -> Self {
        Shared {
            claims: (0..CLAIM_FLAGS).map(|_| AtomicU64::new(0)).collect(),
            threads: threads.max(1),
            epoch: AtomicU64::new(0),
            job: UnsafeCell::new(None),
            blocks: AtomicUsize::new(0),
            next: Line(AtomicUsize::new(0)),
            done: Line(AtomicUsize::new(0)),
            active: Line(AtomicUsize::new(0)),
            panicked: AtomicBool::new(false),
        }
    }

    /// Claims and runs blocks of the published job (epoch `epoch`) until
    /// none is left, as thread `thread` of the team.
    ///
    /// Thread `t` of `n` starts at block `t · blocks / n` and claims forward
    /// (wrapping) while the blocks are free, then backward from its start;
    /// a block is claimed by swapping the job's epoch into its flag (the
    /// thread that sees another value there has it). So with the usual
    /// timing each thread runs the same share of every job, stage after
    /// stage, and the data of a share stays in its thread's cache: where
    /// the cores do not share a cache, moving a stage's data between them
    /// costs more than the stage. Every block is claimed: a free block's
    /// nearest claimed block on its left was claimed by a forward run
    /// (which would then have tried the free block next) or by a backward
    /// run (which starts just left of a claimed block and moves left), so
    /// none is left free once every thread has stopped.
    fn work(&self, job: Job<'_>, blocks: usize, epoch: u64, thread: usize) {
        // The blocks this thread started, added to `done` once at the end,
        // even if a block panics, so the leader never waits for a block
        // that will not finish.
        struct Done<'s>(&'s AtomicUsize, usize);
        impl Drop for Done<'_> {
            fn drop(&mut self) {
                if self.1 > 0 {
                    self.0.fetch_add(self.1, SeqCst);
                }
            }
        }
        let mut done = Done(&self.done, 0);
        let flagged = blocks.min(CLAIM_FLAGS);
        if flagged > 0 && thread < flagged {
            let claim = |i: usize| self.claims[i].swap(epoch, SeqCst) != epoch;
            let start = thread * flagged / self.threads;
            let mut i = start;
            while claim(i) {
                done.1 += 1;
                job(i);
                i = if i + 1 == flagged { 0 } else { i + 1 };
            }
            let mut i = start;
            loop {
                i = if i == 0 { flagged - 1 } else { i - 1 };
                if !claim(i) {
                    break;
                }
                done.1 += 1;
                job(i);
            }
        }
        // Blocks past the flags: the counter.
        loop {
            let i = CLAIM_FLAGS + self.next.fetch_add(1, SeqCst);
            if i >= blocks {
                return;
            }
            done.1 += 1;
            job(i);
        }
    }
}

/// Spins before a waiting thread starts yielding its core (a few µs):
/// long enough to cover the leader's serial work between two jobs of a
/// stage, short enough not to starve a leader that shares a core.
const SPINS_BEFORE_YIELD: u32 = 1 << 10;

/// Waits a little, then lets other threads run: a follower may share its
/// core with the leader (more threads than cores).
#[inline]
fn backoff(spins: &mut u32) {
    if *spins < SPINS_BEFORE_YIELD {
        std::hint::spin_loop();
        *spins += 1;
    } else {
        std::thread::yield_now();
    }
}

/// The step's workers, as seen by the stage code (which runs on the
/// leader). See the module docs.
pub struct Team<'t> {
    shared: Option<&'t Shared>,
    threads: usize,
}

impl Team<'static> {
    /// A team of one: every job runs on the caller, blocks in order.
    #[must_use]
    pub fn serial() -> Self {
        Team {
            shared: None,
            threads: 1,
        }
    }
}

impl Team<'_> {
    /// Number of threads that run jobs (1 for a serial team).
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Runs `job(i)` for every block `i` in `0..blocks`, spread over the
    /// team, and returns when every block has finished. The blocks run in
    /// any order and concurrently: `job` must give the same result for
    /// block `i` whoever runs it.
    pub fn run(&self, blocks: usize, job: &(dyn Fn(usize) + Sync)) {
        self.run_beside(blocks, job, || {});
    }

    /// [`Team::run`] with `beside` run on the leader first while the
    /// followers already claim blocks (the leader then claims what is
    /// left): serial work that does not touch the job's data costs no
    /// follower a wait. On a serial team, `beside` runs, then the blocks
    /// in order; either way `beside` runs before this returns, exactly
    /// once.
    pub fn run_beside(&self, blocks: usize, job: &(dyn Fn(usize) + Sync), beside: impl FnOnce()) {
        let Some(shared) = self.shared.filter(|_| blocks > 1) else {
            beside();
            for i in 0..blocks {
                job(i);
            }
            return;
        };
        let epoch = shared.epoch.load(SeqCst);
        debug_assert!(
            epoch.is_multiple_of(2),
            "a job is published while another runs"
        );
        // SAFETY: only the lifetime is erased; the module docs (point 1)
        // prove the reference is not used after this call returns.
        let erased: Job<'static> = unsafe { std::mem::transmute::<Job<'_>, Job<'static>>(job) };
        // SAFETY: the epoch is even and `active == 0` (the last `run`
        // waited for it): no follower reads the cell now.
        unsafe { *shared.job.get() = Some(erased) };
        shared.blocks.store(blocks, SeqCst);
        shared.next.store(0, SeqCst);
        shared.done.store(0, SeqCst);
        shared.epoch.store(epoch + 1, SeqCst);
        // Retire the job even if a block of the leader's panics.
        struct Retire<'s>(&'s Shared, u64, usize);
        impl Drop for Retire<'_> {
            fn drop(&mut self) {
                let (shared, epoch, blocks) = (self.0, self.1, self.2);
                let mut spins = 0;
                while shared.done.load(SeqCst) < blocks {
                    backoff(&mut spins);
                }
                shared.epoch.store(epoch + 2, SeqCst);
                let mut spins = 0;
                while shared.active.load(SeqCst) != 0 {
                    backoff(&mut spins);
                }
            }
        }
        let retire = Retire(shared, epoch, blocks);
        beside();
        shared.work(job, blocks, epoch + 1, 0);
        drop(retire);
        if shared.panicked.load(SeqCst) {
            panic!("a block of a parallel stage panicked on a worker thread");
        }
    }

    /// `f(i)` for every block `i` in `0..blocks`, spread over the team, the
    /// results in block order (what a parallel map and collect gives, with
    /// the blocks on the step's team).
    pub fn map_blocks<T: Send>(&self, blocks: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
        let mut out = Vec::with_capacity(blocks);
        self.extend_mapped(&mut out, blocks, 1, f);
        out
    }

    /// Appends `count` items to `out`, item `i` being `f(i)`, made in
    /// blocks of `len` items spread over the team and written where they
    /// stay (as rayon's `collect_into_vec`): no item is moved or copied
    /// after it is made, which matters for large items (a wide contact
    /// chunk is over a kilobyte).
    pub fn extend_mapped<T: Send>(
        &self,
        out: &mut Vec<T>,
        count: usize,
        len: usize,
        f: impl Fn(usize) -> T + Sync,
    ) {
        let len = len.max(1);
        let start = out.len();
        out.reserve(count);
        let spare = &mut out.spare_capacity_mut()[..count];
        self.for_each_chunk_mut(spare, len, |b, slots| {
            for (j, slot) in slots.iter_mut().enumerate() {
                slot.write(f(b * len + j));
            }
        });
        // SAFETY: `for_each_chunk_mut` returned normally, so every block of
        // `0..count` ran to its end and wrote each of its slots (module
        // docs, point 4); `start + count` is within the reserved capacity.
        unsafe { out.set_len(start + count) };
    }

    /// Calls `f(i, block)` for the blocks of `items` of `len` items each
    /// (the last one shorter), spread over the team; `i` is the block's
    /// index, so block `i` starts at item `i · len`.
    pub fn for_each_chunk_mut<T: Send>(
        &self,
        items: &mut [T],
        len: usize,
        f: impl Fn(usize, &mut [T]) + Sync,
    ) {
        // A slice of `()` as long as `items` costs no memory: the two-slice
        // form carries the one proof of disjoint blocks.
        let mut none = vec![(); items.len()];
        self.for_each_chunk_pair_mut(items, &mut none, len, |i, chunk, _| f(i, chunk));
    }

    /// [`Team::for_each_chunk_mut`] with `beside`, serial work of the
    /// caller's that shares no data with `items`, run first on the leader
    /// while the other threads start on the blocks (on a serial team, before
    /// the blocks).
    pub fn for_each_chunk_mut_beside<T: Send>(
        &self,
        items: &mut [T],
        len: usize,
        f: impl Fn(usize, &mut [T]) + Sync,
        beside: impl FnOnce(),
    ) {
        let mut none = vec![(); items.len()];
        self.for_each_chunk_pair_mut_beside(
            items,
            &mut none,
            len,
            |i, chunk, _| f(i, chunk),
            beside,
        );
    }

    /// `f(i, block)` for the blocks of `items` of `len` items each, as
    /// [`Team::for_each_chunk_mut`] runs them, the results in block order
    /// ([`Team::map_blocks`] for work that changes its items).
    pub fn map_chunks_mut<T: Send, R: Send>(
        &self,
        items: &mut [T],
        len: usize,
        f: impl Fn(usize, &mut [T]) -> R + Sync,
    ) -> Vec<R> {
        // One block of items and one result slot per job block: the
        // two-slice form's proof of disjoint blocks covers both.
        let mut blocks: Vec<&mut [T]> = items.chunks_mut(len.max(1)).collect();
        let mut found: Vec<Option<R>> = blocks.iter().map(|_| None).collect();
        self.for_each_chunk_pair_mut(&mut blocks, &mut found, 1, |i, block, slot| {
            slot[0] = Some(f(i, &mut *block[0]));
        });
        // (Every block ran: none is `None`.)
        found.into_iter().flatten().collect()
    }

    /// [`Team::for_each_chunk_mut`] over two slices of the same length at
    /// once: `f(i, a_block, b_block)` gets the same item range of both
    /// (the body sims and their states, say).
    ///
    /// # Panics
    ///
    /// When the slices' lengths differ (a bug of the caller, not input).
    pub fn for_each_chunk_pair_mut<A: Send, B: Send>(
        &self,
        a: &mut [A],
        b: &mut [B],
        len: usize,
        f: impl Fn(usize, &mut [A], &mut [B]) + Sync,
    ) {
        self.for_each_chunk_pair_mut_beside(a, b, len, f, || {});
    }

    /// [`Team::for_each_chunk_pair_mut`] with `beside`, serial work of the
    /// caller's that shares no data with `a` and `b`, run first on the
    /// leader while the other threads start on the blocks (on a serial
    /// team, before the blocks).
    ///
    /// # Panics
    ///
    /// When the slices' lengths differ (a bug of the caller, not input).
    pub fn for_each_chunk_pair_mut_beside<A: Send, B: Send>(
        &self,
        a: &mut [A],
        b: &mut [B],
        len: usize,
        f: impl Fn(usize, &mut [A], &mut [B]) + Sync,
        beside: impl FnOnce(),
    ) {
        // A slice of `()` costs no memory.
        let mut none = vec![(); a.len()];
        self.for_each_chunk_triple_mut_beside(
            a,
            b,
            &mut none,
            len,
            |i, ca, cb, _| f(i, ca, cb),
            beside,
        );
    }

    /// [`Team::for_each_chunk_pair_mut`] over three slices of the same
    /// length at once (the contacts, their staged records and their
    /// results, say), with `beside` run on the leader while the followers
    /// start on the blocks (see [`Team::run_beside`]).
    ///
    /// # Panics
    ///
    /// When the slices' lengths differ (a bug of the caller, not input).
    pub fn for_each_chunk_triple_mut_beside<A: Send, B: Send, C: Send>(
        &self,
        a: &mut [A],
        b: &mut [B],
        c: &mut [C],
        len: usize,
        f: impl Fn(usize, &mut [A], &mut [B], &mut [C]) + Sync,
        beside: impl FnOnce(),
    ) {
        assert!(
            a.len() == b.len() && a.len() == c.len(),
            "chunked slices differ in length"
        );
        let len = len.max(1);
        let n = a.len();
        let blocks = n.div_ceil(len);
        if self.shared.is_none() || blocks <= 1 {
            beside();
            for (i, ((ca, cb), cc)) in a
                .chunks_mut(len)
                .zip(b.chunks_mut(len))
                .zip(c.chunks_mut(len))
                .enumerate()
            {
                f(i, ca, cb, cc);
            }
            return;
        }
        let bases = (
            Base(a.as_mut_ptr()),
            Base(b.as_mut_ptr()),
            Base(c.as_mut_ptr()),
        );
        let bases = &bases;
        self.run_beside(
            blocks,
            &|i| {
                let start = i * len;
                let count = len.min(n - start);
                // SAFETY: for each slice, `start + count ≤ n` (equal lengths),
                // block `i` is claimed once, and blocks do not overlap (module
                // docs, point 2); the slices stay mutably borrowed until `run`
                // returns.
                let (ca, cb, cc) = unsafe {
                    (
                        std::slice::from_raw_parts_mut(bases.0.0.add(start), count),
                        std::slice::from_raw_parts_mut(bases.1.0.add(start), count),
                        std::slice::from_raw_parts_mut(bases.2.0.add(start), count),
                    )
                };
                f(i, ca, cb, cc);
            },
            beside,
        );
    }
}

/// Which body states each item of a stage reads and writes, checked once so
/// that the items can then run on the team and write the states directly.
///
/// Items come in groups (the contact colours); an item has `N` slots, each
/// a state index, and a mask of the slots it writes. [`StatePlan::verify`]
/// checks, per group, that no state is written by two slots and that no
/// state one item writes is read by another item of the group. Then
/// [`Team::for_each_planned`] runs a group's items concurrently, each
/// seeing only its own slots.
#[derive(Clone, Debug, Default)]
pub struct StatePlan<const N: usize> {
    slots: Vec<[u32; N]>,
    writes: Vec<u32>,
    /// First item of each group, and the item count at the end.
    group_start: Vec<usize>,
    /// The state count the plan was verified against (`None`: not verified,
    /// or verification failed).
    verified: Option<usize>,
    /// Verification scratch of the serial check.
    scratch: VerifyScratch,
    /// One scratch per thread for the check on a team (taken out while it
    /// runs; not cloned).
    team_scratch: ScratchPool,
    /// A number no other verification of any plan has given (set by a
    /// successful [`StatePlan::verify`]): a [`CrossPlan`] names the two
    /// plans it checked by it.
    id: u64,
}

/// The source of [`StatePlan`] ids: each successful verification takes
/// the next one, so an id names one verified content of one plan.
static PLAN_IDS: AtomicU64 = AtomicU64::new(1);

impl<const N: usize> StatePlan<N> {
    /// Forgets every item and group.
    pub fn clear(&mut self) {
        const { assert!(N <= 32, "a write mask has 32 bits") };
        self.slots.clear();
        self.writes.clear();
        self.group_start.clear();
        self.verified = None;
    }

    /// Starts a new group; the items pushed next belong to it.
    pub fn begin_group(&mut self) {
        self.group_start.push(self.slots.len());
        self.verified = None;
    }

    /// Adds an item to the current group: its state indices, and a mask
    /// whose bit `k` says slot `k` is written.
    pub fn push(&mut self, slots: [u32; N], writes: u32) {
        if self.group_start.is_empty() {
            self.group_start.push(0);
        }
        self.slots.push(slots);
        self.writes.push(writes);
        self.verified = None;
    }

    /// Adds groups of `counts` items each, whose state indices and write
    /// masks the caller fills in the slices returned (every new item, in
    /// group order; all zero until then), so that a team can fill them in
    /// blocks: the same plan as, per group, [`StatePlan::begin_group`] and
    /// its items' [`StatePlan::push`]es.
    pub fn push_groups(
        &mut self,
        counts: impl IntoIterator<Item = usize>,
    ) -> (&mut [[u32; N]], &mut [u32]) {
        let start = self.slots.len();
        let mut end = start;
        for count in counts {
            self.group_start.push(end);
            end += count;
        }
        self.slots.resize(end, [0; N]);
        self.writes.resize(end, 0);
        self.verified = None;
        (&mut self.slots[start..], &mut self.writes[start..])
    }

    /// Number of groups.
    #[must_use]
    pub fn group_count(&self) -> usize {
        self.group_start.len()
    }

    fn group(&self, g: usize) -> std::ops::Range<usize> {
        let start = self.group_start[g];
        let end = self
            .group_start
            .get(g + 1)
            .copied()
            .unwrap_or(self.slots.len());
        start..end
    }

    /// Checks the plan against `state_count` states: every index in range,
    /// within each group no state written twice and none written by one
    /// item and read by another. Returns whether it holds; only a verified
    /// plan runs on several threads.
    pub fn verify(&mut self, state_count: usize) -> bool {
        self.verified = None;
        let mut scratch = std::mem::take(&mut self.scratch);
        let holds = (0..self.group_count()).all(|g| self.check_group(g, &mut scratch, state_count));
        self.scratch = scratch;
        self.settle(holds, state_count)
    }

    /// [`StatePlan::verify`] with the groups checked on `team` (each
    /// block one group, with a scratch of its own): the same answer. On
    /// two threads the serial check of the large pyramid's contact plan
    /// (about 1,900 chunks of 16 slots) was about 2% of the leader's
    /// samples, with the other thread waiting.
    pub fn verify_on(&mut self, state_count: usize, team: &Team) -> bool {
        if team.threads() == 1 || self.group_count() < 2 || self.slots.len() < PARALLEL_VERIFY {
            return self.verify(state_count);
        }
        self.verified = None;
        let mut pool = std::mem::take(&mut self.team_scratch);
        pool.0.resize_with(team.threads(), Default::default);
        let plan = &*self;
        let holds = team
            .map_blocks(self.group_count(), |g| {
                let mut scratch = pool.take();
                plan.check_group(g, &mut scratch, state_count)
            })
            .into_iter()
            .all(|ok| ok);
        self.team_scratch = pool;
        self.settle(holds, state_count)
    }

    /// Marks the plan verified (with a new id) when `holds`.
    fn settle(&mut self, holds: bool, state_count: usize) -> bool {
        if holds {
            self.verified = Some(state_count);
            self.id = PLAN_IDS.fetch_add(1, SeqCst);
        }
        holds
    }

    /// Checks group `g` (see [`StatePlan::verify`]) with `scratch`.
    fn check_group(&self, g: usize, scratch: &mut VerifyScratch, state_count: usize) -> bool {
        let generation = scratch.next_generation(state_count);
        let range = self.group(g);
        for item in range.clone() {
            let (slots, writes) = (&self.slots[item], self.writes[item]);
            for (k, &index) in slots.iter().enumerate() {
                let i = index as usize;
                if i >= state_count {
                    return false;
                }
                if writes & (1 << k) == 0 {
                    continue;
                }
                if scratch.writer_generation[i] == generation {
                    return false;
                }
                scratch.writer_generation[i] = generation;
                scratch.writer_item[i] = item as u32;
            }
        }
        for item in range {
            let (slots, writes) = (&self.slots[item], self.writes[item]);
            for (k, &index) in slots.iter().enumerate() {
                let i = index as usize;
                if writes & (1 << k) == 0
                    && scratch.writer_generation[i] == generation
                    && scratch.writer_item[i] != item as u32
                {
                    return false;
                }
            }
        }
        true
    }
}

/// Items from which [`StatePlan::verify_on`] checks the groups on the team.
const PARALLEL_VERIFY: usize = 1024;

/// A plan check's scratch: per state, the generation of the group that
/// writes it and the writing item.
#[derive(Clone, Debug, Default)]
struct VerifyScratch {
    writer_generation: Vec<u32>,
    writer_item: Vec<u32>,
    generation: u32,
}

impl VerifyScratch {
    /// Covers `state_count` states and returns a generation no entry holds.
    fn next_generation(&mut self, state_count: usize) -> u32 {
        if self.writer_generation.len() < state_count {
            self.writer_generation.resize(state_count, 0);
            self.writer_item.resize(state_count, 0);
        }
        if self.generation == u32::MAX {
            self.writer_generation.fill(0);
            self.generation = 0;
        }
        self.generation += 1;
        self.generation
    }
}

/// One [`VerifyScratch`] per thread of a team: a block takes one no other
/// block holds (at most one block runs per thread, so one is free).
#[derive(Debug, Default)]
struct ScratchPool(Vec<std::sync::Mutex<VerifyScratch>>);

impl ScratchPool {
    /// A scratch no other block holds.
    fn take(&self) -> std::sync::MutexGuard<'_, VerifyScratch> {
        loop {
            for m in &self.0 {
                match m.try_lock() {
                    Ok(guard) => return guard,
                    // A block that panicked left it: its contents are
                    // only marks, and a new generation ignores them.
                    Err(std::sync::TryLockError::Poisoned(p)) => return p.into_inner(),
                    Err(std::sync::TryLockError::WouldBlock) => {}
                }
            }
            std::hint::spin_loop();
        }
    }
}

impl Clone for ScratchPool {
    /// Scratch only: a clone starts with none.
    fn clone(&self) -> Self {
        ScratchPool::default()
    }
}

/// Two verified plans checked against each other, so that group `g` of
/// the one and group `g` of the other can run as one job
/// ([`Team::for_each_planned_pair`]): no state that an item of either
/// group writes is read or written by an item of the other.
///
/// The check names the two plans' verifications (their ids) and the state
/// count; a plan changed since (cleared, pushed to, verified again) no
/// longer matches, and the pair then runs as two jobs.
#[derive(Clone, Debug, Default)]
pub struct CrossPlan {
    /// The plan ids and state count of the last successful check.
    verified: Option<(u64, u64, usize)>,
    /// Per state: the generation that last marked it written.
    marks: Vec<u32>,
    generation: u32,
}

impl CrossPlan {
    /// An unchecked pair.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether `a` and `b`, as they are now, were checked together for
    /// `state_count` states.
    #[must_use]
    pub fn holds<const N: usize, const M: usize>(
        &self,
        a: &StatePlan<N>,
        b: &StatePlan<M>,
        state_count: usize,
    ) -> bool {
        a.verified == Some(state_count)
            && b.verified == Some(state_count)
            && self.verified == Some((a.id, b.id, state_count))
    }

    /// Checks `a` against `b` (both verified for `state_count` states):
    /// for every group index both have, no state written by an item of
    /// one is a slot of an item of the other. Returns whether it holds; a
    /// check already made for the same verifications returns at once.
    pub fn verify<const N: usize, const M: usize>(
        &mut self,
        a: &StatePlan<N>,
        b: &StatePlan<M>,
        state_count: usize,
    ) -> bool {
        if self.holds(a, b, state_count) {
            return true;
        }
        self.verified = None;
        if a.verified != Some(state_count) || b.verified != Some(state_count) {
            return false;
        }
        if self.marks.len() < state_count {
            self.marks.resize(state_count, 0);
        }
        for g in 0..a.group_count().min(b.group_count()) {
            if !self.disjoint(a, b, g) || !self.disjoint(b, a, g) {
                return false;
            }
        }
        self.verified = Some((a.id, b.id, state_count));
        true
    }

    /// No state written by group `g` of `w` is a slot of group `g` of `r`.
    fn disjoint<const N: usize, const M: usize>(
        &mut self,
        w: &StatePlan<N>,
        r: &StatePlan<M>,
        g: usize,
    ) -> bool {
        if self.generation == u32::MAX {
            self.marks.fill(0);
            self.generation = 0;
        }
        self.generation += 1;
        let generation = self.generation;
        for item in w.group(g) {
            for (k, &index) in w.slots[item].iter().enumerate() {
                if w.writes[item] & (1 << k) != 0 {
                    // In range: `w` was verified for this state count.
                    self.marks[index as usize] = generation;
                }
            }
        }
        r.group(g).all(|item| {
            r.slots[item]
                .iter()
                .all(|&index| self.marks[index as usize] != generation)
        })
    }
}

/// One side of [`Team::for_each_planned_pair`]: the items of group
/// `group` of `plan` (`items[i]` is the group's `i`-th item), run
/// `per_block` to a block.
pub struct PlannedGroup<'i, T, const N: usize> {
    /// The verified plan.
    pub plan: &'i StatePlan<N>,
    /// The group of the plan.
    pub group: usize,
    /// One item per planned item of the group.
    pub items: &'i mut [T],
    /// Items per block on the team.
    pub per_block: usize,
}

/// The states one planned item may touch: its slots of the plan.
pub struct PlannedStates<'p, const N: usize> {
    base: *mut BodyState,
    len: usize,
    slots: &'p [u32; N],
    writes: u32,
}

impl<const N: usize> PlannedStates<'_, N> {
    /// The state in slot `k`.
    #[inline(always)]
    #[must_use]
    pub fn get(&self, k: usize) -> BodyState {
        let i = self.slots[k] as usize;
        assert!(i < self.len, "planned state index out of range");
        // SAFETY: `i` is in bounds of the slice `base` points into, which
        // `for_each_planned` holds mutably borrowed; no other item of the
        // group writes it (point 3 of the module's proof).
        unsafe { self.base.add(i).read() }
    }

    /// Sets the velocities of slot `k`'s state when the plan lets this item
    /// write it; otherwise does nothing (a slot on a state the stage does
    /// not move).
    #[inline(always)]
    pub fn set_velocity(&mut self, k: usize, v: Vec2, w: Real) {
        let i = self.slots[k] as usize;
        assert!(i < self.len, "planned state index out of range");
        if self.writes & (1 << k) != 0 {
            // SAFETY: as in `get`; and this item is the only one of the
            // group that reads or writes state `i` (point 3).
            unsafe {
                let state = self.base.add(i);
                (*state).v = v;
                (*state).w = w;
            }
        }
    }
}

impl Team<'_> {
    /// Runs `f(item, states)` for the items of group `group` of a verified
    /// `plan` (`items[i]` is the group's `i`-th item), `per_block` items per
    /// block, on the team; each call sees the states of its own slots. An
    /// unverified plan, a plan verified for another state count or a serial
    /// team runs the items in order on the caller, with the same result.
    pub fn for_each_planned<T: Send, const N: usize>(
        &self,
        plan: &StatePlan<N>,
        group: usize,
        items: &mut [T],
        states: &mut [BodyState],
        per_block: usize,
        f: impl Fn(&mut T, &mut PlannedStates<'_, N>) + Sync,
    ) {
        let range = plan.group(group);
        assert_eq!(range.len(), items.len(), "one item per planned item");
        let slots = &plan.slots[range.clone()];
        let writes = &plan.writes[range];
        let len = states.len();
        let base = Base(states.as_mut_ptr());
        let base = &base;
        let run_item = |item: &mut T, k: usize| {
            let mut view = PlannedStates {
                base: base.0,
                len,
                slots: &slots[k],
                writes: writes[k],
            };
            f(item, &mut view);
        };
        if plan.verified != Some(len) || self.shared.is_none() {
            for (k, item) in items.iter_mut().enumerate() {
                run_item(item, k);
            }
            return;
        }
        self.for_each_chunk_mut(items, per_block, |block, chunk| {
            for (j, item) in chunk.iter_mut().enumerate() {
                run_item(item, block * per_block.max(1) + j);
            }
        });
    }
}

impl Team<'_> {
    /// Runs the items of two planned groups as one job on the team: every
    /// item of `a` with `fa`, every item of `b` with `fb`, each seeing the
    /// states of its own slots. The two groups must have been checked
    /// together ([`CrossPlan::verify`]); otherwise, on a serial team, or
    /// when either plan is not verified for `states`, `a`'s items run
    /// first and then `b`'s ([`Team::for_each_planned`] each), which gives
    /// the same states: no item of one group touches a state that an item
    /// of the other writes.
    ///
    /// One job instead of two is one wait for the team instead of two
    /// (the joints and the contacts of a colour).
    ///
    /// # Panics
    ///
    /// When a group's item count differs from its plan's (a bug of the
    /// caller, not input).
    pub fn for_each_planned_pair<A: Send, B: Send, const N: usize, const M: usize>(
        &self,
        cross: &CrossPlan,
        a: PlannedGroup<'_, A, N>,
        b: PlannedGroup<'_, B, M>,
        states: &mut [BodyState],
        fa: impl Fn(&mut A, &mut PlannedStates<'_, N>) + Sync,
        fb: impl Fn(&mut B, &mut PlannedStates<'_, M>) + Sync,
    ) {
        let len = states.len();
        if self.shared.is_none() || !cross.holds(a.plan, b.plan, len) {
            self.for_each_planned(a.plan, a.group, a.items, states, a.per_block, fa);
            self.for_each_planned(b.plan, b.group, b.items, states, b.per_block, fb);
            return;
        }
        let (range_a, range_b) = (a.plan.group(a.group), b.plan.group(b.group));
        assert_eq!(range_a.len(), a.items.len(), "one item per planned item");
        assert_eq!(range_b.len(), b.items.len(), "one item per planned item");
        let (slots_a, writes_a) = (&a.plan.slots[range_a.clone()], &a.plan.writes[range_a]);
        let (slots_b, writes_b) = (&b.plan.slots[range_b.clone()], &b.plan.writes[range_b]);
        let (per_a, per_b) = (a.per_block.max(1), b.per_block.max(1));
        let (count_a, count_b) = (a.items.len(), b.items.len());
        let blocks_a = count_a.div_ceil(per_a);
        let blocks_b = count_b.div_ceil(per_b);
        let base = Base(states.as_mut_ptr());
        let (items_a, items_b) = (Base(a.items.as_mut_ptr()), Base(b.items.as_mut_ptr()));
        let (base, items_a, items_b) = (&base, &items_a, &items_b);
        self.run(blocks_a + blocks_b, &|i| {
            if i < blocks_a {
                let start = i * per_a;
                let count = per_a.min(count_a - start);
                // SAFETY: `start + count ≤ count_a`; block `i` runs once per
                // job and the blocks of `a` do not overlap (module docs,
                // point 2); `a.items` stays borrowed until `run` returns.
                let chunk = unsafe { std::slice::from_raw_parts_mut(items_a.0.add(start), count) };
                for (j, item) in chunk.iter_mut().enumerate() {
                    let mut view = PlannedStates {
                        base: base.0,
                        len,
                        slots: &slots_a[start + j],
                        writes: writes_a[start + j],
                    };
                    fa(item, &mut view);
                }
            } else {
                let start = (i - blocks_a) * per_b;
                let count = per_b.min(count_b - start);
                // SAFETY: as for `a`, with `b`'s blocks.
                let chunk = unsafe { std::slice::from_raw_parts_mut(items_b.0.add(start), count) };
                for (j, item) in chunk.iter_mut().enumerate() {
                    let mut view = PlannedStates {
                        base: base.0,
                        len,
                        slots: &slots_b[start + j],
                        writes: writes_b[start + j],
                    };
                    fb(item, &mut view);
                }
            }
        });
    }
}

/// A slice's base pointer, shared by the blocks of a job.
struct Base<T>(*mut T);
// SAFETY: the blocks built from it are disjoint (module docs, points 2 and
// 3) and `T: Send`, so handing them to other threads is sound.
unsafe impl<T: Send> Sync for Base<T> {}

/// Runs `leader` with the step's team: with the `parallel` feature in a
/// rayon pool of more than one thread, `leader` runs on the pool's thread 0
/// while the others serve its jobs; otherwise it runs here with a serial
/// team.
pub fn with_team<R: Send>(leader: impl FnOnce(&Team) -> R + Send) -> R {
    #[cfg(feature = "parallel")]
    {
        let threads = rayon::current_num_threads();
        if threads > 1 {
            return broadcast_team(leader);
        }
    }
    leader(&Team::serial())
}

/// Runs `leader` with a team of `threads` threads, in a rayon pool of its
/// own ([`with_team`] inside that pool): a run on a chosen thread count
/// beside the global pool's (the thread-count determinism checks).
///
/// # Errors
///
/// When rayon cannot build the pool (the system refused a thread).
#[cfg(feature = "parallel")]
pub fn with_threads<R: Send>(
    threads: usize,
    leader: impl FnOnce(&Team) -> R + Send,
) -> Result<R, rayon::ThreadPoolBuildError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    Ok(pool.install(|| with_team(leader)))
}

#[cfg(feature = "parallel")]
fn broadcast_team<R: Send>(leader: impl FnOnce(&Team) -> R + Send) -> R {
    use std::sync::Mutex;
    let shared = Shared::new(rayon::current_num_threads());
    let leader = Mutex::new(Some(leader));
    let result = Mutex::new(None);
    rayon::broadcast(|ctx| {
        if ctx.index() == 0 {
            // Followers leave when the leader is done, or unwinds.
            struct Stop<'s>(&'s Shared);
            impl Drop for Stop<'_> {
                fn drop(&mut self) {
                    self.0.epoch.store(STOP, SeqCst);
                }
            }
            let _stop = Stop(&shared);
            let team = Team {
                shared: Some(&shared),
                threads: ctx.num_threads(),
            };
            let f = leader
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take()
                .expect("thread 0 runs the leader once");
            let r = f(&team);
            *result.lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
        } else {
            follow(&shared, ctx.index());
        }
    });
    result
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .expect("the leader ran")
}

/// A follower's loop: serve published jobs until the leader stops.
#[cfg(feature = "parallel")]
fn follow(shared: &Shared, thread: usize) {
    let mut seen = 0;
    let mut spins = 0;
    loop {
        let epoch = shared.epoch.load(SeqCst);
        if epoch == STOP {
            return;
        }
        if epoch.is_multiple_of(2) || epoch == seen {
            backoff(&mut spins);
            continue;
        }
        spins = 0;
        seen = epoch;
        shared.active.fetch_add(1, SeqCst);
        struct Release<'s>(&'s Shared);
        impl Drop for Release<'_> {
            fn drop(&mut self) {
                if std::thread::panicking() {
                    self.0.panicked.store(true, SeqCst);
                }
                self.0.active.fetch_sub(1, SeqCst);
            }
        }
        let _release = Release(shared);
        if shared.epoch.load(SeqCst) != epoch {
            continue;
        }
        // SAFETY: the epoch still names this job and `active` counts this
        // follower, so the leader neither rewrites the cell nor returns from
        // `run` until the guard above is dropped (module docs, point 1).
        let Some(job) = (unsafe { *shared.job.get() }) else {
            continue;
        };
        let blocks = shared.blocks.load(SeqCst);
        shared.work(job, blocks, epoch, thread);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serial_team_runs_every_block_in_order() {
        let seen = std::sync::Mutex::new(Vec::new());
        Team::serial().run(5, &|i| seen.lock().unwrap().push(i));
        assert_eq!(*seen.lock().unwrap(), vec![0, 1, 2, 3, 4]);
    }

    /// `map_chunks_mut` changes every item once and returns each block's
    /// result in block order, on any team (a serial one too).
    #[test]
    fn mapped_mutable_blocks_come_back_in_block_order() {
        let check = |team: &Team| {
            let mut items: Vec<u32> = (0..1000).collect();
            let sums = team.map_chunks_mut(&mut items, 64, |b, block| {
                block.iter_mut().for_each(|x| *x *= 2);
                (b, block.iter().map(|&x| u64::from(x)).sum::<u64>())
            });
            assert_eq!(sums.len(), 16);
            for (k, &(b, sum)) in sums.iter().enumerate() {
                let first = 64 * k as u64;
                let last = (first + 64).min(1000);
                assert_eq!((b, sum), (k, (first..last).map(|x| 2 * x).sum::<u64>()));
            }
            assert!(items.iter().enumerate().all(|(i, &x)| x == 2 * i as u32));
        };
        check(&Team::serial());
        #[cfg(feature = "parallel")]
        for threads in [2, 3, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| with_team(|team| check(team)));
        }
    }

    /// Every block of a job runs exactly once, for any team size and any
    /// block count (past the claim flags too), job after job.
    #[cfg(feature = "parallel")]
    #[test]
    fn every_block_runs_once_on_any_team() {
        for threads in [2, 3, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                with_team(|team| {
                    for blocks in [0, 1, 2, 3, 7, 64, 1000, CLAIM_FLAGS + 37] {
                        let runs: Vec<AtomicUsize> =
                            (0..blocks).map(|_| AtomicUsize::new(0)).collect();
                        for _ in 0..3 {
                            team.run(blocks, &|i| {
                                runs[i].fetch_add(1, SeqCst);
                            });
                        }
                        for (i, r) in runs.iter().enumerate() {
                            assert_eq!(
                                r.load(SeqCst),
                                3,
                                "block {i} of {blocks}, {threads} threads"
                            );
                        }
                    }
                });
            });
        }
    }

    /// A cross check fails where one plan's group writes a state the other
    /// plan's group of the same index reads, holds where they are apart,
    /// and no longer holds once either plan changes.
    #[test]
    fn a_cross_plan_refuses_a_state_both_groups_touch() {
        let mut a = StatePlan::<2>::default();
        a.begin_group();
        a.push([1, 2], 0b11);
        a.begin_group();
        a.push([3, 0], 0b01);
        let mut b = StatePlan::<2>::default();
        b.begin_group();
        b.push([4, 5], 0b11);
        b.begin_group();
        // Reads state 3, which `a`'s group 1 writes.
        b.push([6, 3], 0b01);
        assert!(a.verify(8) && b.verify(8));
        let mut cross = CrossPlan::new();
        assert!(!cross.verify(&a, &b, 8));
        assert!(!cross.holds(&a, &b, 8));
        // Group 1 of `b` moved to state 7: apart.
        b.clear();
        b.begin_group();
        b.push([4, 5], 0b11);
        b.begin_group();
        b.push([6, 7], 0b01);
        assert!(b.verify(8));
        assert!(cross.verify(&a, &b, 8));
        assert!(cross.holds(&a, &b, 8));
        // The same content verified again is a new verification.
        assert!(a.verify(8));
        assert!(!cross.holds(&a, &b, 8));
        // A state count of which the plans know nothing: refused.
        assert!(!cross.verify(&a, &b, 9));
    }

    /// Two planned groups run as one job give the states of running the
    /// first, then the second, for any team size.
    #[test]
    fn planned_pairs_give_the_serial_result() {
        const N: usize = 600;
        let states0: Vec<BodyState> = (0..N)
            .map(|i| BodyState {
                v: Vec2::new(i as Real, 0.5),
                w: 0.25 * i as Real,
                ..BodyState::IDENTITY
            })
            .collect();
        // Group 0: `a` moves states 4k (reading 4k + 1), `b` moves states
        // 4k + 3: apart.
        let (mut a, mut b) = (StatePlan::<2>::default(), StatePlan::<1>::default());
        a.begin_group();
        let mut items_a = Vec::new();
        for k in (0..N / 4).map(|k| 4 * k) {
            a.push([k as u32, k as u32 + 1], 0b01);
            items_a.push(k as Real);
        }
        b.begin_group();
        let mut items_b = Vec::new();
        for k in (0..N / 4).map(|k| 4 * k + 3) {
            b.push([k as u32], 0b1);
            items_b.push(k as Real);
        }
        assert!(a.verify(N) && b.verify(N));
        let mut cross = CrossPlan::new();
        assert!(cross.verify(&a, &b, N));
        let run = |team: &Team| {
            let mut states = states0.clone();
            let (mut ia, mut ib) = (items_a.clone(), items_b.clone());
            for _ in 0..3 {
                team.for_each_planned_pair(
                    &cross,
                    PlannedGroup {
                        plan: &a,
                        group: 0,
                        items: &mut ia,
                        per_block: 8,
                    },
                    PlannedGroup {
                        plan: &b,
                        group: 0,
                        items: &mut ib,
                        per_block: 5,
                    },
                    &mut states,
                    |x, view| {
                        let (s, t) = (view.get(0), view.get(1));
                        *x += 1.0;
                        view.set_velocity(0, s.v + t.v * 0.5, s.w - t.w + *x);
                    },
                    |x, view| {
                        let s = view.get(0);
                        view.set_velocity(0, s.v * 2.0, s.w + *x);
                    },
                );
            }
            let bits: Vec<u64> = states
                .iter()
                .flat_map(|s| [s.v.x, s.v.y, s.w])
                .map(|x| crate::math::to_f64(x).to_bits())
                .collect();
            (bits, ia)
        };
        let serial = run(&Team::serial());
        assert_eq!(with_team(run), serial);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            assert_eq!(on_threads(threads, run), serial, "{threads} threads");
        }
    }

    /// The plan check on a team answers as the serial one: plans of
    /// twelve groups of 200 items (past `PARALLEL_VERIFY`) that hold, that
    /// write a state twice in one group, that read in one item what
    /// another writes, and that name a state out of range; each twice in
    /// a row (the scratch generations move on).
    #[test]
    fn the_plan_check_on_a_team_gives_the_serial_answer() {
        const STATES: usize = 5000;
        let plan = |flaw: Option<&str>| {
            let mut p = StatePlan::<2>::default();
            for g in 0..12u32 {
                p.begin_group();
                for k in 0..200u32 {
                    // Item k of group g writes state 1 + 2k + g % 2 and
                    // reads state 0 (read by many, written by none).
                    let mut slots = [1 + 2 * k + g % 2, 0];
                    let mut writes = 0b01;
                    match flaw {
                        Some("twice") if g == 7 && k == 150 => slots[0] = 1 + 2 * 3 + 1,
                        Some("read") if g == 4 && k == 20 => {
                            slots[1] = 1 + 2 * 9;
                            writes = 0b01;
                        }
                        Some("range") if g == 11 && k == 199 => slots[0] = STATES as u32,
                        _ => {}
                    }
                    p.push(slots, writes);
                }
            }
            p
        };
        let run = |team: &Team| {
            ["none", "twice", "read", "range"].map(|flaw| {
                let mut p = plan((flaw != "none").then_some(flaw));
                [p.verify_on(STATES, team), p.verify_on(STATES, team)]
            })
        };
        let serial = run(&Team::serial());
        assert_eq!(serial, [[true; 2], [false; 2], [false; 2], [false; 2]]);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            assert_eq!(on_threads(threads, run), serial, "{threads} threads");
        }
    }

    /// `run` on a team of `threads` threads (a rayon pool of its own).
    #[cfg(feature = "parallel")]
    fn on_threads<R: Send>(threads: usize, run: impl FnOnce(&Team) -> R + Send) -> R {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| with_team(run))
    }

    /// The leader's side work runs once, and every block runs once, on
    /// any team; on a serial team the side work comes first.
    #[test]
    fn run_beside_runs_the_side_work_once_and_every_block() {
        use std::sync::atomic::AtomicUsize;
        let run = |team: &Team| {
            let blocks: Vec<AtomicUsize> = (0..300).map(|_| AtomicUsize::new(0)).collect();
            let (mut side, done_before) = (0, AtomicUsize::new(usize::MAX));
            team.run_beside(
                blocks.len(),
                &|i| {
                    blocks[i].fetch_add(1, SeqCst);
                },
                || {
                    side += 1;
                    let done = blocks.iter().filter(|b| b.load(SeqCst) > 0).count();
                    done_before.store(done, SeqCst);
                },
            );
            let counts: Vec<usize> = blocks.iter().map(|b| b.load(SeqCst)).collect();
            (side, counts, done_before.into_inner())
        };
        let (side, counts, before) = run(&Team::serial());
        assert_eq!((side, before), (1, 0));
        assert!(counts.iter().all(|&c| c == 1));
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            let (side, counts, _) = on_threads(threads, run);
            assert_eq!(side, 1, "{threads} threads");
            assert!(counts.iter().all(|&c| c == 1), "{threads} threads");
        }
    }

    /// Items made in place come after the vector's old items, each once
    /// and in index order, on any team.
    #[test]
    fn extend_mapped_appends_every_item_in_order() {
        // Items that own memory: a slot left unwritten or written twice
        // would show as a wrong string (or a double free under Miri).
        let run = |team: &Team| {
            let mut out = vec![String::from("kept")];
            team.extend_mapped(&mut out, 1001, 7, |i| format!("item {i}"));
            team.extend_mapped(&mut out, 0, 7, |i| format!("never {i}"));
            out
        };
        let mut expected = vec![String::from("kept")];
        expected.extend((0..1001).map(|i| format!("item {i}")));
        assert_eq!(run(&Team::serial()), expected);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            assert_eq!(on_threads(threads, run), expected, "{threads} threads");
        }
    }

    /// A map gives its blocks' results in block order, on any team.
    #[test]
    fn map_blocks_gives_the_serial_results() {
        let run = |team: &Team| team.map_blocks(37, |i| (i * i) as u64);
        let expected: Vec<u64> = (0..37).map(|i| i * i).collect();
        assert_eq!(run(&Team::serial()), expected);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            assert_eq!(on_threads(threads, run), expected, "{threads} threads");
        }
    }

    #[test]
    fn chunks_cover_the_slice_once() {
        let mut items = vec![0u32; 1003];
        with_team(|team| {
            for _ in 0..50 {
                team.for_each_chunk_mut(&mut items, 16, |i, chunk| {
                    for (k, x) in chunk.iter_mut().enumerate() {
                        *x += (i * 16 + k) as u32 % 7 + 1;
                    }
                });
            }
        });
        for (k, &x) in items.iter().enumerate() {
            assert_eq!(x, 50 * (k as u32 % 7 + 1), "item {k}");
        }
    }
}
