//! Headless rendering (SPEC §5): offscreen targets, frames in flight, a read-back of the
//! last frame into host memory. No window system needed.

use crate::cluster_build::GpuClusterBuilder;
use crate::compute_pass::ComputePass;
use crate::deferred::ComputeLighting;
use crate::error::RenderError;
use crate::frame::{self, FrameInFlight, FrameSetup, FRAMES_IN_FLIGHT};
use crate::gpu_mesh::GpuMesh;
use crate::object_textures::ObjectTextureSets;
use crate::omni_shadow::{OmniShadows, ShadowedLight};
use crate::raster::{object_data, DrawList, PassFrame, RasterPass};
use crate::report::{CpuPhases, FrameStats};
use crate::scene_textures::{SceneTextures, ShadowInputs};
use crate::settings::ShadingModel;
use crate::settings::{DebugView, RenderSettings};
use crate::targets::{depth_format, Output, Targets};
use crate::tonemap::ToneMap;
use ml_cpu::blinn_phong::shadow_view_proj;
use ml_cpu::camera::Camera;
use ml_cpu::cluster::{ClusterAssigner, ClusterGrid, ClusterLists, ClusterStats};
use ml_cpu::gpu_types::{ClusterRange, FrameUniforms, LightCone, ObjectData, PointLight};
use ml_cpu::lights::{animate_into, animation_offset};
use ml_cpu::omni_shadow::shadowed_lights;
use ml_cpu::scene::Scene;
use ml_vk::descriptors::{allocate_set, write_image};
use ml_vk::{commands, release_on_error, vk, Buffer, Context, Image, VkError, VkResultExt};
use std::time::Instant;

/// CPU-side cluster state of `clustered-cpu`: the assigner and this frame's lists.
struct CpuClusters {
    assigner: ClusterAssigner,
    lists: ClusterLists,
}

/// A rendered image (tightly packed RGBA8, row 0 at the top) and its measurements.
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub stats: FrameStats,
}

pub struct HeadlessRenderer<'a> {
    ctx: &'a Context,
    scene: Scene,
    settings: RenderSettings,
    extent: vk::Extent2D,
    pass: RasterPass,
    /// Set 1 of every shading pipeline (blinn-phong's shadow map, sky, albedo and normal maps,
    /// the point-light shadow cubes).
    textures: SceneTextures,
    /// Set 2 of the mesh pipelines: each object's own textures.
    object_textures: ObjectTextureSets,
    /// Point-light shadow cubes (a stand-in without shadowed lights).
    omni: OmniShadows,
    /// The lights with a shadow cube (cube i: `shadowed[i]`), and where they are this frame.
    shadowed: Vec<u32>,
    shadowed_now: Vec<ShadowedLight>,
    /// The sun's shadow-map view-projection (blinn-phong).
    shadow_view_proj: glam::Mat4,
    meshes: Vec<GpuMesh>,
    command_pool: vk::CommandPool,
    descriptor_pool: vk::DescriptorPool,
    frames: Vec<FrameInFlight>,
    readback: Option<Buffer>,
    /// Lights of the current frame (animated copy of the scene's).
    animated: Vec<PointLight>,
    clusters: Option<CpuClusters>,
    /// The cluster grid (fixed: headless rendering keeps camera and size; its shader
    /// parameters are also set for `forward`, which ignores them).
    grid: ClusterGrid,
    /// clustered-gpu, deferred-compute: the compute passes and their shared buffers.
    builder: Option<GpuClusterBuilder>,
    /// deferred-compute: the lighting compute pass.
    lighting: Option<ComputeLighting>,
    /// deferred, deferred-clustered: the tone map after the render pass.
    tonemap: Option<ToneMap>,
    /// Every object's transform and material (draws push their index; the G-buffer stores it).
    objects: Option<Buffer>,
    /// Spot cones, parallel to the lights (static: only positions animate).
    cones: Option<Buffer>,
    /// --debug-view shadow-map: the pass that paints the map over the output, and its set per
    /// frame slot (pointing at that slot's colour target).
    shadow_map_view: Option<(ComputePass, Vec<vk::DescriptorSet>)>,
    /// clustered-gpu: light-index entries every frame recorded from now on must hold (grows
    /// when a frame reports it needed more).
    required_indices: usize,
    /// Per frame slot: whether the frame it last ran overflowed its light-index list.
    overflowed: Vec<bool>,
    /// Per frame slot: whether it has been submitted since its results were last collected.
    pending: Vec<bool>,
    /// Top of the heat-map scale (lights per cluster), from the newest known frame.
    heat_top: f32,
    /// Slot of the frame that was read back last.
    last_frame: usize,
    /// Format of the depth target (targets are made again on a resize).
    depth_format: vk::Format,
}

