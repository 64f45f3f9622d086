//! What every fuzz target checks, shared by the targets under fuzz_targets/ and by
//! tests/fuzz_corpus.rs, which replays each target's corpus in the ordinary test run.
//!
//! Each check feeds bytes to one of the library's public readers: it must return (a value or
//! an error), never panic; where a format is written back (traces, run specs, patterns), a value
//! read must come back equal after writing and reading it again.

use std::path::Path;

use sortsim::net::pattern::Pattern;
use sortsim::spec::machine::{validate, MachineSpec};
use sortsim::spec::parse_json;
use sortsim::spec::run::RunSpec;
use sortsim::spec::scene::SceneSpec;

/// A check of one target: bytes in, a panic only for a bug.
type Check = fn(&[u8]);

/// Spec and OBJ readers take text: other bytes are not a case for them.
fn utf8(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Reads `text` as a `T`; if it reads, writes it back and asserts it reads back equal.
fn round_trip<T>(name: &str, text: &str)
where
    T: serde::de::DeserializeOwned + serde::Serialize + PartialEq + std::fmt::Debug,
{
    if let Ok(value) = parse_json::<T>(file(name), text) {
        let again = serde_json::to_string(&value).expect("what was read serializes");
        let back: T = parse_json(file(name), &again).expect("what was written reads");
        assert_eq!(back, value, "{name}: written and read back");
    }
}

/// The file name errors carry; relative paths inside a spec resolve beside it (nothing there).
fn file(name: &str) -> &'static Path {
    match name {
        "machine" => Path::new("fuzz-input/machine.json"),
        "scene" => Path::new("fuzz-input/scene.json"),
        "run" => Path::new("fuzz-input/run.json"),
        "sweep" => Path::new("fuzz-input/sweep.json"),
        "obj" => Path::new("fuzz-input/mesh.obj"),
        "calibration" => Path::new("fuzz-input/calibration.json"),
        "paper" => Path::new("fuzz-input/paper.json"),
        _ => Path::new("fuzz-input/pattern.json"),
    }
}

pub fn machine(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<MachineSpec>(file("machine"), text) {
        let _ = validate(file("machine"), spec);
    }
}

pub fn scene(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<SceneSpec>(file("scene"), text) {
        let _ = spec.validate(file("scene"));
    }
}

pub fn run(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    round_trip::<RunSpec>("run", text);
}

pub fn sweep(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let _ = sortsim::sweep::spec::parse_sweep(file("sweep"), text);
}

pub fn obj(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let _ = sortsim::scene::obj::parse(file("obj"), text);
}

pub fn trace(data: &[u8]) {
    if let Ok(trace) = sortsim::trace::decode(data) {
        let again = sortsim::trace::encode(&trace);
        let back = sortsim::trace::decode(&again).expect("an encoded trace decodes");
        assert_eq!(back, trace, "a trace encoded and decoded back");
    }
}

pub fn pattern(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    round_trip::<Pattern>("pattern", text);
}

