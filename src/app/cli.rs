//! Command-line arguments (clap): structure, help and validation of flags only. Turning them
//! into calls happens in the command modules beside this one; the work itself in the library.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

#[derive(Parser, Debug)]
#[command(
    name = "sortsim",
    version,
    about = "Deterministic simulator of parallel polygon-rendering machines",
    long_about = "Deterministic discrete-event simulator of parallel polygon-rendering machines \
(sort-middle, sort-last, pixel merging, adaptive supersampling). With no command it runs the \
built-in default job and writes its report under reports/default in the current folder.\n\n\
Bundled machines, scenes and sweeps are read from the data root: --root or SORTSIM_ROOT, else \
the current folder when it is a sortsim checkout (it has machines/ and scenes/), else the copy \
carried in the binary. A relative file named on the command line is read from the current \
folder when it exists there, else from the data root.",
    after_help = "Examples:\n  sortsim check machines/*.json\n  sortsim netsim machines/delta.json tests/patterns/complement-16x32.json --fidelity packet\n  sortsim bench phold --lps 1024 --events-per-lp 16"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Data root: the folder holding machines/, scenes/, sweeps/ and papers/.
    #[arg(long, global = true, value_name = "DIR", env = crate::app::data::ROOT_VAR)]
    pub root: Option<PathBuf>,
    /// Print every table in full (per-node rows of a run); the report files always have them.
    #[arg(short, long, global = true)]
    pub verbose: bool,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Validate machine, scene, run and sweep specs, network patterns, calibration specs,
    /// paper files and traces (the kind is detected).
    #[command(after_help = check_help())]
    Check {
        /// Spec files to validate.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Simulate an algorithm on a machine and a scene; write its report.
    #[command(
        after_help = "Example:\n  sortsim run --machine machines/delta.json --scene scenes/plb-head-standin.json \\\n      --algo sort-middle/ellsworth --procs 64 --frames 0..4 --set granularity=8 -o reports/plb-64\n\n--help lists every algorithm's options with their defaults.",
        after_long_help = run_long_help()
    )]
    Run(RunArgs),
    /// What accuracy costs in time: image error against a supersampled reference, simulated
    /// frame time, memory and simulator wall time per anti-aliasing mode and network fidelity.
    #[command(
        after_help = "Example:\n  sortsim accuracy scenes/p000-tetra-500.json --machine machines/power-challenge.json \\\n      --algo sort-middle/static --procs 8 --frames 0..2 --modes none,adaptive,supersample:16 \\\n      --fidelities ideal,hops,flow,packet -o reports/accuracy/tetra\n\nModes other than none pass the option aa=<mode> to the algorithm; a fidelity sets\nmachine.network.fidelity. Wall times go to cost.json and accuracy.md only, so\naccuracy.json is byte-identical for identical inputs."
    )]
    Accuracy(AccuracyArgs),
    /// Draw one frame of a scene with the sequential reference renderer; print its statistics.
    #[command(
        after_help = "Example:\n  sortsim render scenes/spd-teapot.json --frame 0 -o teapot.png\n  sortsim render scenes/spd-teapot.json --aa supersample:16 -o teapot-aa.png"
    )]
    Render(RenderArgs),
    /// Statistics of a scene's frames next to the paper's numbers (JSON with --json).
    #[command(
        after_help = "Example:\n  sortsim scene-stats scenes/polio-standin.json --frames 0..3 --regions 40x32 --json"
    )]
    SceneStats(SceneStatsArgs),
    /// Run every point of a sweep spec in parallel; write sweep.csv, sweep.json and plots.
    #[command(
        after_help = "Example:\n  sortsim sweep sweeps/p002-fig9-plb.json -o reports/fig9-plb --jobs 2\n\nA sweep spec is a run spec in which machine, scene, algo, procs and seed may be lists,\nplus \"vary\": {\"option\": [values]}; every combination is run. Rerunning with the same\nDIR skips the points whose summary.json exists."
    )]
    Sweep(SweepArgs),
    /// The papers side by side: run the experiments behind each paper's figures and tables and
    /// write, per paper, paper.md, paper.json, index.html and plots with the paper's values.
    #[command(
        after_help = "Examples:\n  sortsim paper 002 -o reports/paper\n  sortsim paper all --quick\n\nEach row holds the paper's number (papers/NNN.json: figure or table, section, quote),\nsortsim's, the deviation, the tolerance and a verdict: exact, within tolerance, shape\nholds (the number misses, the paper's claim holds) or differs (with the reason)."
    )]
    Paper(PaperArgs),
    /// Fit a machine's cost parameters (or a stand-in scene's shape) to a paper's numbers at
    /// once (least squares over the targets, each in units of its tolerance; Nelder-Mead);
    /// write the fitted file and the residual table.
    #[command(
        after_help = "Examples:\n  sortsim calibrate machines/fits/multicluster-to-001.json -o reports/calibrate\n  sortsim calibrate scenes/fits/p003-brooks-to-003.json\n\nThe spec names the machine (or the scene), the paper, the target rows of papers/NNN.json\nand the parameters: groups of fields (times, bandwidths or numbers) scaled by one factor\neach, within a range, e.g. {\"name\": \"cpu costs\", \"fields\": [\"cpu.costs.*\"], \"range\": [0.5, 2]}\nor {\"name\": \"footprint\", \"fields\": [\"geometry.0.generator.footprint\"], \"range\": [0.05, 1]}."
    )]
    Calibrate(CalibrateArgs),
    /// Check sortsim against independent programs: its `flow` network model against SimGrid's
    /// max-min model (CM02), its rasterizer against Mesa's llvmpipe (OpenGL), case by case.
    #[command(
        after_help = "Examples:\n  sortsim validate network -o reports/validate\n  sortsim validate all --quick\n\nNeeds Python 3 with Debian's python3-simgrid (network) and python3-moderngl with Mesa's\nEGL and llvmpipe (raster): apt-get install python3-simgrid python3-moderngl libgl1-mesa-dri\nlibegl1. SORTSIM_PYTHON names another interpreter. Exits with 1 when an answer differs\nbeyond the stated tolerance."
    )]
    Validate(ValidateArgs),
    /// Simulate a list of messages on a machine's network and print each completion time.
    #[command(
        after_help = "Example:\n  sortsim netsim machines/multicluster-torus.json tests/patterns/hot-spot-4x4.json --fidelity flow\n  sortsim netsim machines/delta.json tests/patterns/complement-16x32.json --compare"
    )]
    Netsim(NetsimArgs),
    /// Benchmarks of the simulator itself.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Ellsworth's utilization simulator and performance model (paper 002, Figures 4 and 5).
    #[command(
        after_help = "Example:\n  sortsim utilization scenes/plb-head-standin.json --procs 2,4,...,512 --granularity 1..=12 \\\n      --counts both --frame-step 4 -o reports/utilization-plb"
    )]
    Utilization(UtilizationArgs),
    /// Pixel traces and the trace-driven merge-traffic simulation (paper 003).
    #[command(subcommand)]
    Trace(TraceCommand),
    /// Print the JSON Schema of a spec kind (the files under schemas/ are these).
    #[command(
        after_help = "Example:\n  sortsim schema machine > machine.schema.json\n\nIn VS Code, map the schemas to files with `json.schemas` in settings.json, e.g.\n  {\"fileMatch\": [\"machines/*.json\"], \"url\": \"./schemas/machine.schema.json\"}"
    )]
    Schema {
        /// The spec kind whose schema to print.
        #[arg(value_parser = crate::spec::schema::KINDS)]
        kind: String,
    },
    /// Print a shell completion script for sortsim.
    #[command(
        after_help = "Example:\n  sortsim completions bash > ~/.local/share/bash-completion/completions/sortsim\n  sortsim completions zsh > ~/.zfunc/_sortsim"
    )]
    Completions {
        /// The shell to complete in.
        shell: clap_complete::Shell,
    },
}