/// Copies into host-visible buffers, then read by the CPU.
const TRANSFER_TO_HOST: ((vk::PipelineStageFlags, vk::AccessFlags), (vk::PipelineStageFlags, vk::AccessFlags)) =
    ((vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ));

/// Most light-index entries clustered-cpu builds (512 MiB of indices, twice that while
/// assigning); beyond it the render fails with a clear message.
const MAX_CPU_LIST_ENTRIES: usize = 1 << 27;

/// Heat-map top before any frame has reported its maximum (clustered-gpu's first frames).
const DEFAULT_HEAT_TOP: f32 = 64.0;
/// clustered-gpu re-renders a final frame whose lists overflowed (after growing them); if it
/// still overflows this often something is wrong, and the render fails instead of lying.
const MAX_RERENDERS: u32 = 2;

/// What a window adds to each frame (the viewer): commands recorded after the frame's passes,
/// in the same command buffer, and the semaphores its submission waits on and signals.
pub trait FrameHook {
    /// Record after the frame's passes; `colour` is the frame's colour target (the image a
    /// headless render reads back), in TRANSFER_SRC_OPTIMAL, and stays so.
    fn record(&mut self, ctx: &Context, cmd: vk::CommandBuffer, colour: &Image) -> Result<(), VkError>;
    /// The semaphore the submission waits on (and at which stage), and the one it signals.
    fn semaphores(&self) -> (Option<(vk::Semaphore, vk::PipelineStageFlags)>, Option<vk::Semaphore>);
}