/// Every command-line value parser the library owns, fed the same text: times, sizes and
/// rates, frame ranges and processor lists, the anti-aliasing modes, sweep shards, Slurm's
/// time, memory and partition, and each algorithm's `--set KEY=VALUE` options. None may
/// panic; what they accept must keep their promises (a frame range non-empty and inside the
/// scene, a list within its limit, a time or size written back reads back equal).
pub fn options(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    use sortsim::units::{Bandwidth, Bytes, SimTime};
    if let Ok(t) = text.parse::<SimTime>() {
        let back: SimTime = format!("{}ps", t.ps())
            .parse()
            .expect("picoseconds read back");
        assert_eq!(back, t, "{text:?}: a time written in ps reads back equal");
    }
    if let Ok(b) = text.parse::<Bytes>() {
        let back: Bytes = format!("{}B", b.get()).parse().expect("bytes read back");
        assert_eq!(back, b, "{text:?}: a size written in B reads back equal");
    }
    let _ = text.parse::<Bandwidth>();
    for count in [1, 80, u32::MAX] {
        if let Ok(range) = sortsim::spec::run::parse_frames(Some(text), count) {
            assert!(
                !range.is_empty() && range.end <= count,
                "{text:?}: frames {range:?} of {count}"
            );
        }
    }
    if let Ok(list) = sortsim::algo::sort_middle::utilization::parse_list(text) {
        assert!(
            list.len() as u64 <= sortsim::limits::MAX_LIST_ITEMS,
            "{text:?}: {} values",
            list.len()
        );
    }
    let _ = sortsim::raster::aa::AaMethod::parse(text);
    let _ = text.parse::<sortsim::accuracy::AaMode>();
    let _ = text.parse::<sortsim::sweep::shard::Shard>();
    let _ = sortsim::sweep::slurm::check_time(text);
    let _ = sortsim::sweep::slurm::check_mem(text);
    let _ = sortsim::sweep::slurm::check_value("--partition", text, "debug");
    let (key, value) = text.split_once('=').unwrap_or(("aa", text));
    let options = sortsim::algo::Options::new([(key.to_string(), value.to_string())].into());
    for algo in sortsim::algo::AlgorithmId::ALL {
        let _ = algo.check_option_values(&options);
    }
}

/// A calibration spec: when it reads, each parameter's fields are scaled at both ends of its
/// range in a bundled machine's and a bundled scene's JSON, as a fit's first candidates are. The
/// field paths are the spec's free text, so walking them must end in an error, never a panic,
/// and what is scaled must still be a spec the machine or scene reader answers.
pub fn calibration(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let Ok(spec) = sortsim::calibrate::parse_spec(file("calibration"), text) else {
        return;
    };
    // Each bundled file, read once for every input, beside the check that reads what is
    // scaled from it.
    static SUBJECTS: std::sync::OnceLock<[(serde_json::Value, Check); 2]> =
        std::sync::OnceLock::new();
    let subjects = SUBJECTS.get_or_init(|| {
        let read = |text: &str| serde_json::from_str(text).expect("a bundled spec");
        [
            (read(include_str!("../machines/delta.json")), machine),
            (read(include_str!("../scenes/p003-brooks.json")), scene),
        ]
    });
    for (subject, read_back) in subjects {
        for end in [0, 1] {
            let factors: Vec<f64> = spec.parameters.iter().map(|p| p.range[end]).collect();
            let scaled = sortsim::calibrate::scaled_spec(subject, &spec.parameters, &factors);
            if let Ok(scaled) = scaled {
                read_back(scaled.to_string().as_bytes());
            }
        }
    }
}

/// A paper's data file: when it reads, its roles are checked against a list of fits, and every
/// row is printed and judged as a paper's report does, against sortsim numbers near and far.
pub fn paper(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let Ok(paper) = sortsim::paper::data::parse(file("paper"), text, None) else {
        return;
    };
    let fits: Vec<(String, String, String)> = [
        ("delta.json", "002", "peak-polio"),
        ("scenes/p003-brooks.json", "003", "reduction-brooks"),
    ]
    .map(|(file, paper, row)| (file.into(), paper.into(), row.into()))
    .into();
    let _ = sortsim::paper::data::check_roles(&paper, &fits);
    for row in &paper.rows {
        let _ = (row.claim(), row.tolerance_text());
        let near = row.value.or(row.range.map(|[lo, _]| lo)).unwrap_or(1.0);
        for m in [near, near * 1.5, 0.0, -1.0, f64::MAX, f64::NAN] {
            let _ = row.deviation_pct(m);
            let measured = sortsim::paper::Measured::value(m, "");
            let _ = sortsim::paper::verdict::judge(row, &measured);
        }
    }
}

