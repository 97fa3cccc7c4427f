//! Prints the state hash of each benchmark scene after a number of steps
//! (`cargo run --release --example scene_hashes -- [steps] [scenes…]`):
//! a quick check that a change meant to keep results bit-identical does.
//! Joint scenes (`weld_cantilever`, `car`, `elevator`, `spring_bridge`)
//! are accepted by name too.

use janus2d_testbed::benchmarks::{BOX2D_TEN, by_name};
use janus2d_testbed::engine::scripted_step;
use janus2d_testbed::janus::Janus;
use janus2d_testbed::joint_bench;

fn main() {
    let mut args = std::env::args().skip(1);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(120);
    let mut names: Vec<String> = args.collect();
    if names.is_empty() {
        names = BOX2D_TEN.iter().map(|s| s.to_string()).collect();
    }
    for name in names {
        let Some(desc) = by_name(&name).or_else(|| joint_bench::by_name(&name).map(|j| j.desc))
        else {
            eprintln!("unknown scene {name}");
            continue;
        };
        let mut scene = match Janus::new(&desc) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let mut buf = Vec::new();
        for step in 0..steps {
            scripted_step(&mut scene, &desc, step, &mut buf);
        }
        println!("{name:<15} {:#018x}", scene.world.state_hash());
    }
}