impl<'a> HeadlessRenderer<'a> {
    pub fn new(ctx: &'a Context, mut scene: Scene, settings: RenderSettings) -> Result<HeadlessRenderer<'a>, RenderError> {
        settings.check(ctx, scene.lights.len())?;
        if !scene.cones.is_empty() && scene.cones.len() != scene.lights.len() {
            return Err(RenderError::Invalid(format!("the scene has {} spot cones for {} lights", scene.cones.len(), scene.lights.len())));
        }
        let shadowed = mark_shadowed(&mut scene, &settings);
        let depth = depth_format(ctx, Output::of(settings.technique))?;
        let extent = vk::Extent2D { width: settings.width, height: settings.height };
        // clustered-gpu animates on the GPU; the others keep an animated copy on the CPU.
        let animated = if settings.technique.is_gpu_built() { Vec::new() } else { scene.lights.clone() };
        let grid = ClusterGrid::new(settings.clusters, settings.width, settings.height, &scene.camera);
        let clusters =
            settings.technique.is_cpu_built().then(|| CpuClusters { assigner: ClusterAssigner::new(), lists: ClusterLists::default() });
        let blinn_phong = settings.shading == ShadingModel::BlinnPhong;
        // Each of these needs the ones before it; a failure releases those.
        let gbuffer_depth = depth_format(ctx, Output::GBuffer)?;
        let mut omni = OmniShadows::new(ctx, settings.omni)?;
        let mut textures = release_on_error(ctx, SceneTextures::new(ctx, blinn_phong, gbuffer_depth, &omni), &mut [&mut omni])?;
        let made = ObjectTextureSets::new(ctx, &scene.textures, &scene.objects);
        let mut object_textures = release_on_error(ctx, made, &mut [&mut omni, &mut textures])?;
        let layouts = (textures.set_layout, object_textures.set_layout);
        let made = RasterPass::new(ctx, depth, (settings.technique, settings.lighting(&scene)), layouts);
        let pass = release_on_error(ctx, made, &mut [&mut omni, &mut textures, &mut object_textures])?;
        let (lo, hi) = scene.bounds();
        let shadow_view_proj = shadow_view_proj(lo, hi, scene.blinn_phong.sun_direction);
        let mut r = HeadlessRenderer {
            ctx,
            scene,
            settings,
            extent,
            pass,
            textures,
            object_textures,
            omni,
            shadowed,
            shadowed_now: Vec::new(),
            shadow_view_proj,
            meshes: Vec::new(),
            command_pool: vk::CommandPool::null(),
            descriptor_pool: vk::DescriptorPool::null(),
            frames: Vec::new(),
            readback: None,
            animated,
            clusters,
            grid,
            builder: None,
            lighting: None,
            tonemap: None,
            objects: None,
            cones: None,
            shadow_map_view: None,
            required_indices: 0,
            overflowed: vec![false; FRAMES_IN_FLIGHT],
            pending: vec![false; FRAMES_IN_FLIGHT],
            heat_top: DEFAULT_HEAT_TOP,
            last_frame: 0,
            depth_format: depth,
        };
        // Anything made before a failure is released by Drop.
        r.create_resources()?;
        r.create_frames()?;
        Ok(r)
    }

    /// Render with `settings` from now on where they differ from the current ones only in
    /// what the pipelines do not depend on — size, cluster grid, debug view, frames, clock —
    /// and say so (true); false, changing nothing, for anything else (make a new renderer).
    /// New frame slots (targets, their sets, per-frame buffers), cluster grid, clustered-gpu
    /// builder for a new grid, tone map and shadow-map view for a new debug view; pipelines,
    /// meshes, textures and the scene's buffers stay (the viewer's resizes and overlay).
    pub fn reconfigure(&mut self, settings: RenderSettings) -> Result<bool, RenderError> {
        let same_pipelines = RenderSettings {
            width: self.settings.width,
            height: self.settings.height,
            clusters: self.settings.clusters,
            debug_view: self.settings.debug_view,
            frames: self.settings.frames,
            time: self.settings.time,
            ..settings
        } == self.settings;
        if !same_pipelines {
            return Ok(false);
        }
        settings.check(self.ctx, self.scene.lights.len())?;
        let ctx = self.ctx;
        self.release_frames()?;
        let (new_grid, new_view) = (settings.clusters != self.settings.clusters, settings.debug_view != self.settings.debug_view);
        self.settings = settings;
        self.extent = vk::Extent2D { width: settings.width, height: settings.height };
        self.grid = ClusterGrid::new(settings.clusters, settings.width, settings.height, &self.scene.camera);
        if new_grid {
            self.make_builder()?;
        }
        if new_view {
            if let Some(mut t) = self.tonemap.take() {
                t.destroy(ctx);
            }
            if let Some((mut view, _)) = self.shadow_map_view.take() {
                view.destroy(ctx);
            }
            self.create_view_passes()?;
        }
        self.create_frames()?;
        Ok(true)
    }

    /// Light the scene with `lights` from now on (the viewer's light count, layout or radius
    /// changed): new light buffers, frame slots and, for clustered-gpu, builder; pipelines,
    /// meshes and textures stay. Scenes with spot lights refuse (their cones belong to their
    /// lights and are compiled into the pipelines): make a new renderer for those.
    pub fn set_lights(&mut self, lights: Vec<PointLight>) -> Result<(), RenderError> {
        if !self.scene.cones.is_empty() {
            return Err(RenderError::Invalid("a scene with spot lights cannot change its lights in place".into()));
        }
        self.settings.check(self.ctx, lights.len())?;
        self.release_frames()?;
        self.scene.lights = lights;
        self.shadowed = mark_shadowed(&mut self.scene, &self.settings);
        self.animated = if self.settings.technique.is_gpu_built() { Vec::new() } else { self.scene.lights.clone() };
        self.make_builder()?;
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
        self.overflowed.fill(false);
        if let Some(mut b) = self.readback.take() {
            b.destroy(ctx);
        }
        if let Some((_, sets)) = &mut self.shadow_map_view {
            sets.clear();
        }
        // SAFETY: the device is idle and the frames that used the pool's sets are gone.
        unsafe { ctx.device.reset_descriptor_pool(self.descriptor_pool, vk::DescriptorPoolResetFlags::empty()) }
            .ctx("vkResetDescriptorPool")
    }

    /// What every frame shares: meshes, the shadow map, pools, the scene's buffers, the
    /// technique's compute passes.
    fn create_resources(&mut self) -> Result<(), VkError> {
        let ctx = self.ctx;
        self.upload_objects()?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create infos.
        self.command_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }.ctx("vkCreateCommandPool")?;
        self.make_builder()?;
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        // One cone per light where the scene has spots; else one the shaders never read.
        let cones = if self.scene.cones.is_empty() { vec![LightCone::NONE] } else { self.scene.cones.clone() };
        self.cones = Some(Buffer::device_local_with(ctx, "light cones", bytemuck::cast_slice(&cones), usage)?);
        if self.settings.technique.lights_in_compute() {
            self.lighting = Some(ComputeLighting::new(ctx, self.textures.set_layout, self.settings.lighting(&self.scene))?);
        }
        self.create_view_passes()?;
        // Per frame at most: the shading set (1 uniform + 5 storage: lights, cluster ranges and
        // indices, objects, cones), the build set (1 uniform + 8 storage), the lighting set
        // (1 uniform, 5 storage, 4 sampled images, 1 storage image), the subpass input set (4
        // input attachments), the tone map's set (1 sampled image, 1 storage image) and the
        // shadow-map view's (1 storage image).
        let n = FRAMES_IN_FLIGHT as u32;
        let sizes = [
            vk::DescriptorPoolSize { ty: vk::DescriptorType::UNIFORM_BUFFER, descriptor_count: 3 * n },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: 18 * n },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER, descriptor_count: 5 * n },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_IMAGE, descriptor_count: 3 * n },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::INPUT_ATTACHMENT, descriptor_count: 4 * n },
        ];
        let dp_info = vk::DescriptorPoolCreateInfo::default().max_sets(6 * n).pool_sizes(&sizes);
        // SAFETY: as above.
        self.descriptor_pool = unsafe { ctx.device.create_descriptor_pool(&dp_info, None) }.ctx("vkCreateDescriptorPool")?;
        Ok(())
    }

    /// The scene's objects on the GPU: its meshes, the object buffer, and (blinn-phong) the
    /// sun's shadow map of them.
    fn upload_objects(&mut self) -> Result<(), VkError> {
        let ctx = self.ctx;
        for kind in self.scene.mesh_kinds() {
            let mesh = self.scene.mesh(kind).ok_or_else(|| VkError::Limit(format!("the scene has no mesh {kind:?}")))?;
            self.meshes.push(GpuMesh::upload(ctx, kind, &mesh)?);
        }
        let objects: Vec<ObjectData> = self.scene.objects.iter().map(object_data).collect();
        self.objects =
            Some(Buffer::device_local_with(ctx, "objects", bytemuck::cast_slice(&objects), vk::BufferUsageFlags::STORAGE_BUFFER)?);
        if self.settings.shading == ShadingModel::BlinnPhong {
            let inputs = ShadowInputs { scene: &self.scene, meshes: &self.meshes, view_proj: self.shadow_view_proj };
            self.textures.render_shadow_map(ctx, &inputs)?;
        }
        Ok(())
    }

    /// Draw `scene`'s objects (and meshes) from now on, lights and camera unchanged (the
    /// viewer's object and material combos): new meshes, object buffer, sun shadow map and
    /// frame slots; pipelines stay. False, changing nothing, where either scene has object
    /// textures (their sets and the pipelines' texture code depend on them).
    pub fn set_objects(&mut self, scene: &Scene) -> Result<bool, RenderError> {
        let Some(&stand_ins) = self.object_textures.per_object.first() else { return Ok(false) };
        if !scene.textures.is_empty() || !self.scene.textures.is_empty() {
            return Ok(false);
        }
        let ctx = self.ctx;
        self.release_frames()?;
        for mesh in &mut self.meshes {
            mesh.destroy(ctx);
        }
        self.meshes.clear();
        if let Some(mut b) = self.objects.take() {
            b.destroy(ctx);
        }
        self.scene.objects = scene.objects.clone();
        self.scene.meshes = scene.meshes.clone();
        let (lo, hi) = self.scene.bounds();
        self.shadow_view_proj = shadow_view_proj(lo, hi, self.scene.blinn_phong.sun_direction);
        // Without textures every object binds the one set of stand-ins.
        self.object_textures.per_object = vec![stand_ins; self.scene.objects.len()];
        self.upload_objects()?;
        self.create_frames()?;
        Ok(true)
    }

    /// The passes the debug view decides: the tone map (pbr's curve, not for surface views) of
    /// the subpass techniques and the shadow-map view's compute pass.
    fn create_view_passes(&mut self) -> Result<(), VkError> {
        let ctx = self.ctx;
        if self.settings.technique.lights_in_subpass() {
            let surface_view = !matches!(self.settings.debug_view, DebugView::None | DebugView::ClusterHeat);
            self.tonemap = Some(ToneMap::new(ctx, self.settings.shading == ShadingModel::Pbr && !surface_view)?);
        }
        if matches!(self.settings.debug_view, DebugView::ShadowMap | DebugView::ShadowCube) {
            let bindings = [(0, vk::DescriptorType::STORAGE_IMAGE)];
            // constant_id 0 (CUBE): the point-light cube instead of the sun's map.
            let cube = [(0, u32::from(self.settings.debug_view == DebugView::ShadowCube))];
            let pass = ComputePass::new(ctx, &bindings, &[self.textures.set_layout], (ml_shaders::DEBUG_SHADOW_MAP_COMP, &cube))?;
            self.shadow_map_view = Some((pass, Vec::new()));
        }
        Ok(())
    }

    /// The frame slots (targets at the current size, their sets and buffers), the cluster
    /// boxes of clustered-gpu and the read-back buffer.
    fn create_frames(&mut self) -> Result<(), VkError> {
        let ctx = self.ctx;
        let depth = self.depth_format;
        let render_pass = self.pass.render_pass;
        let extent = self.extent;
        let output = self.pass.output;
        let gbuffer = self.pass.gbuffer();
        let make_targets = || Targets::new(ctx, render_pass, extent, depth, (output, gbuffer));
        let setup = FrameSetup {
            pool: self.command_pool,
            descriptor_pool: self.descriptor_pool,
            set_layout: self.pass.set_layout,
            light_count: self.scene.lights.len(),
            cluster_count: self.settings.clusters.count(),
            // Clustered techniques start with room for 16 entries per light (grown on demand);
            // forward never reads the list.
            initial_indices: if self.settings.technique.is_clustered() { self.scene.lights.len() * 16 } else { 1 },
            passes: self.pass_names().len() as u32,
            make_targets: &make_targets,
            builder: self.builder.as_ref(),
            lighting: self.lighting.as_ref(),
            subpasses: self.tonemap.as_ref().map(|t| (&self.pass, t)),
            objects: self.objects.as_ref().map_or(vk::Buffer::null(), |b| b.raw),
            cones: self.cones.as_ref().map_or(vk::Buffer::null(), |b| b.raw),
        };
        for _ in 0..FRAMES_IN_FLIGHT {
            self.frames.push(FrameInFlight::new(ctx, &setup)?);
        }
        if let Some((pass, _)) = &self.shadow_map_view {
            let mut sets = Vec::new();
            let layout = pass.set_layout;
            for frame in &self.frames {
                let set = allocate_set(ctx, self.descriptor_pool, layout)?;
                let target = frame.targets.as_ref().expect("made with the frame");
                let info = vk::DescriptorImageInfo::default().image_view(target.color.view).image_layout(vk::ImageLayout::GENERAL);
                write_image(ctx, set, 0, vk::DescriptorType::STORAGE_IMAGE, info);
                sets.push(set);
            }
            self.shadow_map_view.as_mut().expect("set above").1 = sets;
        }
        // The boxes depend on projection and size only: once here.
        self.compute_cluster_bounds()?;
        let bytes = extent.width as u64 * extent.height as u64 * 4;
        self.readback =
            Some(Buffer::new(ctx, "read-back", bytes, vk::BufferUsageFlags::TRANSFER_DST, gpu_allocator::MemoryLocation::GpuToCpu)?);
        Ok(())
    }

    /// The passes the timer reports, in order.
    fn pass_names(&self) -> Vec<&'static str> {
        let mut names = if self.omni.active() { vec!["omni shadows"] } else { Vec::new() };
        names.extend(self.technique_pass_names());
        names
    }

    fn technique_pass_names(&self) -> Vec<&'static str> {
        let t = self.settings.technique;
        if t.lights_in_compute() {
            vec!["cluster build", "g-buffer", "lighting"]
        } else if t.lights_in_subpass() {
            vec!["g-buffer + lighting", "tone map"]
        } else if t.is_gpu_built() {
            vec!["cluster build", t.name()]
        } else {
            vec![t.name()]
        }
    }

    /// Render `settings.frames` frames, two in flight, and read back the last one. With
    /// clustered-gpu, a last frame whose light lists overflowed is rendered again once the
    /// lists have grown, so the image is never one with lights missing.
    pub fn render(&mut self) -> Result<RenderOutput, RenderError> {
        let mut stats = FrameStats::new(&self.pass_names());
        let start = Instant::now();
        let mut last = 0;
        for i in 0..self.settings.frames {
            last = i as usize % FRAMES_IN_FLIGHT;
            self.run_frame(last, self.settings.clock(i), &mut stats, None)?;
        }
        self.collect_all(&mut stats)?;
        let mut rerenders = 0;
        while self.overflowed[last] {
            if rerenders == MAX_RERENDERS {
                return Err(RenderError::Invalid(format!(
                    "clustered-gpu: the light lists still overflowed after {MAX_RERENDERS} re-renders ({} entries needed)",
                    self.required_indices
                )));
            }
            rerenders += 1;
            stats.rerendered_frames += 1;
            last = (last + 1) % FRAMES_IN_FLIGHT;
            self.run_frame(last, self.settings.clock(self.settings.frames - 1), &mut stats, None)?;
            self.collect_all(&mut stats)?;
        }
        stats.wall_ms = start.elapsed().as_secs_f64() * 1e3;
        if self.pass.output == Output::Subpasses {
            let targets = self.frames[0].targets.as_ref().expect("made with the frame");
            stats.gbuffer_lazily_allocated = Some(targets.gbuffer.iter().all(|i| i.is_lazily_allocated()));
        }
        // Averages are over every frame rendered, re-renders included.
        stats.frames = self.settings.frames + stats.rerendered_frames;
        self.last_frame = last;
        let rgba = self.read_back(last)?;
        Ok(RenderOutput { width: self.extent.width, height: self.extent.height, rgba, stats })
    }

    /// The scene's camera (where the next frame is seen from).
    pub fn camera(&self) -> Camera {
        self.scene.camera
    }

    /// See the next frames from `camera` (the viewer's moving camera): the cluster grid
    /// follows. clustered-gpu's view-space cluster boxes depend on the projection only: made
    /// again when it changed (field of view, near, far).
    pub fn set_camera(&mut self, camera: Camera) -> Result<(), RenderError> {
        self.scene.camera = camera;
        let projection = self.grid.projection;
        self.grid = ClusterGrid::new(self.settings.clusters, self.extent.width, self.extent.height, &camera);
        if self.grid.projection != projection && self.builder.is_some() {
            // Frame 0's uniforms carry the projection to the bounds pass: wait for its frame.
            self.ctx.wait_idle()?;
            self.compute_cluster_bounds()?;
        }
        Ok(())
    }

    /// clustered-gpu and deferred-compute: a fresh GPU cluster builder for the scene's lights
    /// and the grid (its lists start small again); nothing for the other techniques.
    fn make_builder(&mut self) -> Result<(), VkError> {
        if let Some(mut b) = self.builder.take() {
            b.destroy(self.ctx);
        }
        self.required_indices = 0;
        if self.settings.technique.is_gpu_built() {
            self.builder = Some(GpuClusterBuilder::new(self.ctx, &self.scene.lights, self.settings.clusters.count())?);
        }
        Ok(())
    }

    /// clustered-gpu's view-space cluster boxes, from the grid frame 0's uniforms carry (its
    /// frame must be done); nothing without a GPU builder.
    fn compute_cluster_bounds(&mut self) -> Result<(), VkError> {
        if self.builder.is_some() {
            self.write_uniforms(0, 0.0);
            let set = self.frames[0].gpu.as_ref().expect("made with the builder").set;
            self.builder.as_ref().expect("checked").compute_bounds(self.ctx, set)?;
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
        if let Some(gpu) = &self.frames[f].gpu {
            let feedback = gpu.feedback();
            let needed = feedback.needed as usize;
            let clusters = self.settings.clusters.count();
            stats.clusters =
                Some(ClusterStats { mean_lights: needed as f64 / clusters as f64, max_lights: feedback.max_count, index_len: needed });
            self.heat_top = feedback.max_count.max(1) as f32;
            self.overflowed[f] = feedback.overflowed != 0;
            if self.overflowed[f] {
                stats.overflowed_frames += 1;
                eprintln!(
                    "clustered-gpu: a frame needed {needed} light-index entries but its list held {}; growing the lists (that frame is re-rendered if it is the last)",
                    self.frames[f].index_capacity()
                );
                self.required_indices = self.required_indices.max(needed);
            }
        }
        Ok(())
    }

    fn collect_all(&mut self, stats: &mut FrameStats) -> Result<(), VkError> {
        (0..FRAMES_IN_FLIGHT).try_for_each(|f| self.collect(f, stats))
    }

    /// Write slot `f`'s buffers for clock `t`; the milliseconds of CPU light assignment in it
    /// (None where the CPU does not assign).
    fn update_frame(&mut self, f: usize, t: f32, stats: &mut FrameStats) -> Result<Option<f64>, VkError> {
        let mut assign_ms = None;
        if self.builder.is_some() {
            if self.frames[f].ensure_index_capacity(self.ctx, self.required_indices)? {
                stats.index_growths += 1;
            }
        } else {
            animate_into(&self.scene.lights, t, &mut self.animated);
            self.frames[f].lights.write(0, &self.animated);
        }
        if let Some(c) = &mut self.clusters {
            let start = Instant::now();
            // The CPU also holds the lists (and their pairs) in memory: cap what it builds.
            let limit = frame::max_index_entries(self.ctx).min(MAX_CPU_LIST_ENTRIES);
            c.assigner
                .assign(&self.grid, &self.animated, &mut c.lists, limit)
                .map_err(|e| frame::lists_too_long(e.at_least, limit, "clustered-cpu builds (or the device binds)"))?;
            assign_ms = Some(start.elapsed().as_secs_f64() * 1e3);
            let cluster_stats = c.lists.stats();
            self.heat_top = cluster_stats.max_lights.max(1) as f32;
            stats.clusters = Some(cluster_stats);
            if self.frames[f].upload_clusters(self.ctx, &c.lists)? {
                stats.index_growths += 1;
            }
        }
        let offset = animation_offset(t);
        self.shadowed_now = self
            .shadowed
            .iter()
            .map(|&i| {
                let p = self.scene.lights[i as usize].position_radius;
                // The same sum the light buffer (CPU or GPU animation) holds for this light.
                ShadowedLight { position: glam::Vec3::new(p[0] + offset.x, p[1] + offset.y, p[2] + offset.z), radius: p[3] }
            })
            .collect();
        self.write_uniforms(f, t);
        Ok(assign_ms)
    }

    fn write_uniforms(&mut self, f: usize, t: f32) {
        let g = &self.grid;
        let debug_view = self.settings.debug_view.code();
        let cam = &self.scene.camera;
        let bp = &self.scene.blinn_phong;
        // World size of a shadow-map texel: the orthographic projection's first row is the
        // sun's x axis over the half-width it covers.
        let shadow_texel_world = 2.0 / self.shadow_view_proj.row(0).truncate().length() / self.textures.shadow_size as f32;
        let frame = &mut self.frames[f];
        let uniforms = FrameUniforms {
            view: g.view.to_cols_array_2d(),
            proj: g.projection.to_cols_array_2d(),
            inv_view_proj: (g.projection * g.view).inverse().to_cols_array_2d(),
            // w: clip w = w·depth + (1 − w) (Camera::w_of_depth).
            camera_pos: cam.position.extend(cam.w_of_depth().0).to_array(),
            light_count: self.scene.lights.len() as u32,
            ambient: self.scene.ambient,
            omni_texel: self.omni.texel(),
            directional_count: self.scene.directional.len() as u32,
            cluster_dims: [g.dims.x, g.dims.y, g.dims.z, debug_view],
            viewport: [self.extent.width, self.extent.height, 0, 0],
            cluster_slices: [g.log_scale, g.log_bias, self.heat_top, 0.0],
            cluster_frustum: [g.near, g.far, g.projection.x_axis.x, g.projection.y_axis.y],
            light_animation: animation_offset(t).extend(0.0).to_array(),
            cluster_build: [frame.index_capacity() as u32, 0, 0, 0],
            shadow_view_proj: self.shadow_view_proj.to_cols_array_2d(),
            sun_direction: bp.sun_direction.extend(1.0 / self.textures.shadow_size as f32).to_array(),
            sun_strength: bp.sun_strength.extend(shadow_texel_world).to_array(),
            spot_position_range: bp.spot.position.extend(bp.spot.range).to_array(),
            spot_direction_power: bp.spot.direction.extend(bp.spot.power).to_array(),
            spot_strength: bp.spot.strength.extend(0.0).to_array(),
            ambient_light: bp.ambient.extend(0.0).to_array(),
            texture_transform: bp.texture_transform.to_cols_array(),
            directional_direction: std::array::from_fn(|i| {
                self.scene.directional.get(i).map_or([0.0; 4], |d| d.direction.extend(0.0).to_array())
            }),
            directional_color: std::array::from_fn(|i| self.scene.directional.get(i).map_or([0.0; 4], |d| d.color.extend(0.0).to_array())),
        };
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
        let mut pass = 0;
        if self.omni.active() {
            frame.timer.begin(ctx, cmd, pass);
            self.omni.record(ctx, cmd, &self.shadowed_now, (&self.meshes, &self.scene.objects));
            frame.timer.end(ctx, cmd, pass);
            pass += 1;
        }
        if let (Some(builder), Some(gpu)) = (&self.builder, &frame.gpu) {
            frame.timer.begin(ctx, cmd, pass);
            builder.record(ctx, cmd, gpu);
            frame.timer.end(ctx, cmd, pass);
            pass += 1;
        }
        frame.timer.begin(ctx, cmd, pass);
        let targets = frame.targets.as_ref().expect("made with the frame");
        let legend = self.settings.debug_view == DebugView::ClusterHeat;
        let pass_frame = PassFrame {
            framebuffer: targets.framebuffer,
            extent: self.extent,
            set: frame.set,
            textures: self.textures.set,
            input_set: frame.input_set,
        };
        let draws = DrawList { meshes: &self.meshes, objects: &self.scene.objects, object_sets: &self.object_textures.per_object };
        self.pass.record(ctx, cmd, &pass_frame, &draws, legend);
        frame.timer.end(ctx, cmd, pass);
        if let Some(lighting) = &self.lighting {
            pass += 1;
            frame.timer.begin(ctx, cmd, pass);
            lighting.record(ctx, cmd, [frame.lighting_set, self.textures.set], targets, self.extent);
            frame.timer.end(ctx, cmd, pass);
        }
        if let Some(tonemap) = &self.tonemap {
            pass += 1;
            frame.timer.begin(ctx, cmd, pass);
            tonemap.record(ctx, cmd, frame.tonemap_set, targets, self.extent);
            frame.timer.end(ctx, cmd, pass);
        }
        if let Some((view, sets)) = &self.shadow_map_view {
            // Over whatever the technique drew (untimed: a debug view).
            view.record_into_colour_target(ctx, cmd, &[sets[f], self.textures.set], targets.color.raw, self.extent);
        }
        if let Some(hook) = hook {
            hook.record(ctx, cmd, &targets.color)?;
        }
        // SAFETY: recording state.
        unsafe { ctx.device.end_command_buffer(cmd) }.ctx("vkEndCommandBuffer")
    }

    /// The cluster lists the GPU built for the frame `render` returned (clustered-gpu; None
    /// otherwise), copied to the host. Lists are sorted per cluster (the GPU's order is not
    /// deterministic); for tests and tools, not the frame loop.
    pub fn gpu_cluster_lists(&self) -> Result<Option<ClusterLists>, VkError> {
        if self.builder.is_none() {
            return Ok(None);
        }
        let ctx = self.ctx;
        let frame = &self.frames[self.last_frame];
        let needed = frame.gpu.as_ref().expect("clustered-gpu frame").feedback().needed as u64;
        let copies = [(&frame.cluster_ranges, frame.cluster_ranges.size), (&frame.light_indices, (needed * 4).max(4))];
        let mut host = Vec::new();
        for (_, size) in copies {
            host.push(Buffer::new(
                ctx,
                "cluster read-back",
                size,
                vk::BufferUsageFlags::TRANSFER_DST,
                gpu_allocator::MemoryLocation::GpuToCpu,
            )?);
        }
        let copied = commands::one_shot(ctx, |cmd| {
            for ((src, size), dst) in copies.iter().zip(&host) {
                // SAFETY: recording state; both buffers are alive and large enough. The frame's
                // build ended with a barrier making its writes visible to transfers.
                unsafe { ctx.device.cmd_copy_buffer(cmd, src.raw, dst.raw, &[vk::BufferCopy::default().size(*size)]) };
            }
            commands::memory_barrier(ctx, cmd, TRANSFER_TO_HOST.0, TRANSFER_TO_HOST.1);
        });
        let lists = copied.map(|()| {
            let ranges: Vec<ClusterRange> = bytemuck::pod_collect_to_vec(host[0].mapped());
            let all: Vec<u32> = bytemuck::pod_collect_to_vec(host[1].mapped());
            let mut indices = Vec::with_capacity(needed as usize);
            for r in &ranges {
                let mut list = all[r.offset as usize..(r.offset + r.count) as usize].to_vec();
                list.sort_unstable();
                indices.extend(list);
            }
            ClusterLists { ranges, indices }
        });
        for mut b in host {
            b.destroy(ctx);
        }
        lists.map(Some)
    }

    /// Copy frame `f`'s colour target (left in TRANSFER_SRC_OPTIMAL by the render pass, whose
    /// outgoing dependency orders this copy after the colour writes) into host memory.
    fn read_back(&mut self, f: usize) -> Result<Vec<u8>, VkError> {
        let ctx = self.ctx;
        let image = self.frames[f].targets.as_ref().expect("made with the frame").color.raw;
        let buffer = self.readback.as_ref().expect("created with the renderer");
        let extent = self.extent;
        commands::one_shot(ctx, |cmd| commands::copy_colour_to_host(ctx, cmd, image, extent, buffer.raw))?;
        Ok(buffer.mapped().to_vec())
    }
}

