//! `manylights bench`: every technique × light count on one scene, per-pass GPU
//! time (median, p95, mean over the frames after the warm-up), CPU time per frame and lights
//! per cluster, written to results.csv, results.json and results.png. A combination whose frames
//! would take longer than the budget is skipped and says so: brute force estimated from a smaller
//! count (linear), clustered techniques from one frame (see `Previous`).

use crate::applies::{check_rules, draws_meshlets, objects_rule, Auto, Given, Rule, Techniques, CLUSTER_GRID, VISIBILITY_BUFFER};
use crate::auto::{self, technique_choice};
use crate::{cluster_choice, print_warnings, scene_source, shading_choice, Progress, Whole};
use anyhow::{bail, Context as _, Result};
use clap::Args;
use ml_cpu::camera::CameraSpec;
use ml_cpu::cluster::ClusterDims;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene_request::SceneRequest;
use ml_render::report::Spread;
use ml_render::settings::SettingsRequest;
use ml_render::{Antialiasing, Geometry, Raster, RenderOutput, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::sync::atomic::Ordering;

mod probe;

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
            Rule::technique("raster", VISIBILITY_BUFFER, draws_meshlets),
            Rule::technique("raster_split", VISIBILITY_BUFFER, draws_meshlets),
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
    // Every argument checked before the device is; a CPU driver then gets sizes it can finish.
    asked(a)?;
    let ctx = Context::new(&ContextDesc { validation: a.validation, device_index: a.device, window: None })?;
    let note = fit_to_a_cpu(a, &ctx.info);
    let a = &*a;
    let Asked { choices, counts, resolution, rasters, sample_counts, rules, named, auto } = asked(a)?;
    let work = if a.probe { Work::Probe(probe_lengths(&a.probe_lights)?) } else { Work::Techniques(Box::new(Plan::new(a, resolution)?)) };
    std::fs::create_dir_all(&a.out).with_context(|| format!("cannot make folder '{}'", a.out.display()))?;
    // What the run writes, checked before it runs (a bad path must not cost a sweep).
    let outputs: &[&str] = if a.probe { &PROBE_RESULTS } else { &RESULTS };
    for name in outputs {
        ml_cpu::files::check_writable(&a.out.join(name))?;
    }
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
    let mut bar = Progress::new((variants.len() * counts.len()) as u64, "");
    let mut results: Vec<Measured> = Vec::new();
    for &lights in &counts {
        for &variant in &variants {
            bar.set_message(format!("{} at {lights} lights", variant.label()));
            // A variant the device cannot run at one count it cannot run at any (no scene of
            // the next count built for it).
            let refused = results.iter().find_map(|m| m.skipped.as_deref().filter(|s| m.variant == variant && s.starts_with(NOT_MEASURED)));
            if let Some(why) = refused {
                let skipped = Some(why.to_owned());
                results.push(Measured { variant, lights, skipped, output: None, grid: None, ms_per_frame: 0.0 });
                bar.inc();
                continue;
            }
            // The same variant at the largest smaller count, measured or estimated.
            let previous = results
                .iter()
                .filter(|m| m.variant == variant && m.lights < lights)
                .map(|m| (m.lights, m.ms_per_frame))
                .max_by_key(|&(n, _)| n);
            results.push(measure(&ctx, a, &mut plan, (variant, lights), previous)?);
            bar.inc();
        }
    }
    bar.finish();
    let device = device_json(&ctx);
    drop(ctx);
    let auto = json!({ "technique": auto_technique.name(), "why": auto_why, "probe": probe::times_json(&quick) });
    write_results(a, resolution, (&device, &auto), &results)?;
    check_messages(messages.load(Ordering::SeqCst))
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

fn spread_json(s: &Spread) -> Value {
    json!({ "median_ms": s.median, "p95_ms": s.p95, "mean_ms": s.mean })
}

fn write_results(a: &BenchArgs, (w, h): (u32, u32), (device, auto): (&Value, &Value), results: &[Measured]) -> Result<()> {
    let skip = a.warmup as usize;
    let mut csv = String::from(
        "technique,raster,aa,lights,width,height,frames,status,pass,gpu_median_ms,gpu_p95_ms,gpu_mean_ms,cpu_median_ms,cpu_p95_ms,cpu_assign_median_ms,cpu_upload_median_ms,cpu_record_median_ms,cpu_submit_median_ms,clusters,lights_per_cluster_mean,lights_per_cluster_max\n",
    );
    let mut rows = Vec::new();
    for m in results {
        let (technique, raster) = (m.variant.technique.name(), raster_name(m.variant));
        let aa = m.variant.antialiasing.name();
        let head = format!("{technique},{raster},{aa},{},{w},{h},{}", m.lights, a.frames);
        let Some(out) = &m.output else {
            let why = m.skipped.clone().unwrap_or_default();
            csv += &format!("{head},\"{why}\",,,,,,,,,,,,,\n");
            rows.push(json!({ "technique": technique, "raster": raster, "aa": aa, "lights": m.lights, "status": why }));
            continue;
        };
        let stats = &out.stats;
        let cpu = stats.cpu_spread(skip);
        let grid = m.grid.map_or(String::new(), |d| format!("{}x{}x{}", d.x, d.y, d.z));
        let clusters =
            stats.clusters.map_or((String::new(), String::new()), |c| (format!("{:.3}", c.mean_lights), c.max_lights.to_string()));
        let passes = stats.gpu_spread(skip).unwrap_or_default();
        // Total median and p95, then each phase's median.
        let cpu_cols = cpu.map_or(",,,,,".to_owned(), |(total, phases)| {
            let medians: Vec<String> = phases.iter().map(|(_, s)| format!("{:.4}", s.median)).collect();
            format!("{:.4},{:.4},{}", total.median, total.p95, medians.join(","))
        });
        if passes.is_empty() {
            csv += &format!("{head},measured (no GPU timestamps),,,,,{cpu_cols},{grid},{},{}\n", clusters.0, clusters.1);
        }
        for (pass, s) in &passes {
            csv += &format!(
                "{head},measured,{pass},{:.4},{:.4},{:.4},{cpu_cols},{grid},{},{}\n",
                s.median, s.p95, s.mean, clusters.0, clusters.1
            );
        }
        rows.push(json!({
            "technique": technique,
            "raster": raster,
            "aa": aa,
            "lights": m.lights,
            "status": "measured",
            "passes": passes.iter().map(|(n, s)| json!({ "pass": n, "gpu": spread_json(s) })).collect::<Vec<_>>(),
            "cpu": cpu.as_ref().map(|(total, phases)| {
                let mut j = json!({ "total": spread_json(total) });
                for (name, s) in phases {
                    j[*name] = spread_json(s);
                }
                j
            }),
            "clusters": m.grid.map(|d| [d.x, d.y, d.z]),
            "lights_per_cluster": stats.clusters.map(|c| json!({ "mean": c.mean_lights, "max": c.max_lights })),
        }));
    }
    let report = json!({
        "device": device,
        "commit": env!("MANYLIGHTS_COMMIT"),
        "settings": {
            "scene": a.scene, "objects": a.objects, "resolution": [w, h], "frames": a.frames, "warmup": a.warmup,
            "budget_s": a.budget_s, "shading": a.shading, "techniques": a.techniques, "lights": a.lights,
            "raster": a.raster, "raster_split": a.raster_split, "aa": a.aa,
            "clusters": a.clusters,
        },
        "auto": auto,
        "results": rows,
    });
    // Always a plot, empty (and saying why) where nothing was measured.
    let series = frame_times(results, skip);
    let (size, rgb) = plot(&series, (w, h)).map_err(|e| anyhow::anyhow!("cannot draw results.png: {e}"))?;
    let rgba: Vec<u8> = rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
    let [csv_path, json_path, png_path] = RESULTS.map(|name| a.out.join(name));
    let png = ml_cpu::files::png_bytes(&png_path, &rgba, size)?;
    let json = serde_json::to_string_pretty(&report).expect("plain JSON values");
    // The three replace an earlier run's together, or none does.
    ml_cpu::files::write_all_replacing(&[(csv_path, csv.as_bytes()), (json_path, json.as_bytes()), (png_path, &png)])?;
    print!("{csv}");
    Ok(())
}

/// What a bench run writes in its folder, and a probe run.
const RESULTS: [&str; 3] = ["results.csv", "results.json", "results.png"];
pub const PROBE_RESULTS: [&str; 2] = ["probe.csv", "probe.json"];

/// The raster column: the visibility technique's rasteriser, empty for the others.
fn raster_name(v: Variant) -> &'static str {
    if v.technique.geometry() == Geometry::Meshlets {
        v.raster.name()
    } else {
        ""
    }
}