#[derive(Subcommand, Debug)]
pub enum TraceCommand {
    /// Record every fragment of one frame, before z-buffering, into a trace file.
    #[command(
        after_help = "Example:\n  sortsim trace record scenes/p003-zinnia.json --frame 0 -o traces/p003-zinnia.trace"
    )]
    Record {
        /// Scene spec (scenes/*.json).
        scene: PathBuf,
        /// The frame to record (0 is the first).
        #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
        frame: u32,
        /// Trace file to write.
        #[arg(short, long, value_name = "TRACE", allow_negative_numbers = true)]
        out: PathBuf,
    },
    /// Count the merge traffic of direct send, PixelFlow and distributed snooping on n
    /// processors, from a trace (no rasterization).
    #[command(
        after_help = "Example:\n  sortsim trace replay traces/p003-zinnia.trace --algo snooping --procs 1,2,4,...,64 \\\n      --assign background-last -o reports/zinnia-snooping"
    )]
    Replay(TraceReplayArgs),
}

#[derive(Args, Debug)]
pub struct TraceReplayArgs {
    /// Trace file written by `sortsim trace record`.
    pub trace: PathBuf,
    /// Merging algorithms, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "direct-send,pixelflow,snooping",
        allow_negative_numbers = true
    )]
    pub algo: Vec<MergeAlgoArg>,
    /// Processor counts: 1,2,4,...,64 (geometric), 1..=16, 8,64; a range is A..B (B excluded)
    /// or A..=B (B included).
    #[arg(long, default_value = "1,2,4,...,64", allow_negative_numbers = true)]
    pub procs: String,
    /// Primitive assignment: round-robin in database order, seeded random, or round-robin
    /// with the largest primitive given last to the last processor.
    #[arg(
        long,
        value_enum,
        default_value = "scatter",
        allow_negative_numbers = true
    )]
    pub assign: AssignArg,
    /// Seed of the run's random streams (ChaCha); the same seed gives the same bytes.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,
    /// Direct send z-buffers each processor's fragments first and sends only active pixels.
    #[arg(long)]
    pub local_zbuffer: bool,
    /// Also write DIR/replay.csv, replay.json and the paper 003 Figure 5/6 style plots.
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MergeAlgoArg {
    #[value(alias = "sort-last/direct-send")]
    DirectSend,
    #[value(alias = "sort-last/pixelflow")]
    Pixelflow,
    #[value(alias = "sort-last/snooping")]
    Snooping,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AssignArg {
    Scatter,
    Random,
    BackgroundLast,
}

#[derive(Args, Debug)]
pub struct UtilizationArgs {
    /// Scene with a viewing sequence.
    pub scene: PathBuf,
    /// Machine whose cpu costs price the region times (machines/delta.json when absent).
    #[arg(long, allow_negative_numbers = true)]
    pub machine: Option<PathBuf>,
    /// Processor counts: a list such as 2,4,...,512 (geometric), 2..=512:x2, 8,64,512 or 1..=16;
    /// a range is A..B (B excluded) or A..=B (B included).
    #[arg(long, default_value = "2,4,...,512", allow_negative_numbers = true)]
    pub procs: String,
    /// Granularity ratios (regions per processor): 1..=12, 1,2,4,8,12 or 2..=12:2; a range is
    /// A..B (B excluded) or A..=B (B included).
    #[arg(long, default_value = "1..=12", allow_negative_numbers = true)]
    pub granularity: String,
    /// Whose polygon counts drive the assignment: this frame's, the previous frame's, or both.
    #[arg(
        long,
        value_enum,
        default_value = "both",
        allow_negative_numbers = true
    )]
    pub counts: CountsArg,
    /// Frames: A..B (B excluded), A..=B (B included) or A; all frames when absent.
    #[arg(long, allow_negative_numbers = true)]
    pub frames: Option<String>,
    /// Sample every K-th frame of the range (the previous frame's counts are still those of
    /// the frame just before each sampled one).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub frame_step: u32,
    /// Also write DIR/utilization.csv, utilization.json and the Figure 4 and 5 plots.
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CountsArg {
    Previous,
    Current,
    Both,
}

