//! The renderer: the scene on the GPU, the frames in flight and the technique's passes.
//! Headless (offscreen targets, a read-back of the last frame, no window system) or under a
//! window (the viewer adds its commands through a `FrameHook`). It knows no pass by name:
//! the technique's choices give an ordered list of passes (`plan::plan`, made by
//! `assembly::assemble`) that it binds, prepares, records with the barriers their declared
//! uses need (`sync`), times and collects from.

use crate::antialiasing::{Antialiasing, AntialiasingStats};
use crate::assembly::{assemble, scene_parts, Assembly};
use crate::clusters;
use crate::error::RenderError;
use crate::exposure::auto_exposure::{self, AutoExposure};
use crate::frame::{lists_too_long, max_index_entries, FrameInFlight, FrameSetup, SlotLists};
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Prepare, Recording, SlotReport};
use crate::read_back::{self, HostRead, ReadBack};
use crate::report::{CpuPhases, FrameStats};
use crate::scene::SceneGpu;
use crate::scene_part::{self, FrameCounts, OwnedParts, PartAccess, PartHost};
use crate::settings::{Geometry, LightAssignment, RenderSettings};
use crate::shadows::omni_shadow::OmniShadows;
use crate::shadows::stores::{ShadowStores, SharedShadows};
use crate::sync;
use crate::targets::{depth_format, Output, Targets};
use ml_cpu::camera::{Camera, View};
use ml_cpu::cluster::{count_entries, ClusterGrid};
use ml_cpu::gpu_types::{FrameUniforms, PointLight};
use ml_cpu::lights::{motion_offset, move_into};
use ml_cpu::scene::Scene;
use ml_vk::{commands, release_on_error, vk, Context, Image, VkError, VkResultExt};
use std::cell::RefCell;
use std::rc::Rc;
use std::time::Instant;

/// A rendered image (tightly packed RGBA8, row 0 at the top) and its measurements.
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub stats: FrameStats,
}

/// What `Renderer::render_into` tells as it renders: each frame submitted (a progress bar)
/// and, if it wants them, each frame's image (an image sequence). `()` wants nothing.
pub trait FrameSink {
    /// Frame `i` (from 0) was submitted.
    fn submitted(&mut self, _i: u32) {}
    /// Whether frames' images are read back and handed to `image` (an image sequence).
    fn wants_images(&self) -> bool {
        false
    }
    /// Of an image sequence, whether frame `i`'s image is wanted (a shard of it, or the frames
    /// not yet written): the others are rendered without being waited for or read back.
    fn wants_image(&self, _i: u32) -> bool {
        self.wants_images()
    }
    /// Frame `i`'s image, RGBA8, rows from the top (the sink's to keep: a sequence's writer
    /// encodes it on another thread while the next frame renders).
    fn image(&mut self, _i: u32, _rgba: Vec<u8>) -> Result<(), RenderError> {
        Ok(())
    }
}

impl FrameSink for () {}

pub struct Renderer<'a> {
    ctx: &'a Context,
    scene: Scene,
    settings: RenderSettings,
    extent: vk::Extent2D,
    /// The scene's meshes, buffers and textures on the GPU.
    gpu: SceneGpu,
    /// The scene's parts beside the shadow stores (the features' parts, the assembly's list: the environment
    /// light's maps, the blinn-phong lights).
    parts: OwnedParts,
    /// The shadow stores (the shadow passes share them).
    shadows: SharedShadows,
    /// The technique's passes, in recording order.
    passes: Vec<Box<dyn Pass>>,
    command_pool: vk::CommandPool,
    frames: Vec<FrameInFlight>,
    /// The states of the named resources the frame slots share (`sync::SCENE_WIDE`), from
    /// frame to frame across the slots.
    shared_sync: sync::SyncStates,
    /// Per frame slot, host memory its colour target is copied into: by the frame's own commands
    /// for an image sequence (`in_flight_image`), or after it (`read_back`).
    readbacks: ReadBack,
    /// Per slot, the sequence frame whose image its commands copy into its read-back buffer,
    /// handed to the sink once the slot's fence has signalled.
    in_flight_image: Vec<Option<u32>>,
    /// The scene's lights at rest as the GPU reads them: shadowed ones marked with their
    /// shadow slots (`OmniShadows::mark`).
    lights: Vec<PointLight>,
    /// Whether lights are moved on the GPU (by the light grid), else on the CPU into
    /// `animated`, which every frame uploads.
    lights_on_gpu: bool,
    animated: Vec<PointLight>,
    /// What the frames are seen through: the camera's view and projection at the image's size.
    view: View,
    /// The cluster grid cut along `view` (its shader parameters are also set for techniques
    /// without one).
    grid: ClusterGrid,
    /// Per frame slot: what its last frame reported (the heat map's top, the exposure meter).
    reports: Vec<SlotReport>,
    /// Per frame slot: whether it has been submitted since its results were last collected.
    pending: Vec<bool>,
    /// Per frame slot: the shadow rays its last frame's compute lighting traced, and the
    /// surfaces the anti-aliased visibility lighting shaded.
    rays_traced: Vec<(u64, u64)>,
    /// Top of the heat-map scale (lights per cluster), from the newest known frame.
    heat_top: f32,
    /// Slot of the frame that was read back last.
    last_frame: usize,
    /// Format of the depth target (targets are made again on a resize).
    depth_format: vk::Format,
    /// The EV the next frame is exposed with (auto exposure moves it).
    exposure: AutoExposure,
}

/// Heat-map top before any frame has reported its maximum (clustered-gpu's first frames).
const DEFAULT_HEAT_TOP: f32 = 64.0;

