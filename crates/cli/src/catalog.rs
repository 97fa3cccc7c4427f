//! The built-in scenes: a table of names, groups, default steps and
//! counts kept beside the builders, so that listing the catalog or finding
//! one scene builds nothing but the scene asked for.
//!
//! | group       | scenes                                                          |
//! |-------------|-----------------------------------------------------------------|
//! | `benchmark` | Box2D v3's ten benchmark scenes and `pyramid20` ([`janus2d_testbed::benchmarks`]) |
//! | `hard`      | the hard cases ([`janus2d_testbed::hard`]); those named as a benchmark are `hard/NAME` |
//! | `portal`    | `portal_drop`, `portal_stream`, `hole_stream` (the last has no portal: the same stream through a hole) |
//! | `joints`    | the peers' joint scenes (`weld_cantilever`, `car`, `elevator`, `spring_bridge`: [`janus2d_testbed::joint_bench`]) and `joint_zoo`, every joint kind in one scene ([`janus2d_testbed::joint_zoo`]) |
//!
//! Every scene runs with its own settings (gravity, step, substeps, sleep,
//! softness) and for its own number of steps unless told otherwise; the
//! scenes with a per-step script (`rain`, `junkyard`) run it. The counts
//! in [`CATALOG`] are the scene's at the start; a test builds every row
//! and checks them against the testbed's builders.

use janus2d_testbed::desc::SceneDesc;
use janus2d_testbed::{benchmarks, hard, joint_bench, joint_zoo};

use crate::error::CliError;

/// One built-in scene: what `janus2d list` prints without building it, and
/// how to build it.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// The name `janus2d run` takes.
    pub name: &'static str,
    /// `benchmark`, `hard`, `portal` or `joints`.
    pub group: &'static str,
    /// Steps it runs by default.
    pub steps: usize,
    /// Bodies at the start.
    pub bodies: usize,
    /// Joints at the start (of every kind).
    pub joints: usize,
    /// Portal pairs at the start.
    pub portal_pairs: usize,
    /// A per-step script runs before each step.
    pub scripted: bool,
    build: fn() -> SceneDesc,
}

impl Entry {
    /// Builds the scene's description (only this one).
    #[must_use]
    pub fn build(&self) -> SceneDesc {
        (self.build)()
    }

    /// One line about it: bodies, joints, portal pairs at the start.
    #[must_use]
    pub fn about(&self) -> String {
        let plural =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        let mut s = plural(self.bodies, "body", "bodies");
        if self.joints > 0 {
            s.push_str(&format!(", {}", plural(self.joints, "joint", "joints")));
        }
        if self.portal_pairs > 0 {
            s.push_str(&format!(
                ", {}",
                plural(self.portal_pairs, "portal pair", "portal pairs")
            ));
        }
        if self.scripted {
            s.push_str(", scripted");
        }
        s
    }
}

/// A row of [`CATALOG`].
const fn row(
    name: &'static str,
    group: &'static str,
    steps: usize,
    [bodies, joints, portal_pairs]: [usize; 3],
    scripted: bool,
    build: fn() -> SceneDesc,
) -> Entry {
    Entry {
        name,
        group,
        steps,
        bodies,
        joints,
        portal_pairs,
        scripted,
        build,
    }
}

/// Builds the benchmark scene `name` (a name of [`benchmarks::NAMES`]).
fn benchmark(name: &str) -> SceneDesc {
    // Every caller passes one of the table's names, all of which
    // `by_name` knows (the table's test checks it); an empty scene
    // otherwise rather than a panic.
    benchmarks::by_name(name).unwrap_or_else(|| SceneDesc::new("missing", 0))
}

/// Builds the joint scene `name` (a name of [`joint_bench::NAMES`]).
fn joint_scene(name: &str) -> SceneDesc {
    joint_bench::by_name(name).map_or_else(|| SceneDesc::new("missing", 0), |s| s.desc)
}