#[derive(Args, Debug)]
pub struct RunArgs {
    /// Machine spec (machines/*.json): processors, costs, network, memory.
    #[arg(long, allow_negative_numbers = true)]
    pub machine: PathBuf,
    /// Scene spec (scenes/*.json): geometry, camera and its motion, frames.
    #[arg(long, allow_negative_numbers = true)]
    pub scene: PathBuf,
    #[arg(long, help = crate::algo::AlgorithmId::IDS_HELP, allow_negative_numbers = true)]
    pub algo: String,
    /// Processors the run uses (at most the machine's nodes).
    #[arg(long, allow_negative_numbers = true)]
    pub procs: u32,
    /// Frames: A..B (B excluded), A..=B (B included) or A; all frames when absent.
    #[arg(long, allow_negative_numbers = true)]
    pub frames: Option<String>,
    /// key=value: an algorithm option (granularity=8) or a machine field (machine.network.fidelity=packet).
    #[arg(long = "set", value_name = "KEY=VALUE", allow_negative_numbers = true)]
    pub set: Vec<String>,
    /// Seed of the run's random streams (ChaCha); the same seed gives the same bytes.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,
    /// Skip timeline.json (recording it costs host memory on large runs).
    #[arg(long, conflicts_with = "timeline_frames")]
    pub no_timeline: bool,
    /// Frames timeline.json covers, within --frames (A..B, A..=B or A); all when absent. A
    /// long run's timeline then costs the memory of these frames only.
    #[arg(long, value_name = "FRAMES", allow_negative_numbers = true)]
    pub timeline_frames: Option<String>,
    /// Report folder (summary.json, summary.md, cost.json, timeline.json, frame PNG).
    #[arg(
        short,
        long,
        value_name = "DIR",
        default_value = "reports/run",
        allow_negative_numbers = true
    )]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct AccuracyArgs {
    /// Scene spec; its last frame in --frames is the one compared with the reference.
    pub scene: PathBuf,
    /// Machine spec (its network fidelity is the one the modes run at).
    #[arg(long, allow_negative_numbers = true)]
    pub machine: PathBuf,
    #[arg(long, help = crate::algo::AlgorithmId::IDS_HELP, allow_negative_numbers = true)]
    pub algo: String,
    /// Processors the run uses.
    #[arg(long, allow_negative_numbers = true)]
    pub procs: u32,
    /// Frames: A..B (B excluded), A..=B (B included) or A; all frames when absent. Images are compared on the last.
    #[arg(long, allow_negative_numbers = true)]
    pub frames: Option<String>,
    /// Anti-aliasing modes, comma-separated: none, adaptive, supersample:N.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "none,adaptive,supersample:16",
        value_parser = aa_mode,
        allow_negative_numbers = true,
    )]
    pub modes: Vec<crate::accuracy::AaMode>,
    /// Network fidelities to run the `none` mode at, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "ideal,hops,flow,packet",
        allow_negative_numbers = true
    )]
    pub fidelities: Vec<FidelityArg>,
    /// key=value: an algorithm option (granularity=8) or a machine field (machine.cpu.send_overhead=100us).
    #[arg(long = "set", value_name = "KEY=VALUE", allow_negative_numbers = true)]
    pub set: Vec<String>,
    /// Seed of the run's random streams (ChaCha); the same seed gives the same bytes.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,
    /// Samples per pixel side of the reference image (16: 16x16 samples per pixel).
    #[arg(long, default_value_t = crate::accuracy::DEFAULT_REFERENCE_SCALE,
          allow_negative_numbers = true,
          value_parser = clap::value_parser!(u32).range(1..=crate::accuracy::reference::MAX_SCALE as i64))]
    pub reference_scale: u32,
    /// Report folder; reports/accuracy/<scene name> when absent.
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
}

