//! Rebuilds the binary when the data it bundles changes (src/app/data.rs embeds these
//! folders; cargo does not see into a macro's reads on its own).

fn main() {
    for folder in [
        "machines",
        "scenes",
        "sweeps",
        "papers",
        "schemas",
        "traces",
        "tests/patterns",
    ] {
        println!("cargo:rerun-if-changed={folder}");
    }
}
