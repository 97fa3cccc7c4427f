//! The command line's integration tests in one binary: the commands
//! through the library (`cli`) and `janus2d serve` end to end (`serve`).

mod cli;
mod serve;
