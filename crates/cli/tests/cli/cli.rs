//! The command line through its library: scenes by name and from files,
//! the scene-file format's round trip and errors, frames, CSV, arguments.

use std::path::PathBuf;

use clap::Parser;
use janus2d_cli::cli::{Cli, Command, parse_draw, parse_size};
use janus2d_cli::runner::{self, Fit, Frames, RunOptions};
use janus2d_cli::scene_file::{self, ErrorKind, SceneFile};
use janus2d_cli::{CliError, catalog};

fn quiet(steps: usize) -> RunOptions {
    RunOptions {
        steps: Some(steps),
        progress: false,
        ..RunOptions::default()
    }
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("janus2d-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[cfg(feature = "portals")]
fn example() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/playground.json")
}

#[test]
fn every_small_built_in_scene_runs() {
    for e in catalog::entries() {
        if e.bodies > 700 {
            continue; // the big ones run in the CI smoke line and the benchmarks
        }
        let mut scene = runner::load(e.name).unwrap();
        let mut out = Vec::new();
        let s = runner::run(&mut scene, &quiet(3), &mut out).unwrap();
        assert_eq!(s.steps, 3, "{}", e.name);
        assert!(s.bodies > 0, "{}", e.name);
        let text = String::from_utf8(out).unwrap();
        assert!(text.contains("done: 3 steps"), "{text}");
        assert!(text.contains("ms/step by stage"), "{text}");
    }
}

#[cfg(feature = "portals")]
#[test]
fn the_example_file_builds_and_runs() {
    let mut scene = runner::load(example().to_str().unwrap()).unwrap();
    assert_eq!(scene.name, "playground");
    assert_eq!(scene.world().body_count(), 11);
    assert_eq!(scene.world().joint_count(), 3);
    assert_eq!(scene.world().portal_pair_count(), 1);
    let mut out = Vec::new();
    let s = runner::run(&mut scene, &quiet(120), &mut out).unwrap();
    assert!(s.probe.is_some());
    assert_eq!(s.non_finite_steps, 0);
    #[cfg(feature = "portals")]
    assert!(
        s.crossings[0] >= 1,
        "the crate drops through the floor portal"
    );
}

/// A built-in scene written as a file and read back builds the same world:
/// the same state hash after 60 steps.
#[test]
fn export_round_trip_is_bit_identical() {
    let mut names = vec!["bridge", "single_box", "double_domino", "hard/pyramid20"];
    if cfg!(feature = "portals") {
        names.push("portal_drop");
    }
    for name in names {
        let e = catalog::find(name).unwrap();
        let file = SceneFile::from_desc(&e.build()).unwrap();
        let json = file.to_json();
        let back = scene_file::parse(&json, name).unwrap();
        assert_eq!(back, file, "{name}: serialise → parse is the identity");
        let (_, built) = scene_file::load(&json, name).unwrap();
        let mut from_file = built.world;
        let mut builtin = runner::load(name).unwrap();
        for step in 0..60 {
            from_file.step(built.dt).unwrap();
            builtin.step(step).unwrap();
        }
        assert_eq!(
            from_file.state_hash(),
            builtin.world().state_hash(),
            "{name}: the file builds the same world"
        );
    }
    // A scripted scene is refused with a message.
    let rain = catalog::find("rain").unwrap();
    assert!(
        SceneFile::from_desc(&rain.build())
            .unwrap_err()
            .contains("script")
    );
}

const GOOD: &str = r#"{
  "bodies": [
    { "id": "ground", "type": "static",
      "shapes": [ { "geometry": { "box": { "half": [5, 0.5] } } } ] },
    { "id": "box", "position": [0, 2],
      "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } }, "density": 2 } ] }
  ],
  "joints": [ { "body_a": "ground", "body_b": "box", "anchor": [0, 2] } ]
}"#;

fn bad(from: &str, to: &str) -> scene_file::SceneFileError {
    let text = GOOD.replacen(from, to, 1);
    assert_ne!(text, GOOD, "the replacement applies");
    match scene_file::load(&text, "bad.json") {
        Err(e) => e,
        Ok(_) => panic!("`{to}` should be refused"),
    }
}

#[test]
fn a_good_file_loads() {
    let (file, built) = scene_file::load(GOOD, "good.json").unwrap();
    assert_eq!(file.bodies.len(), 2);
    assert_eq!(built.world.body_count(), 2);
    assert_eq!(built.world.joint_count(), 1);
    assert!((built.world.mass(built.bodies[1]).unwrap() - 2.0).abs() < 1e-5);
}

#[test]
fn bad_files_name_line_and_field() {
    // Wrong type: the field path and its line.
    let e = bad("\"density\": 2", "\"density\": \"heavy\"");
    assert_eq!(e.kind, ErrorKind::Data);
    assert_eq!(e.field, "bodies[1].shapes[0].density");
    assert_eq!(e.line, 6);
    let shown = e.to_string();
    assert!(shown.starts_with("bad.json:6:"), "{shown}");
    assert!(shown.contains("bodies[1].shapes[0].density"), "{shown}");

    // A misspelt key: unknown field, named, on its line.
    let e = bad("\"density\": 2", "\"densty\": 2");
    assert_eq!(e.kind, ErrorKind::Data);
    assert_eq!(e.line, 6);
    assert!(e.message.contains("densty"), "{}", e.message);
    assert_eq!(e.field, "bodies[1].shapes[0].densty");

    // A missing required key.
    let e = bad("\"half\": [0.5, 0.5]", "\"halve\": [0.5, 0.5]");
    assert!(
        e.message.contains("halve") || e.message.contains("half"),
        "{e}"
    );
    assert_eq!(e.line, 6);

    // Not JSON: a missing comma.
    let e = bad("\"id\": \"box\", ", "\"id\": \"box\" ");
    assert_eq!(e.kind, ErrorKind::Syntax);
    assert_eq!(e.line, 5);
    assert!(e.column > 0);

    // Parses, but the engine refuses: a bad value, located after parsing.
    let e = bad("\"half\": [0.5, 0.5]", "\"half\": [0.5, -0.5]");
    assert_eq!(e.kind, ErrorKind::Invalid);
    assert_eq!(e.field, "bodies[1].shapes[0].geometry");
    assert_eq!(e.line, 6);

    // An unknown body reference.
    let e = bad("\"body_b\": \"box\"", "\"body_b\": \"crate\"");
    assert_eq!(e.kind, ErrorKind::Invalid);
    assert_eq!(e.field, "joints[0].body_b");
    assert_eq!(e.line, 8);
    assert!(e.message.contains("crate"), "{}", e.message);

    // A step that is not positive.
    let text = GOOD.replacen('{', "{ \"settings\": { \"dt\": 0 },", 1);
    let e = scene_file::load(&text, "bad.json").err().unwrap();
    assert_eq!((e.field.as_str(), e.line), ("settings.dt", 1));

    // Trailing garbage.
    let e = scene_file::load(&format!("{GOOD} x"), "bad.json")
        .err()
        .unwrap();
    assert_eq!(e.kind, ErrorKind::Syntax);
}

#[test]
fn a_missing_file_or_scene_is_a_typed_error() {
    match runner::load("no/such/scene.json") {
        Err(CliError::SceneFile(e)) => assert_eq!(e.kind, ErrorKind::Io),
        other => panic!("{:?}", other.err()),
    }
    assert!(matches!(
        runner::load("large_pyramdi"),
        Err(CliError::UnknownScene { .. })
    ));
}

#[test]
fn frames_and_csv_are_written() {
    let dir = temp("png");
    let csv = temp("run.csv");
    let gif = temp("run.gif");
    let mut scene = runner::load("single_box").unwrap();
    let options = RunOptions {
        frames: Frames::Png(dir.clone()),
        every: Some(2),
        size: (64, 48),
        csv: Some(csv.clone()),
        ..quiet(6)
    };
    let s = runner::run(&mut scene, &options, &mut Vec::new()).unwrap();
    // The first frame and one every 2 steps.
    assert_eq!(s.frames, 4);
    // Named by step, not by index.
    let mut pngs: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    pngs.sort();
    assert_eq!(
        pngs,
        [
            "frame_00000.png",
            "frame_00002.png",
            "frame_00004.png",
            "frame_00006.png"
        ]
    );
    let rows = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = rows.lines().collect();
    assert_eq!(lines.len(), 7, "header + one row per step");
    let cols = lines[0].split(',').count();
    assert!(lines.iter().all(|l| l.split(',').count() == cols));
    assert!(lines[6].starts_with("6,0.1"));

    let svg_dir = temp("svg");
    let mut scene = runner::load("single_box").unwrap();
    let options = RunOptions {
        frames: Frames::Svg(svg_dir.clone()),
        every: Some(3),
        ..quiet(6)
    };
    let s = runner::run(&mut scene, &options, &mut Vec::new()).unwrap();
    assert_eq!(s.frames, 3);
    let doc = std::fs::read_to_string(svg_dir.join("frame_00006.svg")).unwrap();
    assert_eq!(doc.matches("<polygon").count(), 2, "the ground and the box");

    let mut scene = runner::load("single_box").unwrap();
    let options = RunOptions {
        frames: Frames::Gif(gif.clone()),
        size: (64, 48),
        follow: true,
        ..quiet(10)
    };
    let s = runner::run(&mut scene, &options, &mut Vec::new()).unwrap();
    assert_eq!(s.frames, 6, "the first and every 2nd step");
    let bytes = std::fs::read(&gif).unwrap();
    assert_eq!(&bytes[..6], b"GIF89a");
}

/// `--overlay` writes step, time, bodies and ms/step in the frame's top
/// left corner and nowhere else.
#[test]
fn the_overlay_marks_the_corner_and_long_runs_pad_wider() {
    let plain = temp("overlay-off");
    let marked = temp("overlay-on");
    for (dir, overlay) in [(&plain, false), (&marked, true)] {
        let mut scene = runner::load("single_box").unwrap();
        let options = RunOptions {
            frames: Frames::Png(dir.clone()),
            every: Some(3),
            size: (320, 120),
            overlay,
            ..quiet(3)
        };
        runner::run(&mut scene, &options, &mut Vec::new()).unwrap();
    }
    let read = |d: &PathBuf| {
        let bytes = std::fs::read(d.join("frame_00003.png")).unwrap();
        let pm = tiny_skia::Pixmap::decode_png(&bytes).unwrap();
        pm.pixels()
            .iter()
            .map(|p| [p.red(), p.green(), p.blue()])
            .collect::<Vec<_>>()
    };
    let (a, b) = (read(&plain), read(&marked));
    let changed: Vec<usize> = (0..a.len()).filter(|&i| a[i] != b[i]).collect();
    assert!(changed.len() > 200, "{} px changed", changed.len());
    // One line at the top left: within 24 px of the top.
    assert!(
        changed.iter().all(|&i| i / 320 < 24),
        "the overlay stays in its corner"
    );
}

#[test]
fn the_camera_fits_once_each_frame_growing_or_every_n_steps() {
    assert_eq!("once".parse::<Fit>().unwrap(), Fit::Once);
    assert_eq!("each".parse::<Fit>().unwrap(), Fit::Each);
    assert_eq!("grow".parse::<Fit>().unwrap(), Fit::Grow);
    assert_eq!("25".parse::<Fit>().unwrap(), Fit::Every(25));
    for bad in ["0", "-3", "always", ""] {
        assert!(bad.parse::<Fit>().is_err(), "`{bad}`");
    }
    let cli = Cli::try_parse_from(["janus2d", "run", "rain", "--fit", "grow"]).unwrap();
    let Command::Run(args) = cli.command else {
        panic!("run")
    };
    assert_eq!(args.options().unwrap().fit, Fit::Grow);
    let cli = Cli::try_parse_from(["janus2d", "run", "rain", "--fit", "sometimes"]).unwrap();
    let Command::Run(args) = cli.command else {
        panic!("run")
    };
    assert!(
        args.options().is_err(),
        "a bad --fit is an error, not a panic"
    );

    for fit in [Fit::Each, Fit::Grow, Fit::Every(2)] {
        let dir = temp(&format!("fit-{fit:?}"));
        let mut scene = runner::load("single_box").unwrap();
        let options = RunOptions {
            frames: Frames::Svg(dir.clone()),
            fit,
            ..quiet(4)
        };
        let s = runner::run(&mut scene, &options, &mut Vec::new()).unwrap();
        assert_eq!(s.frames, 5, "{fit:?}");
        let doc = std::fs::read_to_string(dir.join("frame_00004.svg")).unwrap();
        assert_eq!(doc.matches("<polygon").count(), 2, "{fit:?}: both in view");
    }
}

#[test]
fn threads_substeps_and_bad_options() {
    let mut scene = runner::load("hard/pyramid20").unwrap();
    let two = RunOptions {
        threads: 2,
        ..quiet(2)
    };
    let threaded = runner::run(&mut scene, &two, &mut Vec::new());
    if cfg!(feature = "parallel") {
        threaded.unwrap();
    } else {
        assert!(matches!(threaded, Err(CliError::Invalid(m)) if m.contains("parallel")));
    }
    let mut scene = runner::load("hard/pyramid20").unwrap();
    let options = RunOptions {
        threads: 1,
        substeps: Some(2),
        profile: true,
        ..quiet(5)
    };
    let mut out = Vec::new();
    runner::run(&mut scene, &options, &mut out).unwrap();
    assert_eq!(scene.world().settings().substeps, 2);
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains("narrowphase") && text.contains("share"),
        "{text}"
    );

    let mut scene = runner::load("single_box").unwrap();
    let zero = RunOptions {
        threads: 0,
        ..quiet(1)
    };
    assert!(matches!(
        runner::run(&mut scene, &zero, &mut Vec::new()),
        Err(CliError::Invalid(_))
    ));
    let no_substeps = RunOptions {
        substeps: Some(0),
        ..quiet(1)
    };
    assert!(runner::run(&mut scene, &no_substeps, &mut Vec::new()).is_err());
}

#[test]
fn arguments_parse() {
    let cli = Cli::try_parse_from([
        "janus2d", "run", "tumbler", "--steps", "10", "--gif", "a.gif", "--size", "320x200",
    ])
    .unwrap();
    let Command::Run(args) = cli.command else {
        panic!("run");
    };
    let o = args.options().unwrap();
    assert_eq!((o.steps, o.size), (Some(10), (320, 200)));
    assert_eq!(o.frames, Frames::Gif("a.gif".into()));
    // --png and --gif exclude each other.
    assert!(Cli::try_parse_from(["janus2d", "run", "x", "--png", "d", "--gif", "g"]).is_err());
    assert!(Cli::try_parse_from(["janus2d", "run", "x", "--svg", "d", "--gif", "g"]).is_err());
    assert!(parse_size("0x10").is_err() && parse_size("wide").is_err());
    let d = parse_draw("+contacts,-joints").unwrap();
    assert!(d.contacts && !d.joints && d.shapes);
    let d = parse_draw("aabbs").unwrap();
    assert!(d.aabbs && !d.shapes);
    assert!(parse_draw("colours").is_err());
    let mut out = Vec::new();
    janus2d_cli::cli::list(&mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("large_pyramid") && text.contains("hard:"));
}
