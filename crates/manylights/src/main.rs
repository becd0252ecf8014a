//! `manylights`: the command line. Parses arguments and calls the library; every failure
//! ends as one `error: …` line on stderr and a non-zero exit (2 for arguments clap refuses).

// The argument structs' doc comments are the --help text, written for a terminal: their
// brackets ([shading], [:FOV]) are literal, not links.
#![allow(rustdoc::broken_intra_doc_links)]

use anyhow::{anyhow, bail, Context as _, Result};
use clap::error::ErrorKind;
use clap::{Args, CommandFactory as _, FromArgMatches as _, Parser, Subcommand};
use ml_cpu::camera::CameraSpec;
use ml_cpu::cluster::ClusterDims;
use ml_cpu::environment::{parse_intensity, parse_rotation_deg, Environment, EnvironmentAsk, EnvironmentSource};
use ml_cpu::lights::{LightColors, LightLayout, RadiusRange};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene_request::{BuiltScene, SceneRequest, SceneSource, SceneWarning};
use ml_cpu::scene_section::Sections;
use ml_render::settings::{AtlasSettings, SettingsRequest, MAX_SHADOWED_LIGHTS};
use ml_render::{
    Antialiasing, DebugView, Exposure, LightGridMarks, OmniShadowMode, OmniShadowSettings, Raster, RenderSettings, Renderer, ShadingModel,
    SunShadowMode, Technique,
};
use ml_vk::{Context, ContextDesc};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::Ordering;

mod applies;
mod auto;
mod bench;
use applies::{check_options_apply, Auto, Given, Techniques};
mod messages;
mod output;
mod tables;

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
    /// one's — or, with a # in --out, every frame's.
    #[arg(long, default_value_t = 1, value_parser = Whole::<u32>::new(1, MAX_FRAMES as u64), allow_negative_numbers = true)]
    frames: u32,
    /// Frames rendered first and thrown away (untimed, unsaved; 0 to 100000), so that the
    /// timing table shows the GPU's steady state: a GPU lowers its clocks while the scene
    /// loads and takes a moment under load to raise them again.
    #[arg(long, default_value_t = 0, value_parser = Whole::<u32>::new(0, MAX_FRAMES as u64), allow_negative_numbers = true)]
    warmup: u32,
    /// Output PNG file; a name with a run of # (frames/####.png) is an image sequence: every
    /// frame, the #s replaced by its number from 0, zero-padded to their count, in a folder
    /// made if it does not exist.
    #[arg(long)]
    out: PathBuf,
    /// Of an image sequence, shard I of N (I from 0): the frames from ⌊F·I/N⌋ up to
    /// ⌊F·(I+1)/N⌋ of the F --frames, each the image the whole sequence gives it; or env: a
    /// Slurm array task's (SLURM_ARRAY_TASK_ID less SLURM_ARRAY_TASK_MIN, of
    /// SLURM_ARRAY_TASK_COUNT).
    #[arg(long)]
    shard: Option<String>,
    /// Of an image sequence, write only the frames whose files do not exist yet (a file
    /// that exists is whole: outputs are replaced only once complete): a rerun of a sequence or
    /// a shard that was stopped.
    #[arg(long)]
    resume: bool,
    /// Count, after the lighting, the lights the light loop tests per pixel and those that
    /// reach the pixel's surface (a table row; an untimed extra pass each frame), and with
    /// shadow rays the rays the lighting traces (the shadow-ray row; the lighting then counts
    /// them, at a small cost). For the compute-lit techniques: deferred-compute, visibility.
    #[arg(long)]
    light_stats: bool,
    /// Render K times wider and taller and filter each KxK block down to a pixel in the
    /// display's linear light (1 to 16; 1: off): the reference anti-aliasing is measured
    /// against, and offline stills. The table's times are the large image's.
    #[arg(long, default_value_t = 1, value_parser = Whole::<u32>::new(1, MAX_SUPERSAMPLE as u64), allow_negative_numbers = true)]
    supersample: u32,
}

/// `--supersample`'s largest factor (8 gives 64 samples a pixel, as many as a reference needs).
const MAX_SUPERSAMPLE: u32 = 16;

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
    /// Run a scripted session (its commands: docs/usage.md, "`view`: the window"): frames,
    /// technique and light changes, resizes, screenshots, quit.
    #[arg(long)]
    script: Option<PathBuf>,
}