/// Refuse, before anything is drawn, light lists that cannot fit in what the device binds as
/// one storage buffer (clustered techniques): `cluster::count_entries` bounds the entries from
/// below — the lights' spheres, less the distance they move, against the cluster grid — so a
/// scene that fits is never refused, and one that does not is refused in milliseconds rather
/// than after frames of GPU list building and growing.
fn check_lists_fit(
    ctx: &Context,
    settings: &RenderSettings,
    grid: &ClusterGrid,
    lights: &[PointLight],
    motion: f32,
) -> Result<(), RenderError> {
    if !settings.technique.has_cluster_grid() {
        return Ok(());
    }
    let limit = max_index_entries(ctx);
    let needed = count_entries(grid, lights, motion, limit);
    if needed > limit {
        let holder = format!("'{}' binds as one storage buffer", ctx.info.name);
        return Err(lists_too_long(needed, limit, &holder).in_technique(settings.technique.name()));
    }
    Ok(())
}

/// What a window adds to each frame (the viewer): commands recorded after the frame's passes,
/// in the same command buffer, and the semaphores its submission waits on and signals.
pub trait FrameHook {
    /// Record after the frame's passes; `colour` is the frame's colour target (the image a
    /// headless render reads back), in TRANSFER_SRC_OPTIMAL with its writes visible to
    /// transfers (`sync::frame_end`), and stays so.
    fn record(&mut self, ctx: &Context, cmd: vk::CommandBuffer, colour: &Image) -> Result<(), VkError>;
    /// The semaphore the submission waits on (and at which stage), and the one it signals.
    fn semaphores(&self) -> (Option<(vk::Semaphore, vk::PipelineStageFlags)>, Option<vk::Semaphore>);
}

/// What `scene` settles of `settings`: transparency only where there is something
/// transparent, and nodes that keep the PBR extensions' texels where they vary per point.
fn settle_for_scene(settings: &mut RenderSettings, scene: &Scene) {
    if !scene.has_transparent_objects() {
        settings.transparency = None;
    }
    let lobe_textures = settings.lighting(scene).lobe_textures();
    if let Some(t) = &mut settings.transparency {
        t.lobe_textures = lobe_textures;
    }
}

