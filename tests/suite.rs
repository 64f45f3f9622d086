//! The integration tests, as one test binary: each file under tests/ is a module here (one
//! executable of about 118 MB instead of sixty-two of about 57 MB; the build takes as long).
//! The README's own test (`readme.rs`) stays a binary of its own, since it moves its process's
//! folder.
//!
//! Must never hold tests itself: a test belongs to the file of its topic.

mod common;
mod raster_common;

mod aa_hard_cases;
mod aa_memory_paper;
mod accuracy;
mod answers_unchanged;
mod bad_input;
mod calibrate;
mod cli;
mod docs;
mod engine_network;
mod engine_programs;
mod engine_slices;
mod front_end_ahead;
mod fuzz_corpus;
mod install;
mod instructions;
mod net_contention;
mod net_docs;
mod net_interface;
mod net_pattern;
mod net_properties;
mod net_topology;
mod net_transport;
mod options;
mod pages;
mod paper;
mod raster_coverage;
mod raster_equivalence;
mod raster_far;
mod raster_inputs;
mod safe_to_kill;
mod scale;
mod scene_animation;
mod scene_bad_input;
mod scene_generators;
mod scene_images;
mod scene_obj;
mod scene_standins;
mod schemas;
mod sort_first;
mod sort_last_001;
mod sort_last_001_paper;
mod sort_last_003;
mod sort_last_003_paper;
mod sort_last_aa;
mod sort_last_adaptive;
mod sort_last_binary_swap;
mod sort_last_bounds;
mod sort_last_pieces;
mod sort_last_radix_k;
mod sort_last_rle;
mod sort_last_tree;
mod sort_last_two_three_swap;
mod sort_middle;
mod sort_middle_paper;
mod sweep_plot;
mod sweep_run;
mod sweep_slurm;
mod sweep_spec;
mod trace_corpus;
mod trace_format;
mod trace_paper;
mod trace_replay;
mod utilization_cli;
mod utilization_paper;
mod utilization_regions;
mod validate;
