//! `manylights`: the command line. Parses arguments and calls the library; every failure
//! ends as one `error: …` line on stderr and a non-zero exit.

use anyhow::{bail, Context as _, Result};
use clap::{Args, Parser, Subcommand};
use ml_cpu::bench_scene::bench_scene;
use ml_cpu::cluster::ClusterDims;
use ml_cpu::lights::{LightLayout, LightParams, RadiusRange};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_cpu::{gltf_scene, scene_file};
use ml_render::report::table;
use ml_render::targets::gbuffer_bytes_per_pixel;
use ml_render::{DebugView, HeadlessRenderer, OmniShadowMode, OmniShadowSettings, RenderSettings, ShadingModel, Technique};
use ml_vk::{Context, ContextDesc};
use std::path::{Path, PathBuf};

mod auto;
mod bench;
mod messages;
use std::process::ExitCode;
use std::sync::atomic::Ordering;

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
    /// of settings and GPU times, P pause, F12 screenshot, Esc quit.
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
    /// Frames to render; timings are averaged over them, the image is the last one.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Output PNG file.
    #[arg(long)]
    out: PathBuf,
}

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
#[derive(Args, Clone)]
struct SceneArgs {
    /// Scene to render: seed (built in), room (a closed room with a pillar and one point light,
    /// for point-light shadows), bench (a floor, 300 objects, --lights N (default 1024) lights
    /// whose radius shrinks as N^(−1/3): the benchmark's), a scene file FILE.toml (README:
    /// "Scene files") or a glTF 2.0 file FILE.gltf|FILE.glb (rendered with pbr unless
    /// --shading says otherwise).
    #[arg(long, default_value = "seed")]
    scene: String,
    /// Lighting technique: forward, clustered-cpu, clustered-gpu, deferred, deferred-clustered,
    /// deferred-compute, or auto: deferred-compute where this device runs the probe's light loop
    /// (`bench --probe`) over 1.25× faster as a compute shader than as a fragment shader, else
    /// deferred-clustered.
    #[arg(long, default_value = "forward")]
    technique: String,
    /// Shading model: seed (seed 000's Cook–Torrance), blinn-phong (seed 002: shadowed sun,
    /// spot light, textures, normal maps, sky reflections) or pbr (seed's specular + Lambert
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
    /// shadow-cube (the first shadowed point light's cube, unfolded; needs --omni-shadow).
    #[arg(long, default_value = "none")]
    debug_view: String,
    /// Object kind of the seed scene: sphere, teapot, torusknot, plane, disc, cube, room.
    #[arg(long, default_value = "sphere")]
    object: String,
    /// Material: gold, copper, chromium, nickel, titanium, cobalt, platinum, white, red, blue, black.
    #[arg(long, default_value = "gold")]
    material: String,
    /// Number of point lights (default 64; with a scene file: replaces the file's lights with
    /// N lights of --light-layout).
    #[arg(long)]
    lights: Option<u64>,
    /// Light placement: grid (the seed's) or random (uniform in x,z ∈ [−20,20], y ∈ [−2,12]).
    #[arg(long, default_value = "grid")]
    light_layout: String,
    /// Seed of the random layout (and of random radii).
    #[arg(long, default_value_t = 1)]
    light_seed: u64,
    /// Light radius R, or MIN..MAX for radii drawn per light.
    #[arg(long, default_value = "15")]
    light_radius: String,
    /// Point-light shadows (seed 003): off, or how the cubes are rendered — copy (seed 003:
    /// each face offscreen, then copied into the cube), direct (each face into its cube
    /// layer) or multiview (all six faces in one pass).
    #[arg(long, default_value = "off")]
    omni_shadow: String,
    /// How many point lights cast shadows (the strongest as seen from the camera).
    #[arg(long, default_value_t = 1)]
    shadowed_lights: u32,
    /// Texels per side of each shadow-cube face.
    #[arg(long, default_value_t = OmniShadowSettings::DEFAULT_SIZE)]
    cube_size: u32,
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Fix the animation clock at T (otherwise it advances 1/60 s per frame from 0; in the
    /// viewer, with real time).
    #[arg(long)]
    time: Option<f32>,
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

/// The scene and the shading model to render it with.
fn build_scene(args: &SceneArgs) -> Result<(Scene, ShadingModel)> {
    let lights = |count: u64| -> Result<LightParams> {
        Ok(LightParams {
            count: LightParams::check_count(count)?,
            layout: LightLayout::from_name(&args.light_layout)?,
            seed: args.light_seed,
            radius: RadiusRange::parse(&args.light_radius)?,
        })
    };
    let shading = |file: Option<&str>| ShadingModel::from_name(args.shading.as_deref().or(file).unwrap_or("seed"));
    match args.scene.as_str() {
        "room" => Ok((Scene::shadow_room(), shading(None)?)),
        // Lights uniform in the random box, their radius following the count (bench_scene.rs).
        "bench" => Ok((bench_scene(lights(args.lights.unwrap_or(1024))?.count, args.light_seed)?, shading(None)?)),
        "seed" => {
            let model = shading(None)?;
            let scene =
                Scene::seed(MeshKind::from_name(&args.object)?, Material::named(&args.material)?, &lights(args.lights.unwrap_or(64))?)?;
            // Seed 002's lighting wants something to cast shadows on.
            Ok((if model == ShadingModel::BlinnPhong { scene.with_floor() } else { scene }, model))
        }
        path if [".toml", ".gltf", ".glb"].iter().any(|ext| path.to_lowercase().ends_with(ext)) => {
            let file = if path.to_lowercase().ends_with(".toml") {
                scene_file::load(Path::new(path))?
            } else {
                gltf_scene::load(Path::new(path))?
            };
            for w in &file.warnings {
                eprintln!("warning: '{path}': {w}");
            }
            let model = shading(file.shading.as_deref()).with_context(|| format!("'{path}': shading model"))?;
            let mut scene = file.scene;
            if let Some(n) = args.lights {
                scene.lights = lights(n)?.build()?;
                // The file's spot cones belonged to its own lights.
                scene.cones.clear();
            }
            if scene.lights.is_empty() && scene.directional.is_empty() {
                eprintln!("warning: '{path}': the scene has no lights, so only ambient and emitted light show (--lights N adds some)");
            }
            Ok((scene, model))
        }
        other => bail!("unknown scene '{other}': expected seed, room, a scene file FILE.toml or a glTF file FILE.gltf|FILE.glb"),
    }
}

/// Fail before rendering if the PNG could not be written: nothing is computed for nothing.
fn check_output(path: &Path) -> Result<()> {
    if path.is_dir() {
        bail!("cannot write '{}': it is a directory", path.display());
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !parent.is_dir() {
        bail!("cannot write '{}': folder '{}' does not exist", path.display(), parent.display());
    }
    let existed = path.exists();
    std::fs::OpenOptions::new().append(true).create(true).open(path).with_context(|| format!("cannot write '{}'", path.display()))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// Render settings from the arguments for `technique` (`--technique` itself may say auto) and
/// a scene of `lights` point lights (the shading model as the scene decided).
fn render_settings(args: &SceneArgs, technique: Technique, lights: usize, shading: ShadingModel, frames: u32) -> Result<RenderSettings> {
    Ok(RenderSettings {
        technique,
        shading,
        clusters: match args.clusters.as_str() {
            "auto" => ClusterDims::for_lights(lights, args.width, args.height),
            grid => ClusterDims::parse(grid)?,
        },
        debug_view: DebugView::from_name(&args.debug_view)?,
        omni: match args.omni_shadow.as_str() {
            "off" if args.shadowed_lights != 1 || args.cube_size != OmniShadowSettings::DEFAULT_SIZE => {
                bail!("--shadowed-lights and --cube-size need point-light shadows: add --omni-shadow layered|direct|multiview|copy")
            }
            "off" => None,
            mode => Some(OmniShadowSettings { mode: OmniShadowMode::from_name(mode)?, lights: args.shadowed_lights, size: args.cube_size }),
        },
        width: args.width,
        height: args.height,
        frames,
        time: args.time,
    })
}

fn render(cmd: &RenderArgs) -> Result<()> {
    let args = &cmd.scene;
    let choice = auto::technique_choice(&args.technique)?;
    let (scene, shading) = build_scene(args)?;
    check_output(&cmd.out)?;
    // Every setting is checked before the GPU work; auto's technique is set once it is known.
    let mut settings = render_settings(args, choice.unwrap_or(Technique::DeferredClustered), scene.lights.len(), shading, cmd.frames)?;
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
    let technique = settings.technique;
    let light_count = scene.lights.len();
    let object_textures = !scene.textures.is_empty();
    let result = HeadlessRenderer::new(&ctx, scene, settings).and_then(|mut r| r.render());
    let device = format!("{} ({}, {} {})", ctx.info.name, ctx.info.type_name(), ctx.info.driver_name, ctx.info.driver_info);
    drop(ctx);
    let output = result?;
    image::save_buffer_with_format(&cmd.out, &output.rgba, output.width, output.height, image::ColorType::Rgba8, image::ImageFormat::Png)
        .with_context(|| format!("cannot write '{}'", cmd.out.display()))?;
    let stats = &output.stats;
    let mut rows = vec![
        ("device", device),
        ("resolution", format!("{}x{}", output.width, output.height)),
        ("technique", technique.name().to_owned() + if auto_why.is_some() { " (auto)" } else { "" }),
        ("shading", settings.shading.name().to_owned()),
        ("lights", light_count.to_string()),
        ("frames", stats.frames.to_string()),
    ];
    if let Some(why) = auto_why {
        rows.push(("auto", why));
    }
    match stats.gpu_ms() {
        Some(passes) => rows.extend(passes.into_iter().map(|(name, ms)| ("gpu ms", format!("{ms:.3}  ({name} pass, mean)")))),
        None => rows.push(("gpu ms", "n/a (device has no timestamp queries)".into())),
    }
    if technique.lights_in_subpass() || technique.lights_in_compute() {
        let memory = match output.stats.gbuffer_lazily_allocated {
            Some(true) => "; transient, lazily allocated",
            Some(false) => "; transient (this device has no lazily allocated memory)",
            None => "",
        };
        let layout = if object_textures {
            "octahedral normal 2×f32, object index u32, albedo-occlusion RGBA8, roughness-metallic RG8, emissive RGBA8"
        } else {
            "octahedral normal 2×f32, object index u32, albedo RGBA8"
        };
        rows.push(("g-buffer", format!("{} bytes/pixel + depth ({layout}){memory}", gbuffer_bytes_per_pixel(object_textures))));
    }
    if let Some(ms) = stats.assign_ms() {
        rows.push(("cpu assign ms", format!("{ms:.3}  (light assignment, mean)")));
    }
    if let Some(c) = stats.clusters {
        let d = settings.clusters;
        rows.push(("clusters", format!("{}x{}x{} = {}", d.x, d.y, d.z, d.count())));
        rows.push(("lights/cluster", format!("mean {:.2}, max {}", c.mean_lights, c.max_lights)));
        rows.push(("index list", format!("{} entries ({} buffer growths)", c.index_len, stats.index_growths)));
    }
    if stats.overflowed_frames > 0 {
        rows.push((
            "overflows",
            format!(
                "{} frame(s) outgrew their light lists; {} re-rendered at the grown size",
                stats.overflowed_frames, stats.rerendered_frames
            ),
        ));
    }
    if settings.debug_view == DebugView::ClusterHeat {
        let top = stats.clusters.map_or(1, |c| c.max_lights.max(1));
        rows.push(("heat legend", format!("log scale: black 0, blue 1, cyan, green, yellow, red {top} lights per cluster")));
    }
    if let Some(o) = settings.omni {
        rows.push(("omni shadows", format!("{}: {} light(s), cubes of 6×{}² (distance / radius, D32)", o.mode.name(), o.lights, o.size)));
    }
    rows.push(("cpu ms/frame", format!("{:.3}  (assign + upload + record + submit)", stats.cpu_ms())));
    rows.push(("wall ms/frame", format!("{:.3}", stats.wall_ms_per_frame())));
    rows.push(("output", cmd.out.display().to_string()));
    print!("{}", table(&rows));
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
    let (scene, shading) = build_scene(args)?;
    let technique = auto::resolve_alone(&args.technique, args.validation, args.device)?;
    let first = render_settings(args, technique, scene.lights.len(), shading, 1)?;
    let choices = ml_viewer::Choices {
        technique: first.technique,
        shading: first.shading,
        object: args.object.clone(),
        material: args.material.clone(),
        lights: scene.lights.len() as u64,
        layout: args.light_layout.clone(),
        radius: RadiusRange::parse(&args.light_radius)?.max,
        clusters: first.clusters,
        debug_view: first.debug_view,
        omni: first.omni,
    };
    let initial = choices.clone();
    // The arguments with what the overlay changed; a scene file keeps its own lights until the
    // light count, layout or radius is changed.
    let build = |c: &ml_viewer::Choices, (width, height): (u32, u32)| -> Result<(Scene, RenderSettings)> {
        let mut a = args.clone();
        a.shading = Some(c.shading.name().to_owned());
        a.object = c.object.clone();
        a.material = c.material.clone();
        if (c.lights, &c.layout, c.radius) != (initial.lights, &initial.layout, initial.radius) {
            a.lights = Some(c.lights);
            a.light_layout = c.layout.clone();
            if c.radius != initial.radius {
                a.light_radius = c.radius.to_string();
            }
        }
        let (scene, shading) = build_scene(&a)?;
        let settings = RenderSettings {
            technique: c.technique,
            shading,
            clusters: c.clusters,
            debug_view: c.debug_view,
            omni: c.omni,
            width,
            height,
            frames: 1,
            time: args.time,
        };
        Ok((scene, settings))
    };
    let options = ml_viewer::ViewerOptions {
        choices,
        width: args.width,
        height: args.height,
        vsync: !cmd.no_vsync,
        validation: args.validation,
        device: args.device,
        time: args.time,
        seed_scene: args.scene == "seed",
        script,
    };
    ml_viewer::run(options, &build)
}

fn info() -> Result<()> {
    let devices = ml_vk::context::list_devices()?;
    for d in devices {
        let l = &d.limits;
        let rows = vec![
            ("device", format!("{}: {} ({})", d.index, d.name, d.type_name())),
            ("vulkan", d.api_version_string()),
            ("driver", format!("{} {}", d.driver_name, d.driver_info)),
            ("usable", if d.suitable { "yes".into() } else { "no (needs Vulkan 1.2 and a graphics queue)".to_string() }),
            ("maxImageDimension2D", l.max_image_dimension2_d.to_string()),
            ("maxStorageBufferRange", l.max_storage_buffer_range.to_string()),
            ("maxUniformBufferRange", l.max_uniform_buffer_range.to_string()),
            ("maxPushConstantsSize", l.max_push_constants_size.to_string()),
            ("maxComputeWorkGroupInvocations", l.max_compute_work_group_invocations.to_string()),
            ("maxComputeSharedMemorySize", l.max_compute_shared_memory_size.to_string()),
            ("timestampPeriod (ns)", l.timestamp_period.to_string()),
            ("timestampComputeAndGraphics", (l.timestamp_compute_and_graphics != 0).to_string()),
            ("maxImageArrayLayers", l.max_image_array_layers.to_string()),
            ("imageCubeArray", d.features.image_cube_array.to_string()),
            ("multiview", d.features.multiview.to_string()),
        ];
        println!("{}", table(&rows));
    }
    Ok(())
}