/// One simulated run of a small case built from the bytes: a bundled machine with up to three
/// of its fields replaced (any of its times, sizes, rates, counts, the fidelity; a cpu's costs
/// up to 1 ms and its time slice kept), a scene of one to three tiny generated objects at up to
/// 96 x 96 pixels, one to 16 processors (now and then up to 70), any algorithm, and any of its
/// options set to a value its schema allows or to an edge of one (0, 2^32). Whatever the checks
/// refuse is a refusal; what they accept must run to an answer or a `RunError`, never a panic,
/// and must keep two promises: the same case run again, with the front end made on the
/// simulation's own thread and a wake-up at every slice, gives the same frames, image and
/// statistics (timeline included); and without anti-aliasing the
/// image's colours are the sequential reference renderer's. With `SORTSIM_FUZZ_SHOW` set, each
/// case is printed before it runs (a hang reported by libFuzzer says nothing else).
pub fn simulate(data: &[u8]) {
    let mut u = arbitrary::Unstructured::new(data);
    let Ok(case) = simulated::Case::build(&mut u) else {
        return;
    };
    if std::env::var_os("SORTSIM_FUZZ_SHOW").is_some() {
        eprintln!("{case:?}");
    }
    let Some(cfg) = case.config() else {
        return;
    };
    let Ok(first) = sortsim::algo::run(&cfg) else {
        return;
    };
    let again = sortsim::algo::run(&sortsim::algo::RunConfig {
        front_end_ahead: false,
        wake_every_slice: true,
        ..cfg.clone()
    })
    .expect("a case that ran once runs again");
    assert_eq!(first.frames, again.frames, "{case:?}: frames of two runs");
    assert!(first.image == again.image, "{case:?}: images of two runs");
    assert_eq!(
        format!("{:?}", first.stats),
        format!("{:?}", again.stats),
        "{case:?}: statistics of two runs"
    );
    if !cfg.options.is_given("aa") || cfg.options.value("aa") == Some("none") {
        let last = cfg
            .scene
            .frame(cfg.frames.end - 1)
            .expect("the run drew it");
        let (expected, _) = sortsim::algo::reference::render(&last);
        assert!(
            first.image.colors() == expected.colors(),
            "{case:?}: the image is not the reference renderer's"
        );
    }
}

/// The pieces of [`simulate`]'s cases.
mod simulated {
    use std::sync::Arc;

    use arbitrary::{Result, Unstructured};
    use serde_json::{json, Value};
    use sortsim::algo::{AlgorithmId, Options, RunConfig};
    use sortsim::scene::Scene;
    use sortsim::spec::machine::{validate, MachineSpec};
    use sortsim::spec::scene::SceneSpec;

    use super::file;

    /// The bundled machines a case starts from.
    const MACHINES: [&str; 9] = [
        include_str!("../machines/delta.json"),
        include_str!("../machines/bgp-intrepid-8k.json"),
        include_str!("../machines/denali-crossbar.json"),
        include_str!("../machines/gpu-cluster-a100.json"),
        include_str!("../machines/multicluster-pipeline.json"),
        include_str!("../machines/multicluster-torus.json"),
        include_str!("../machines/pixelflow-pipeline.json"),
        include_str!("../machines/power-challenge.json"),
        include_str!("../machines/snooping-bus.json"),
    ];

    const TIMES: [&str; 6] = ["0ps", "1ps", "80ns", "1ms", "1s", "100000s"];
    /// A cpu's costs stay short: on a time-sliced cpu every slice of a charge is an event
    /// (a second of charges is 489 of them on multicluster-torus's 2,048 us slices), so long
    /// ones make cases that run for minutes, which libFuzzer reports as hangs.
    const CPU_TIMES: [&str; 5] = ["0ps", "1ps", "80ns", "1us", "1ms"];
    const SIZES: [&str; 6] = ["0B", "1B", "64B", "4KiB", "1MiB", "1GiB"];
    const RATES: [&str; 5] = ["1B/s", "1MB/s", "17MB/s", "1GB/s", "1000TB/s"];
    const COUNTS: [&str; 11] = [
        "0",
        "1",
        "2",
        "3",
        "4",
        "7",
        "8",
        "17",
        "64",
        "65536",
        "4294967296",
    ];

    #[derive(Debug)]
    pub struct Case {
        machine: usize,
        machine_fields: Vec<(String, Value)>,
        scene: Value,
        algo: AlgorithmId,
        procs: u32,
        options: Vec<(String, String)>,
    }