/// What `render` and `view` share: the scene, technique and their settings. Each option's
/// help ends with its default: clap's `[default: X]` where it is one value, a sentence
/// "Default: …" where the scene decides it.
#[derive(Args)]
struct SceneArgs {
    /// Scene: seed (built in: a grid of --object in --material), room (a closed room with a
    /// pillar and one point light, for point-light shadows), bench (a floor, --objects
    /// objects and lights whose radius shrinks as their count grows: the benchmark's), a
    /// scene file FILE.toml (docs/scenes.md) or a glTF 2.0 file FILE.gltf|FILE.glb (rendered
    /// with pbr unless --shading says otherwise).
    #[arg(long, default_value = "seed")]
    scene: String,
    /// Objects of the bench scene (0 to 100000): more objects on the same floor, denser; the
    /// first 300 are always the same.
    #[arg(long, default_value_t = ml_cpu::bench_scene::BENCH_OBJECTS, value_parser = OBJECTS, allow_negative_numbers = true)]
    objects: usize,
    /// Percent of the scene's objects made transparent (alphaMode BLEND, alpha one half),
    /// spread evenly through it (0 to 100).
    #[arg(long, default_value_t = 0, value_parser = PERCENT, allow_negative_numbers = true)]
    transparent_objects: u32,
    /// Panes of faint glass added across the whole view in front of the scene, a transparent
    /// layer on every pixel each (0 to 256): a stress test of transparency.
    #[arg(long, default_value_t = 0, value_parser = GLASS_LAYERS, allow_negative_numbers = true)]
    glass_layers: u32,
    /// Lighting technique: forward, clustered-cpu, clustered-gpu, deferred, deferred-clustered,
    /// deferred-compute, visibility (meshlets culled on the GPU into a visibility buffer, lit
    /// in compute), or auto: visibility (deferred-compute on a device without its features)
    /// where this device runs the probe's light loop (`bench --probe`) over 1.25× faster as a
    /// compute shader than as a fragment shader, else deferred-clustered. Every technique
    /// gives forward's image.
    #[arg(long, default_value = "auto")]
    technique: String,
    /// Shading model: seed (specular-only Cook–Torrance: GGX, Schlick–Smith, Schlick Fresnel),
    /// blinn-phong (Lambert + normalised Blinn-Phong with a shadowed sun, a spot light,
    /// textures, normal maps and sky reflections) or pbr (the seed model's specular + Lambert
    /// diffuse, ACES tone map). Default: the scene file's [shading] model, else seed.
    #[arg(long)]
    shading: Option<String>,
    /// Cluster grid XxYxZ of the techniques that assign lights on the CPU (clustered-cpu,
    /// deferred-clustered; the GPU techniques' light grid fits itself to the lights), or
    /// auto: 16x9x24 scaled by 1, 2 or 4 on every axis as ∛(lights / 4096) rounds (32x18x48
    /// from ~11.6k lights, 64x36x96 from ~93k), so that lights per cluster stay few as lights
    /// shrink.
    #[arg(long, default_value = "auto")]
    clusters: String,
    /// Debug view: none, cluster-heat (lights each fragment tests: its cluster's in
    /// clustered-cpu, the light grid's near it in clustered-gpu),
    /// gbuffer-albedo, gbuffer-normal, gbuffer-material, depth, shadow-map (the sun's;
    /// blinn-phong), shadow-cube (the first shadowed point light's cube, unfolded; a cube mode
    /// of --omni-shadow), shadow-atlas (--omni-shadow atlas), meshlets, triangles (a colour per
    /// meshlet or triangle; visibility), alpha (opaque grey, alpha-masked green, blended
    /// orange), transparency-layers (transparent layers per pixel, white where some were
    /// merged; scenes with transparent objects), ray-cost (the traversal steps of each point's
    /// shadow rays, log scale; --omni-shadow rays), aa (surfaces shaded per pixel: blue one,
    /// cyan two, green three, yellow four, red more; visibility).
    #[arg(long, default_value = "none")]
    debug_view: String,
    /// Object of the seed scene: sphere, teapot, torusknot, plane, disc, cube, room.
    #[arg(long, default_value = "sphere")]
    object: String,
    /// Material of the seed scene's objects: gold, copper, chromium, nickel, titanium, cobalt,
    /// platinum, white, red, blue, black.
    #[arg(long, default_value = "gold")]
    material: String,
    /// Point lights (1 to 67108864, where the device binds their buffer); in a scene file, N lights of --light-layout replace the
    /// file's own. Default: 64 in the seed scene, 1024 in the bench scene, a scene file's own
    /// lights (64 where it has none); the room keeps its one light.
    #[arg(long, value_parser = Whole::<u64>::new(1, ml_cpu::limits::MAX_LIGHTS), allow_negative_numbers = true)]
    lights: Option<u64>,
    /// Light placement: grid (a square grid above the scene; in a scene or glTF file, once the
    /// count calls for it, layers of such grids down through the scene's box), random (uniform
    /// in the scene's box) or surface (just above random points of the scene's surfaces,
    /// area-weighted). The seed scene places them in its fixed frame (the grid over
    /// x,z ∈ [−15,15] at y = 7.5, the box x,z ∈ [−20,20], y ∈ [−2,12]); scene and glTF files in
    /// one fitted to their box, where every layout's fitted radius brings a few lights to each
    /// point at any count. The bench scene's lights are always random.
    #[arg(long, default_value = "grid")]
    light_layout: String,
    /// Seed of the random and surface layouts, of radii drawn from a --light-radius range and
    /// of the bench scene's lights.
    #[arg(long, default_value_t = 1, value_parser = Whole::<u64>::new(0, u64::MAX), allow_negative_numbers = true)]
    light_seed: u64,
    /// Colours of the lights placed by layout: palette (the seed's red, green, blue and yellow)
    /// or white (near-white: warm, neutral and cool, which show a model's materials). Default:
    /// palette in the seed scene, white in a scene or glTF file.
    #[arg(long)]
    light_colors: Option<String>,
    /// Environment light (the pbr model): an equirectangular Radiance .hdr or OpenEXR file,
    /// sky (the built-in sky) or none (the constant ambient term). Default: a scene file's
    /// own; the sky for a scene or glTF file without lights of its own; else none.
    #[arg(long)]
    environment: Option<String>,
    /// Multiplier of the environment's radiance. Default: 1, or a scene file's own.
    #[arg(long, allow_negative_numbers = true)]
    environment_intensity: Option<String>,
    /// Turn of the environment about the up axis, in degrees. Default: 0, or a scene file's
    /// own.
    #[arg(long, allow_negative_numbers = true)]
    environment_rotation: Option<String>,
    /// What pixels no surface covers show: colour (a dark grey) or environment (the
    /// environment light's image, exposed and tone-mapped as the surfaces are; debug views
    /// keep the colour). Default: a scene file's own ([environment] background), else colour.
    #[arg(long, value_parser = ["colour", "environment"])]
    background: Option<String>,
    /// A glTF file's material variant (KHR_materials_variants) to draw, by name. Default: the
    /// materials its primitives name.
    #[arg(long)]
    variant: Option<String>,
    /// Light radius R, or MIN..MAX for radii drawn per light. Default: 15 in the seed scene up to
    /// its 64 lights (beyond, one that follows the count); in a scene or glTF file the radius at
    /// which about 4 lights reach a point of the scene, from its box and the light count.
    #[arg(long)]
    light_radius: Option<String>,
    /// Point-light shadows: off; through cube maps, rendered by copy (each face offscreen,
    /// then copied into its cube layer), direct (each face into its cube layer), multiview
    /// (all six faces in one pass), layered (one pass, each face an instance writing its
    /// layer) or compute (every face of every cube drawn by compute shaders, meshlets culled
    /// per face); or atlas (one shadow atlas of --shadow-budget MiB: only the faces a visible
    /// pixel may sample, each light's as large as the light is on screen, drawn in compute,
    /// kept while their light stays); or rays (no maps: a shadow ray from each point to each
    /// shadowed light that lights it, through a hierarchy of the scene's triangles, exact and
    /// hard).
    #[arg(long, default_value = "off")]
    omni_shadow: String,
    /// Who draws the sun's shadow map (blinn-phong), once at start: graphics (a depth-only
    /// render pass) or compute (the compute shadow raster of --omni-shadow compute, in one
    /// orthographic view); or rays (no map: a shadow ray from each point toward the sun).
    #[arg(long, default_value = "graphics")]
    sun_shadow: String,
    /// How many point lights cast shadows (with --omni-shadow): K (the strongest as seen from
    /// the camera) or all (every light that reaches the view, the strongest 4096 at most;
    /// with --omni-shadow rays, every light).
    #[arg(long, default_value = "1", allow_negative_numbers = true)]
    shadowed_lights: String,
    /// Texels per side of each shadow-cube face (with --omni-shadow; 1 to 16384, and at most
    /// the device's largest cube); with --omni-shadow atlas, every face this size (a power of
    /// two, 32 to 2048). Default: 1024; with --omni-shadow atlas, each light's size on screen.
    #[arg(long, value_parser = Whole::<u32>::new(1, ml_render::settings::MAX_DIMENSION as u64), allow_negative_numbers = true)]
    cube_size: Option<u32>,
    /// MiB that point-light shadows may take with --omni-shadow atlas (1 to the device's
    /// memory): the atlas, its tables and the raster's lists. When the faces do not fit, every
    /// face shrinks by one factor (the table reports it).
    #[arg(long, default_value_t = AtlasSettings::DEFAULT.budget_mib, value_parser = SHADOW_BUDGET, allow_negative_numbers = true)]
    shadow_budget: u32,
    /// Whether atlas faces whose light did not move keep last frame's texels (on) or are
    /// drawn again every frame (off; the same images, for comparisons).
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    shadow_cache: String,
    /// Transparent (alphaMode BLEND) objects: the per-pixel layers' memory, in nodes of 32
    /// bytes per pixel on average (1 to 256; the pool is one storage buffer). Fragments beyond
    /// it are dropped and counted (the table and a warning say how many).
    #[arg(long, default_value_t = ml_render::DEFAULT_TRANSPARENCY_BUDGET, value_parser = TRANSPARENCY_BUDGET, allow_negative_numbers = true)]
    transparency_budget: u32,
    /// Image width in pixels (1 to 16384, and at most the device's largest image).
    #[arg(long, default_value_t = 1280, value_parser = SIDE, allow_negative_numbers = true)]
    width: u32,
    /// Image height in pixels (1 to 16384, and at most the device's largest image).
    #[arg(long, default_value_t = 720, value_parser = SIDE, allow_negative_numbers = true)]
    height: u32,
    /// Image size WxH (e.g. 1920x1080), as bench spells it: the same as --width W --height H.
    #[arg(long, conflicts_with_all = ["width", "height"])]
    resolution: Option<String>,
    /// The camera: eye position, the point it looks at and its vertical field of view in
    /// degrees (60 where left out), as EYE_X,EYE_Y,EYE_Z:TARGET_X,TARGET_Y,TARGET_Z[:FOV]; its
    /// near and far planes fit the scene. The viewer's C key prints its camera in this form.
    /// Default: the scene's own camera.
    #[arg(long, allow_hyphen_values = true)]
    camera: Option<String>,
    /// Draw every point light as a small cube glowing in its colour, sized by its radius and
    /// depth-tested like any object, at the light's rest place (at most 65536 lights; not
    /// with --omni-shadow, whose cubes would see the markers round their own lights).
    #[arg(long)]
    show_lights: bool,
    /// Exposure: stops (EV, -20 to 20; lit colour × 2^EV before the tone map and gamma), or
    /// auto (the image's log-average luminance brought to middle grey, metered on the GPU); not
    /// with a --debug-view, whose values are shown as they are. Default: auto for scene files
    /// and glTF files, 0 for the built-in scenes.
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<String>,
    /// Fix the animation clock at T seconds. Default: the clock advances 1/60 s per frame from
    /// 0 (in the viewer, with real time).
    #[arg(long, allow_negative_numbers = true)]
    time: Option<f32>,
    /// GPU culling of the visibility technique: on, or off (every meshlet drawn; the image
    /// must not change).
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    culling: String,
    /// Whether the light grid lists only the lights near the frame's surfaces, after a pass
    /// that marks the cells their points walk (deferred-compute, visibility): auto (where the
    /// lights are more than a third of the pixels, a pixel of N coverage samples counted N/2
    /// times, where the pass costs less than listing every light), on, or off. The same lights light every pixel either way.
    #[arg(long, default_value = "auto", value_parser = LightGridMarks::NAMES)]
    light_grid_marks: String,
    /// Who draws the visibility technique's visibility buffer: hardware (the graphics
    /// pipeline), compute (compute shaders only: triangles up to --raster-split pixels a
    /// thread each, larger ones clipped and drawn by a work group per 64x64-pixel bin),
    /// hybrid (the small ones in compute, the others by the hardware into the same buffer) or
    /// auto (each timed on this device and scene for a few frames, the fastest kept, and said
    /// why).
    #[arg(long, default_value = "auto", value_parser = ["hardware", "hybrid", "compute", "auto"])]
    raster: String,
    /// Anti-aliasing: coverage samples per pixel, off, 4, 8 or 16 (Vulkan's standard positions;
    /// the counts the device offers), each distinct surface of a pixel shaded once and the
    /// pixel the mean of its samples in the display's linear light: forward, clustered and
    /// deferred by Vulkan multisampling, visibility in its 64-bit buffer (any raster; --raster
    /// auto then picks compute). auto: 8 on a GPU (4 where the settings take no 8, off where
    /// they take none), off on a CPU driver, said why.
    #[arg(long, default_value = "auto", value_parser = ["off", "4", "8", "16", "auto"])]
    aa: String,
    /// Specular anti-aliasing: on, highlights under a normal map widened by the spread of the
    /// normals each filtered texel averages (Toksvig), so that they do not sparkle far away;
    /// off lights the filtered normal alone.
    #[arg(long, default_value = "on", value_parser = ["on", "off"])]
    specular_aa: String,
    /// The compute and hybrid rasters' largest triangle drawn by one thread: bounding box up to
    /// PX pixels a side (1 to 64).
    #[arg(long, default_value_t = Raster::DEFAULT_SPLIT, value_parser = RASTER_SPLIT, allow_negative_numbers = true)]
    raster_split: u32,
    /// Enable the Khronos validation layer with synchronization validation; any message
    /// makes the run fail.
    #[arg(long)]
    validation: bool,
    /// Vulkan device index (see `manylights info`). Default: the best one (discrete first).
    #[arg(long, value_parser = DEVICE, allow_negative_numbers = true)]
    device: Option<usize>,
    /// The options given on the command line (the others keep their defaults).
    #[arg(skip)]
    given: Given,
}