/// Per variant, (lights, GPU ms per frame: the pass medians summed) of each measured count.
fn frame_times(results: &[Measured], skip: usize) -> Vec<(Variant, Vec<(f64, f64)>)> {
    let mut series: Vec<(Variant, Vec<(f64, f64)>)> = Vec::new();
    for m in results {
        let Some(passes) = m.output.as_ref().and_then(|o| o.stats.gpu_spread(skip)) else { continue };
        let ms: f64 = passes.iter().map(|(_, s)| s.median).sum();
        match series.iter_mut().find(|(v, _)| *v == m.variant) {
            Some((_, points)) => points.push((m.lights as f64, ms)),
            None => series.push((m.variant, vec![(m.lights as f64, ms)])),
        }
    }
    series
}

/// results.png: GPU ms per frame against lights, log-log, a line per technique (the text in
/// egui's embedded Ubuntu font: no system fonts needed).
/// The frame-time plot: its size and RGB8 pixels (written by the caller, which replaces the
/// previous plot only with a complete one).
type Plot = ((u32, u32), Vec<u8>);

fn plot(series: &[(Variant, Vec<(f64, f64)>)], (w, h): (u32, u32)) -> Result<Plot, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        // Fails only for a broken font file, which egui's is not; text would then be missing.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
    let points = series.iter().flat_map(|(_, p)| p.iter());
    let measured = points.clone().count() > 0;
    // Nothing measured: the axes of 1k–1M lights and 0.1–100 ms, empty.
    let (x0, x1) = if measured { points.clone().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.0), hi.max(p.0))) } else { (1e3, 1e6) };
    let (y0, y1) = if measured { points.fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.1), hi.max(p.1))) } else { (0.1, 100.0) };
    // Whole decades, so that the log axes have labels.
    let decades =
        |lo: f64, hi: f64| (10f64.powf(lo.log10().floor()), 10f64.powf(hi.log10().ceil()).max(10f64.powf(lo.log10().floor() + 1.0)));
    let ((x0, x1), (y0, y1)) = (decades(x0, x1), decades(y0, y1));
    const SIZE: (u32, u32) = (960, 600);
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            if measured {
                format!("GPU ms per frame at {w}x{h} (median)")
            } else {
                format!("GPU ms per frame at {w}x{h}: nothing measured (results.csv says why)")
            },
            ("sans-serif", 24),
        )
        .margin(16)
        // Room for the last decade's label, which is centred on the right edge.
        .margin_right(48)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("lights")
        .y_desc("GPU ms per frame")
        .x_label_formatter(&|v| count_label(*v))
        .y_label_formatter(&|v| format!("{v}"))
        .draw()?;
    for (variant, points) in series {
        // A variant keeps its colour in every plot, whichever others are in it.
        let index = Technique::ALL.iter().position(|t| *t == variant.technique).unwrap_or(0);
        let colour = Palette99::pick(if variant.raster == Raster::Hardware { index } else { Technique::ALL.len() + index }).to_rgba();
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(variant.label())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    drop(chart);
    drop(root);
    Ok((SIZE, rgb))
}

/// 1000 → 1k, 1000000 → 1M (axis labels).
fn count_label(v: f64) -> String {
    match v {
        v if v >= 1e6 => format!("{}M", v / 1e6),
        v if v >= 1e3 => format!("{}k", v / 1e3),
        v => format!("{v:.0}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_labels_are_short() {
        assert_eq!([10.0, 1000.0, 16000.0, 1e6].map(count_label), ["10", "1k", "16k", "1M"]);
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
