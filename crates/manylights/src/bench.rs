//! `manylights bench`: every technique × light count on one scene, per-pass GPU
//! time (median, p95, mean over the frames after the warm-up), CPU time per frame and lights
//! per cluster, written to results.csv, results.json and results.png. A combination whose frames
//! would take longer than the budget is skipped and says so: brute force estimated from a smaller
//! count (linear), clustered techniques from one frame (see `Previous`).

use crate::applies::{check_rules, objects_rule, Auto, Given, Rule, Techniques, CLUSTER_GRID, VISIBILITY_BUFFER};
use crate::auto::{self, technique_choice};
use crate::{cluster_choice, print_warnings, scene_source, shading_choice, Progress, Whole};
use anyhow::{bail, Context as _, Result};
use clap::Args;
use ml_cpu::camera::CameraSpec;
use ml_cpu::cluster::ClusterDims;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene_request::SceneRequest;
use ml_render::settings::SettingsRequest;
use ml_render::{Antialiasing, Geometry, Raster, RenderOutput, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::sync::atomic::Ordering;

mod probe;
mod sheet;

/// Each option's help ends with its default: clap's `[default: X]`, or a sentence "Default: …"
/// where the scene decides it.
#[derive(Args)]
pub struct BenchArgs {
    /// Scene, as render's --scene: bench (a floor, --objects objects, lights whose radius
    /// shrinks as their count grows), seed, room, FILE.toml, FILE.gltf|FILE.glb.
    #[arg(long, default_value = "bench")]
    scene: String,
    /// Objects of the bench scene (0 to 100000): more on the same floor, denser.
    #[arg(long, default_value_t = ml_cpu::bench_scene::BENCH_OBJECTS, value_parser = crate::OBJECTS, allow_negative_numbers = true)]
    objects: usize,
    /// Percent of the scene's objects made transparent (alphaMode BLEND, alpha one half),
    /// spread evenly through it (0 to 100).
    #[arg(long, default_value_t = 0, value_parser = crate::PERCENT, allow_negative_numbers = true)]
    transparent_objects: u32,
    /// Panes of faint glass added across the whole view in front of the scene, a transparent
    /// layer on every pixel each (0 to 256): a stress test of transparency.
    #[arg(long, default_value_t = 0, value_parser = crate::GLASS_LAYERS, allow_negative_numbers = true)]
    glass_layers: u32,
    /// Transparent objects: the per-pixel layers' memory, in nodes of 32 bytes per pixel on
    /// average (1 to 256).
    #[arg(long, default_value_t = ml_render::DEFAULT_TRANSPARENCY_BUDGET, value_parser = crate::TRANSPARENCY_BUDGET, allow_negative_numbers = true)]
    transparency_budget: u32,
    /// Techniques, comma-separated: forward, clustered-cpu, clustered-gpu, deferred,
    /// deferred-clustered, deferred-compute, visibility, or auto (the one `--technique auto`
    /// picks on this device).
    #[arg(long, default_value = "forward,clustered-cpu,clustered-gpu,deferred,deferred-clustered,deferred-compute,visibility")]
    techniques: String,
    /// Light counts, comma-separated; k and M multiply by 1,000 and 1,000,000.
    #[arg(long, default_value = "1k,16k,256k,1M", allow_hyphen_values = true)]
    lights: String,
    /// Image size WxH of every combination, and of the probe's passes (each side 1 to 16384,
    /// and at most the device's largest image).
    #[arg(long, default_value = "1920x1080", allow_hyphen_values = true)]
    resolution: String,
    /// Measured frames per combination (with --probe: rounds per loop length), 1 to 100000.
    #[arg(long, default_value_t = 300, value_parser = Whole::<u32>::new(1, MAX_FRAMES as u64), allow_negative_numbers = true)]
    frames: u32,
    /// Frames rendered first and not measured (with --probe: rounds), 0 to 100000.
    #[arg(long, default_value_t = 60, value_parser = Whole::<u32>::new(0, MAX_FRAMES as u64), allow_negative_numbers = true)]
    warmup: u32,
    /// Skip a combination whose frames would take longer than this many seconds (estimated
    /// from one frame).
    #[arg(long, default_value_t = 120.0, allow_negative_numbers = true)]
    budget_s: f64,
    /// Shading model, as render's --shading: seed, blinn-phong or pbr. Default: the scene
    /// file's [shading] model, else seed.
    #[arg(long)]
    shading: Option<String>,
    /// The camera, as render's --camera: EYE_X,EYE_Y,EYE_Z:TARGET_X,TARGET_Y,TARGET_Z[:FOV].
    /// Default: the scene's own camera.
    #[arg(long, allow_hyphen_values = true)]
    camera: Option<String>,
    /// Cluster grid XxYxZ of the techniques that have one, or auto (as render's --clusters:
    /// scaled with each light count).
    #[arg(long, default_value = "auto")]
    clusters: String,
    /// Enable the Khronos validation layer with synchronization validation; any message
    /// makes the run fail.
    #[arg(long)]
    validation: bool,
    /// Vulkan device index (see `manylights info`). Default: the best one (discrete first).
    #[arg(long, value_parser = crate::DEVICE, allow_negative_numbers = true)]
    device: Option<usize>,
    /// Folder for results.csv, results.json and results.png (with --probe: probe.csv and
    /// probe.json), made if missing.
    #[arg(long, default_value = "bench-results")]
    out: PathBuf,
    /// Measure only shard I of N (I from 0) of the sweep's rows (every light count × technique,
    /// rasteriser and sample count, in the table's order): a block of them, as render's
    /// --shard splits frames; `env`: a Slurm array task's (SLURM_ARRAY_TASK_ID less
    /// SLURM_ARRAY_TASK_MIN, of SLURM_ARRAY_TASK_COUNT). Its sheet says which shard it is.
    /// Default: the whole sweep.
    #[arg(long, allow_hyphen_values = true)]
    shard: Option<String>,
    /// Measure nothing: join the sheets of every shard of one run, in these folders
    /// (comma-separated), into the sheet of the whole sweep in --out.
    #[arg(long, allow_hyphen_values = true)]
    merge: Option<String>,
    /// Instead of the techniques: the compute-vs-fragment probe — one BRDF loop over every
    /// pixel of --resolution as a fragment shader and as a compute shader, --warmup + --frames
    /// rounds per loop length of --probe-lights — and the ratio of their times.
    #[arg(long)]
    probe: bool,
    /// Rasterisers of the visibility technique, comma-separated: hardware, hybrid, compute
    /// (each a row of its own; the other techniques have one).
    #[arg(long, default_value = "hardware,compute")]
    raster: String,
    /// Anti-aliasing sample counts, comma-separated: off, 4, 8, 16 or auto (render's --aa:
    /// 8 on a GPU, off on a CPU driver); the counts other than off make rows of every technique
    /// (and every rasteriser's for visibility); a count the device does not offer one makes a
    /// row that says so.
    #[arg(long, default_value = "auto")]
    aa: String,
    /// The compute and hybrid rasters' largest triangle drawn by one thread, pixels a side (1
    /// to 64; render's --raster-split).
    #[arg(long, default_value_t = Raster::DEFAULT_SPLIT, value_parser = crate::RASTER_SPLIT, allow_negative_numbers = true)]
    raster_split: u32,
    /// Loop lengths (lights every pixel sums) of --probe, comma-separated, each at most 65536.
    #[arg(long, default_value = "16,64,256,1024", allow_hyphen_values = true)]
    probe_lights: String,
    /// The options given on the command line (the others keep their defaults).
    #[arg(skip)]
    pub(crate) given: Given,
}

/// The most measured frames, and the most warm-up frames, of a combination (or probe length):
/// as many as `render --frames` takes.
const MAX_FRAMES: u32 = crate::MAX_FRAMES;

impl BenchArgs {
    /// Frames (or probe rounds) rendered per combination: warm-up and measured.
    fn rounds(&self) -> Result<u32> {
        self.warmup
            .checked_add(self.frames)
            .with_context(|| format!("--warmup {} with --frames {} is too many frames", self.warmup, self.frames))
    }

    /// The options that apply only with some techniques, rasterisers or with (or without)
    /// --probe.
    pub(crate) fn rules(&self, rasters: &[Raster]) -> Vec<Rule> {
        let probe_only = |id| Rule::setting(id, Some(self.probe), "bench without --probe", "--probe");
        let not_probe = |id| Rule::setting(id, Some(!self.probe), "bench --probe", "bench without --probe, which renders the techniques");
        let mut rules: Vec<Rule> = [
            "shard",
            "techniques",
            "lights",
            "scene",
            "objects",
            "shading",
            "camera",
            "clusters",
            "raster",
            "raster_split",
            "aa",
            "transparent_objects",
            "glass_layers",
            "transparency_budget",
        ]
        .into_iter()
        .map(not_probe)
        .collect();
        rules.extend([
            probe_only("probe_lights"),
            objects_rule(&self.scene),
            // A file may have transparent objects of its own (known once it is loaded).
            Rule::setting(
                "transparency_budget",
                (self.transparent_objects == 0 && self.glass_layers == 0 && !crate::is_scene_file(&self.scene)).then_some(false),
                "a scene without transparent objects",
                "transparent objects (alphaMode BLEND in a glTF file, --transparent-objects or --glass-layers)",
            ),
            Rule::technique("clusters", CLUSTER_GRID, Technique::has_cluster_grid),
            Rule::technique("raster", VISIBILITY_BUFFER, Technique::draws_meshlets),
            Rule::technique("raster_split", VISIBILITY_BUFFER, Technique::draws_meshlets),
            Rule::setting(
                "raster_split",
                Some(rasters.iter().any(|r| *r != Raster::Hardware)),
                "--raster hardware",
                "a rasteriser in compute (--raster compute or hybrid)",
            ),
        ]);
        rules
    }
}

/// `123`, `16k`, `1M`.
fn parse_count(text: &str) -> Result<u64> {
    let t = text.trim();
    let (digits, factor) = match t.chars().last() {
        Some('k' | 'K') => (&t[..t.len() - 1], 1_000),
        Some('m' | 'M') => (&t[..t.len() - 1], 1_000_000),
        _ => (t, 1),
    };
    let n: u64 = digits.parse().with_context(|| format!("'{text}' is not a light count (e.g. 4096, 16k, 1M)"))?;
    n.checked_mul(factor).filter(|&n| n > 0).with_context(|| format!("light count '{text}' is out of range"))
}

/// `--resolution WxH`, each side 1 to MAX_DIMENSION (the device may allow less: checked once
/// it is known).
pub(crate) fn parse_resolution(text: &str) -> Result<(u32, u32)> {
    let (w, h) = text.split_once('x').with_context(|| format!("--resolution '{text}': expected WxH, e.g. 1920x1080"))?;
    let max = ml_render::settings::MAX_DIMENSION;
    let side = |s: &str| s.trim().parse::<u32>().ok().filter(|n| (1..=max).contains(n));
    match (side(w), side(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => bail!("--resolution {text}: each side must be 1 to {max}"),
    }
}

/// What every combination renders: the scene (its light count set per combination) and the
/// settings (the technique set per combination), as `render` would with the same arguments.
struct Plan {
    scene: SceneRequest,
    settings: SettingsRequest,
    /// Whether the scene's warnings were shown (once for the run).
    warned: bool,
}

impl Plan {
    fn new(a: &BenchArgs, (width, height): (u32, u32)) -> Result<Plan> {
        let source = scene_source(&a.scene, MeshKind::Sphere, Material::named("gold")?, a.objects)?;
        let scene = SceneRequest {
            shading: shading_choice(a.shading.as_deref())?,
            camera: a.camera.as_deref().map(CameraSpec::parse).transpose().context("--camera")?,
            aspect: width.max(1) as f32 / height.max(1) as f32,
            transparent_percent: a.transparent_objects,
            glass_layers: a.glass_layers,
            ..SceneRequest::new(source)
        };
        // The clock runs (the lights move from frame to frame); technique, raster and samples
        // are each combination's.
        let settings = SettingsRequest {
            clusters: cluster_choice(&a.clusters)?,
            transparency: ml_render::TransparencySettings { budget: a.transparency_budget, ..Default::default() },
            ..SettingsRequest::new(RenderSettings { time: None, ..RenderSettings::new(Technique::Forward, width, height) })
        };
        Ok(Plan { scene, settings, warned: false })
    }
}

/// What a run measures: the probe at these loop lengths, or the techniques.
enum Work {
    Probe(Vec<u32>),
    Techniques(Box<Plan>),
}

/// What a row measures: a technique, for the visibility technique its rasteriser, and the
/// anti-aliasing.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Variant {
    technique: Technique,
    raster: Raster,
    antialiasing: Antialiasing,
}

impl Variant {
    /// `visibility`, `visibility (compute raster)`, `visibility (compute raster, 8x AA)`,
    /// `forward`, …
    fn label(self) -> String {
        let aa = match self.antialiasing {
            Antialiasing::Off => String::new(),
            aa => format!(", {}x AA", aa.samples()),
        };
        match self.raster {
            Raster::Hardware if self.antialiasing == Antialiasing::Off => self.technique.name().to_owned(),
            Raster::Hardware => format!("{} ({}x AA)", self.technique.name(), self.antialiasing.samples()),
            Raster::Compute { .. } => format!("{} ({} raster{aa})", self.technique.name(), self.raster.name()),
        }
    }
}

/// --aa: the sample counts of the rows (None: auto, the device's).
fn antialiasing_list(a: &BenchArgs) -> Result<Vec<Option<Antialiasing>>> {
    unique_list(&a.aa, |name| auto::antialiasing_choice(name).context("--aa"))
}

/// --raster: the rasterisers the visibility rows use.
fn raster_list(a: &BenchArgs) -> Result<Vec<Raster>> {
    unique_list(&a.raster, |name| Ok(Raster::from_name(name, a.raster_split)?))
}

/// A comma-separated list of names, each parsed, in order, repeats dropped.
fn unique_list<T: PartialEq>(text: &str, parse: impl Fn(&str) -> Result<T>) -> Result<Vec<T>> {
    let mut list = Vec::new();
    for name in text.split(',').map(str::trim) {
        let value = parse(name)?;
        if !list.contains(&value) {
            list.push(value);
        }
    }
    Ok(list)
}

/// One combination's result.
struct Measured {
    variant: Variant,
    lights: u64,
    /// Why it was not measured.
    skipped: Option<String>,
    output: Option<RenderOutput>,
    /// The cluster grid of a measured clustered technique.
    grid: Option<ClusterDims>,
    /// Milliseconds a frame: measured (wall clock), or estimated where skipped.
    ms_per_frame: f64,
}

/// What a CPU driver measures unless told otherwise: the defaults (1080p, 300 frames, up to a
/// million lights) would take it hours, every combination skipped for the time budget and
/// nothing plotted.
const CPU_DEFAULTS: [(&str, &str); 4] = [("resolution", "320x180"), ("frames", "5"), ("warmup", "1"), ("lights", "1k,16k")];

/// On a CPU driver, CPU_DEFAULTS for each of those options not given; the note that says so
/// (printed once every argument has been checked: an error stays the only line).
fn fit_to_a_cpu(a: &mut BenchArgs, device: &ml_vk::DeviceInfo) -> Option<String> {
    if device.device_type != ml_vk::vk::PhysicalDeviceType::CPU || a.probe {
        return None;
    }
    let mut taken = Vec::new();
    for (id, value) in CPU_DEFAULTS {
        if a.given.has(id) {
            continue;
        }
        match id {
            "resolution" => a.resolution = value.to_owned(),
            "frames" => a.frames = value.parse().expect("a count"),
            "warmup" => a.warmup = value.parse().expect("a count"),
            _ => a.lights = value.to_owned(),
        }
        taken.push(format!("--{id} {value}"));
    }
    (!taken.is_empty())
        .then(|| format!("note: '{}' is a CPU driver: measuring {} (give them to choose others)", device.name, taken.join(" ")))
}

/// The arguments read and checked: the techniques asked for, the light counts (ascending),
/// the image size, the rasters and sample counts, and whether auto is among the techniques.
struct Asked {
    choices: Vec<Option<Technique>>,
    counts: Vec<u64>,
    resolution: (u32, u32),
    rasters: Vec<Raster>,
    sample_counts: Vec<Option<ml_render::Antialiasing>>,
    rules: Vec<Rule>,
    named: Vec<Technique>,
    auto: Auto,
}

fn asked(a: &BenchArgs) -> Result<Asked> {
    let choices: Vec<Option<Technique>> = a.techniques.split(',').map(|t| technique_choice(t.trim())).collect::<Result<_>>()?;
    let mut counts: Vec<u64> = a.lights.split(',').map(parse_count).collect::<Result<_>>()?;
    // Ascending: each count's estimate can lean on the smaller ones measured before it.
    counts.sort_unstable();
    counts.dedup();
    let resolution = parse_resolution(&a.resolution)?;
    a.rounds()?;
    if a.budget_s.is_nan() || a.budget_s <= 0.0 {
        bail!("--budget-s {} must be greater than 0", a.budget_s);
    }
    let rasters = raster_list(a)?;
    let sample_counts = antialiasing_list(a)?;
    let rules = a.rules(&rasters);
    let named: Vec<Technique> = choices.iter().flatten().copied().collect();
    let auto = if choices.contains(&None) { Auto::Pending } else { Auto::No };
    check_rules(&rules, &a.given, &Techniques { flag: "--techniques", named: named.clone(), auto })?;
    Ok(Asked { choices, counts, resolution, rasters, sample_counts, rules, named, auto })
}

pub fn bench(a: &mut BenchArgs) -> Result<()> {
    if let Some(folders) = &a.merge {
        return merge(a, folders);
    }
    // Every argument checked before the device is; a CPU driver then gets sizes it can finish.
    asked(a)?;
    let ctx = Context::new(&ContextDesc { validation: a.validation, device_index: a.device, window: None })?;
    let note = fit_to_a_cpu(a, &ctx.info);
    let a = &*a;
    let Asked { choices, counts, resolution, rasters, sample_counts, rules, named, auto } = asked(a)?;
    let shard = a.shard.as_deref().map(|text| crate::output::parse_shard(text, |name| std::env::var(name).ok())).transpose()?;
    let work = if a.probe { Work::Probe(probe_lengths(&a.probe_lights)?) } else { Work::Techniques(Box::new(Plan::new(a, resolution)?)) };
    // What the run writes, checked before it runs (a bad path must not cost a sweep).
    prepare_folder(&a.out, if a.probe { &PROBE_RESULTS } else { &sheet::RESULTS })?;
    if let Some(note) = note {
        eprintln!("{note}");
    }
    let messages = ctx.validation_counter();
    let mut plan = match work {
        Work::Techniques(plan) => plan,
        Work::Probe(lengths) => {
            let result = probe::run(&ctx, a, resolution, &lengths);
            let device = device_json(&ctx);
            let meshlets = ml_render::settings::missing_meshlet_feature(&ctx.info.features).is_none();
            drop(ctx);
            let rows = result?;
            probe::write(a, resolution, &device, meshlets, &rows)?;
            return check_messages(messages.load(Ordering::SeqCst));
        }
    };
    // Every run records the quick probe and what auto makes of it.
    let (auto_technique, auto_why, quick) = auto::pick(&ctx, None)?;
    if auto == Auto::Pending {
        check_rules(&rules, &a.given, &Techniques { flag: "--techniques", named, auto: Auto::Picked(auto_technique) })?.warn();
    }
    auto::announce(auto_technique, &auto_why);
    // --aa auto: the device's count (a row that cannot take it says so, as for any count).
    let cpu = ctx.info.device_type == ml_vk::vk::PhysicalDeviceType::CPU;
    let (device_aa, aa_why) = ml_render::auto_antialiasing(cpu, |_| Ok(()));
    if sample_counts.contains(&None) {
        println!("auto aa: {}: {aa_why}", device_aa.name());
    }
    let sample_counts: Vec<Antialiasing> = sample_counts.iter().map(|c| c.unwrap_or(device_aa)).fold(Vec::new(), |mut list, aa| {
        if !list.contains(&aa) {
            list.push(aa);
        }
        list
    });
    let mut variants: Vec<Variant> = Vec::new();
    for technique in choices.into_iter().map(|c| c.unwrap_or(auto_technique)) {
        let rasters = if technique.geometry() == Geometry::Meshlets { rasters.clone() } else { vec![Raster::Hardware] };
        for raster in rasters {
            if let Some(feature) = ml_render::settings::missing_raster_feature(raster, &ctx.info.features) {
                eprintln!("warning: the {} raster needs {feature}, which '{}' lacks: not measured", raster.name(), ctx.info.name);
                continue;
            }
            for &antialiasing in &sample_counts {
                let v = Variant { technique, raster, antialiasing };
                if !variants.contains(&v) {
                    variants.push(v);
                }
            }
        }
    }
    // The sweep's rows, lights outer; a shard measures its block of them.
    let sweep: Vec<(u64, Variant)> = counts.iter().flat_map(|&lights| variants.iter().map(move |&v| (lights, v))).collect();
    let rows = crate::output::shard_block(sweep.len() as u64, shard);
    let mut bar = Progress::new(rows.end - rows.start, "");
    let mut results: Vec<(usize, Measured)> = Vec::new();
    for (row, &(lights, variant)) in sweep.iter().enumerate().filter(|(i, _)| rows.contains(&(*i as u64))) {
        bar.set_message(format!("{} at {lights} lights", variant.label()));
        // A variant the device cannot run at one count it cannot run at any (no scene of
        // the next count built for it).
        let refused =
            results.iter().find_map(|(_, m)| m.skipped.as_deref().filter(|s| m.variant == variant && s.starts_with(NOT_MEASURED)));
        if let Some(why) = refused {
            let skipped = Some(why.to_owned());
            results.push((row, Measured { variant, lights, skipped, output: None, grid: None, ms_per_frame: 0.0 }));
            bar.inc();
            continue;
        }
        // The same variant at the largest smaller count (of this run), measured or estimated.
        let previous = results
            .iter()
            .filter(|(_, m)| m.variant == variant && m.lights < lights)
            .map(|(_, m)| (m.lights, m.ms_per_frame))
            .max_by_key(|&(n, _)| n);
        results.push((row, measure(&ctx, a, &mut plan, (variant, lights), previous)?));
        bar.inc();
    }
    bar.finish();
    let device = device_json(&ctx);
    drop(ctx);
    let auto = json!({ "technique": auto_technique.name(), "why": auto_why, "probe": probe::times_json(&quick) });
    let skip = a.warmup as usize;
    let (w, h) = resolution;
    let mut report = json!({
        "device": device,
        "commit": env!("MANYLIGHTS_COMMIT"),
        "settings": {
            "scene": a.scene, "objects": a.objects, "resolution": [w, h], "frames": a.frames, "warmup": a.warmup,
            "budget_s": a.budget_s, "shading": a.shading, "techniques": a.techniques, "lights": a.lights,
            "raster": a.raster, "raster_split": a.raster_split, "aa": a.aa,
            "clusters": a.clusters,
        },
        "auto": auto,
        "rows": sweep.len(),
        "results": results.iter().map(|(row, m)| sheet::row_json(*row, m, skip)).collect::<Vec<_>>(),
    });
    if let Some((index, count)) = shard {
        report["shard"] = json!({ "index": index, "count": count });
    }
    sheet::write(&a.out, &report)?;
    check_messages(messages.load(Ordering::SeqCst))
}

/// `--merge`: the shards' sheets joined into the whole sweep's, in --out; nothing measured, so
/// no option of the measurement applies.
fn merge(a: &BenchArgs, folders: &str) -> Result<()> {
    // Every option of bench but these two is about measuring.
    let options = <BenchArgs as clap::Args>::augment_args(clap::Command::new("bench"));
    let measuring = options.get_arguments().map(|o| o.get_id().as_str()).filter(|id| !["merge", "out"].contains(id));
    if let Some(other) = measuring.into_iter().find(|id| a.given.has(id)) {
        bail!("--{} does not apply to bench --merge, which joins the shards' sheets and measures nothing", other.replace('_', "-"));
    }
    let folders: Vec<PathBuf> = folders.split(',').map(str::trim).filter(|f| !f.is_empty()).map(PathBuf::from).collect();
    let report = sheet::merge(&folders)?;
    prepare_folder(&a.out, &sheet::RESULTS)?;
    sheet::write(&a.out, &report)
}

/// Make folder `out` if missing and check that the files `names` in it can be written.
fn prepare_folder(out: &std::path::Path, names: &[&str]) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot make folder '{}'", out.display()))?;
    names.iter().try_for_each(|name| Ok(ml_cpu::files::check_writable(&out.join(name))?))
}