fn aa_mode(s: &str) -> Result<crate::accuracy::AaMode, String> {
    s.parse()
}

#[derive(Args, Debug)]
pub struct SweepArgs {
    /// Sweep spec (JSON); its paths are relative to its own folder.
    pub spec: PathBuf,
    /// Report folder; reports/sweep-<spec name> when absent.
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
    /// Simulations at a time; the number of cores when absent (with --slurm: in each array
    /// task, its --cpus-per-task, 1 when absent).
    #[arg(long, value_name = "J", value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub jobs: Option<u32>,
    /// Run only shard I of T (0 <= I < T): the points dealt to it, balanced by estimated
    /// cost; no table (that is --collect's). What each Slurm array task runs.
    #[arg(long, value_name = "I/T", conflicts_with_all = ["collect", "slurm"], allow_negative_numbers = true)]
    pub shard: Option<crate::sweep::Shard>,
    /// Build the table, plots and page from the points' files in DIR, written by the shards;
    /// fails with the list of missing points.
    #[arg(long, conflicts_with = "slurm")]
    pub collect: bool,
    /// Write DIR/slurm/sweep.sbatch (a job array of --tasks shards) and collect.sbatch
    /// instead of running; DIR and the spec must be on a filesystem every node sees.
    #[arg(long)]
    pub slurm: bool,
    /// Array tasks for --slurm; one per point, at most 32, when absent.
    #[arg(long, value_name = "T", requires = "slurm", value_parser = clap::value_parser!(u32).range(1..=100_000), allow_negative_numbers = true)]
    pub tasks: Option<u32>,
    /// Slurm partition of both jobs.
    #[arg(long, value_name = "P", requires = "slurm", value_parser = |v: &str| crate::sweep::slurm::check_value("--partition", v, "debug"), allow_negative_numbers = true)]
    pub partition: Option<String>,
    /// Wall-clock limit of each array task (Slurm's format: 30, 1:30:00, 2-00:00:00).
    #[arg(long, value_name = "HH:MM:SS", requires = "slurm", value_parser = crate::sweep::slurm::check_time, allow_negative_numbers = true)]
    pub time: Option<String>,
    /// Memory of each array task (Slurm's format: 4G, 500M).
    #[arg(long, value_name = "M", requires = "slurm", value_parser = crate::sweep::slurm::check_mem, allow_negative_numbers = true)]
    pub mem: Option<String>,
    /// Submit both jobs with sbatch (the collect job after the whole array succeeds) and
    /// print their ids.
    #[arg(long, requires = "slurm")]
    pub submit: bool,
}

