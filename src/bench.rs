//! Benchmarks reachable from the command line (`sortsim bench ...`).
