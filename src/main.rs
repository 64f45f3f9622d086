//! The `sortsim` command line: parse, dispatch, print errors. No simulation logic here.
fn main() {}