/// The ranges of the counts and sizes `render`, `view` and `bench` share.
const OBJECTS: Whole<usize> = Whole::new(0, ml_cpu::limits::MAX_BENCH_OBJECTS as u64);
const PERCENT: Whole<u32> = Whole::new(0, 100);
const GLASS_LAYERS: Whole<u32> = Whole::new(0, ml_cpu::transparency::MAX_GLASS_LAYERS as u64);
/// `--transparency-budget`'s range.
const TRANSPARENCY_BUDGET: Whole<u32> = Whole::new(1, ml_render::MAX_TRANSPARENCY_BUDGET as u64);
const SIDE: Whole<u32> = Whole::new(1, ml_render::settings::MAX_DIMENSION as u64);
const RASTER_SPLIT: Whole<u32> = Whole::new(1, Raster::MAX_SPLIT as u64);
const SHADOW_BUDGET: Whole<u32> = Whole::checked_later(u32::MAX as u64, "1 to the device's memory in MiB");
const DEVICE: Whole<usize> = Whole::checked_later(u32::MAX as u64, "0 to the last device `manylights info` lists");

/// A whole number for a flag, from `min` to `max`. It is read as a signed number of any size
/// first, so that a negative or huge value gets the range in its message ("--width -100 is out
/// of range: use 1 to 16384") instead of being taken for no number; its flags take
/// `allow_negative_numbers`, so that clap hands it a negative value instead of taking it for
/// another flag.
pub(crate) struct Whole<T> {
    min: u64,
    max: u64,
    /// The range in words, where the device decides it (checked once it is known); the parser
    /// then refuses only what the type cannot hold.
    range: Option<&'static str>,
    value: std::marker::PhantomData<fn() -> T>,
}

