//! Whether a stage runs on the step's team or on the leader alone, chosen
//! by timing both.
//!
//! A stage on the team pays for each job's hand-off and, above all, for
//! the body states it moves between the cores' caches: a colour's chunks
//! run on both threads, so the next colour (or the next stage) finds half
//! of its bodies in the other core's cache. Whether the split pays depends
//! on the scene, not on a count: on a 2-core machine the solve of the
//! large pyramid (six colours of about 310 chunks, bodies in creation
//! order) takes 0.6× its time alone, while the spinner's (colours of up to
//! 250 chunks over a stirred pile) took 1.2× its time alone, and
//! tumbler's 1.25×. So the world times the solve both ways now and then
//! and keeps the faster:
//!
//! ```text
//! step   0 … 7 │ 8   9  10  11 │ 12 … 11+period │ T   L   T   L │ …
//! runs   team  │ T   L   T   L │ the faster     │ trial again   │
//!              │ trial (best of two each)
//! ```
//!
//! `T` on the team, `L` on the leader. The first [`FIRST_WAIT`] steps run
//! on the team untimed: a world's first step builds what later steps
//! keep (colourings, buffers) and would decide the first trial. The
//! period doubles (up to [`MAX_PERIOD`]) while a trial keeps the same
//! answer by a clear margin ([`CLEAR_MARGIN`]) and falls back to
//! [`FIRST_PERIOD`] when the answer changes or is close. A scene that
//! grows or shrinks (bodies raining in, a pile falling asleep) is tried
//! again at once: when the stage's work (what the caller counts, the
//! solve's constraints) has moved by more than [`WORK_DRIFT`] since the
//! last trial. The state is the same bit for bit either way (the stages
//! give the same results on any team): only time depends on the choice,
//! so nothing here is state, and a snapshot holds none of it.

/// Steps of a trial: team and leader alternately, two each.
pub const TRIAL_STEPS: u32 = 4;

/// Steps on the team before the first trial.
pub const FIRST_WAIT: u32 = 8;

/// Steps between the first trials (and after an answer changed or was
/// close).
pub const FIRST_PERIOD: u32 = 32;

/// The longest period between trials: each trial's two steps on the
/// slower side then cost under 1% of the steps in between.
pub const MAX_PERIOD: u32 = 512;

/// A trial begins at once when the work has grown or shrunk by more than
/// this fraction of the work at the last trial.
pub const WORK_DRIFT: f64 = 0.5;

/// A trial's answer is clear when the slower side took at least this
/// many times the faster's best.
pub const CLEAR_MARGIN: f64 = 1.15;

/// The choice between the team and the leader alone for one stage (see
/// the module docs).
///
/// ```
/// use janus2d_core::team_choice::{TeamChoice, TRIAL_STEPS};
/// let mut choice = TeamChoice::starting_trial();
/// // A trial in which the leader alone is twice as fast…
/// for _ in 0..TRIAL_STEPS {
///     let seconds = if choice.on_team(1000) { 2e-3 } else { 1e-3 };
///     choice.record(seconds);
/// }
/// // …puts the next steps on the leader, while the work stays about the
/// // same.
/// assert!(!choice.on_team(1100));
/// ```
///
/// (`TeamChoice::default()` would first run [`FIRST_WAIT`] steps on the
/// team; `starting_trial` begins with a trial.)
#[derive(Clone, Debug)]
pub struct TeamChoice {
    /// Steps since the current trial began.
    clock: u32,
    /// Steps between the end of a trial and the next.
    period: u32,
    /// The best time of this trial on the team and alone, s.
    best: [f64; 2],
    /// The answer of the last trial: the team is faster.
    team: bool,
    /// The work when the last trial began (`None` before the first).
    work: Option<usize>,
}

impl Default for TeamChoice {
    /// Before any trial: the team, untimed, for [`FIRST_WAIT`] steps,
    /// then the first trial.
    fn default() -> Self {
        TeamChoice {
            clock: TRIAL_STEPS,
            period: FIRST_WAIT,
            best: [f64::INFINITY; 2],
            team: true,
            work: None,
        }
    }
}

impl TeamChoice {
    /// A choice whose first step begins a trial (the team assumed
    /// before it).
    #[must_use]
    pub fn starting_trial() -> Self {
        TeamChoice {
            clock: 0,
            period: FIRST_PERIOD,
            ..TeamChoice::default()
        }
    }

    /// Whether this step's stage, of `work` (any count that grows with
    /// the stage's cost), runs on the team. A work that has moved by more
    /// than [`WORK_DRIFT`] since the last trial begins a trial.
    pub fn on_team(&mut self, work: usize) -> bool {
        if let Some(last) = self.work {
            let drift = (work as f64 - last as f64).abs();
            if self.clock >= TRIAL_STEPS && drift > WORK_DRIFT * last as f64 {
                self.clock = 0;
                self.period = FIRST_PERIOD;
            }
        }
        if self.clock == 0 {
            self.work = Some(work);
        }
        if self.clock < TRIAL_STEPS {
            self.clock.is_multiple_of(2)
        } else {
            self.team
        }
    }

