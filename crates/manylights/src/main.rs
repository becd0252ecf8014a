//! `manylights`: the command line. Parses arguments and calls the library; every failure
//! ends as one `error: …` line on stderr and a non-zero exit.

use anyhow::{anyhow, bail, Context as _, Result};
use clap::{Args, Parser, Subcommand};
use ml_cpu::camera::CameraSpec;
use ml_cpu::cluster::ClusterDims;
use ml_cpu::lights::{LightLayout, RadiusRange};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene_request::{SceneRequest, SceneSource, SceneWarning};
use ml_render::report;
use ml_render::settings::{AtlasSettings, SettingsRequest, MAX_SHADOWED_LIGHTS};
use ml_render::{DebugView, Exposure, OmniShadowMode, OmniShadowSettings, Raster, Renderer, ShadingModel, SunShadowMode, Technique};
use ml_vk::{Context, ContextDesc};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::Ordering;

mod auto;
mod bench;
mod messages;
mod output;

#[derive(Parser)]
#[command(name = "manylights", version, about = "A Vulkan renderer for scenes lit by many lights")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene headless (no window system) to a PNG and print a timing table.
    Render(Box<RenderArgs>),
    /// Open a window on a scene: first-person camera (WASD/QE, right-drag, wheel), an overlay
    /// of settings and GPU times, F frame the scene, P pause, F12 screenshot, Esc quit.
    View(Box<ViewArgs>),
    /// Measure techniques × light counts: per-pass GPU time (median, p95), CPU time, lights
    /// per cluster; writes results.csv and results.json.
    Bench(Box<bench::BenchArgs>),
    /// List Vulkan devices, drivers, versions and the limits manylights depends on.
    Info,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames to render (1 to 100000); timings are averaged over them, the image is the last
    /// one — or, with a # in --out, every frame's.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Output PNG file; a name with a run of # (frames/####.png) is an image sequence: every
    /// frame, the #s replaced by its number from 0, zero-padded to their count, in a folder
    /// made if it does not exist.
    #[arg(long)]
    out: PathBuf,
}

/// The most frames `render` takes: at 60 frames a second, half an hour of animation.
const MAX_FRAMES: u32 = 100_000;

#[derive(Args)]
struct ViewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Present without waiting for the display (mailbox, else immediate, where the window
    /// system has them).
    #[arg(long)]
    no_vsync: bool,
    /// Run a scripted session (README: "Viewer"): frames, technique and light changes,
    /// resizes, screenshots, quit.
    #[arg(long)]
    script: Option<PathBuf>,
}