/// Every built-in scene, benchmarks first, then hard cases, then portal
/// scenes, then joint scenes: name, group, default steps, bodies / joints /
/// portal pairs at the start, scripted, builder.
pub const CATALOG: &[Entry] = &[
    row(
        "large_pyramid",
        "benchmark",
        500,
        [5051, 0, 0],
        false,
        || benchmark("large_pyramid"),
    ),
    row("pyramid20", "benchmark", 600, [211, 0, 0], false, || {
        benchmark("pyramid20")
    }),
    row(
        "many_pyramids",
        "benchmark",
        200,
        [22001, 0, 0],
        false,
        || benchmark("many_pyramids"),
    ),
    row(
        "joint_grid",
        "benchmark",
        500,
        [10000, 19800, 0],
        false,
        || benchmark("joint_grid"),
    ),
    row("tumbler", "benchmark", 750, [2027, 1, 0], false, || {
        benchmark("tumbler")
    }),
    row("smash", "benchmark", 300, [9601, 0, 0], false, || {
        benchmark("smash")
    }),
    row("spinner", "benchmark", 500, [6078, 1, 0], false, || {
        benchmark("spinner")
    }),
    row("rain", "benchmark", 1000, [1, 0, 0], true, || {
        benchmark("rain")
    }),
    row("junkyard", "benchmark", 800, [8002, 0, 0], true, || {
        benchmark("junkyard")
    }),
    row("compounds", "benchmark", 500, [3001, 0, 0], false, || {
        benchmark("compounds")
    }),
    row("washer", "benchmark", 500, [8102, 0, 0], false, || {
        benchmark("washer")
    }),
    row("single_box", "hard", 90, [2, 0, 0], false, || {
        hard::single_box().desc
    }),
    row("hard/pyramid20", "hard", 600, [211, 0, 0], false, || {
        hard::pyramid20().desc
    }),
    row(
        "hard/large_pyramid",
        "hard",
        600,
        [5051, 0, 0],
        false,
        || hard::large_pyramid().desc,
    ),
    row("vertical_stack_12", "hard", 3600, [13, 0, 0], false, || {
        hard::vertical_stack(12).desc
    }),
    row("vertical_stack_15", "hard", 3600, [16, 0, 0], false, || {
        hard::vertical_stack(15).desc
    }),
    row("vertical_stack_20", "hard", 3600, [21, 0, 0], false, || {
        hard::vertical_stack(20).desc
    }),
    row("double_domino", "hard", 600, [16, 0, 0], false, || {
        hard::double_domino().desc
    }),
    row("confined", "hard", 600, [626, 0, 0], false, || {
        hard::confined().desc
    }),
    row("high_mass_ratio_1", "hard", 600, [166, 0, 0], false, || {
        hard::high_mass_ratio_1().desc
    }),
    row("high_mass_ratio_2", "hard", 600, [4, 0, 0], false, || {
        hard::high_mass_ratio_drop(false).desc
    }),
    row("high_mass_ratio_3", "hard", 600, [4, 0, 0], false, || {
        hard::high_mass_ratio_drop(true).desc
    }),
    row("bridge", "hard", 600, [161, 161, 0], false, || {
        hard::bridge().desc
    }),
    row("ball_and_chain", "hard", 600, [42, 41, 0], false, || {
        hard::ball_and_chain().desc
    }),
    row("stretched_chain", "hard", 600, [41, 40, 0], false, || {
        hard::stretched_chain().desc
    }),
    row("joint_grid_40", "hard", 600, [1600, 3120, 0], false, || {
        hard::joint_grid_40().desc
    }),
    row(
        "portal_drop",
        "portal",
        120,
        [3, 0, 1],
        false,
        benchmarks::portal_drop,
    ),
    row("portal_stream", "portal", 1800, [203, 0, 1], false, || {
        benchmark("portal_stream")
    }),
    row("hole_stream", "portal", 1800, [201, 0, 0], false, || {
        benchmark("hole_stream")
    }),
    row("weld_cantilever", "joints", 120, [11, 10, 0], false, || {
        joint_scene("weld_cantilever")
    }),
    row("car", "joints", 360, [4, 2, 0], false, || {
        joint_scene("car")
    }),
    row("elevator", "joints", 300, [3, 1, 0], false, || {
        joint_scene("elevator")
    }),
    row("spring_bridge", "joints", 240, [25, 21, 0], false, || {
        joint_scene("spring_bridge")
    }),
    row(
        joint_zoo::NAME,
        "joints",
        300,
        [13, 10, 0],
        false,
        joint_zoo::joint_zoo,
    ),
];

/// The built-in scenes this build runs, in [`CATALOG`]'s order: without the
/// `portals` feature the scenes with portals are left out.
pub fn entries() -> impl Iterator<Item = &'static Entry> {
    CATALOG
        .iter()
        .filter(|e| cfg!(feature = "portals") || e.portal_pairs == 0)
}

