//! The shadow atlas, GPU half (docs/DESIGN.md#shadow-atlas): one storage buffer of 32-bit
//! depths (distance / radius, as in the cube array) in Z-order, holding every visible face of
//! every shadowed light, and a table of where each light's faces lie (`ShadowCubeTiles`).
//! The shading passes read both through set 1 (omni_shadow.glsl); the atlas pass
//! (passes/omni_shadow_compute.rs) writes them each frame from the CPU's plan
//! (ml_cpu::shadow_atlas), drawing only the faces the plan says. Everything shadows take — the
//! atlas, the table and the raster's lists — fits the budget. Without an atlas both buffers
//! are small stand-ins the shaders never read.

use crate::error::RenderError;
use crate::shadows::shadow_settings::{AtlasSettings, OmniShadowSettings};
use gpu_allocator::MemoryLocation;
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::{OmniRasterCounters, ShadowCubeTiles};
use ml_cpu::shadow_atlas::{AtlasPlan, PlannedLight, ShadowAtlas, MIN_FACE};
use ml_shaders::common::NO_TILE;
use ml_vk::{vk, Buffer, Context};

/// Bytes of one (meshlet instance, face) pair and of one large triangle in the raster's lists.
const LIST_ENTRY: u64 = 8;
/// The most large triangles the raster lists (as the cube array's compute raster).
const MAX_LARGE: u64 = 1 << 20;

/// What the shadow raster's lists hold in the atlas: an eighth of the budget for the pairs, a
/// sixteenth (at most MAX_LARGE) for the large triangles. Past them the culling's or the
/// raster's own thread draws what did not fit (slow, nothing lost, reported).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasLists {
    pub pairs: u32,
    pub large: u32,
}

impl AtlasLists {
    fn for_budget(ctx: &Context, budget: u64) -> AtlasLists {
        let entries = |bytes: u64| (bytes.min(ctx.info.limits.max_storage_buffer_range as u64) / LIST_ENTRY).max(1) as u32;
        AtlasLists { pairs: entries(budget / 8), large: entries((budget / 16).min(MAX_LARGE * LIST_ENTRY)) }
    }

    fn bytes(&self) -> u64 {
        (self.pairs as u64 + self.large as u64) * LIST_ENTRY
    }
}

pub struct ShadowAtlasGpu {
    /// The depths, Z-ordered (a stand-in of one texel without an atlas).
    pub depths: Buffer,
    /// Per shadowed light, its faces (a stand-in of one entry without an atlas).
    pub tiles: Buffer,
    /// The plan-maker, which remembers last frame's faces (None without an atlas).
    allocator: Option<ShadowAtlas>,
    pub lists: AtlasLists,
    budget: u64,
}