// Not derived: a derive would ask `T` to be Clone and Copy too.
impl<T> Clone for Whole<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Whole<T> {}

impl<T> Whole<T> {
    pub(crate) const fn new(min: u64, max: u64) -> Whole<T> {
        Whole { min, max, range: None, value: std::marker::PhantomData }
    }

    /// Any value from 0 to `max` (the type's), the range `range` checked later.
    pub(crate) const fn checked_later(max: u64, range: &'static str) -> Whole<T> {
        Whole { min: 0, max, range: Some(range), value: std::marker::PhantomData }
    }
}

impl<T: TryFrom<u64> + Clone + Send + Sync + 'static> clap::builder::TypedValueParser for Whole<T> {
    type Value = T;

    fn parse_ref(&self, _: &clap::Command, arg: Option<&clap::Arg>, value: &std::ffi::OsStr) -> Result<T, clap::Error> {
        let flag = arg.and_then(clap::Arg::get_long).map_or_else(|| "the value".to_owned(), |long| format!("--{long}"));
        let text = value.to_string_lossy();
        let refuse = |why: String| clap::Error::raw(ErrorKind::ValueValidation, format!("{flag} {why}\n"));
        let out_of_range = || {
            let range = self.range.map_or_else(|| format!("{} to {}", self.min, self.max), str::to_owned);
            refuse(format!("{text} is out of range: use {range}"))
        };
        // `16k` and `1M` as bench's light counts are spelt (thousands, millions). Nothing
        // else around the number: ' 5' is a mistake (a quoting slip), not 5.
        let (digits, factor) = match text.char_indices().last() {
            Some((i, 'k' | 'K')) => (&text[..i], 1_000),
            Some((i, 'M')) => (&text[..i], 1_000_000),
            _ => (&text[..], 1),
        };
        match digits.parse::<i128>().map(|n| n.saturating_mul(factor)) {
            Ok(n) => u64::try_from(n)
                .ok()
                .filter(|n| (self.min..=self.max).contains(n))
                .and_then(|n| T::try_from(n).ok())
                .ok_or_else(out_of_range),
            Err(e) if matches!(e.kind(), std::num::IntErrorKind::PosOverflow | std::num::IntErrorKind::NegOverflow) => Err(out_of_range()),
            Err(_) => Err(refuse(format!("'{text}' is not a whole number"))),
        }
    }
}

