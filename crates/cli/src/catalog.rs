//! The built-in scenes: the testbed's descriptions, looked up by name.
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
//! scenes with a per-step script (`rain`, `junkyard`) run it.

use janus2d_testbed::desc::SceneDesc;
use janus2d_testbed::{benchmarks, hard, joint_bench, joint_zoo};

use crate::error::CliError;

/// One built-in scene.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The name `janus2d run` takes.
    pub name: String,
    /// `benchmark`, `hard`, `portal` or `joints`.
    pub group: &'static str,
    /// Steps it runs by default.
    pub steps: usize,
    /// The description.
    pub desc: SceneDesc,
}

impl Entry {
    /// One line about it: bodies, joints, portal pairs at the start.
    #[must_use]
    pub fn about(&self) -> String {
        let d = &self.desc;
        let mut s = format!("{} bodies", d.bodies.len());
        let joints = d.joints.len() + d.extra_joints.len();
        if joints > 0 {
            s.push_str(&format!(", {joints} joints"));
        }
        if !d.portals.is_empty() {
            s.push_str(&format!(", {} portal pair", d.portals.len()));
        }
        if !matches!(d.script, janus2d_testbed::desc::Script::None) {
            s.push_str(", scripted");
        }
        s
    }
}

const PORTAL_SCENES: [&str; 2] = ["portal_stream", "hole_stream"];

/// Every built-in scene, benchmarks first, then hard cases, then portal
/// scenes, then joint scenes. Without the `portals` feature the scenes with portals are left
/// out.
#[must_use]
pub fn entries() -> Vec<Entry> {
    let mut out = Vec::new();
    for name in benchmarks::NAMES {
        if PORTAL_SCENES.contains(&name) {
            continue;
        }
        if let Some(desc) = benchmarks::by_name(name) {
            out.push(Entry {
                name: name.to_owned(),
                group: "benchmark",
                steps: desc.steps,
                desc,
            });
        }
    }
    for case in hard::all() {
        let name = if out.iter().any(|e| e.name == case.name) {
            format!("hard/{}", case.name)
        } else {
            case.name.to_owned()
        };
        out.push(Entry {
            name,
            group: "hard",
            steps: case.steps,
            desc: case.desc,
        });
    }
    let mut portal = vec![benchmarks::portal_drop()];
    portal.extend(PORTAL_SCENES.iter().filter_map(|n| benchmarks::by_name(n)));
    for desc in portal {
        out.push(Entry {
            name: desc.name.to_owned(),
            group: "portal",
            steps: desc.steps,
            desc,
        });
    }
    let mut joints: Vec<SceneDesc> = joint_bench::all().into_iter().map(|s| s.desc).collect();
    joints.push(joint_zoo::joint_zoo());
    for desc in joints {
        out.push(Entry {
            name: desc.name.to_owned(),
            group: "joints",
            steps: desc.steps,
            desc,
        });
    }
    if cfg!(not(feature = "portals")) {
        out.retain(|e| e.desc.portals.is_empty());
    }
    out
}

/// The built-in scene called `name` (`hard/NAME` reaches any hard case).
pub fn find(name: &str) -> Result<Entry, CliError> {
    let all = entries();
    if let Some(e) = all.iter().find(|e| e.name == name) {
        return Ok(e.clone());
    }
    if let Some(rest) = name.strip_prefix("hard/")
        && let Some(case) = hard::all().into_iter().find(|c| c.name == rest)
    {
        return Ok(Entry {
            name: name.to_owned(),
            group: "hard",
            steps: case.steps,
            desc: case.desc,
        });
    }
    if cfg!(not(feature = "portals")) && ["portal_drop", "portal_stream"].contains(&name) {
        return Err(CliError::NeedsPortals(name.to_owned()));
    }
    Err(CliError::UnknownScene {
        name: name.to_owned(),
        suggestions: suggest(name, all.iter().map(|e| e.name.as_str())),
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
        let all = entries();
        for (i, e) in all.iter().enumerate() {
            assert!(
                all[..i].iter().all(|o| o.name != e.name),
                "{} twice",
                e.name
            );
            assert_eq!(find(&e.name).unwrap().name, e.name);
        }
        assert!(all.iter().any(|e| e.name == "hard/pyramid20"));
        assert!(all.iter().any(|e| e.name == "vertical_stack_12"));
        #[cfg(feature = "portals")]
        assert!(all.iter().any(|e| e.name == "portal_drop"));
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