    impl Case {
        pub fn build(u: &mut Unstructured) -> Result<Case> {
            let machine = u.choose_index(MACHINES.len())?;
            let mut leaves = Vec::new();
            let spec: Value = serde_json::from_str(MACHINES[machine]).expect("a bundled machine");
            for part in ["cpu", "memory", "network"] {
                leaves_of(&spec[part], part, &mut leaves);
            }
            let mut machine_fields = Vec::new();
            for _ in 0..u.int_in_range(0..=3)? {
                let (path, old) = u.choose(&leaves)?;
                machine_fields.push((path.clone(), replacement(u, path, old)?));
            }
            let algo = *u.choose(&AlgorithmId::ALL)?;
            let procs = match u.ratio(1, 8)? {
                true => u.int_in_range(1..=70)?,
                false => u.int_in_range(1..=16)?,
            };
            let schema = algo.options_schema();
            let mut options = Vec::new();
            if let Some(properties) = schema["properties"].as_object() {
                for (key, property) in properties {
                    if u.ratio(1, 3)? {
                        options.push((key.clone(), option_value(u, &schema, property)?));
                    }
                }
            }
            Ok(Case {
                machine,
                machine_fields,
                scene: scene(u)?,
                algo,
                procs,
                options,
            })
        }

        /// The run, when every check a `sortsim run` makes accepts it.
        pub fn config(&self) -> Option<RunConfig> {
            let mut machine: Value = serde_json::from_str(MACHINES[self.machine]).ok()?;
            for (path, value) in &self.machine_fields {
                let mut at = &mut machine;
                for part in path.split('.') {
                    at = match at {
                        Value::Array(items) => &mut items[part.parse::<usize>().ok()?],
                        other => &mut other[part],
                    };
                }
                *at = value.clone();
            }
            let spec: MachineSpec = serde_json::from_value(machine).ok()?;
            let machine = validate(file("machine"), spec).ok()?;
            let machine = machine.with_nodes(self.procs).ok()?;
            let options = Options::new(self.options.iter().cloned().collect());
            self.algo.check_option_values(&options).ok()?;
            let spec: SceneSpec = serde_json::from_value(self.scene.clone()).ok()?;
            let scene = Arc::new(Scene::from_spec(file("scene"), spec).ok()?);
            let frames = 0..scene.frame_count();
            let cfg = RunConfig {
                machine,
                scene,
                algo: self.algo,
                frames,
                options,
                seed: 1,
                // Recorded, so that the two runs' statistics compare their timelines too.
                timeline: true,
                timeline_frames: None,
                front_end_ahead: true,
                wake_every_slice: false,
            };
            sortsim::algo::check_options(&cfg).ok()?;
            Some(cfg)
        }
    }