fn main() -> ExitCode {
    // Before any thread: it may set a variable the Vulkan driver reads.
    ml_vk::driver_env::prepare();
    let cli = match parse_arguments() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    // Interrupted (Ctrl+C, SIGTERM, SIGHUP), a render or bench leaves no temporary file beside
    // its outputs: every finished output was renamed into place whole, the one being written
    // is removed. (The handler runs on a thread of its own, so it may take locks.)
    if let Err(e) = ctrlc::set_handler(|| {
        ml_cpu::files::remove_temporaries();
        std::process::exit(130);
    }) {
        eprintln!("warning: no signal handler ({e}): an interrupted write may leave a .partial file beside its output");
    }
    let result = match cli.command {
        Command::Render(args) => render(&args),
        Command::View(args) => view(&args),
        Command::Bench(mut args) => bench::bench(&mut args),
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

/// The command line, each command knowing which options it was given; else the exit code
/// once --help or --version is printed, or an argument error (on one line).
fn parse_arguments() -> Result<Cli, ExitCode> {
    let matches = Cli::command().try_get_matches().map_err(argument_error)?;
    let mut cli = Cli::from_arg_matches(&matches).map_err(argument_error)?;
    // --resolution WxH is --width W --height H.
    let scene = match &mut cli.command {
        Command::Render(args) => Some(&mut args.scene),
        Command::View(args) => Some(&mut args.scene),
        _ => None,
    };
    if let Some(scene) = scene.filter(|s| s.resolution.is_some()) {
        match bench::parse_resolution(scene.resolution.as_deref().unwrap_or_default()) {
            Ok((width, height)) => (scene.width, scene.height) = (width, height),
            Err(e) => {
                eprintln!("error: {e}");
                return Err(ExitCode::from(2));
            }
        }
    }
    if let Some((_, options)) = matches.subcommand() {
        let given = Given::of(options);
        match &mut cli.command {
            Command::Render(args) => args.scene.given = given,
            Command::View(args) => args.scene.given = given,
            Command::Bench(args) => args.given = given,
            Command::Info => {}
        }
    }
    Ok(cli)
}

/// What clap's `e` ends the run with: --help and --version print and succeed; a bare
/// `manylights` prints the help and, on stderr, the line naming the commands; anything else
/// is clap's whole message on one line. Exit code 2 for errors.
fn argument_error(e: clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let mut cli = Cli::command();
            println!("{}", cli.render_help());
            let commands: Vec<&str> = cli.get_subcommands().map(clap::Command::get_name).filter(|&name| name != "help").collect();
            eprintln!("error: manylights needs a command: {} (the help above says what each does)", commands.join(", "));
            ExitCode::from(2)
        }
        _ => {
            eprintln!("error: {}", messages::argument_error(&e.to_string()));
            ExitCode::from(2)
        }
    }
}