/// The built-in scene called `name` (`hard/NAME` reaches any hard case).
/// Builds nothing: [`Entry::build`] builds the one found.
pub fn find(name: &str) -> Result<&'static Entry, CliError> {
    if let Some(e) = entries().find(|e| e.name == name) {
        return Ok(e);
    }
    if let Some(rest) = name.strip_prefix("hard/")
        && let Some(e) = entries().find(|e| e.group == "hard" && e.name == rest)
    {
        return Ok(e);
    }
    if CATALOG.iter().any(|e| e.name == name && e.portal_pairs > 0) {
        return Err(CliError::NeedsPortals(name.to_owned()));
    }
    Err(CliError::UnknownScene {
        name: name.to_owned(),
        suggestions: suggest(name, entries().map(|e| e.name)),
    })
}

/// Up to three names within a small edit distance of `name`, or that
/// contain it.
fn suggest<'a>(name: &str, names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut scored: Vec<(usize, &str)> = names
        .filter_map(|n| {
            let d = distance(name, n);
            let close = d <= 2 + name.len() / 4 || (name.len() >= 3 && n.contains(name));
            close.then_some((d, n))
        })
        .collect();
    scored.sort();
    scored
        .into_iter()
        .take(3)
        .map(|(_, n)| n.to_owned())
        .collect()
}

/// Levenshtein distance.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = if ca == *cb {
                prev
            } else {
                1 + prev.min(cur).min(row[j])
            };
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found() {
        let all: Vec<&Entry> = entries().collect();
        for (i, e) in all.iter().enumerate() {
            assert!(
                all[..i].iter().all(|o| o.name != e.name),
                "{} twice",
                e.name
            );
            assert_eq!(find(e.name).unwrap().name, e.name);
        }
        assert!(all.iter().any(|e| e.name == "hard/pyramid20"));
        assert!(all.iter().any(|e| e.name == "vertical_stack_12"));
        assert_eq!(find("hard/single_box").unwrap().name, "single_box");
        #[cfg(feature = "portals")]
        assert!(all.iter().any(|e| e.name == "portal_drop"));
    }

    /// What the table says agrees with what the builders build: each
    /// testbed scene once, in the table's order, with its counts and steps
    /// (a benchmark's steps are its description's, a hard case's the
    /// case's).
    #[test]
    fn the_table_matches_the_builders() {
        let mut expected: Vec<(String, &str, usize, SceneDesc)> = Vec::new();
        for name in benchmarks::NAMES {
            if ["portal_stream", "hole_stream"].contains(&name) {
                continue;
            }
            let d = benchmarks::by_name(name).unwrap();
            expected.push((name.to_owned(), "benchmark", d.steps, d));
        }
        for case in hard::all() {
            let name = if expected.iter().any(|e| e.0 == case.name) {
                format!("hard/{}", case.name)
            } else {
                case.name.to_owned()
            };
            expected.push((name, "hard", case.steps, case.desc));
        }
        let mut portal = vec![benchmarks::portal_drop()];
        portal.push(benchmarks::by_name("portal_stream").unwrap());
        portal.push(benchmarks::by_name("hole_stream").unwrap());
        for d in portal {
            expected.push((d.name.to_owned(), "portal", d.steps, d));
        }
        let mut joints: Vec<SceneDesc> = joint_bench::all().into_iter().map(|s| s.desc).collect();
        joints.push(joint_zoo::joint_zoo());
        for d in joints {
            expected.push((d.name.to_owned(), "joints", d.steps, d));
        }
        assert_eq!(CATALOG.len(), expected.len(), "one row per testbed scene");
        for (row, (name, group, steps, d)) in CATALOG.iter().zip(&expected) {
            assert_eq!(
                (row.name, row.group, row.steps),
                (name.as_str(), *group, *steps)
            );
            let built = row.build();
            assert_eq!(built.name, d.name, "{name}: builds its own scene");
            assert_eq!(built.bodies.len(), d.bodies.len(), "{name}");
            assert_eq!(row.bodies, d.bodies.len(), "{name}: bodies");
            assert_eq!(
                row.joints,
                d.joints.len() + d.extra_joints.len(),
                "{name}: joints"
            );
            assert_eq!(row.portal_pairs, d.portals.len(), "{name}: portal pairs");
            assert_eq!(
                row.scripted,
                !matches!(d.script, janus2d_testbed::desc::Script::None),
                "{name}: script"
            );
        }
    }

    #[test]
    fn a_typo_is_a_typed_error_with_suggestions() {
        match find("pyramid02") {
            Err(CliError::UnknownScene { suggestions, .. }) => {
                assert!(
                    suggestions.contains(&"pyramid20".to_owned()),
                    "{suggestions:?}"
                );
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(distance("kitten", "sitting"), 3);
    }
}