impl<'a> Renderer<'a> {
    pub fn new(ctx: &'a Context, scene: Scene, mut settings: RenderSettings) -> Result<Renderer<'a>, RenderError> {
        settle_for_scene(&mut settings, &scene);
        settings.check(ctx, scene.lights.len())?;
        settings.check_scene(&scene)?;
        let view = View::new(scene.camera, settings.width, settings.height);
        let grid = ClusterGrid::new(settings.clusters, &view);
        check_lists_fit(ctx, &settings, &grid, &scene.lights, scene.light_motion)?;
        if !scene.cones.is_empty() && scene.cones.len() != scene.lights.len() {
            return Err(RenderError::Invalid(format!("the scene has {} spot cones for {} lights", scene.cones.len(), scene.lights.len())));
        }
        let depth = depth_format(ctx, Output::of(settings.technique))?;
        let lights_on_gpu = settings.technique.assignment() == LightAssignment::Gpu;
        // The scene's parts, then its geometry and textures (set 1 binds what the parts name),
        // then the shadow stores' casters; a failure releases what was made before it.
        let mut parts = OwnedParts::make(ctx, &scene, scene_parts())?;
        // The sun's map in the G-buffer's depth format (sampleable).
        let made = depth_format(ctx, Output::GBuffer)
            .map_err(RenderError::from)
            .and_then(|format| ShadowStores::new(ctx, &scene, settings.shadow_config(), format));
        let mut shadows = release_on_error(ctx, made, &mut [&mut parts])?;
        let made =
            SceneGpu::new(ctx, &scene, settings.scene_config(), &|name| scene_part::resource(scene_part::all(&shadows, &parts), name));
        let mut gpu = release_on_error(ctx, made, &mut [&mut parts, &mut shadows])?;
        let drawn = shadows.casters_changed(ctx, &scene, &gpu);
        release_on_error(ctx, drawn, &mut [&mut parts, &mut shadows, &mut gpu])?;
        shadows.omni.choose(&scene, settings.aspect());
        let lights = gpu_lights(&scene, &shadows.omni);
        let mut shared_sync = sync::SyncStates::default();
        if let Some(layout) = shadows.omni.initial_cube_layout() {
            shared_sync.know(sync::SHADOW_CUBES, layout);
        }
        // Cleared when it was made (its pass draws it where the sun casts a map).
        shared_sync.know(sync::SUN_MAP, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
        let mut r = Renderer {
            ctx,
            extent: vk::Extent2D { width: settings.width, height: settings.height },
            view,
            grid,
            animated: if lights_on_gpu { Vec::new() } else { lights.clone() },
            lights,
            scene,
            settings,
            gpu,
            parts,
            shadows: Rc::new(RefCell::new(shadows)),
            passes: Vec::new(),
            command_pool: vk::CommandPool::null(),
            frames: Vec::new(),
            shared_sync,
            readbacks: ReadBack::new("read-back"),
            in_flight_image: vec![None; FRAMES_IN_FLIGHT],
            lights_on_gpu,
            reports: vec![SlotReport::default(); FRAMES_IN_FLIGHT],
            pending: vec![false; FRAMES_IN_FLIGHT],
            rays_traced: vec![(0, 0); FRAMES_IN_FLIGHT],
            heat_top: DEFAULT_HEAT_TOP,
            last_frame: 0,
            depth_format: depth,
            exposure: AutoExposure::new(settings.exposure),
        };
        // Anything made before a failure is released by Drop.
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create infos.
        r.command_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }.ctx("vkCreateCommandPool")?;
        r.make_passes()?;
        r.create_frames()?;
        Ok(r)
    }

    /// The technique's passes for the current scene and settings (replacing any).
    fn make_passes(&mut self) -> Result<(), RenderError> {
        for p in &mut self.passes {
            p.destroy(self.ctx);
        }
        self.passes.clear();
        let assembly = Assembly {
            settings: &self.settings,
            shading: self.settings.lighting(&self.scene),
            lights: &self.lights,
            scene: &self.gpu,
            shadows: &self.shadows,
            objects: &self.scene.objects,
            depth_format: self.depth_format,
        };
        self.passes = assemble(self.ctx, &assembly)?;
        Ok(())
    }

    /// Render with `settings` from now on where their pipeline key's renderer part is the
    /// current one's (`PipelineKey::renderer_part`: the scene's GPU resources are made for
    /// it), and say so (true); false, changing nothing, for anything else (make a new
    /// renderer). New frame slots (targets, per-frame buffers, the passes' sets) and cluster
    /// grid, and new passes where the key changed (grid, debug view, exposure meter); meshes,
    /// textures and the scene's buffers stay (the viewer's resizes and overlay).
    pub fn reconfigure(&mut self, mut settings: RenderSettings) -> Result<bool, RenderError> {
        settle_for_scene(&mut settings, &self.scene);
        let (key, new_key) = (self.settings.pipeline_key(), settings.pipeline_key());
        if key.renderer_part() != new_key.renderer_part() {
            return Ok(false);
        }
        settings.check(self.ctx, self.scene.lights.len())?;
        settings.check_scene(&self.scene)?;
        let view = View::new(self.scene.camera, settings.width, settings.height);
        let grid = ClusterGrid::new(settings.clusters, &view);
        check_lists_fit(self.ctx, &settings, &grid, &self.scene.lights, self.scene.light_motion)?;
        self.release_frames()?;
        self.exposure.set_mode(settings.exposure);
        self.settings = settings;
        self.extent = vk::Extent2D { width: settings.width, height: settings.height };
        (self.view, self.grid) = (view, grid);
        // The passes depend on the grid (the GPU build's sizes), the debug view (legend,
        // tone-map curve, view passes) and the exposure meter; the view only needs new frame
        // slots.
        if new_key != key {
            self.make_passes()?;
        }
        self.create_frames()?;
        Ok(true)
    }

    /// Light the scene with `lights` from now on (the viewer's light count, layout or radius
    /// changed): new light buffers, frame slots and passes; meshes and textures stay. Scenes with spot lights refuse (their cones belong to their
    /// lights and are compiled into the pipelines): make a new renderer for those.
    pub fn set_lights(&mut self, lights: Vec<PointLight>) -> Result<(), RenderError> {
        if !self.scene.cones.is_empty() {
            return Err(RenderError::Invalid("a scene with spot lights cannot change its lights in place".into()));
        }
        self.settings.check(self.ctx, lights.len())?;
        self.settings.check_casters(lights.len(), self.scene.directional.len())?;
        check_lists_fit(self.ctx, &self.settings, &self.grid, &lights, self.scene.light_motion)?;
        self.release_frames()?;
        self.scene.lights = lights;
        self.shadows.borrow_mut().omni.choose(&self.scene, self.settings.aspect());
        self.lights = gpu_lights(&self.scene, &self.shadows.borrow().omni);
        // The atlas keeps its faces: a face is drawn again when the light of its key (the
        // scene index) is not where it was or has another radius, which covers lights that
        // changed, came or went.
        self.animated = if self.lights_on_gpu { Vec::new() } else { self.lights.clone() };
        self.make_passes()?;
        self.create_frames()?;
        Ok(())
    }

    /// Destroy the frame slots and what points at them (for `resize` and `set_lights`).
    fn release_frames(&mut self) -> Result<(), VkError> {
        let ctx = self.ctx;
        ctx.wait_idle()?;
        for frame in &mut self.frames {
            frame.destroy(ctx);
        }
        self.frames.clear();
        self.pending.fill(false);
        self.reports.fill(SlotReport::default());
        self.readbacks.destroy(ctx);
        self.in_flight_image.fill(None);
        Ok(())
    }

    /// Draw `scene`'s objects (and meshes) from now on, lights and camera unchanged (the
    /// viewer's object and material combos): new meshes, object buffer, sun shadow map,
    /// passes (the GPU-driven ones hold the scene's meshlets) and frame slots. False, changing
    /// nothing, where either scene has object textures (their sets and the pipelines' texture
    /// code depend on them) or the two differ in material lobes (compiled in or not).
    pub fn set_objects(&mut self, scene: &Scene) -> Result<bool, RenderError> {
        if self.gpu.object_textures.per_object.is_empty() || !scene.textures.is_empty() || !self.scene.textures.is_empty() {
            return Ok(false);
        }
        let lobes = |scene: &Scene| self.settings.lighting(scene).constant("MATERIAL_LOBES");
        if lobes(scene) != lobes(&self.scene) {
            return Ok(false);
        }
        self.release_frames()?;
        self.scene.objects = scene.objects.clone();
        self.scene.meshes = scene.meshes.clone();
        self.gpu.replace_objects(self.ctx, &self.scene)?;
        let mut shadows = self.shadows.borrow_mut();
        shadows.casters_changed(self.ctx, &self.scene, &self.gpu)?;
        // Other casters: every atlas face is drawn again.
        shadows.omni.atlas.forget();
        drop(shadows);
        self.make_passes()?;
        self.create_frames()?;
        Ok(true)
    }

    /// The frame slots (targets at the current size, buffers), the passes' sets pointing at
    /// them, what the projection decides (the GPU build's cluster boxes) and the read-back.
    fn create_frames(&mut self) -> Result<(), VkError> {
        let ctx = self.ctx;
        let (extent, depth) = (self.extent, self.depth_format);
        let technique = self.settings.technique;
        let gbuffer = crate::targets::gbuffer_images(self.settings.lighting(&self.scene).gbuffer_kind());
        let raster = self.settings.raster;
        let layers = self.settings.blends_layers();
        let cpu_lists = technique.has_cluster_grid();
        let antialiasing = self.settings.antialiasing;
        let make_targets = || Targets::new(ctx, extent, depth, (Output::of(technique), gbuffer), (raster, layers, antialiasing));
        let setup = FrameSetup {
            pool: self.command_pool,
            // The light grid keeps its own copy of the lights (GPU techniques).
            light_count: if self.lights_on_gpu { 1 } else { self.scene.lights.len() },
            // The CPU's cluster lists (the GPU techniques' light grid keeps its own).
            cluster_count: if cpu_lists { self.settings.clusters.count() } else { 1 },
            // Room for 16 entries per light to start with (grown on demand).
            initial_indices: if cpu_lists { self.scene.lights.len() * 16 } else { 1 },
            passes: self.pass_names().len() as u32,
            make_targets: &make_targets,
        };
        for f in 0..FRAMES_IN_FLIGHT {
            self.frames.push(FrameInFlight::new(ctx, &setup)?);
            for work in self.passes.iter_mut().filter_map(|p| p.frame_work()) {
                work.create_slot(ctx, f, extent)?;
            }
        }
        for f in 0..FRAMES_IN_FLIGHT {
            self.bind_passes(f)?;
        }
        self.projection_changed();
        self.readbacks.make_all(ctx, extent.width as u64 * extent.height as u64 * 4)
    }

    /// Point every pass's sets of slot `f` at its buffers and targets, the scene's and the
    /// passes' own (the slot is idle). In debug builds, every resource a pass's shaders bind
    /// that the frame orders by declared uses must be among the pass's (`sync::undeclared`).
    fn bind_passes(&mut self, f: usize) -> Result<(), VkError> {
        let owned: Vec<(sync::BufferName, vk::Buffer)> =
            self.passes.iter_mut().filter_map(|p| p.frame_work()).flat_map(|w| w.slot_buffers(f)).collect();
        let shadows = self.shadows.borrow();
        let parts = scene_part::all(&*shadows, &self.parts);
        let scene: Vec<_> = self.gpu.named_buffers().into_iter().chain(parts.flat_map(|p| p.named_buffers())).collect();
        drop(shadows);
        let resources = self.frames[f].resources(f, &scene).with(&owned);
        let checked = cfg!(debug_assertions);
        let ordered: Vec<&'static str> =
            if checked { self.passes.iter().flat_map(|p| p.uses()).map(|u| u.name).collect() } else { Vec::new() };
        for p in &mut self.passes {
            resources.take_found();
            p.bind_frame(self.ctx, &resources)?;
            if checked {
                let missing = sync::undeclared(&resources.take_found(), &p.uses(), &ordered);
                let pass = p.timer_name().unwrap_or("an untimed pass");
                assert!(missing.is_empty(), "{pass} binds {missing:?}, which the frame orders by declared uses, without declaring them");
            }
        }
        Ok(())
    }

    /// Slot 0's uniforms with the new projection (or size), no frame in flight.
    fn projection_changed(&mut self) {
        self.write_uniforms(0, 0.0);
    }

    /// The passes the timer reports, in order.
    fn pass_names(&self) -> Vec<&'static str> {
        self.passes.iter().filter_map(|p| p.timer_name()).collect()
    }

