//! `drive-sim`: run, predict and sweep scenes.
fn main() {}