/// `sortsim check --help`: the example, then the machine kinds from their registries.
fn check_help() -> String {
    let names = |all: &[&str]| all.join(", ");
    format!(
        "Example:\n  sortsim check machines/*.json\n\nA machine's network.topology is one of {}; \
         its network.switching {}; its network.fidelity {}.",
        names(&crate::net::TopologyKind::ALL.map(|t| t.name())),
        names(&crate::net::Switching::ALL.map(|t| t.name())),
        names(&crate::net::Fidelity::ALL.map(|t| t.name())),
    )
}

/// `sortsim run --help`: the example, then every algorithm's options from their structs.
fn run_long_help() -> String {
    format!(
        "Example:\n  sortsim run --machine machines/delta.json --scene scenes/plb-head-standin.json \\\n      --algo sort-middle/ellsworth --procs 64 --frames 0..4 --set granularity=8 -o reports/plb-64\n\n{}\nMachine fields are set the same way: --set machine.network.fidelity=packet (a field the file leaves out too, when the machine spec has it there: --set machine.network.node.placement=cyclic).",
        crate::algo::AlgorithmId::options_help()
    )
}

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// Calibration spec (JSON).
    pub spec: PathBuf,
    /// Report folder; reports/calibrate-<spec name> when absent.
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
    /// Simulations at a time; the number of cores when absent.
    #[arg(long, value_name = "J", value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub jobs: Option<u32>,
    /// Targets of the spec to leave out of the fit (comma-separated row ids); the report
    /// gives their residuals on the fitted machine, a test of what the fit predicts.
    #[arg(
        long,
        value_name = "ID,ID",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub hold_out: Vec<String>,
    /// Allow targets that papers/NNN.json marks predicted (mark them fitted afterwards).
    #[arg(long)]
    pub allow_predicted: bool,
}