    /// Records the time the stage took, in seconds, on the side
    /// [`TeamChoice::on_team`] gave for this step, and moves to the next
    /// step.
    pub fn record(&mut self, seconds: f64) {
        if self.clock < TRIAL_STEPS {
            let side = usize::from(!self.clock.is_multiple_of(2));
            if seconds < self.best[side] {
                self.best[side] = seconds;
            }
        }
        self.clock += 1;
        if self.clock == TRIAL_STEPS {
            let [team, alone] = self.best;
            let answer = team <= alone;
            let clear = team.max(alone) >= CLEAR_MARGIN * team.min(alone);
            self.period = if answer == self.team && clear {
                (2 * self.period.max(FIRST_PERIOD)).min(MAX_PERIOD)
            } else {
                FIRST_PERIOD
            };
            self.team = answer;
            self.best = [f64::INFINITY; 2];
        }
        if self.clock >= TRIAL_STEPS + self.period {
            self.clock = 0;
        }
    }

    /// Steps until the next trial begins (0 during one).
    #[must_use]
    pub fn steps_to_trial(&self) -> u32 {
        if self.clock < TRIAL_STEPS {
            0
        } else {
            TRIAL_STEPS + self.period - self.clock
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `steps` steps whose stage takes `team` or `alone` seconds;
    /// returns how many ran on the team.
    fn run(choice: &mut TeamChoice, steps: u32, team: f64, alone: f64) -> u32 {
        let mut on_team = 0;
        for _ in 0..steps {
            let t = choice.on_team(1000);
            on_team += u32::from(t);
            choice.record(if t { team } else { alone });
        }
        on_team
    }

    #[test]
    fn the_first_steps_run_on_the_team_untimed() {
        let mut choice = TeamChoice::default();
        assert_eq!(choice.steps_to_trial(), FIRST_WAIT);
        // However slow the team, the first FIRST_WAIT steps are its.
        assert_eq!(run(&mut choice, FIRST_WAIT, 1.0, 1.0e-3), FIRST_WAIT);
        assert_eq!(choice.steps_to_trial(), 0);
        run(&mut choice, TRIAL_STEPS, 1.0, 1.0e-3);
        assert!(!choice.on_team(1000));
    }

    #[test]
    fn the_faster_side_runs_every_step_outside_the_trials() {
        let mut choice = TeamChoice::default();
        // The leader alone is faster: after the first wait, only the
        // trials' team steps (two per trial) run on the team.
        let steps = 2000;
        let on_team = run(&mut choice, steps, 1.5e-3, 1.0e-3) - FIRST_WAIT;
        let trials = on_team / 2;
        assert_eq!(on_team % 2, 0);
        // Clear answers double the period: 32, 64, 128, 256, then 512
        // (the trials begin at steps 8, 44, 112, 244, 504, 1020, 1536).
        assert_eq!(trials, 7, "{trials} trials in {steps} steps");
        assert!(!choice.on_team(1000) || choice.steps_to_trial() == 0);
        // The team faster: all but two steps a trial on the team.
        let mut choice = TeamChoice::default();
        let on_team = run(&mut choice, steps, 1.0e-3, 1.5e-3);
        // (The first trial confirms the team: 64, 128, 256, 512; trials
        // at 8, 76, 208, 468, 984, 1500.)
        assert_eq!(steps - on_team, 12, "{} steps alone", steps - on_team);
    }

    #[test]
    fn a_close_or_changed_answer_brings_the_next_trial_back_soon() {
        let mut choice = TeamChoice::starting_trial();
        // The team, as assumed before any trial, and clearly: the period
        // doubles; and again.
        run(&mut choice, TRIAL_STEPS, 1.0e-3, 2.0e-3);
        assert_eq!(choice.steps_to_trial(), 2 * FIRST_PERIOD);
        run(&mut choice, 2 * FIRST_PERIOD + TRIAL_STEPS, 1.0e-3, 2.0e-3);
        assert_eq!(choice.steps_to_trial(), 4 * FIRST_PERIOD);
        // A close answer (10% apart) goes back to the first period.
        run(&mut choice, 4 * FIRST_PERIOD + TRIAL_STEPS, 1.0e-3, 1.1e-3);
        assert_eq!(choice.steps_to_trial(), FIRST_PERIOD);
        assert!(choice.on_team(1000));
        // The scene changes: the leader now wins, at the next trial.
        run(&mut choice, FIRST_PERIOD + TRIAL_STEPS, 2.0e-3, 1.0e-3);
        assert!(!choice.on_team(1000));
        assert_eq!(choice.steps_to_trial(), FIRST_PERIOD);
    }

    #[test]
    fn a_scene_that_grows_is_tried_again_at_once() {
        let mut choice = TeamChoice::starting_trial();
        run(&mut choice, TRIAL_STEPS, 2.0e-3, 1.0e-3);
        assert!(!choice.on_team(1000));
        assert!(choice.steps_to_trial() > 0);
        // Two fifths more work: no trial yet.
        assert!(!choice.on_team(1400));
        choice.record(1.0e-3);
        // Three fifths more: this step is a trial's first, on the team.
        assert!(choice.on_team(1600));
        assert_eq!(choice.steps_to_trial(), 0);
    }

    #[test]
    fn each_side_keeps_its_best_time_of_the_trial() {
        // One slow team step (a machine hiccup) does not decide a trial:
        // the team's other step is the faster one.
        let mut choice = TeamChoice::starting_trial();
        let times = [9.0e-3, 1.5e-3, 1.0e-3, 1.5e-3];
        for t in times {
            choice.on_team(1000);
            choice.record(t);
        }
        assert!(choice.on_team(1000));
    }
}