fn check_messages(count: u32) -> Result<()> {
    if count > 0 {
        bail!("the validation layer reported {count} message(s) (printed above)");
    }
    Ok(())
}

fn device_json(ctx: &Context) -> Value {
    json!({
        "name": ctx.info.name,
        "type": ctx.info.type_name(),
        "driver": format!("{} {}", ctx.info.driver_name, ctx.info.driver_info),
        "vulkan": ctx.info.api_version_string(),
    })
}

/// --probe-lights: ascending loop lengths, each at most 65,536 (a longer loop at 1080p is
/// hours on a CPU device and says nothing a shorter one does not).
fn probe_lengths(text: &str) -> Result<Vec<u32>> {
    let mut lengths: Vec<u32> = text
        .split(',')
        .map(|t| {
            let n = parse_count(t)?;
            u32::try_from(n)
                .ok()
                .filter(|&n| n <= probe::MAX_LIGHTS)
                .with_context(|| format!("--probe-lights '{}': at most {} lights per pixel", t.trim(), probe::MAX_LIGHTS))
        })
        .collect::<Result<_>>()?;
    lengths.sort_unstable();
    lengths.dedup();
    Ok(lengths)
}

/// The time per frame a technique took (or was estimated to take) at a smaller light count,
/// `(lights, ms)`. Scaled linearly to more lights it is what brute force will take, so a
/// hopeless brute-force combination is skipped without a frame of it; clustered techniques
/// grow slower than linearly, so for them it only decides whether one frame may be rendered,
/// which then estimates the rest.
type Previous = Option<(u64, f64)>;