    /// Render `settings.frames` frames, two in flight, and read back the last one.
    pub fn render(&mut self) -> Result<RenderOutput, RenderError> {
        self.render_into(&mut ())
    }

    /// Renders `frames` frames and throws their images and times away, so that what `render`
    /// measures next is the device's steady state: a GPU lowers its clocks while the CPU
    /// loads the scene (an H100 falls from 1,980 to 345 MHz) and raises them only under load.
    /// The frames `render` then returns are the ones it returns without a warm-up. `sink` is
    /// told of each frame submitted (a progress bar), and given no image.
    pub fn warm_up(&mut self, frames: u32, sink: &mut dyn FrameSink) -> Result<(), RenderError> {
        /// Passes on the submissions alone.
        struct Submissions<'s>(&'s mut dyn FrameSink);
        impl FrameSink for Submissions<'_> {
            fn submitted(&mut self, i: u32) {
                self.0.submitted(i);
            }
        }
        if frames == 0 {
            return Ok(());
        }
        let measured = std::mem::replace(&mut self.settings.frames, frames);
        let result = self.render_into(&mut Submissions(sink));
        self.settings.frames = measured;
        result.map(|_| ())
    }

    /// `render`, telling `sink` of every frame submitted and, where it wants them, handing it
    /// every frame's image (each then waited for): an image sequence whose last image is
    /// `render`'s.
    pub fn render_into(&mut self, sink: &mut dyn FrameSink) -> Result<RenderOutput, RenderError> {
        self.render_frames(0..self.settings.frames, sink)
    }

    /// `render_into` for frames `range` of the settings' frames alone (a shard of an image
    /// sequence, or what a rerun has left to write): each frame at its own clock, so a frame's
    /// image is the one the whole sequence gives it — where nothing carries from frame to
    /// frame. Auto exposure does (a frame is exposed from the one two back): with it, start the
    /// range at 0, and only the frames the sink wants are waited for and read back.
    pub fn render_frames(&mut self, range: std::ops::Range<u32>, sink: &mut dyn FrameSink) -> Result<RenderOutput, RenderError> {
        let mut stats = FrameStats::new(&self.pass_names());
        let start = Instant::now();
        let mut last = 0;
        let frames = self.settings.frames;
        let range = range.start.min(frames)..range.end.min(frames);
        if range.is_empty() {
            return Err(RenderError::Invalid(format!("no frames to render in {range:?}")));
        }
        let meters = self.settings.meters_exposure();
        // Frames submitted so far (a frame drawn again is not told to the sink twice).
        let mut told = range.start;
        let mut i = range.start;
        loop {
            if i == range.end {
                match self.hand_over_all(sink, &mut stats)? {
                    Some(first) => i = first,
                    None => break,
                }
            }
            last = i as usize % FRAMES_IN_FLIGHT;
            // Exposed from the image of the slot's previous frame (two back), whether or not
            // the frame before was waited for: the same EVs, so the same images, either way.
            self.collect(last, &mut stats)?;
            if let Some(first) = self.overflowed_image(last..last + 1, &mut stats)? {
                i = first;
                continue;
            }
            self.hand_over(last..last + 1, sink, &mut stats)?;
            self.adapt_exposure(1.0, last);
            // The first frame settles its exposure as the last does: a sequence does not start
            // dark, and later frames meter a settled image (two back). A sequence and a plain
            // render do the same, so their last images stay equal.
            let settles = meters && ((i == 0 && frames > 1) || i + 1 == frames);
            let wanted = sink.wants_images() && sink.wants_image(i);
            // A sequence's image is copied by the frame's own commands and handed over when
            // its slot next comes round, unless the frame settles its exposure first.
            let mut copy = (wanted && !settles).then(|| CopyToHost { buffer: self.readbacks.raw(last), extent: self.extent });
            self.run_frame(last, self.settings.clock(i), &mut stats, copy.as_mut().map(|c| c as &mut dyn FrameHook))?;
            if i + 1 == frames && self.redraws(last, &mut stats)? {
                // The last image drawn again where the frame overflowed a list that has grown
                // since: what the frames after it would draw (drawn in place, a large triangle
                // is slow, and a CPU driver may cut its long loop short).
                stats.redraws += 1;
                self.run_frame(last, self.settings.clock(i), &mut stats, copy.as_mut().map(|c| c as &mut dyn FrameHook))?;
            }
            if copy.is_some() {
                self.in_flight_image[last] = Some(i);
            }
            if i == 0 && frames > 1 && meters {
                if let Some(first) = self.hand_over_all(sink, &mut stats)? {
                    i = first;
                    continue;
                }
                last = self.settle_exposure(last, self.settings.clock(i), &mut stats)?;
            }
            if wanted && settles {
                if let Some(first) = self.hand_over_all(sink, &mut stats)? {
                    i = first;
                    continue;
                }
                // The last image is the one `render` returns: with its exposure settled.
                if i + 1 == frames {
                    last = self.settle_exposure(last, self.settings.clock(i), &mut stats)?;
                }
                self.hand_image((i, last), true, sink, &mut stats)?;
            }
            if i == told {
                sink.submitted(i);
                told += 1;
            }
            i += 1;
        }
        if !sink.wants_images() {
            // (An image sequence settled its last frame before handing it over.)
            last = self.settle_exposure(last, self.settings.clock(range.end - 1), &mut stats)?;
        }
        stats.wall_ms = start.elapsed().as_secs_f64() * 1e3;
        if Output::of(self.settings.technique) == Output::Subpasses {
            let targets = self.frames[0].targets.as_ref().expect("made with the frame");
            stats.gbuffer_lazily_allocated = Some(targets.gbuffer.iter().all(|i| i.is_lazily_allocated()));
        }
        stats.frames = range.len() as u32;
        // Rays are counted with the light statistics (compute lightings only).
        let counts = FrameCounts { rays_traced: self.settings.light_stats.then_some(self.rays_traced[last].0) };
        for part in scene_part::all(&*self.shadows.borrow(), &self.parts) {
            part.report(&counts, &mut stats);
        }
        let antialiasing = self.settings.antialiasing;
        if antialiasing != Antialiasing::Off {
            let (width, height) = (self.extent.width, self.extent.height);
            // The visibility technique's buffer (and the hardware raster's images), whose
            // lighting counts the surfaces it shades; or the mesh techniques' multisampled
            // attachments.
            let attachments = self.frames[0].targets.as_ref().expect("made with the frame").multisampled_bytes();
            let (sample_bytes, surfaces) = match self.settings.technique.geometry() {
                Geometry::Meshlets => (antialiasing.buffer_bytes(width, height) + attachments, Some(self.rays_traced[last].1)),
                Geometry::Meshes => (attachments, None),
            };
            stats.set_feature(AntialiasingStats { antialiasing, width, height, sample_bytes, surfaces });
        }
        stats.memory = Some(self.ctx.memory_use());
        self.last_frame = last;
        let rgba = self.read_back(last)?;
        Ok(RenderOutput { width: self.extent.width, height: self.extent.height, rgba, stats })
    }

    /// Auto exposure: render the frame at clock `t` (in slot `last`) again, into the other
    /// slot, while the EV its image asks for is not the one it used (at most
    /// `auto_exposure::REPEATS` times); the slot that holds the final image.
    fn settle_exposure(&mut self, mut last: usize, t: f32, stats: &mut FrameStats) -> Result<usize, RenderError> {
        if !self.settings.meters_exposure() {
            return Ok(last);
        }
        for _ in 0..auto_exposure::REPEATS {
            self.adapt_exposure(1.0, last);
            if self.exposure.settled(last) {
                break;
            }
            stats.exposure_repeats += 1;
            last = (last + 1) % FRAMES_IN_FLIGHT;
            self.run_frame(last, t, stats, None)?;
            self.collect_all(stats)?;
        }
        stats.exposure_ev = Some(self.exposure.slot_ev(last));
        Ok(last)
    }

    /// Auto exposure: a frame at clock `t` rendered off screen and exposed again until it
    /// settles, as `render` settles its frames, so that a viewer's first frames start at the
    /// scene's exposure instead of easing in from 0 EV (a glTF model lit by fitted lights
    /// wants several EV). Nothing where the exposure is fixed.
    pub fn settle_first_exposure(&mut self, t: f32) -> Result<(), RenderError> {
        if !self.settings.meters_exposure() {
            return Ok(());
        }
        let mut stats = FrameStats::new(&self.pass_names());
        self.collect_all(&mut stats)?;
        let slot = (self.last_frame + 1) % FRAMES_IN_FLIGHT;
        self.run_frame(slot, t, &mut stats, None)?;
        self.collect_all(&mut stats)?;
        self.last_frame = self.settle_exposure(slot, t, &mut stats)?;
        Ok(())
    }

    /// Auto exposure: move the next frame's EV `share` of the way to the one that brings the
    /// log-average luminance of slot `slot`'s last frame (collected) to middle grey.
    fn adapt_exposure(&mut self, share: f32, slot: usize) {
        self.exposure.adapt(share, self.reports[slot].log2_luminance);
    }

    /// The EV the next frame is exposed with.
    pub fn exposure_ev(&self) -> f32 {
        self.exposure.ev()
    }

    /// The scene it renders (the viewer frames it).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The scene's camera (where the next frame is seen from).
    pub fn camera(&self) -> Camera {
        self.scene.camera
    }

    /// See the next frames from `camera` (the viewer's moving camera): the cluster grid
    /// follows. The GPU build's view-space cluster boxes depend on the projection only: made
    /// again when it changed (field of view, near, far).
    pub fn set_camera(&mut self, camera: Camera) -> Result<(), RenderError> {
        self.scene.camera = camera;
        let projection = self.view.projection;
        self.view = View::new(camera, self.extent.width, self.extent.height);
        self.grid = ClusterGrid::new(self.settings.clusters, &self.view);
        if self.view.projection != projection {
            // Frame 0's uniforms carry the projection to the passes: wait for its frame.
            self.ctx.wait_idle()?;
            self.projection_changed();
        }
        Ok(())
    }

    /// The settings it renders with.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Wait until the next frame slot's previous frame is done (its timings go into `stats`);
    /// returns the slot, which `draw` renders into next.
    pub fn wait_next_slot(&mut self, stats: &mut FrameStats) -> Result<usize, RenderError> {
        let f = (self.last_frame + 1) % FRAMES_IN_FLIGHT;
        self.collect(f, stats)?;
        Ok(f)
    }

    /// Render one frame at clock `t` into the next frame slot, two in flight, with `hook`'s
    /// commands and semaphores (the viewer presents it); the slot's previous frame's timings
    /// go into `stats`.
    pub fn draw(&mut self, t: f32, hook: &mut dyn FrameHook, stats: &mut FrameStats) -> Result<(), RenderError> {
        let f = (self.last_frame + 1) % FRAMES_IN_FLIGHT;
        // The slot's previous frame was collected by `wait_next_slot`.
        self.adapt_exposure(auto_exposure::VIEWER_SMOOTHING, f);
        self.run_frame(f, t, stats, Some(hook))?;
        self.last_frame = f;
        Ok(())
    }

    /// The newest frame's colour target, read back (waits for it): what `render` returns.
    pub fn read_newest(&mut self) -> Result<Vec<u8>, RenderError> {
        let mut stats = FrameStats::new(&self.pass_names());
        self.collect_all(&mut stats)?;
        Ok(self.read_back(self.last_frame)?)
    }

    /// Names of the passes whose GPU times `FrameStats` reports, in order.
    pub fn timed_passes(&self) -> Vec<&'static str> {
        self.pass_names()
    }

    /// Wait for slot `f`, collect its results, update, record and submit a frame at clock `t`
    /// (with `hook`'s commands and semaphores).
    fn run_frame(&mut self, f: usize, t: f32, stats: &mut FrameStats, hook: Option<&mut dyn FrameHook>) -> Result<(), RenderError> {
        let ctx = self.ctx;
        let fence = self.frames[f].fence;
        self.collect(f, stats)?;
        let start = Instant::now();
        let assign = self.update_frame(f, t, stats)?;
        let updated = Instant::now();
        let (wait, signal) = hook.as_ref().map_or((None, None), |h| h.semaphores());
        self.record(f, hook)?;
        let recorded = Instant::now();
        let (waits, stages): (Vec<vk::Semaphore>, Vec<vk::PipelineStageFlags>) = wait.into_iter().unzip();
        let signals: Vec<vk::Semaphore> = signal.into_iter().collect();
        // SAFETY: the fence was waited on in `collect` and the command buffer is executable.
        unsafe {
            ctx.device.reset_fences(&[fence]).ctx("vkResetFences")?;
            let cmds = [self.frames[f].cmd];
            let submit = [vk::SubmitInfo::default()
                .command_buffers(&cmds)
                .wait_semaphores(&waits)
                .wait_dst_stage_mask(&stages)
                .signal_semaphores(&signals)];
            ctx.device.queue_submit(ctx.queue, &submit, fence).ctx("vkQueueSubmit")?;
        }
        self.pending[f] = true;
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        stats.add_cpu(CpuPhases {
            assign,
            upload: ms(updated - start) - assign.unwrap_or(0.0),
            record: ms(recorded - updated),
            submit: ms(recorded.elapsed()),
        });
        Ok(())
    }

    /// Wait for slot `f`'s last frame and take in what it measured and reported.
    fn collect(&mut self, f: usize, stats: &mut FrameStats) -> Result<(), VkError> {
        let ctx = self.ctx;
        // SAFETY: the fence belongs to this device.
        unsafe { ctx.device.wait_for_fences(&[self.frames[f].fence], true, u64::MAX) }.ctx("vkWaitForFences")?;
        if !std::mem::take(&mut self.pending[f]) {
            return Ok(());
        }
        if let Some(ms) = self.frames[f].timer.read_ms(ctx)? {
            stats.add_gpu(&ms);
        }
        let mut report = SlotReport::default();
        for work in self.passes.iter_mut().filter_map(|p| p.frame_work()) {
            work.collect(f, &mut report, stats);
        }
        self.rays_traced[f] = self.frames[f].take_ray_count();
        self.reports[f] = report;
        if let Some(max_lights) = report.max_lights {
            self.heat_top = max_lights.max(1) as f32;
        }
        Ok(())
    }

    /// Wait for slot `slot`'s frame and collect it: whether a pass asks for it to be drawn
    /// again (`FrameWork::redraws`).
    fn redraws(&mut self, slot: usize, stats: &mut FrameStats) -> Result<bool, VkError> {
        self.collect(slot, stats)?;
        let ctx = self.ctx;
        Ok(self.passes.iter_mut().filter_map(|p| p.frame_work()).any(|w| w.redraws(ctx, slot)))
    }

    /// Of the images of `slots` (collected) not yet handed over, the first frame that
    /// overflowed a list that has grown since, if any (`FrameWork::redraws`): its image may
    /// lack what it drew in place (a CPU driver cuts a long loop short). Then the frames from
    /// it on are drawn again, in order, with the grown lists: the images in flight are dropped
    /// and that frame returned. Each time some list has grown, so it ends.
    fn overflowed_image(&mut self, slots: std::ops::Range<usize>, stats: &mut FrameStats) -> Result<Option<u32>, VkError> {
        let mut first = None;
        for f in slots {
            if let Some(i) = self.in_flight_image[f] {
                if self.redraws(f, stats)? {
                    first = Some(first.map_or(i, |j: u32| j.min(i)));
                }
            }
        }
        if first.is_some() {
            self.collect_all(stats)?;
            self.in_flight_image.fill(None);
            stats.redraws += 1;
        }
        Ok(first)
    }

    /// Wait for every slot and hand the sink their images, unless one overflowed
    /// (`overflowed_image`): then the frame to draw again from.
    fn hand_over_all(&mut self, sink: &mut dyn FrameSink, stats: &mut FrameStats) -> Result<Option<u32>, RenderError> {
        self.collect_all(stats)?;
        if let Some(first) = self.overflowed_image(0..FRAMES_IN_FLIGHT, stats)? {
            return Ok(Some(first));
        }
        self.hand_over(0..FRAMES_IN_FLIGHT, sink, stats)?;
        Ok(None)
    }

    fn collect_all(&mut self, stats: &mut FrameStats) -> Result<(), VkError> {
        (0..FRAMES_IN_FLIGHT).try_for_each(|f| self.collect(f, stats))
    }

    /// Write slot `f`'s buffers for clock `t`; the milliseconds of CPU light assignment in it
    /// (None where the CPU does not assign).
    fn update_frame(&mut self, f: usize, t: f32, stats: &mut FrameStats) -> Result<Option<f64>, RenderError> {
        let technique = self.settings.technique;
        self.update_slot(f, t, stats).map_err(|e| e.in_technique(technique.name()))
    }

    /// `update_frame`'s work (its errors are said with the technique by the caller).
    fn update_slot(&mut self, f: usize, t: f32, stats: &mut FrameStats) -> Result<Option<f64>, RenderError> {
        let ctx = self.ctx;
        if !self.lights_on_gpu {
            move_into(&self.lights, motion_offset(t, self.scene.light_motion), &mut self.animated);
            self.frames[f].lights.write(0, &self.animated);
        }
        let mut lists = SlotLists { frame: &mut self.frames[f], grew: false };
        let mut prepare = Prepare {
            ctx,
            slot: f,
            grid: &self.grid,
            view: &self.view,
            rest_lights: &self.lights,
            light_offset: motion_offset(t, self.scene.light_motion),
            lights: &self.animated,
            lists: &mut lists,
            stats,
            assigned: None,
            rebind: false,
        };
        for work in self.passes.iter_mut().filter_map(|p| p.frame_work()) {
            work.prepare(&mut prepare)?;
        }
        let (assigned, rebind) = (prepare.assigned, prepare.rebind);
        let assign_ms = assigned.map(|(ms, _)| ms);
        if let Some((_, cluster_stats)) = assigned {
            self.heat_top = cluster_stats.max_lights.max(1) as f32;
            stats.clusters = Some(cluster_stats);
        }
        if lists.grew {
            stats.index_growths += 1;
        }
        if lists.grew || rebind {
            self.bind_passes(f)?;
        }
        self.write_uniforms(f, t);
        Ok(assign_ms)
    }

    fn write_uniforms(&mut self, f: usize, t: f32) {
        let (g, v) = (&self.grid, &self.view);
        let debug_view = self.settings.debug_view.code();
        let cam = &v.camera;
        let exposure = self.exposure.expose(f);
        let frame = &mut self.frames[f];
        let light_offset = motion_offset(t, self.scene.light_motion);
        let mut uniforms = FrameUniforms {
            view: v.view.to_cols_array_2d(),
            proj: v.projection.to_cols_array_2d(),
            inv_view_proj: v.view_proj().inverse().to_cols_array_2d(),
            // w: clip w = w·depth + (1 − w) (Camera::w_of_depth).
            camera_pos: cam.position.extend(cam.w_of_depth().0).to_array(),
            light_count: self.scene.lights.len() as u32,
            ambient: self.scene.ambient,
            directional_count: self.scene.directional.len() as u32,
            viewport: [v.width, v.height, debug_view, 0],
            light_animation: light_offset.extend(0.0).to_array(),
            exposure: [exposure, 0.0, 0.0, 0.0],
            ..FrameUniforms::default()
        };
        clusters::grid_uniforms(g, (self.heat_top, frame.index_capacity() as u32), &mut uniforms);
        for part in scene_part::all(&*self.shadows.borrow(), &self.parts) {
            part.frame_uniforms(&mut uniforms);
        }
        for work in self.passes.iter_mut().filter_map(|p| p.frame_work()) {
            work.frame_uniforms(&mut uniforms, light_offset);
        }
        frame.uniforms.write(0, &[uniforms]);
    }

    fn record(&mut self, f: usize, hook: Option<&mut dyn FrameHook>) -> Result<(), VkError> {
        let ctx = self.ctx;
        let frame = &mut self.frames[f];
        let cmd = frame.cmd;
        // SAFETY: the frame's fence has signalled, so the command buffer is not pending.
        unsafe {
            ctx.device.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty()).ctx("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            ctx.device.begin_command_buffer(cmd, &begin).ctx("vkBeginCommandBuffer")?;
        }
        frame.timer.reset(ctx, cmd);
        let targets = frame.targets.as_ref().expect("made with the frame");
        let view_proj = self.view.view_proj();
        let rec = Recording { ctx, cmd, slot: f, extent: self.extent, targets, scene: &self.gpu, objects: &self.scene.objects, view_proj };
        let mut timed = 0;
        let image = |name: sync::ImageName| {
            targets.named_image(name).or_else(|| scene_part::named_image(scene_part::all(&*self.shadows.borrow(), &self.parts), name))
        };
        for pass in &self.passes {
            // The barrier that orders the pass's declared uses is part of its time, as the
            // barriers it records itself are.
            let timer = pass.timer_name().map(|_| timed);
            if let Some(t) = timer {
                frame.timer.begin(ctx, cmd, t);
            }
            frame.sync.barrier(&mut self.shared_sync, (ctx, cmd), &pass.uses(), &image);
            pass.record(&rec);
            if let Some(t) = timer {
                frame.timer.end(ctx, cmd, t);
                timed += 1;
            }
        }
        // The colour target as the read-back and a window's blit take it; what the passes'
        // `collect` reads, as the host reads it or copied for it.
        let reads: Vec<HostRead> = self.passes.iter_mut().filter_map(|p| p.frame_work()).flat_map(|w| w.host_reads(f)).collect();
        let frame_end: Vec<sync::Use> = std::iter::once(sync::frame_end()).chain(reads.iter().map(HostRead::at_frame_end)).collect();
        frame.sync.barrier(&mut self.shared_sync, (ctx, cmd), &frame_end, &image);
        read_back::record_copies(ctx, cmd, &reads);
        if let Some(hook) = hook {
            hook.record(ctx, cmd, &targets.color)?;
        }
        // SAFETY: recording state.
        unsafe { ctx.device.end_command_buffer(cmd) }.ctx("vkEndCommandBuffer")
    }

    /// The point-light shadow cubes' texels (distance / radius) as the last frame left them,
    /// layer after layer (cube i: layers 6i … 6i + 5), row by row; for tests and tools.
    pub fn shadow_cube_depths(&self) -> Result<Vec<f32>, VkError> {
        self.shadows.borrow().omni.read_depths(self.ctx)
    }

    /// The sun's shadow map's texels (depth, row by row; blinn-phong, else one texel at the far
    /// plane); for tests and tools.
    pub fn sun_shadow_depths(&self) -> Result<Vec<f32>, VkError> {
        self.shadows.borrow().read_sun_map(self.ctx)
    }

    /// Copy frame `f`'s colour target (left in TRANSFER_SRC_OPTIMAL by the frame's last
    /// barrier, `sync::frame_end`, which orders later transfers after the colour writes) into
    /// host memory.
    fn read_back(&mut self, f: usize) -> Result<Vec<u8>, VkError> {
        let ctx = self.ctx;
        let image = self.frames[f].targets.as_ref().expect("made with the frame").color.raw;
        let (buffer, extent) = (self.readbacks.raw(f), self.extent);
        commands::one_shot(ctx, |cmd| commands::copy_colour_to_host(ctx, cmd, image, extent, buffer))?;
        Ok(self.readbacks.bytes(f).to_vec())
    }

    /// Hand the sink the images the slots' own commands copied (in frame order), each once its
    /// slot was collected.
    fn hand_over(&mut self, slots: std::ops::Range<usize>, sink: &mut dyn FrameSink, stats: &mut FrameStats) -> Result<(), RenderError> {
        let mut ready: Vec<(u32, usize)> =
            slots.filter(|&f| !self.pending[f]).filter_map(|f| Some((self.in_flight_image[f].take()?, f))).collect();
        ready.sort_unstable();
        for frame_slot in ready {
            self.hand_image(frame_slot, false, sink, stats)?;
        }
        Ok(())
    }

    /// Hand the sink frame `i`'s image from slot `f`'s read-back buffer — copied there now where
    /// `copy`, else by the frame's own commands — counting the time it took.
    fn hand_image(
        &mut self,
        (i, f): (u32, usize),
        copy: bool,
        sink: &mut dyn FrameSink,
        stats: &mut FrameStats,
    ) -> Result<(), RenderError> {
        let taken = Instant::now();
        let rgba = if copy { self.read_back(f)? } else { self.readbacks.bytes(f).to_vec() };
        stats.read_back.0 += 1;
        stats.read_back.1 += taken.elapsed().as_secs_f64() * 1e3;
        sink.image(i, rgba)
    }
}