/// Pick the lights that get a shadow cube (the strongest as seen from the camera) and mark
/// them: PointLight::color[3] = cube index + 1. Returns their indices, cube order.
fn mark_shadowed(scene: &mut Scene, settings: &RenderSettings) -> Vec<u32> {
    let shadowed = settings.omni.map_or(Vec::new(), |o| shadowed_lights(&scene.lights, o.lights as usize, scene.camera.position));
    for (cube, &i) in shadowed.iter().enumerate() {
        scene.lights[i as usize].color[3] = (cube + 1) as f32;
    }
    shadowed
}

impl Drop for HeadlessRenderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        let _ = ctx.wait_idle();
        for frame in &mut self.frames {
            frame.destroy(ctx);
        }
        if let Some(mut b) = self.readback.take() {
            b.destroy(ctx);
        }
        if let Some(mut b) = self.builder.take() {
            b.destroy(ctx);
        }
        if let Some(mut l) = self.lighting.take() {
            l.destroy(ctx);
        }
        if let Some(mut t) = self.tonemap.take() {
            t.destroy(ctx);
        }
        for mut b in [self.objects.take(), self.cones.take()].into_iter().flatten() {
            b.destroy(ctx);
        }
        if let Some((mut view, _)) = self.shadow_map_view.take() {
            view.destroy(ctx);
        }
        for mesh in &mut self.meshes {
            mesh.destroy(ctx);
        }
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            ctx.device.destroy_descriptor_pool(self.descriptor_pool, None);
            ctx.device.destroy_command_pool(self.command_pool, None);
        }
        self.pass.destroy(ctx);
        self.textures.destroy(ctx);
        self.object_textures.destroy(ctx);
        self.omni.destroy(ctx);
    }
}
