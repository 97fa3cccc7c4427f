//! What each optional stage costs the ten benchmark scenes, read from the
//! world's own stage timers and counters (`cargo run --release --example
//! feature_costs -- [steps]`): per scene, the share of the step spent in
//! the portal stage, continuous collision and the restitution pass, and
//! whether the scene calls for each (portal pairs, fast bodies, bouncy
//! shapes), with the hit-event and force-event gathering's reads and the
//! joint rows. A stage whose feature the scene lacks should read 0 work and
//! a share well under 1 %. Timing is one run on a shared machine: read the
//! shares, not the milliseconds.

use janus2d_testbed::benchmarks::{BOX2D_TEN, by_name};
use janus2d_testbed::engine::scripted_step;
use janus2d_testbed::janus::Janus;

fn main() {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(240);
    println!(
        "{:<14} {:>8} {:>9} {:>9} {:>9} {:>8} {:>9} {:>9} {:>7}",
        "scene",
        "ms/step",
        "portals%",
        "contin.%",
        "restit.%",
        "ran:ptl",
        "rest.cts",
        "hit+force",
        "j.rows"
    );
    for name in BOX2D_TEN {
        let Some(desc) = by_name(name) else { continue };
        let Ok(mut scene) = Janus::new(&desc) else {
            continue;
        };
        let mut buf = Vec::new();
        let (mut total, mut portals, mut continuous, mut restitution) = (0.0, 0.0, 0.0, 0.0);
        let (mut portal_ran, mut restitution_contacts, mut event_reads, mut joint_rows) =
            (0usize, 0usize, 0usize, 0usize);
        for step in 0..steps {
            scripted_step(&mut scene, &desc, step, &mut buf);
            let p = scene.world.profile();
            total += p.total;
            portals += p.portals;
            continuous += p.continuous;
            restitution += p.solver.restitution;
            let c = scene.world.counters();
            portal_ran += usize::from(c.portal_stage_ran);
            restitution_contacts += c.restitution_contacts;
            joint_rows += c.joint_rows;
            let w = scene.world.event_work();
            event_reads += w.hit_points_read + w.force_contacts_read;
        }
        let share = |t: f64| 100.0 * t / total.max(f64::MIN_POSITIVE);
        println!(
            "{:<14} {:>8.3} {:>9.3} {:>9.3} {:>9.3} {:>8} {:>9} {:>9} {:>7}",
            name,
            1e3 * total / steps as f64,
            share(portals),
            share(continuous),
            share(restitution),
            portal_ran,
            restitution_contacts,
            event_reads,
            joint_rows / steps.max(1)
        );
    }
}