/// Records the copy of a sequence frame's colour target into its slot's read-back buffer at the
/// end of the frame's own commands: the GPU goes on with the next frame while the host takes
/// this one's bytes.
struct CopyToHost {
    buffer: vk::Buffer,
    extent: vk::Extent2D,
}

impl FrameHook for CopyToHost {
    fn record(&mut self, ctx: &Context, cmd: vk::CommandBuffer, colour: &Image) -> Result<(), VkError> {
        commands::copy_colour_to_host(ctx, cmd, colour.raw, self.extent, self.buffer);
        Ok(())
    }

    fn semaphores(&self) -> (Option<(vk::Semaphore, vk::PipelineStageFlags)>, Option<vk::Semaphore>) {
        (None, None)
    }
}

impl PartHost for Renderer<'_> {
    fn part_access(&mut self) -> PartAccess<'_> {
        PartAccess { ctx: self.ctx, scene: &mut self.scene, parts: &mut self.parts }
    }
}

/// `scene`'s lights as the GPU reads them: marked with the shadow slots `omni` chose.
fn gpu_lights(scene: &Scene, omni: &OmniShadows) -> Vec<PointLight> {
    let mut lights = scene.lights.clone();
    omni.mark(&mut lights);
    lights
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        let _ = ctx.wait_idle();
        for frame in &mut self.frames {
            frame.destroy(ctx);
        }
        self.readbacks.destroy(ctx);
        for p in &mut self.passes {
            p.destroy(ctx);
        }
        // SAFETY: the device is idle; a null handle is ignored.
        unsafe { ctx.device.destroy_command_pool(self.command_pool, None) };
        self.gpu.destroy(ctx);
        self.shadows.borrow_mut().destroy(ctx);
        ml_vk::Release::release(&mut self.parts, ctx);
    }
}