/// How the status of a combination the device cannot run begins (the reason follows).
const NOT_MEASURED: &str = "not measured: ";

fn measure(ctx: &Context, a: &BenchArgs, plan: &mut Plan, (variant, lights): (Variant, u64), previous: Previous) -> Result<Measured> {
    let technique = variant.technique;
    let frames = a.rounds()?;
    let skip = |ms: f64, how: &str| {
        let estimate_s = ms * frames as f64 / 1e3;
        (estimate_s > a.budget_s).then(|| {
            format!("skipped: {frames} frames would take about {estimate_s:.0} s ({ms:.0} ms a frame, {how}; budget {} s)", a.budget_s)
        })
    };
    if let Some((n, ms)) = previous {
        let scaled = ms * lights as f64 / n as f64;
        let why = if technique.is_clustered() {
            (scaled / 1e3 > a.budget_s).then(|| {
                format!("skipped: one frame would take about {:.0} s (scaled from {n} lights; budget {} s)", scaled / 1e3, a.budget_s)
            })
        } else {
            skip(scaled, &format!("scaled from {n} lights"))
        };
        if let Some(why) = why {
            return Ok(Measured { variant, lights, skipped: Some(why), output: None, grid: None, ms_per_frame: scaled });
        }
    }
    let built = SceneRequest { lights: Some(lights), ..plan.scene.clone() }.build()?;
    if !std::mem::replace(&mut plan.warned, true) {
        print_warnings(&built.warnings);
    }
    let scene = built.scene;
    let base = plan.settings.settings;
    let chosen = RenderSettings { technique, raster: variant.raster, antialiasing: variant.antialiasing, ..base };
    let request = SettingsRequest { settings: chosen, ..plan.settings };
    let mut settings = request.for_scene(&scene, built.shading);
    // A sample count the device does not offer this technique is a row that says so, not the
    // end of the sweep.
    if variant.antialiasing != Antialiasing::Off {
        if let Err(e) = settings.check(ctx, scene.lights.len()) {
            return Ok(Measured {
                variant,
                lights,
                skipped: Some(format!("{NOT_MEASURED}{e}")),
                output: None,
                grid: None,
                ms_per_frame: 0.0,
            });
        }
    }
    let probe = Renderer::new(ctx, scene.clone(), settings).and_then(|mut r| r.render())?;
    if let Some(why) = skip(probe.stats.wall_ms, "one frame measured") {
        return Ok(Measured { variant, lights, skipped: Some(why), output: None, grid: None, ms_per_frame: probe.stats.wall_ms });
    }
    settings.frames = frames;
    let output = Renderer::new(ctx, scene, settings).and_then(|mut r| r.render())?;
    let grid = technique.has_cluster_grid().then_some(settings.clusters);
    let ms_per_frame = output.stats.wall_ms_per_frame();
    Ok(Measured { variant, lights, skipped: None, output: Some(output), grid, ms_per_frame })
}

/// What a probe run writes in its folder.
pub const PROBE_RESULTS: [&str; 2] = ["probe.csv", "probe.json"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_labels_are_short() {
        assert_eq!([10.0, 1000.0, 16000.0, 1e6].map(sheet::count_label), ["10", "1k", "16k", "1M"]);
    }

    #[test]
    fn counts_and_resolutions_parse() {
        for bad in ["0x10", "10x0", "16385x10", "-1x10", "x"] {
            assert!(parse_resolution(bad).is_err(), "{bad}");
        }
        assert_eq!(["64", "16k", "1M", "2m"].map(|t| parse_count(t).unwrap()), [64, 16_000, 1_000_000, 2_000_000]);
        for bad in ["", "0", "k", "1.5k", "-3"] {
            assert!(parse_count(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_resolution("64x48").unwrap(), (64, 48));
        assert!(parse_resolution("64").is_err());
    }
}