#[derive(Args, Debug)]
pub struct ValidateArgs {
    /// What to check: network (flow against SimGrid), raster (against llvmpipe) or all.
    #[arg(default_value = "all", value_parser = ["network", "raster", "all"])]
    pub what: String,
    /// The smaller half of the cases (seconds instead of a minute).
    #[arg(long)]
    pub quick: bool,
    /// Report folder.
    #[arg(
        short,
        long,
        value_name = "DIR",
        default_value = "reports/validate",
        allow_negative_numbers = true
    )]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct PaperArgs {
    /// Which paper: 000, 001, 002, 003 (the seed papers), 004 (radix-k on Blue Gene/P) or all.
    #[arg(default_value = "all", value_parser = ["000", "001", "002", "003", "004", "all"])]
    pub paper: String,
    /// Fewer frames per run (the seed papers in about 30 s here; 004 runs one frame either way).
    #[arg(long)]
    pub quick: bool,
    /// Report folder; each paper gets a folder NNN/ inside it.
    #[arg(
        short,
        long,
        value_name = "DIR",
        default_value = "reports/paper",
        allow_negative_numbers = true
    )]
    pub out: PathBuf,
    /// Simulations at a time; the number of cores when absent.
    #[arg(long, value_name = "J", value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub jobs: Option<u32>,
}