impl ShadowAtlasGpu {
    pub fn new(ctx: &Context, settings: Option<OmniShadowSettings>) -> Result<ShadowAtlasGpu, RenderError> {
        let mut gpu = ShadowAtlasGpu {
            depths: Buffer::null(),
            tiles: Buffer::null(),
            allocator: None,
            lists: AtlasLists { pairs: 1, large: 1 },
            budget: 0,
        };
        let atlas = settings.and_then(|s| s.atlas().map(|a| (s.lights, a)));
        let (lights, depth_bytes) = match atlas {
            Some((lights, a)) => {
                gpu.budget = a.budget_bytes();
                gpu.lists = AtlasLists::for_budget(ctx, gpu.budget);
                let others = gpu.lists.bytes() + tables_bytes(lights);
                let room = gpu.budget.saturating_sub(others).min(ctx.info.limits.max_storage_buffer_range as u64);
                let allocator = ShadowAtlas::new(room).map_err(|e| {
                    RenderError::Invalid(format!("a shadow budget of {} MiB leaves {room} bytes for the atlas: {e}", a.budget_mib))
                })?;
                let bytes = allocator.bytes();
                gpu.allocator = Some(allocator);
                (lights, bytes)
            }
            None => (1, 4),
        };
        ml_vk::build(ctx, gpu, |g| {
            use vk::BufferUsageFlags as U;
            // Transfer source: tests and tools read the depths back.
            g.depths = Buffer::new(
                ctx,
                "shadow atlas",
                depth_bytes,
                U::STORAGE_BUFFER | U::TRANSFER_SRC | U::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )?;
            let tile_bytes = lights as u64 * size_of::<ShadowCubeTiles>() as u64;
            g.tiles = Buffer::new(ctx, "shadow atlas tiles", tile_bytes, U::STORAGE_BUFFER | U::TRANSFER_DST, MemoryLocation::GpuOnly)?;
            // Free space reads "nothing in reach" (the debug view shows it black); the faces
            // are cleared before they are drawn.
            let (depths, tiles) = (g.depths.raw, g.tiles.raw);
            ml_vk::commands::one_shot(ctx, |cmd| {
                // SAFETY: recording state; both buffers are alive and nothing else uses them yet.
                unsafe {
                    ctx.device.cmd_fill_buffer(cmd, depths, 0, vk::WHOLE_SIZE, 1.0f32.to_bits());
                    ctx.device.cmd_fill_buffer(cmd, tiles, 0, vk::WHOLE_SIZE, NO_TILE);
                }
                let shaders = vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::COMPUTE_SHADER;
                ml_vk::commands::memory_barrier(
                    ctx,
                    cmd,
                    (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
                    (shaders | vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::SHADER_READ | vk::AccessFlags::TRANSFER_WRITE),
                );
            })?;
            Ok(())
        })
    }

    /// The frame's plan for `lights` (keys: scene light indices; slot i: `lights[i]`), seen by
    /// `camera` on a `size` image; None without an atlas.
    pub fn plan(
        &mut self,
        lights: &[(u32, PlannedLight)],
        camera: &Camera,
        size: (u32, u32),
        settings: AtlasSettings,
    ) -> Option<Result<AtlasPlan, ml_cpu::shadow_atlas::AtlasError>> {
        let allocator = self.allocator.as_mut()?;
        Some(allocator.plan(lights, camera, size, settings.fixed_size, settings.cache))
    }

    /// The atlas's layout (None without an atlas).
    pub fn blocks(&self) -> Option<ml_cpu::shadow_atlas::AtlasBlocks> {
        self.allocator.as_ref().map(ShadowAtlas::blocks)
    }

    /// Forget every face (the casters changed): the next frame draws them all.
    pub fn forget(&mut self) {
        if let Some(a) = &mut self.allocator {
            a.clear();
        }
    }

    /// The budget, and what the atlas's buffers take of it (the atlas, its tables, the
    /// raster's lists): (budget, used, atlas) bytes.
    pub fn memory(&self) -> (u64, u64, u64) {
        let lights = (self.tiles.size / size_of::<ShadowCubeTiles>() as u64) as u32;
        (self.budget, self.depths.size + self.lists.bytes() + tables_bytes(lights), self.depths.size)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.depths.destroy(ctx);
        self.tiles.destroy(ctx);
    }
}

impl ml_vk::Release for ShadowAtlasGpu {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// The per-light tables: the tiles, the raster's copy of the lights (a vec4 each) and of the
/// redrawn lights' slots (a u32 each), and its counters.
fn tables_bytes(lights: u32) -> u64 {
    lights as u64 * (size_of::<ShadowCubeTiles>() as u64 + 16 + 4) + size_of::<OmniRasterCounters>() as u64
}

/// The tile table of a plan for `lights` shadowed lights.
pub fn tile_table(plan: &AtlasPlan, lights: usize) -> Vec<ShadowCubeTiles> {
    let mut table = vec![ShadowCubeTiles { base: [NO_TILE; 6], size: MIN_FACE, redraw: 0 }; lights];
    for t in &plan.tiles {
        let entry = &mut table[t.light as usize];
        entry.base[t.face as usize] = t.base as u32;
        entry.size = t.size;
        entry.redraw |= u32::from(t.redraw) << t.face;
    }
    table
}