/// What `--scene` names: the seed scene (of `object` in `material`), room, bench (of `objects`
/// objects), or a file.
fn scene_source(name: &str, object: MeshKind, material: Material, objects: usize) -> Result<SceneSource> {
    Ok(match name {
        "seed" => SceneSource::Seed { object, material },
        "room" => SceneSource::Room,
        "bench" => SceneSource::Bench { objects },
        path if is_scene_file(path) => SceneSource::File(PathBuf::from(path)),
        folder if Path::new(folder).is_dir() => {
            bail!("--scene '{folder}' is a folder: name the scene file in it (FILE.toml, FILE.gltf or FILE.glb)")
        }
        other => bail!("unknown scene '{other}': expected seed, room, bench, a scene file FILE.toml or a glTF file FILE.gltf|FILE.glb"),
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
    let environment = EnvironmentAsk {
        source: args.environment.as_deref().map(EnvironmentSource::parse),
        intensity: args.environment_intensity.as_deref().map(parse_intensity).transpose().map_err(anyhow::Error::msg)?,
        rotation_deg: args.environment_rotation.as_deref().map(parse_rotation_deg).transpose().map_err(anyhow::Error::msg)?,
    };
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
        transparent_percent: args.transparent_objects,
        glass_layers: args.glass_layers,
        light_colors: args.light_colors.as_deref().map(LightColors::from_name).transpose()?,
        sections: Sections::default(),
        variant: args.variant.clone(),
    }
    .asking(environment))
}