    /// Every number and string under `value`, by dotted path.
    fn leaves_of(value: &Value, path: &str, out: &mut Vec<(String, Value)>) {
        match value {
            Value::Object(fields) => {
                for (k, v) in fields {
                    leaves_of(v, &format!("{path}.{k}"), out);
                }
            }
            Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    leaves_of(v, &format!("{path}.{i}"), out);
                }
            }
            Value::Null => {}
            leaf => out.push((path.to_string(), leaf.clone())),
        }
    }

    /// Another value of the kind `old` is: a time for a time, a rate for a rate, and so on.
    fn replacement(u: &mut Unstructured, path: &str, old: &Value) -> Result<Value> {
        let text = old.as_str().unwrap_or("");
        let pick = |u: &mut Unstructured, list: &[&str]| -> Result<Value> {
            Ok(Value::from(*u.choose(list)?))
        };
        Ok(match old {
            Value::Bool(_) => Value::Bool(u.arbitrary()?),
            Value::Number(_) => {
                json!(*u.choose(&[0u64, 1, 2, 3, 7, 16, 1 << 20, u32::MAX as u64])?)
            }
            // For the same reason the slice itself is kept.
            _ if path.ends_with("timeslice") => old.clone(),
            _ if path.ends_with("fidelity") => pick(u, &["ideal", "hops", "flow", "packet"])?,
            _ if path.starts_with("cpu.") && !text.ends_with('B') => pick(u, &CPU_TIMES)?,
            _ if text.ends_with("/s") => pick(u, &RATES)?,
            _ if text.ends_with('B') => pick(u, &SIZES)?,
            _ if text.ends_with('s') => pick(u, &TIMES)?,
            _ => old.clone(),
        })
    }

    /// A value for an option whose schema is `property`: one its schema lists, one of its
    /// examples' kind, or an edge of a count.
    fn option_value(u: &mut Unstructured, schema: &Value, property: &Value) -> Result<String> {
        let mut kind = property;
        if let Some(first) = kind["anyOf"].get(0) {
            if u.ratio(1, 4)? {
                return Ok("none".into());
            }
            kind = first;
        }
        if let Some(name) = kind["$ref"].as_str().and_then(|r| r.rsplit('/').next()) {
            kind = &schema["$defs"][name];
        }
        if let Some(values) = kind["enum"].as_array() {
            return Ok(u.choose(values)?.as_str().unwrap_or("").to_string());
        }
        let pattern = kind["pattern"].as_str().unwrap_or("");
        let list: &[&str] = if pattern.contains("supersample") {
            &[
                "none",
                "adaptive",
                "supersample:4",
                "supersample:9",
                "supersample:3",
            ]
        } else if pattern.contains("auto|") {
            &["auto", "2", "2,2", "4,2", "2,2,2,2", "3", "16", "1,2"]
        } else if pattern.contains("KiB") {
            &SIZES
        } else if pattern.contains("ms|s") {
            &TIMES
        } else {
            &COUNTS
        };
        Ok(u.choose(list)?.to_string())
    }

    /// A scene of one to three small objects in front of the default camera.
    fn scene(u: &mut Unstructured) -> Result<Value> {
        let mut objects = Vec::new();
        for _ in 0..u.int_in_range(1..=3)? {
            let generator = match u.int_in_range(0..=9)? {
                0 => json!({"kind": "spd-tetra", "size_factor": u.int_in_range(0..=2)?}),
                1 => json!({"kind": "gears", "grid": 1, "teeth": u.int_in_range(4..=9)?}),
                2 => json!({"kind": "mountain", "levels": u.int_in_range(0..=3)?,
                            "roughness": 0.5, "seed": u.int_in_range(0..=9)?}),
                3 => json!({"kind": "teapot", "n": u.int_in_range(1..=3)?}),
                4 => json!({"kind": "plane"}),
                5 => json!({"kind": "big-triangle"}),
                6 => json!({"kind": "uv-sphere", "rings": u.int_in_range(2..=8)?,
                            "segments": u.int_in_range(3..=8)?}),
                7 => json!({"kind": "random-tetrahedra", "count": u.int_in_range(1..=40)?,
                            "size": *u.choose(&[1e-6, 0.05, 0.3, 2.0])?,
                            "seed": u.int_in_range(0..=9)?}),
                8 => json!({"kind": "letter-b", "segments": u.int_in_range(2..=8)?, "depth": 0.2}),
                _ => {
                    json!({"kind": "icosa-shell", "frequency": u.int_in_range(1..=2)?, "bump": 0.1})
                }
            };
            let mut object = json!({"generator": generator, "color": [0.8, 0.5, 0.2]});
            if u.ratio(1, 3)? {
                let seed = u.int_in_range(0..=9)?;
                object["motion"] =
                    json!({"kind": "tumble", "seed": seed, "degrees_per_frame": 40.0});
            }
            objects.push(object);
        }
        Ok(json!({
            "resolution": [u.int_in_range(1..=96)?, u.int_in_range(1..=96)?],
            "frames": u.int_in_range(1..=2)?,
            "cull_backfaces": u.arbitrary::<bool>()?,
            "camera": {"kind": "perspective", "eye": [0, 0, 3.6], "target": [0, 0, 0],
                       "up": [0, 1, 0], "fov_deg": 40, "near": 0.05, "far": 100},
            "geometry": objects,
        }))
    }
}
