//! The `janus2d` command (being written).
fn main() {}
