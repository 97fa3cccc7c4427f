//! # janus2d-cli
//!
//! The `janus2d` command: list and run the built-in scenes (the testbed's
//! benchmark scenes, hard cases and portal scenes) or a JSON scene file,
//! headless, with PNG frames or a GIF (through `janus2d-render`), a CSV of
//! every step, a progress bar and a summary with the per-stage profile;
//! or live on a page in the browser (`janus2d serve`).
//!
//! | module         | what                                                        |
//! |----------------|-------------------------------------------------------------|
//! | [`cli`]        | the arguments (`clap`) and the commands                      |
//! | [`catalog`]    | the built-in scenes by name                                  |
//! | [`runner`]     | loading and running a scene: frames, CSV, events, summary    |
//! | [`scene_file`] | the JSON scene format and its errors (line, column, field)   |
//! | [`serve`]      | `janus2d serve`: the page, the WebSocket, one simulation per page |
//! | [`locate`]     | where a field starts in a JSON text                          |
//! | [`error`]      | [`CliError`]                                                 |
//!
//! ```
//! use janus2d_cli::runner::{self, RunOptions};
//! let mut scene = runner::load("single_box").unwrap();
//! let options = RunOptions { steps: Some(10), progress: false, ..RunOptions::default() };
//! let mut out = Vec::new();
//! let summary = runner::run(&mut scene, &options, &mut out).unwrap();
//! assert_eq!((summary.steps, summary.bodies), (10, 2));
//! ```

pub mod catalog;
pub mod cli;
pub mod error;
pub mod locate;
pub mod runner;
pub mod scene_file;
pub mod serve;

pub use error::CliError;