/// The settings the arguments ask for, with `technique` (`--technique` itself may say auto).
fn settings_request(args: &SceneArgs, technique: Technique, frames: u32) -> Result<SettingsRequest> {
    if args.show_lights && args.omni_shadow != "off" {
        bail!("--show-lights and --omni-shadow do not go together: each light's shadow cube would see the marker around it");
    }
    // Options of the shadows asked for without them are refused by `check_options_apply`.
    let omni = match args.omni_shadow.as_str() {
        "off" => None,
        mode => {
            let mode = match OmniShadowMode::from_name(mode)? {
                OmniShadowMode::Atlas(_) => OmniShadowMode::Atlas(AtlasSettings {
                    budget_mib: args.shadow_budget,
                    cache: args.shadow_cache == "on",
                    fixed_size: args.cube_size,
                }),
                cubes => cubes,
            };
            let (lights, all) = match args.shadowed_lights.trim() {
                "all" => (MAX_SHADOWED_LIGHTS, true),
                k => match k.parse::<i128>() {
                    Ok(n) => (
                        u32::try_from(n)
                            .map_err(|_| anyhow!("--shadowed-lights {k} is out of range: use 1 to the scene's lights, or all"))?,
                        false,
                    ),
                    Err(_) => bail!("--shadowed-lights '{k}' is neither a count nor all"),
                },
            };
            Some(OmniShadowSettings { mode, lights, all, size: args.cube_size.unwrap_or(OmniShadowSettings::DEFAULT_SIZE) })
        }
    };
    // The raster is set once the technique (and for auto, the probe) is known
    // (`auto::resolve_raster`), and so are auto's samples (`auto::resolve_antialiasing`).
    let settings = RenderSettings {
        debug_view: DebugView::from_name(&args.debug_view)?,
        omni,
        sun_shadow: SunShadowMode::from_name(&args.sun_shadow)?,
        frames,
        time: args.time,
        culling: args.culling == "on",
        antialiasing: auto::antialiasing_choice(&args.aa)?.unwrap_or(Antialiasing::Off),
        specular_aa: args.specular_aa == "on",
        exposure: exposure_choice(args)?,
        ..RenderSettings::new(technique, args.width, args.height)
    };
    Ok(SettingsRequest {
        clusters: cluster_choice(&args.clusters)?,
        light_grid_marks: LightGridMarks::from_name(&args.light_grid_marks)?,
        background: args.background.as_deref().map(ml_render::Background::from_name).transpose()?,
        transparency: ml_render::TransparencySettings { budget: args.transparency_budget, ..Default::default() },
        ..SettingsRequest::new(settings)
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

/// A file without lights of its own, lit by the default rig under the built-in sky, is exposed
/// as a glTF viewer shows it, at EV 0 (the sky's radiance is in display units: auto exposure
/// brightened such models by 2–3 EV, past what a viewer shows), unless `--exposure` says.
fn viewer_exposure(args: &SceneArgs, built: &BuiltScene, settings: &mut RenderSettings) {
    let default_rig = built.warnings.iter().any(|w| matches!(w, SceneWarning::DefaultRig { .. }));
    let sky = args.environment.as_deref().is_none_or(|e| e == "sky");
    let lit = built.shading == ShadingModel::Pbr && built.scene.sections.get::<Environment>().is_some();
    if args.exposure.is_none() && default_rig && lit && sky {
        settings.exposure = Exposure::Ev(0.0);
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
        let style = "{bar:30} {pos}/{len} {msg} ({elapsed} so far, {eta} left)";
        bar.set_style(indicatif::ProgressStyle::with_template(style).expect("a valid template"));
        bar.set_message(what.to_owned());
        // A single long frame (many lights on a CPU driver) shows its bar too, ticking: a
        // thread shows it once PROGRESS_AFTER has passed unless the work is done by then.
        let ticking = bar.clone();
        std::thread::spawn(move || {
            std::thread::sleep(PROGRESS_AFTER);
            if !ticking.is_finished() {
                ticking.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                ticking.enable_steady_tick(std::time::Duration::from_millis(500));
            }
        });
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
    /// An image sequence's pattern and the writer its frames go to.
    sequence: Option<(output::SequencePattern, output::FrameWriter)>,
    /// The frames it writes, ascending (every frame of a single image's run).
    to_write: Vec<u32>,
    /// The size rendered, and the supersampling factor it is filtered down by.
    size: (u32, u32),
    supersample: u32,
}

impl ml_render::FrameSink for RenderSink {
    fn submitted(&mut self, _i: u32) {
        self.progress.inc();
    }

    fn wants_images(&self) -> bool {
        self.sequence.is_some()
    }

    fn wants_image(&self, i: u32) -> bool {
        self.sequence.is_some() && self.to_write.binary_search(&i).is_ok()
    }

    fn image(&mut self, i: u32, rgba: Vec<u8>) -> Result<(), ml_render::RenderError> {
        let Some((pattern, writer)) = &mut self.sequence else { return Ok(()) };
        writer
            .write(output::sequence_path(pattern, i), rgba, self.size, self.supersample)
            .map_err(|e| ml_render::RenderError::Invalid(e.to_string()))
    }
}

/// The scene's camera as `--camera` reads it (a user starts from it), its target the point
/// ahead nearest the middle of the scene's box.
fn camera_line(scene: &ml_cpu::scene::Scene) -> String {
    let (lo, hi) = scene.bounds();
    let ahead = ((lo + hi) * 0.5 - scene.camera.position).dot(scene.camera.forward());
    ml_cpu::camera::CameraSpec::describe(&scene.camera, if ahead > 0.0 { ahead } else { 1.0 })
}

fn render(cmd: &RenderArgs) -> Result<()> {
    let args = &cmd.scene;
    let choice = auto::technique_choice(&args.technique)?;
    let request = scene_request(args)?;
    // Every setting is checked before the GPU work; auto's technique is set once it is known.
    let wanted = settings_request(args, choice.unwrap_or(Technique::DeferredClustered), cmd.frames)?;
    let mut wanted = supersampled(wanted, cmd.supersample)?;
    wanted.settings.light_stats = cmd.light_stats;
    let mut techniques = Techniques::chosen(choice);
    check_options_apply(args, &request.source, None, &techniques)?;
    let sequence = output::sequence_pattern(&cmd.out)?;
    let shard = output::shard_choice(cmd.shard.as_deref(), cmd.resume, sequence.is_some(), |name| std::env::var(name).ok())?;
    let to_write = output::frames_to_write(cmd.frames, shard, cmd.resume.then_some(sequence.as_ref()).flatten());
    if sequence.is_some() && to_write.is_empty() {
        println!("nothing to render: every frame this run would write exists already");
        return Ok(());
    }
    let built = request.build()?;
    check_options_apply(args, &request.source, Some(&built), &techniques)?;
    viewer_exposure(args, &built, &mut wanted.settings);
    output::prepare(&cmd.out, sequence.as_ref(), &to_write)?;
    let mut settings = wanted.for_scene(&built.scene, built.shading);
    let ctx = Context::new(&ContextDesc { validation: args.validation, device_index: args.device, window: None })?;
    let messages = ctx.validation_counter();
    let auto_why = match choice {
        Some(_) => None,
        None => {
            let (t, why, _) = auto::pick(&ctx, Some((&built.scene, &settings, raster_choice(args)?)))?;
            settings.technique = t;
            techniques.auto = Auto::Picked(t);
            check_options_apply(args, &request.source, Some(&built), &techniques)?.take_effect(&mut settings);
            Some(why)
        }
    };
    // Once every option is known to apply, so that a refusal stays the only line.
    print_warnings(&built.warnings);
    let aa_choice = (auto::antialiasing_choice(&args.aa)?, (raster_choice(args)?, args.raster_split));
    let aa_why;
    (settings.antialiasing, aa_why) = auto::resolve_antialiasing(&ctx, &settings, aa_choice, (built.scene.lights.len(), cmd.supersample));
    // Samples weigh on whether the light grid's marks pay.
    settings.light_grid_marks = wanted.marks_light_grid(built.scene.lights.len(), &settings);
    let raster_why;
    (settings.raster, raster_why) = auto::resolve_raster(&ctx, &built.scene, &settings, (raster_choice(args)?, args.raster_split))?;
    let (lights, gbuffer) = (built.scene.lights.len(), settings.lighting(&built.scene).gbuffer_kind());
    let directional = built.scene.directional.len();
    let camera = camera_line(&built.scene);
    // A sequence renders from its first frame to write, each frame at its own clock — from
    // frame 0 under auto exposure, which carries from frame to frame.
    let first = if settings.meters_exposure() { 0 } else { to_write[0] };
    let frames = first..to_write[to_write.len() - 1] + 1;
    let mut sink = RenderSink {
        progress: Progress::new(u64::from(frames.end - frames.start) + u64::from(cmd.warmup), "frames"),
        sequence: sequence.map(|pattern| (pattern, output::FrameWriter::new())),
        to_write,
        size: (settings.width, settings.height),
        supersample: cmd.supersample,
    };
    let result = Renderer::new(&ctx, built.scene, settings).and_then(|mut r| {
        r.warm_up(cmd.warmup, &mut sink)?;
        r.render_frames(frames, &mut sink)
    });
    sink.progress.finish();
    let device = tables::device_line(&ctx.info);
    drop(ctx);
    let mut output = result?;
    let writing = match &mut sink.sequence {
        Some((_, writer)) => Some(writer.finish()?),
        None => {
            let (image, size) = output::filtered_down(std::mem::take(&mut output.rgba), sink.size, sink.supersample);
            ml_cpu::files::write_png(&cmd.out, &image, size)?;
            None
        }
    };
    let facts = tables::RenderFacts {
        device: &device,
        settings: &settings,
        lights,
        directional,
        gbuffer,
        auto: auto_why.as_deref(),
        raster_auto: raster_why.as_deref(),
        aa_auto: aa_why.as_deref(),
        output: &cmd.out,
        supersample: cmd.supersample,
        camera: &camera,
        sequence: writing.as_ref(),
    };
    print!("{}", tables::table(&tables::render_rows(&facts, &output.stats)));
    if let Some(warning) = output.stats.feature::<ml_render::TransparencyStats>().and_then(|t| t.overflow_warning()) {
        eprintln!("warning: {warning}");
    }
    let count = messages.load(Ordering::SeqCst);
    if count > 0 {
        bail!("the validation layer reported {count} message(s) (printed above)");
    }
    Ok(())
}

/// `wanted` rendered `k` times wider and taller (`--supersample`), refused where that passes
/// the largest image we make.
fn supersampled(wanted: SettingsRequest, k: u32) -> Result<SettingsRequest> {
    let max = ml_render::settings::MAX_DIMENSION;
    let s = wanted.settings;
    let (width, height) = (s.width.saturating_mul(k), s.height.saturating_mul(k));
    if width > max || height > max {
        bail!("--supersample {k} renders {width}x{height}, more than {max} pixels a side: use a smaller --supersample or size");
    }
    Ok(SettingsRequest { settings: RenderSettings { width, height, ..s }, ..wanted })
}

/// The largest viewer script read (a script of a million lines is far past any session).
const MAX_SCRIPT_BYTES: u64 = 16 << 20;

fn view(cmd: &ViewArgs) -> Result<()> {
    let args = &cmd.scene;
    let script = match &cmd.script {
        Some(path) => {
            let bytes =
                ml_cpu::files::read_regular(path, MAX_SCRIPT_BYTES).with_context(|| format!("cannot read script '{}'", path.display()))?;
            let text = String::from_utf8(bytes).map_err(|_| anyhow!("script '{}' is not UTF-8 text", path.display()))?;
            Some(ml_viewer::script::parse(&text).map_err(|e| anyhow::anyhow!("script '{}': {e}", path.display()))?)
        }
        None => None,
    };
    // Checked up front, so that a bad argument fails before a window opens.
    let choice = auto::technique_choice(&args.technique)?;
    let request = scene_request(args)?;
    let mut wanted = settings_request(args, Technique::Forward, 1)?;
    let mut techniques = Techniques::chosen(choice);
    check_options_apply(args, &request.source, None, &techniques)?;
    let built = request.build()?;
    check_options_apply(args, &request.source, Some(&built), &techniques)?;
    viewer_exposure(args, &built, &mut wanted.settings);
    // Before auto's probes: without a display, that is the one line, at once.
    let windows = ml_viewer::connect()?;
    let probe_settings = wanted.for_scene(&built.scene, built.shading);
    let technique =
        auto::resolve_alone(&args.technique, (&built.scene, &probe_settings, raster_choice(args)?), (args.validation, args.device))?;
    let mut unused = Default::default();
    if choice.is_none() {
        techniques.auto = Auto::Picked(technique);
        unused = check_options_apply(args, &request.source, Some(&built), &techniques)?;
    }
    print_warnings(&built.warnings);
    let mut first =
        SettingsRequest { settings: RenderSettings { technique, ..wanted.settings }, ..wanted }.for_scene(&built.scene, built.shading);
    unused.take_effect(&mut first);
    let aa_choice = (auto::antialiasing_choice(&args.aa)?, (raster_choice(args)?, args.raster_split));
    first.antialiasing = auto::resolve_antialiasing_alone(&first, aa_choice, built.scene.lights.len(), (args.validation, args.device))?;
    first.raster =
        auto::resolve_raster_alone(&built.scene, &first, (raster_choice(args)?, args.raster_split), (args.validation, args.device))?;
    let options = ml_viewer::ViewerOptions {
        choices: ml_viewer::Choices::new(&request, &built, &first, wanted.light_grid_marks),
        scene: request,
        width: args.width,
        height: args.height,
        vsync: !cmd.no_vsync,
        validation: args.validation,
        device: args.device,
        time: args.time,
        script,
    };
    ml_viewer::run(windows, options)
}

fn info() -> Result<()> {
    let devices = ml_vk::context::list_devices()?;
    for d in devices {
        println!("{}", tables::table(&tables::device_rows(&d)));
    }
    Ok(())
}