#[derive(Args, Debug)]
pub struct NetsimArgs {
    /// Machine spec (its network is used).
    pub machine: PathBuf,
    /// Pattern file: {"messages": [{"src": 0, "dst": 5, "bytes": "64KiB", "start": "0us"}, ...]}.
    pub pattern: PathBuf,
    /// Override the machine's network.fidelity.
    #[arg(long, value_enum, allow_negative_numbers = true)]
    pub fidelity: Option<FidelityArg>,
    /// Run the pattern at every fidelity and print predicted time against simulator wall time.
    #[arg(long, conflicts_with = "fidelity")]
    pub compare: bool,
    /// Also write DIR/summary.json (the printed report) and DIR/cost.json (wall time); with
    /// --compare, DIR/fidelities.md (the printed table).
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FidelityArg {
    Ideal,
    Hops,
    Flow,
    Packet,
}

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// PHOLD on the engine against a bare binary-heap loop, in the same run.
    #[command(
        after_help = "Example:\n  sortsim bench phold --lps 1024 --events-per-lp 16 --end 2ms\n  sortsim bench phold --lps 64 --events-per-lp 16 --end 100us --instructions"
    )]
    Phold(PholdArgs),
    /// Simulating one frame of Ellsworth's algorithm against rendering it sequentially.
    #[command(
        after_help = "Example:\n  sortsim bench overhead --scene scenes/polio-standin.json --procs 512 --fidelity hops\n  sortsim bench overhead --procs 64 --fidelity hops --instructions"
    )]
    Overhead {
        /// Machine spec.
        #[arg(
            long,
            default_value = "machines/delta.json",
            allow_negative_numbers = true
        )]
        machine: PathBuf,
        /// Scene spec.
        #[arg(
            long,
            default_value = "scenes/polio-standin.json",
            allow_negative_numbers = true
        )]
        scene: PathBuf,
        /// Processors the frame is simulated on.
        #[arg(long, default_value_t = 512, allow_negative_numbers = true)]
        procs: u32,
        /// The frame simulated and drawn.
        #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
        frame: u32,
        /// Network fidelities to measure (the machine's own when absent).
        #[arg(long, value_enum, allow_negative_numbers = true)]
        fidelity: Vec<FidelityArg>,
        /// Also count the instructions of each side under valgrind's callgrind, which the
        /// host's noise does not move (needs valgrind; reruns the benchmark under it, tens of
        /// times slower).
        #[arg(long, allow_negative_numbers = true)]
        instructions: bool,
    },
    /// How the simulator's cost grows: the whole Delta over a viewing sequence, one frame
    /// against drawing it sequentially, staggered torus traffic at hops and flow, PHOLD, and
    /// wall time against messages, processors and triangles, each beside its target.
    #[command(
        after_help = "Example:\n  sortsim bench scale --quick -o reports/bench-scale\n  sortsim bench scale --frames 110\n  sortsim bench scale --quick --instructions"
    )]
    Scale {
        /// 3 frames, up to 16,384 messages and PHOLD up to 16,384 in flight (about 20 s here)
        /// instead of 110 frames, 65,536 messages and a million in flight.
        #[arg(long, allow_negative_numbers = true)]
        quick: bool,
        /// Frames of the headline polio run (overrides the 110 or the 3 of --quick).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=110), allow_negative_numbers = true)]
        frames: Option<u32>,
        /// Where scale.json, scale.txt and the plots go.
        #[arg(
            short,
            long,
            value_name = "DIR",
            default_value = "reports/bench-scale",
            allow_negative_numbers = true
        )]
        out: PathBuf,
        /// Also count the instructions of PHOLD's two loops and of one polio frame simulated
        /// at hops against drawn, under valgrind's callgrind: those comparisons without the
        /// host's noise (needs valgrind; some minutes more).
        #[arg(long, allow_negative_numbers = true)]
        instructions: bool,
    },
    /// Trace replay (paper 003) of one recorded frame for many n, against one pass over the
    /// fragments in the same run.
    #[command(
        after_help = "Example:\n  sortsim bench replay --scene scenes/p003-cube.json --procs all"
    )]
    Replay {
        /// The scene whose frame is recorded (the Cube stand-in: 6.46 M fragments).
        #[arg(
            long,
            default_value = "scenes/p003-cube.json",
            allow_negative_numbers = true
        )]
        scene: PathBuf,
        /// The frame recorded (0 is the first).
        #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
        frame: u32,
        /// `all` (n = 1..=64) or `pow2` (1, 2, 4, ..., 64).
        #[arg(long, default_value = "all", value_parser = ["all", "pow2"], allow_negative_numbers = true)]
        procs: String,
        /// Primitive assignment: scatter, random or background-last.
        #[arg(long, default_value = "scatter", value_parser = ["scatter", "random", "background-last"], allow_negative_numbers = true)]
        assign: String,
        /// Seed of the run's random streams (ChaCha); the same seed gives the same bytes.
        #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
        seed: u64,
    },
}

#[derive(Args, Debug)]
pub struct PholdArgs {
    /// Logical processes.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub lps: u32,
    /// Initial events per LP (events in flight = lps x this).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub events_per_lp: u32,
    /// Probability that an event is scheduled at another LP.
    #[arg(long, default_value_t = 0.9, value_parser = probability, allow_negative_numbers = true)]
    pub remote: f64,
    /// Mean of the exponential part of the delay.
    #[arg(long, default_value = "1us", allow_negative_numbers = true)]
    pub mean: crate::units::SimTime,
    /// Fixed part of the delay (the lookahead).
    #[arg(long, default_value = "100ns", allow_negative_numbers = true)]
    pub lookahead: crate::units::SimTime,
    /// Simulated end time.
    #[arg(long, default_value = "1ms", allow_negative_numbers = true)]
    pub end: crate::units::SimTime,
    /// Seed of the run's random streams (ChaCha); the same seed gives the same bytes.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,
    /// Also write DIR/summary.json (deterministic) and DIR/cost.json (wall times).
    #[arg(short, long, value_name = "DIR", allow_negative_numbers = true)]
    pub out: Option<PathBuf>,
    /// Also count the instructions of each side under valgrind's callgrind, which the
    /// host's noise does not move (needs valgrind; reruns the benchmark under it, tens of
    /// times slower).
    #[arg(long, allow_negative_numbers = true)]
    pub instructions: bool,
}