/// What `render` and `view` share: the scene, technique and their settings.
#[derive(Args)]
struct SceneArgs {
    /// Scene to render: seed (built in), room (a closed room with a pillar and one point light,
    /// for point-light shadows), bench (a floor, --objects objects, --lights N (default 1024)
    /// lights whose radius shrinks as N^(−1/3): the benchmark's), a scene file FILE.toml
    /// (docs/scenes.md) or a glTF 2.0 file FILE.gltf|FILE.glb (rendered with pbr unless
    /// --shading says otherwise).
    #[arg(long, default_value = "seed")]
    scene: String,
    /// Objects of the bench scene (default 300): more objects on the same floor, denser; the
    /// first 300 are always the same.
    #[arg(long)]
    objects: Option<usize>,
    /// Lighting technique: forward, clustered-cpu, clustered-gpu, deferred, deferred-clustered,
    /// deferred-compute, visibility (meshlets culled on the GPU into a visibility buffer, lit
    /// in compute), or auto (the default): visibility (deferred-compute on a device without its
    /// features) where this device runs the probe's light loop (`bench --probe`) over 1.25×
    /// faster as a compute shader than as a fragment shader, else deferred-clustered. Every
    /// technique gives forward's image.
    #[arg(long, default_value = "auto")]
    technique: String,
    /// Shading model: seed (specular-only Cook–Torrance: GGX, Schlick–Smith, Schlick Fresnel),
    /// blinn-phong (Lambert + normalised Blinn-Phong with a shadowed sun, a spot light,
    /// textures, normal maps and sky reflections) or pbr (the seed model's specular + Lambert
    /// diffuse, ACES tone map). Default: the scene file's [shading] model, else seed.
    #[arg(long)]
    shading: Option<String>,
    /// Cluster grid XxYxZ of the clustered techniques (the seed's was 4x4x2), or auto:
    /// 16x9x24 scaled by 1, 2 or 4 on every axis as ∛(lights / 4096) rounds (32x18x48 from
    /// ~11.6k lights, 64x36x96 from ~93k), so that lights per cluster stay few as lights shrink.
    #[arg(long, default_value = "auto")]
    clusters: String,
    /// Debug view: none, cluster-heat (lights per cluster; clustered-cpu, clustered-gpu),
    /// gbuffer-albedo, gbuffer-normal, gbuffer-material, depth, shadow-map (blinn-phong),
    /// shadow-cube (the first shadowed point light's cube, unfolded; needs --omni-shadow),
    /// shadow-atlas (needs --omni-shadow atlas), meshlets, triangles (a colour per meshlet or
    /// triangle; visibility), alpha (opaque grey, alpha-masked green, blended orange).
    #[arg(long, default_value = "none")]
    debug_view: String,
    /// Object kind of the seed scene: sphere, teapot, torusknot, plane, disc, cube, room.
    #[arg(long, default_value = "sphere")]
    object: String,
    /// Material: gold, copper, chromium, nickel, titanium, cobalt, platinum, white, red, blue, black.
    #[arg(long, default_value = "gold")]
    material: String,
    /// Number of point lights (default 64; with a scene file: replaces the file's lights with
    /// N lights of --light-layout; a file without lights gets 64).
    #[arg(long)]
    lights: Option<u64>,
    /// Light placement: grid (a square grid above the scene; in a scene or glTF file, once the
    /// count calls for it, layers of such grids down through the scene's box), random (uniform
    /// in the scene's box) or surface (just above random points of the scene's surfaces,
    /// area-weighted). The built-in scenes place them in their fixed frame (the grid over
    /// x,z ∈ [−15,15] at y = 7.5, the box x,z ∈ [−20,20], y ∈ [−2,12]); scene and glTF files in
    /// one fitted to their box, where every layout's default radius brings a few lights to
    /// each point at any count.
    #[arg(long, default_value = "grid")]
    light_layout: String,
    /// Seed of the random and surface layouts (and of random radii).
    #[arg(long, default_value_t = 1)]
    light_seed: u64,
    /// Light radius R, or MIN..MAX for radii drawn per light. Default: 15 in the seed scene;
    /// in a scene or glTF file the radius at which about 4 lights reach a point of the scene,
    /// from its box and the light count.
    #[arg(long)]
    light_radius: Option<String>,
    /// Point-light shadows: off; through cube maps, rendered by copy (each face offscreen,
    /// then copied into its cube layer), direct (each face into its cube layer), multiview
    /// (all six faces in one pass), layered (one pass, each face an instance writing its
    /// layer) or compute (every face of every cube drawn by compute shaders, meshlets culled
    /// per face); or atlas (one shadow atlas of --shadow-budget MiB: only the faces a visible
    /// pixel may sample, each light's as large as the light is on screen, drawn in compute,
    /// kept while their light stays).
    #[arg(long, default_value = "off")]
    omni_shadow: String,
    /// Who draws the sun's shadow map (blinn-phong), once at start: graphics (a depth-only
    /// render pass) or compute (the compute shadow raster of --omni-shadow compute, in one
    /// orthographic view).
    #[arg(long, default_value = "graphics")]
    sun_shadow: String,
    /// How many point lights cast shadows: K (the strongest as seen from the camera) or all
    /// (every light that reaches the view, the strongest 4096 at most).
    #[arg(long, default_value = "1")]
    shadowed_lights: String,
    /// Texels per side of each shadow-cube face (default 1024); with --omni-shadow atlas,
    /// every face this size (a power of two, 32 to 2048) instead of the light's size on screen.
    #[arg(long)]
    cube_size: Option<u32>,
    /// MiB that point-light shadows may take with --omni-shadow atlas: the atlas, its tables
    /// and the raster's lists. When the faces do not fit, every face shrinks by one factor
    /// (the table reports it).
    #[arg(long)]
    shadow_budget: Option<u32>,
    /// Whether atlas faces whose light did not move keep last frame's texels (on) or are
    /// drawn again every frame (off; the same images, for comparisons).
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    shadow_cache: String,
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// The camera: eye position, the point it looks at and its vertical field of view in
    /// degrees (default 60), as EYE_X,EYE_Y,EYE_Z:TARGET_X,TARGET_Y,TARGET_Z[:FOV]; its near
    /// and far planes fit the scene. Default: the scene's own camera. The viewer's C key
    /// prints its camera in this form.
    #[arg(long, allow_hyphen_values = true)]
    camera: Option<String>,
    /// Draw every point light as a small cube glowing in its colour, sized by its radius and
    /// depth-tested like any object, at the light's rest place (at most 65536 lights; not
    /// with --omni-shadow, whose cubes would see the markers round their own lights).
    #[arg(long)]
    show_lights: bool,
    /// Exposure: stops (EV, -20 to 20; lit colour × 2^EV before the tone map and gamma), or
    /// auto (the image's log-average luminance brought to middle grey, metered on the GPU).
    /// Default: auto for scene files and glTF files, 0 for the built-in scenes.
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<String>,
    /// Fix the animation clock at T (otherwise it advances 1/60 s per frame from 0; in the
    /// viewer, with real time).
    #[arg(long)]
    time: Option<f32>,
    /// GPU culling of the visibility technique: on, or off (every meshlet drawn; the image
    /// must not change).
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    culling: String,
    /// Who draws the visibility technique's visibility buffer: hardware (the graphics
    /// pipeline), compute (compute shaders only: triangles up to --raster-split pixels a
    /// thread each, larger ones clipped and drawn by a work group per 64x64-pixel bin),
    /// hybrid (the small ones in compute, the others by the hardware into the same buffer) or
    /// auto (each timed on this device and scene for a few frames, the fastest kept, and said
    /// why).
    #[arg(long, default_value = "auto", value_parser = ["hardware", "hybrid", "compute", "auto"])]
    raster: String,
    /// The compute raster's largest triangle: bounding box up to PX pixels a side (1 to 64).
    #[arg(long, default_value_t = Raster::DEFAULT_SPLIT)]
    raster_split: u32,
    /// Enable the Khronos validation layer with synchronization validation; any message
    /// makes the run fail.
    #[arg(long)]
    validation: bool,
    /// Vulkan device index (see `manylights info`); default: the best one (discrete first).
    #[arg(long)]
    device: Option<usize>,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help, --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("invalid arguments").trim_start_matches("error: ");
            eprintln!("error: {first} (see `manylights --help`)");
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Render(args) => render(&args),
        Command::View(args) => view(&args),
        Command::Bench(args) => bench::bench(&args),
        Command::Info => info(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", messages::describe(&e).replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}

/// What `--scene` names: the seed scene (of `object` in `material`), room, bench (of `objects`
/// objects, which no other scene takes), or a file.
fn scene_source(name: &str, object: MeshKind, material: Material, objects: Option<usize>) -> Result<SceneSource> {
    if objects.is_some() && name != "bench" {
        bail!("--objects sets the bench scene's object count: use it with --scene bench");
    }
    Ok(match name {
        "seed" => SceneSource::Seed { object, material },
        "room" => SceneSource::Room,
        "bench" => SceneSource::Bench { objects: objects.unwrap_or(ml_cpu::bench_scene::BENCH_OBJECTS) },
        path if is_scene_file(path) => SceneSource::File(PathBuf::from(path)),
        other => bail!("unknown scene '{other}': expected seed, room, a scene file FILE.toml or a glTF file FILE.gltf|FILE.glb"),
    })
}

/// `--shading`: a model, or None for the scene's own.
fn shading_choice(name: Option<&str>) -> Result<Option<ShadingModel>> {
    Ok(name.map(ShadingModel::from_name).transpose()?)
}

/// `--clusters`: a grid, or None for `auto`.
fn cluster_choice(text: &str) -> Result<Option<ClusterDims>> {
    Ok(match text {
        "auto" => None,
        grid => Some(ClusterDims::parse(grid)?),
    })
}

/// The scene the arguments ask for.
fn scene_request(args: &SceneArgs) -> Result<SceneRequest> {
    let source = scene_source(&args.scene, MeshKind::from_name(&args.object)?, Material::named(&args.material)?, args.objects)?;
    Ok(SceneRequest {
        source,
        lights: args.lights,
        layout: LightLayout::from_name(&args.light_layout)?,
        seed: args.light_seed,
        radius: args.light_radius.as_deref().map(RadiusRange::parse).transpose()?,
        shading: shading_choice(args.shading.as_deref())?,
        camera: args.camera.as_deref().map(CameraSpec::parse).transpose().context("--camera")?,
        show_lights: args.show_lights,
        aspect: args.width.max(1) as f32 / args.height.max(1) as f32,
    })
}

/// The settings the arguments ask for, with `technique` (`--technique` itself may say auto).
fn settings_request(args: &SceneArgs, technique: Technique, frames: u32) -> Result<SettingsRequest> {
    if args.show_lights && args.omni_shadow != "off" {
        bail!("--show-lights and --omni-shadow do not go together: each light's shadow cube would see the marker around it");
    }
    let omni = match args.omni_shadow.as_str() {
        "off" if args.shadowed_lights != "1" || args.cube_size.is_some() || args.shadow_budget.is_some() || args.shadow_cache != "on" => {
            bail!(
                "--shadowed-lights, --cube-size, --shadow-budget and --shadow-cache need point-light shadows: add --omni-shadow layered|direct|multiview|copy|compute|atlas"
            )
        }
        "off" => None,
        mode => {
            let mode = match OmniShadowMode::from_name(mode)? {
                OmniShadowMode::Atlas(_) => OmniShadowMode::Atlas(AtlasSettings {
                    budget_mib: args.shadow_budget.unwrap_or(AtlasSettings::DEFAULT.budget_mib),
                    cache: args.shadow_cache == "on",
                    fixed_size: args.cube_size,
                }),
                _ if args.shadow_budget.is_some() || args.shadow_cache != "on" => {
                    bail!("--shadow-budget and --shadow-cache are the shadow atlas's: add --omni-shadow atlas")
                }
                cubes => cubes,
            };
            let (lights, all) = match args.shadowed_lights.trim() {
                "all" => (MAX_SHADOWED_LIGHTS, true),
                k => (k.parse::<u32>().map_err(|_| anyhow!("--shadowed-lights '{k}' is neither a count nor all"))?, false),
            };
            Some(OmniShadowSettings { mode, lights, all, size: args.cube_size.unwrap_or(OmniShadowSettings::DEFAULT_SIZE) })
        }
    };
    Ok(SettingsRequest {
        technique,
        clusters: cluster_choice(&args.clusters)?,
        debug_view: DebugView::from_name(&args.debug_view)?,
        omni,
        sun_shadow: SunShadowMode::from_name(&args.sun_shadow)?,
        width: args.width,
        height: args.height,
        frames,
        time: args.time,
        culling: args.culling == "on",
        exposure: exposure_choice(args)?,
        // Set once the technique (and for auto, the probe) is known: `auto::resolve_raster`.
        raster: Raster::Hardware,
    })
}

/// `--exposure` as given; else auto for a scene or glTF file (whatever its units and lights)
/// and EV 0 for the built-in scenes (whose images stay as they were).
fn exposure_choice(args: &SceneArgs) -> Result<Exposure> {
    match &args.exposure {
        Some(text) => Ok(ml_render::settings::parse_exposure(text).context("--exposure")?),
        None if is_scene_file(&args.scene) => Ok(Exposure::Auto),
        None => Ok(Exposure::Ev(0.0)),
    }
}

/// Whether `--scene` names a file (scene file or glTF) rather than a built-in scene.
fn is_scene_file(name: &str) -> bool {
    [".toml", ".gltf", ".glb"].iter().any(|ext| name.to_lowercase().ends_with(ext))
}

/// `--raster` with `--raster-split`: a rasteriser, or None for auto.
fn raster_choice(args: &SceneArgs) -> Result<Option<Raster>> {
    match args.raster.as_str() {
        "auto" => Ok(None),
        name => Ok(Some(Raster::from_name(name, args.raster_split)?)),
    }
}

/// A built scene's warnings, one line each.
fn print_warnings(warnings: &[SceneWarning]) {
    for w in warnings {
        match w {
            SceneWarning::DefaultRig { .. } => eprintln!("warning: {w} (--lights N, --light-layout and --light-radius choose others)"),
            _ => eprintln!("warning: {w}"),
        }
    }
}

/// A progress bar on stderr that shows itself once the work has taken PROGRESS_AFTER, and
/// never where stderr is not a terminal (indicatif's own rule): short runs and logs stay quiet.
pub(crate) struct Progress {
    bar: indicatif::ProgressBar,
    start: std::time::Instant,
    shown: bool,
}

/// How long work runs before its progress bar appears.
const PROGRESS_AFTER: std::time::Duration = std::time::Duration::from_secs(2);

impl Progress {
    pub(crate) fn new(len: u64, what: &str) -> Progress {
        let bar = indicatif::ProgressBar::with_draw_target(Some(len), indicatif::ProgressDrawTarget::hidden());
        bar.set_style(indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} ({eta} left)").expect("a valid template"));
        bar.set_message(what.to_owned());
        Progress { bar, start: std::time::Instant::now(), shown: false }
    }

    pub(crate) fn set_message(&self, message: String) {
        self.bar.set_message(message);
    }

    /// One more step done.
    pub(crate) fn inc(&mut self) {
        if !self.shown && self.start.elapsed() >= PROGRESS_AFTER {
            self.shown = true;
            self.bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        self.bar.inc(1);
    }

    pub(crate) fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// What `render` does with each frame: counts it on the progress bar and, for an image
/// sequence, writes its PNG.
struct RenderSink {
    progress: Progress,
    sequence: Option<output::SequencePattern>,
    size: (u32, u32),
}

impl ml_render::FrameSink for RenderSink {
    fn submitted(&mut self, _i: u32) {
        self.progress.inc();
    }

    fn wants_images(&self) -> bool {
        self.sequence.is_some()
    }

    fn image(&mut self, i: u32, rgba: &[u8]) -> Result<(), ml_render::RenderError> {
        let Some(pattern) = &self.sequence else { return Ok(()) };
        output::save_png(&output::sequence_path(pattern, i), rgba, self.size).map_err(|e| ml_render::RenderError::Invalid(e.to_string()))
    }
}

fn render(cmd: &RenderArgs) -> Result<()> {
    let args = &cmd.scene;
    let choice = auto::technique_choice(&args.technique)?;
    let request = scene_request(args)?;
    // Every setting is checked before the GPU work; auto's technique is set once it is known.
    let wanted = settings_request(args, choice.unwrap_or(Technique::DeferredClustered), cmd.frames)?;
    if cmd.frames > MAX_FRAMES {
        bail!("--frames {} is out of range: use 1 to {MAX_FRAMES}", cmd.frames);
    }
    let sequence = output::sequence_pattern(&cmd.out)?;
    let built = request.build()?;
    print_warnings(&built.warnings);
    output::prepare(&cmd.out, sequence.as_ref())?;
    let mut settings = wanted.for_scene(&built.scene, built.shading);
    let ctx = Context::new(&ContextDesc { validation: args.validation, device_index: args.device, window: None })?;
    let messages = ctx.validation_counter();
    let auto_why = match choice {
        Some(_) => None,
        None => {
            let (t, why, _) = auto::pick(&ctx)?;
            settings.technique = t;
            Some(why)
        }
    };
    let raster_why;
    (settings.raster, raster_why) = auto::resolve_raster(&ctx, &built.scene, &settings, (raster_choice(args)?, args.raster_split))?;
    let (lights, object_textures) = (built.scene.lights.len(), !built.scene.textures.is_empty());
    let mut sink =
        RenderSink { progress: Progress::new(settings.frames as u64, "frames"), sequence, size: (settings.width, settings.height) };
    let result = Renderer::new(&ctx, built.scene, settings).and_then(|mut r| r.render_into(&mut sink));
    sink.progress.finish();
    let device = report::device_line(&ctx.info);
    drop(ctx);
    let output = result?;
    if sink.sequence.is_none() {
        output::save_png(&cmd.out, &output.rgba, (output.width, output.height))?;
    }
    let facts = report::RenderFacts {
        device: &device,
        settings: &settings,
        lights,
        object_textures,
        auto: auto_why.as_deref(),
        raster_auto: raster_why.as_deref(),
        output: &cmd.out,
    };
    print!("{}", report::table(&report::render_rows(&facts, &output.stats)));
    let count = messages.load(Ordering::SeqCst);
    if count > 0 {
        bail!("the validation layer reported {count} message(s) (printed above)");
    }
    Ok(())
}

fn view(cmd: &ViewArgs) -> Result<()> {
    let args = &cmd.scene;
    let script = match &cmd.script {
        Some(path) => {
            let text = std::fs::read_to_string(path).with_context(|| format!("cannot read script '{}'", path.display()))?;
            Some(ml_viewer::script::parse(&text).map_err(|e| anyhow::anyhow!("script '{}': {e}", path.display()))?)
        }
        None => None,
    };
    // Checked once up front, so that a bad argument fails before a window opens.
    auto::technique_choice(&args.technique)?;
    let request = scene_request(args)?;
    let wanted = settings_request(args, Technique::Forward, 1)?;
    let built = request.build()?;
    print_warnings(&built.warnings);
    let technique = auto::resolve_alone(&args.technique, args.validation, args.device)?;
    let mut first = SettingsRequest { technique, ..wanted }.for_scene(&built.scene, built.shading);
    first.raster =
        auto::resolve_raster_alone(&built.scene, &first, (raster_choice(args)?, args.raster_split), (args.validation, args.device))?;
    let options = ml_viewer::ViewerOptions {
        choices: ml_viewer::Choices::new(&request, &built, &first),
        scene: request,
        width: args.width,
        height: args.height,
        vsync: !cmd.no_vsync,
        validation: args.validation,
        device: args.device,
        time: args.time,
        script,
    };
    ml_viewer::run(options)
}

fn info() -> Result<()> {
    let devices = ml_vk::context::list_devices()?;
    for d in devices {
        println!("{}", report::table(&report::device_rows(&d)));
    }
    Ok(())
}
