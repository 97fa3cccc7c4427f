//! Steps per second of a [`LanderBatch`] with random discrete actions, on
//! 1 and 2 threads (and any thread counts given as arguments).
//!
//! `cargo run --release -p janus2d-batch --example lander_rate -- 256 1 2`

use janus2d_batch::lander::{LanderActions, LanderBatch, LanderConfig};
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let n = args.first().copied().unwrap_or(256);
    let threads: Vec<usize> = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec![1, 2]
    };
    let steps = 400;
    // A fixed pseudo-random action table, the same for every run.
    let mut s = 12345u64;
    let actions: Vec<i64> = (0..steps * n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) % 4) as i64
        })
        .collect();
    let mut base = None;
    for t in threads {
        let mut batch = LanderBatch::new(n, LanderConfig::vector(1000), 1, t).unwrap();
        let mut best = f64::MAX;
        for _ in 0..3 {
            batch.reset_all(1).unwrap();
            let t0 = Instant::now();
            for k in 0..steps {
                batch
                    .step(LanderActions::Discrete(&actions[k * n..(k + 1) * n]))
                    .unwrap();
            }
            best = best.min(t0.elapsed().as_secs_f64());
        }
        let rate = (n * steps) as f64 / best;
        let b = *base.get_or_insert(rate);
        println!(
            "{n} landers, {t} thread(s): {rate:>10.0} env-steps/s ({:.2}x)",
            rate / b
        );
    }
}