fn probability(s: &str) -> Result<f64, String> {
    let p: f64 = s
        .parse()
        .map_err(|_| format!("'{s}' is not a number; expected a probability in 0..=1"))?;
    if (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(format!(
            "{p} is not a probability; expected a number in 0..=1"
        ))
    }
}

fn region_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("'{s}' is not a region size; expected WxH in pixels, such as 64x64");
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// `--aa`: an anti-aliasing method as `--set aa=` spells it.
fn parse_aa(s: &str) -> Result<crate::raster::aa::AaMethod, String> {
    crate::raster::aa::AaMethod::parse(s)
        .ok_or_else(|| format!("expected {}", crate::raster::aa::AaMethod::VALID))
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene spec (scenes/*.json).
    pub scene: PathBuf,
    /// The frame to draw (0 is the first).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub frame: u32,
    /// Anti-aliasing: none, adaptive or supersample:N (N = 4, 9, 16, ... 256), the image
    /// every algorithm reproduces with --set aa=<the same>.
    #[arg(long, default_value = "none", value_parser = parse_aa, allow_negative_numbers = true)]
    pub aa: crate::raster::aa::AaMethod,
    /// PNG file to write.
    #[arg(short, long, value_name = "PNG", allow_negative_numbers = true)]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct SceneStatsArgs {
    /// Scene spec (scenes/*.json).
    pub scene: PathBuf,
    /// Frames: A..B (B excluded), A..=B (B included) or A; frame 0 when absent.
    #[arg(long, allow_negative_numbers = true)]
    pub frames: Option<String>,
    /// Region size for the overlap factor, WxH pixels.
    #[arg(long, value_parser = region_size, allow_negative_numbers = true)]
    pub regions: Option<(u32, u32)>,
    /// Print JSON, one object per frame.
    #[arg(long, allow_negative_numbers = true)]
    pub json: bool,
}

impl From<FidelityArg> for crate::net::Fidelity {
    fn from(f: FidelityArg) -> crate::net::Fidelity {
        use crate::net::Fidelity;
        match f {
            FidelityArg::Ideal => Fidelity::Ideal,
            FidelityArg::Hops => Fidelity::Hops,
            FidelityArg::Flow => Fidelity::Flow,
            FidelityArg::Packet => Fidelity::Packet,
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Every flag and argument of every command says what it takes.
    #[test]
    fn every_flag_has_help() {
        fn walk(cmd: &clap::Command, path: &str, missing: &mut Vec<String>) {
            for arg in cmd.get_arguments() {
                let id = arg.get_id().as_str();
                if ["help", "version"].contains(&id) {
                    continue;
                }
                if arg.get_help().is_none() && arg.get_long_help().is_none() {
                    missing.push(format!("{path} {id}"));
                }
            }
            for sub in cmd.get_subcommands() {
                walk(sub, &format!("{path} {}", sub.get_name()), missing);
            }
        }
        let mut missing = Vec::new();
        walk(&super::Cli::command(), "sortsim", &mut missing);
        assert!(missing.is_empty(), "flags without help: {missing:?}");
    }

    /// `check --help` lists every topology, from the registry the loader reads.
    #[test]
    fn check_help_names_every_topology() {
        let help = super::check_help();
        for t in crate::net::TopologyKind::ALL {
            assert!(help.contains(t.name()), "{} missing from: {help}", t.name());
        }
    }
}
