//! The command line's integration tests in one binary: the commands
//! through the library (`cli`), joints of every kind in scene files
//! (`joints`) and `janus2d serve` end to end (`serve`).

mod cli;
mod joints;
mod scene_features;
mod serve;
