//! Barriers between passes, derived from what each pass declares of the frame's named
//! resources (`Pass::uses`) instead of written by hand inside each pass on assumptions about
//! its neighbours. The renderer keeps each resource's state — who touched it last, in which
//! stages, with which writes not yet made visible, in which layout — and before a pass
//! records one barrier that orders every declared use after the earlier ones: a read after a
//! write waits for the write and makes it visible; a write (or a layout change) after reads
//! waits for the reads. The pass list stays linear: no reordering, no aliasing.
//!
//! Barriers between a pass's own dispatches stay in the pass. A render pass orders its
//! attachments itself (its external subpass dependencies, which also make their layout
//! transitions): it declares where those dependencies begin (`Entry::Chained`), and the
//! renderer only makes sure earlier uses end in those stages.
//!
//! A resource is ordered this way only if every pass that touches it declares it: the state
//! knows nothing of an undeclared use, and would, say, take an image another pass just wrote
//! for undefined. A resource the frame slots share keeps one state for all of them
//! (`SCENE_WIDE`); one that work outside the frames left in a layout starts from it
//! (`SyncStates::know`). Declared by none of their passes, and ordered by hand: the hardware
//! visibility raster's images (its render pass orders them).

use ml_vk::vk;

/// How a pass starts using a resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entry {
    /// It touches it at `stages` with `access`; an image in `layout` — `discard`: every
    /// texel is written before any is read, so what was there need not be kept.
    Barrier { stages: vk::PipelineStageFlags, access: vk::AccessFlags, layout: Option<vk::ImageLayout>, discard: bool },
    /// It orders itself after earlier uses that end in `stages` (a render pass's incoming
    /// external dependency, which also changes the layout).
    Chained { stages: vk::PipelineStageFlags },
}

/// What a pass leaves behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Exit {
    /// Where a later barrier chains from.
    pub stages: vk::PipelineStageFlags,
    /// Writes not yet made available (a later reader's barrier makes them visible).
    pub writes: vk::AccessFlags,
    /// Whether it wrote (a later read needs a barrier even where `writes` were made
    /// available already, as a render pass's outgoing dependency does).
    pub wrote: bool,
    /// Accesses at `stages` that already see its writes (a render pass's outgoing
    /// dependency's destination).
    pub visible: vk::AccessFlags,
    pub layout: Option<vk::ImageLayout>,
}

/// A buffer of the frame's resources (`FrameResources`), by the name the shader blocks that
/// bind it give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferName(pub &'static str);

/// An image of the frame's resources: the name its state between passes goes by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageName(pub &'static str);

/// A pass's use of one of the frame's named resources.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Use {
    pub name: &'static str,
    pub entry: Entry,
    pub exit: Exit,
}

const WRITES: vk::AccessFlags = vk::AccessFlags::from_raw(
    vk::AccessFlags::SHADER_WRITE.as_raw()
        | vk::AccessFlags::COLOR_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags::TRANSFER_WRITE.as_raw()
        | vk::AccessFlags::HOST_WRITE.as_raw()
        | vk::AccessFlags::MEMORY_WRITE.as_raw(),
);

impl Use {
    /// A use of buffer `name` in `stages` with `access` (reads, writes or both); what it
    /// writes is left to the next use to make visible.
    pub fn buffer(name: BufferName, reach: (vk::PipelineStageFlags, vk::AccessFlags)) -> Use {
        Use::at(name.0, reach, None)
    }

    /// `buffer`, for image `name`, which the pass uses in `layout`.
    pub fn image(name: ImageName, reach: (vk::PipelineStageFlags, vk::AccessFlags), layout: vk::ImageLayout) -> Use {
        Use::at(name.0, reach, Some(layout))
    }

    fn at(name: &'static str, (stages, access): (vk::PipelineStageFlags, vk::AccessFlags), layout: Option<vk::ImageLayout>) -> Use {
        let writes = access & WRITES;
        let entry = Entry::Barrier { stages, access, layout, discard: false };
        Use { name, entry, exit: Exit { stages, writes, wrote: !writes.is_empty(), visible: vk::AccessFlags::empty(), layout } }
    }

    /// `image`, for an image whose texels the pass all writes before reading any.
    pub fn overwriting(name: ImageName, reach: (vk::PipelineStageFlags, vk::AccessFlags), layout: vk::ImageLayout) -> Use {
        let mut u = Use::image(name, reach, layout);
        if let Entry::Barrier { discard, .. } = &mut u.entry {
            *discard = true;
        }
        u
    }

    /// A depth image a render pass draws again for shaders that sample it (at `readers`):
    /// its external dependencies order it after their last reads and make its writes visible
    /// to them, leaving it DEPTH_STENCIL_READ_ONLY_OPTIMAL (shadow maps).
    pub fn redrawn_for_readers(name: ImageName, readers: vk::PipelineStageFlags) -> Use {
        Use {
            name: name.0,
            entry: Entry::Chained { stages: readers },
            exit: Exit {
                stages: readers,
                writes: vk::AccessFlags::empty(),
                wrote: true,
                visible: vk::AccessFlags::SHADER_READ,
                layout: Some(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL),
            },
        }
    }
}

/// A resource's state between passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct State {
    /// Stages of the last write (or of the dependency that finished it).
    write_stages: vk::PipelineStageFlags,
    /// Its writes not yet made available.
    writes: vk::AccessFlags,
    /// Whether there was a write since the resource was made (reads need it visible).
    written: bool,
    /// Stages and accesses that see the last write.
    visible_stages: vk::PipelineStageFlags,
    visible: vk::AccessFlags,
    /// Stages of the reads since the last write.
    read_stages: vk::PipelineStageFlags,
    /// An image's layout; None: not known yet (undefined).
    layout: Option<vk::ImageLayout>,
}

/// What one use needs before it: an execution and memory dependency, and for an image the
/// layout change with it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dependency {
    pub src_stages: vk::PipelineStageFlags,
    pub src_access: vk::AccessFlags,
    pub dst_stages: vk::PipelineStageFlags,
    pub dst_access: vk::AccessFlags,
    /// (old, new) where the image changes layout.
    pub layout: Option<(vk::ImageLayout, vk::ImageLayout)>,
}

impl State {
    /// What `u` needs after this state (None: nothing).
    pub fn before(&self, u: &Use) -> Option<Dependency> {
        match u.entry {
            Entry::Chained { stages } => {
                // Earlier uses must end where the pass's own dependency begins.
                let earlier = self.write_stages | self.read_stages;
                (!earlier.is_empty() && !stages.contains(earlier)).then_some(Dependency {
                    src_stages: earlier,
                    src_access: self.writes,
                    dst_stages: stages,
                    dst_access: vk::AccessFlags::empty(),
                    layout: None,
                })
            }
            Entry::Barrier { stages, access, layout, discard } => {
                let old = if discard { vk::ImageLayout::UNDEFINED } else { self.layout.unwrap_or(vk::ImageLayout::UNDEFINED) };
                let transition = layout.filter(|&new| Some(new) != self.layout || (discard && self.layout.is_some())).map(|new| (old, new));
                let reads = !(access & !WRITES).is_empty();
                let writes = !(access & WRITES).is_empty() || transition.is_some();
                let unseen = self.written && !(self.visible_stages.contains(stages) && self.visible.contains(access & !WRITES));
                let mut d = Dependency { layout: transition, ..Dependency::default() };
                // A read (or a write, or a layout change) after a write: wait for it; a read
                // also needs it visible.
                if self.written && (writes || (reads && unseen)) {
                    d.src_stages |= self.write_stages;
                    d.src_access |= self.writes;
                    d.dst_access |= if reads { access & !WRITES } else { vk::AccessFlags::empty() } | (access & WRITES);
                }
                // A write (or a layout change) after reads: wait for them.
                if writes {
                    d.src_stages |= self.read_stages;
                }
                if d.src_stages.is_empty() && transition.is_none() {
                    return None;
                }
                d.dst_stages = stages;
                if transition.is_some() {
                    d.dst_access |= access;
                }
                Some(d)
            }
        }
    }

    /// The state after `u` (its dependency recorded before it).
    pub fn after(&self, u: &Use) -> State {
        let e = u.exit;
        let layout = e.layout.or(self.layout);
        // A layout change waited for every earlier use and made the writes available: what
        // comes next needs to wait for `u` alone (a later reader chains through its stages).
        let base = match self.before(u) {
            Some(Dependency { layout: Some(_), dst_stages, .. }) => State {
                write_stages: if self.written { dst_stages } else { vk::PipelineStageFlags::empty() },
                writes: vk::AccessFlags::empty(),
                read_stages: vk::PipelineStageFlags::empty(),
                ..*self
            },
            _ => *self,
        };
        if e.wrote {
            return State {
                write_stages: e.stages,
                writes: e.writes,
                written: true,
                visible_stages: if e.visible.is_empty() { vk::PipelineStageFlags::empty() } else { e.stages },
                visible: e.visible,
                read_stages: vk::PipelineStageFlags::empty(),
                layout,
            };
        }
        // A read: the write it waited for is now available, and visible where it read.
        let (stages, access) = match u.entry {
            Entry::Barrier { stages, access, .. } => (stages, access),
            Entry::Chained { stages } => (stages, vk::AccessFlags::empty()),
        };
        State {
            writes: vk::AccessFlags::empty(),
            visible_stages: base.visible_stages | stages,
            visible: base.visible | access,
            read_stages: base.read_stages | e.stages,
            layout,
            ..base
        }
    }
}

/// The name of a frame slot's colour target (the image `render` reads back and a window
/// presents) in the frame's resources.
pub const COLOUR_TARGET: ImageName = ImageName("colour target");

/// The HDR target where a compute pass writes it (the compute lighting's linear output, read
/// by the transparent resolve); the render passes that write it order it themselves.
pub const HDR_TARGET: ImageName = ImageName("hdr target");

/// The frame slot's uniforms (FrameUniforms; its shader block's name): written by the host
/// before the frame.
pub const FRAME_BLOCK: BufferName = BufferName("FrameBlock");

/// The frame slot's lights and cluster lists, as their shader blocks name them: written by
/// the host (the CPU assignment), read by every shading pass.
pub const LIGHT_LISTS: [BufferName; 3] = [BufferName("LightBuffer"), BufferName("ClusterRangeBuffer"), BufferName("LightIndexBuffer")];

/// The frame slot's light-grid lists (where each ends, the lights in them — positions,
/// colours — and their scene indices): written by the light grid's build, read by every
/// shading pass.
pub const LIGHT_GRID_LISTS: [BufferName; 4] = [
    BufferName("LightGridListBuffer"),
    BufferName("LightGridPositionBuffer"),
    BufferName("LightGridColorBuffer"),
    BufferName("LightGridIndexBuffer"),
];

/// The frame slot's light-grid marks (a bit per cell a surface point walks, and per 32 cells
/// the list of the first marked one): written by the marks pass (or the build), read by the
/// build and by every shading pass (a marked cell's list is its rank among them).
pub const LIGHT_GRID_OCCUPANCY: BufferName = BufferName("LightGridOccupancyBuffer");

/// How a shading pass reads the lights and lists (whichever the technique has): in `stages`.
pub fn light_list_reads(stages: vk::PipelineStageFlags) -> Vec<Use> {
    let mut names = LIGHT_LISTS.to_vec();
    names.extend(&LIGHT_GRID_LISTS);
    names.push(LIGHT_GRID_OCCUPANCY);
    names.into_iter().map(|name| Use::buffer(name, (stages, vk::AccessFlags::SHADER_READ))).collect()
}

/// The frame slot's depth pyramid (its shader block's name): written by the depth pyramid
/// pass, read by the culling.
pub const DEPTH_PYRAMID: BufferName = BufferName("DepthPyramidBuffer");

/// The frame slot's 64-bit visibility-depth buffer (the compute and hybrid rasters'; its
/// shader block's name): cleared and written by the culling passes, the large triangles and
/// the hybrid's fragments, read by the depth pyramid and the lighting.
pub const VISIBILITY_DEPTH: BufferName = BufferName("VisibilityDepthBuffer");

/// The culling's counters of the frame slot (its shader block's name; `CullCounters`):
/// cleared and written by the culling and the compute raster, read as indirect commands and by
/// the transparent layers' build.
pub const CULL_COUNTERS: BufferName = BufferName("CullCounterBuffer");

/// The compute raster's candidates for the transparent layers (its shader block's name):
/// written by the rasters, read by the layers' build.
pub const LAYER_CANDIDATES: BufferName = BufferName("LayerCandidateBuffer");

/// The frame slot's opaque surface colours at their first samples (visibility with
/// anti-aliasing and transparent layers; its shader block's name): written by the lighting,
/// read by the transparent layers' blend.
pub const SURFACE_COLOURS: BufferName = BufferName("SurfaceColourBuffer");

/// Each meshlet instance's visibility at the end of the last frame (its shader block's name):
/// read by the early culling, written by the late one. The frame slots share it.
pub const MESHLET_VISIBILITY: BufferName = BufferName("MeshletVisibilityBuffer");

/// The point-light shadow cubes (the scene's depth cube array): written by the point-light
/// shadow pass in every mode but the atlas, sampled by the shading passes in
/// DEPTH_STENCIL_READ_ONLY_OPTIMAL (where there are no cubes, by its stand-in).
pub const SHADOW_CUBES: ImageName = ImageName("shadow cubes");

/// The shadow atlas and its tile table (the scene's buffers, as the shading shaders name
/// them): written by the atlas's pass, read by the shading passes.
pub const SHADOW_ATLAS: [BufferName; 2] = [BufferName("ShadowAtlasBuffer"), BufferName("ShadowAtlasTileBuffer")];

/// The compute shadow raster's counters of the point lights' pass (its shader block's name;
/// one buffer for every slot): written and dispatched from by the pass, read back at the
/// frame's end.
pub const SHADOW_RASTER_COUNTERS: BufferName = BufferName("OmniRasterCounterBuffer");

/// The sun's shadow map (blinn-phong; the scene's, a stand-in otherwise): drawn by the sun's
/// shadow pass in the first frame after its casters changed, sampled by the shading passes in
/// DEPTH_STENCIL_READ_ONLY_OPTIMAL.
pub const SUN_MAP: ImageName = ImageName("sun shadow map");

/// How a pass that shades reads the shadow stores (the sun's map, the point lights' cubes and
/// atlas): in `stages`.
pub fn shadow_reads(stages: vk::PipelineStageFlags) -> Vec<Use> {
    let read = (stages, vk::AccessFlags::SHADER_READ);
    let sampled = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
    let maps = [Use::image(SUN_MAP, read, sampled), Use::image(SHADOW_CUBES, read, sampled)];
    maps.into_iter().chain(SHADOW_ATLAS.iter().map(|&name| Use::buffer(name, read))).collect()
}

/// The frame slot's count of the shadow rays its compute lighting traced (its shader block's
/// name): added to by the lighting's subgroups, read by the host after the frame.
pub const RAY_COUNT: BufferName = BufferName("RayCountBuffer");

/// How a compute lighting adds to the ray count (the host reads it in place after the frame).
pub fn ray_count_use() -> Use {
    let add = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
    Use::buffer(RAY_COUNT, add)
}

/// How a pass that shades reads what the frame lit it with: the lights and their lists, and
/// the point-light shadows.
pub fn shading_reads(stages: vk::PipelineStageFlags) -> Vec<Use> {
    let mut uses = light_list_reads(stages);
    uses.extend(shadow_reads(stages));
    uses
}

/// The resources the frame slots share (the scene's): their states are the renderer's, not a
/// slot's. Frames are recorded in the order they are submitted, so a frame's first use of one
/// follows the last frame's, whichever slot that frame ran in.
pub const SCENE_WIDE: [&str; 6] =
    [MESHLET_VISIBILITY.0, SUN_MAP.0, SHADOW_CUBES.0, SHADOW_ATLAS[0].0, SHADOW_ATLAS[1].0, SHADOW_RASTER_COUNTERS.0];

/// Of the frame's resources a pass's shaders bind (`bound`), those that other passes order by
/// their declared uses (`ordered`) but the pass does not declare (`declared`): the state knows
/// nothing of such a use, so no barrier would order it — a pass declares every ordered
/// resource it touches, or none is ordered.
pub fn undeclared(bound: &[&'static str], declared: &[Use], ordered: &[&'static str]) -> Vec<&'static str> {
    bound.iter().copied().filter(|name| ordered.contains(name) && !declared.iter().any(|u| u.name == *name)).collect()
}

/// How the frame leaves its colour target: read by transfers (the read-back, a window's
/// blit) in TRANSFER_SRC_OPTIMAL.
pub fn frame_end() -> Use {
    Use::image(COLOUR_TARGET, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_READ), vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
}

/// The state of every named resource of a frame slot (buffers and images the slot holds) or,
/// for the renderer, of those the slots share (SCENE_WIDE), from frame to frame; new ones
/// start with none known.
#[derive(Debug, Default)]
pub struct SyncStates(std::collections::HashMap<&'static str, State>);

impl SyncStates {
    /// Start image `name` from `layout`, where work outside the frames left it (finished, its
    /// writes visible to every later use), instead of undefined.
    pub fn know(&mut self, name: ImageName, layout: vk::ImageLayout) {
        self.0.insert(name.0, State { layout: Some(layout), ..State::default() });
    }

    /// Record one barrier ordering `uses` after every earlier use of their resources, and
    /// note them: in `self`, a frame slot's states, or in `scene`, the states of the resources
    /// the slots share. `image` gives an image's handle and aspect (None: a buffer, ordered by
    /// a global memory barrier).
    pub fn barrier(
        &mut self,
        scene: &mut SyncStates,
        (ctx, cmd): (&ml_vk::Context, vk::CommandBuffer),
        uses: &[Use],
        image: &dyn Fn(ImageName) -> Option<(vk::Image, vk::ImageAspectFlags)>,
    ) {
        let (mut src, mut dst) = (vk::PipelineStageFlags::empty(), vk::PipelineStageFlags::empty());
        let mut global = vk::MemoryBarrier::default();
        let mut images = Vec::new();
        for u in uses {
            let states = if SCENE_WIDE.contains(&u.name) { &mut scene.0 } else { &mut self.0 };
            let state = states.get(u.name).copied().unwrap_or_default();
            if let Some(d) = state.before(u) {
                src |= d.src_stages;
                dst |= d.dst_stages;
                match (d.layout, image(ImageName(u.name))) {
                    (Some((old, new)), Some((raw, aspect))) => images.push(
                        vk::ImageMemoryBarrier::default()
                            .src_access_mask(d.src_access)
                            .dst_access_mask(d.dst_access)
                            .old_layout(old)
                            .new_layout(new)
                            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .image(raw)
                            .subresource_range(ml_vk::image::full_range(aspect)),
                    ),
                    _ => {
                        global.src_access_mask |= d.src_access;
                        global.dst_access_mask |= d.dst_access;
                    }
                }
            }
            states.insert(u.name, state.after(u));
        }
        if dst.is_empty() {
            return;
        }
        // Nothing earlier to wait for (a first use): the layout change alone.
        let src = if src.is_empty() { vk::PipelineStageFlags::TOP_OF_PIPE } else { src };
        let globals =
            if global.src_access_mask.is_empty() && global.dst_access_mask.is_empty() { &[][..] } else { std::slice::from_ref(&global) };
        // SAFETY: recording state, outside a render pass; the images are the frame's, alive.
        unsafe { ctx.device.cmd_pipeline_barrier(cmd, src, dst, vk::DependencyFlags::empty(), globals, &[], &images) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vk::AccessFlags as A;
    use vk::ImageLayout as L;
    use vk::PipelineStageFlags as S;

    const COLOUR: ImageName = COLOUR_TARGET;

    fn run(uses: &[Use]) -> Vec<Option<Dependency>> {
        let mut state = State::default();
        uses.iter()
            .map(|u| {
                let d = state.before(u);
                state = state.after(u);
                d
            })
            .collect()
    }

    #[test]
    fn a_pass_that_binds_an_ordered_resource_must_declare_it() {
        let read = (S::COMPUTE_SHADER, A::SHADER_READ);
        let declared = [Use::buffer(BufferName("LightIndexBuffer"), read)];
        let ordered = ["LightIndexBuffer", "ClusterRangeBuffer", "LightBuffer"];
        // FrameBlock is ordered by nobody (the host writes it before the frame).
        let bound = ["ClusterRangeBuffer", "FrameBlock", "LightIndexBuffer"];
        assert_eq!(undeclared(&bound, &declared, &ordered), vec!["ClusterRangeBuffer"]);
        assert!(undeclared(&["FrameBlock", "LightIndexBuffer"], &declared, &ordered).is_empty());
    }

    #[test]
    fn a_compute_write_then_a_compute_read_then_the_read_back() {
        let write = Use::overwriting(COLOUR, (S::COMPUTE_SHADER, A::SHADER_WRITE), L::GENERAL);
        let meter = Use::image(COLOUR, (S::COMPUTE_SHADER, A::SHADER_READ), L::GENERAL);
        let copy = Use::image(COLOUR, (S::TRANSFER, A::TRANSFER_READ), L::TRANSFER_SRC_OPTIMAL);
        let d = run(&[write, meter, copy, write]);
        // First use: only the layout, from undefined.
        assert_eq!(d[0].unwrap().layout, Some((L::UNDEFINED, L::GENERAL)));
        assert_eq!(d[0].unwrap().src_stages, S::empty());
        // The read waits for the write and sees it; no layout change.
        let m = d[1].unwrap();
        assert_eq!(
            (m.src_stages, m.src_access, m.dst_stages, m.dst_access, m.layout),
            (S::COMPUTE_SHADER, A::SHADER_WRITE, S::COMPUTE_SHADER, A::SHADER_READ, None)
        );
        // The copy: after the reads (its layout change writes) and made visible to transfers.
        let c = d[2].unwrap();
        assert!(c.src_stages.contains(S::COMPUTE_SHADER));
        assert_eq!(c.layout, Some((L::GENERAL, L::TRANSFER_SRC_OPTIMAL)));
        assert!(c.dst_access.contains(A::TRANSFER_READ));
        // The next frame's write waits for the copy and throws the old texels away.
        let w = d[3].unwrap();
        assert!(w.src_stages.contains(S::TRANSFER));
        assert_eq!(w.layout, Some((L::UNDEFINED, L::GENERAL)));
    }

    #[test]
    fn shadow_cubes_copied_in_every_frame_or_a_known_stand_in() {
        let shading = shadow_reads(S::FRAGMENT_SHADER | S::COMPUTE_SHADER)[0];
        let copy = Use::overwriting(SHADOW_CUBES, (S::TRANSFER, A::TRANSFER_WRITE), L::TRANSFER_DST_OPTIMAL);
        // The stand-in, cleared and left read-only before the frames: nothing to wait for,
        // its texels kept.
        let stand_in = State { layout: Some(L::DEPTH_STENCIL_READ_ONLY_OPTIMAL), ..State::default() };
        assert_eq!(stand_in.before(&shading), None);
        // Copied in, then sampled, then the next frame's copy after the sampling.
        let d = run(&[copy, shading, shading, copy]);
        assert_eq!(d[0].unwrap().layout, Some((L::UNDEFINED, L::TRANSFER_DST_OPTIMAL)));
        let s = d[1].unwrap();
        assert_eq!(
            (s.src_stages, s.src_access, s.layout),
            (S::TRANSFER, A::TRANSFER_WRITE, Some((L::TRANSFER_DST_OPTIMAL, L::DEPTH_STENCIL_READ_ONLY_OPTIMAL)))
        );
        assert!(s.dst_access.contains(A::SHADER_READ));
        assert_eq!(d[2], None);
        let c = d[3].unwrap();
        assert_eq!((c.src_stages, c.layout), (S::FRAGMENT_SHADER | S::COMPUTE_SHADER, Some((L::UNDEFINED, L::TRANSFER_DST_OPTIMAL))));
    }

    #[test]
    fn two_reads_of_one_write_in_the_same_stages_need_one_barrier() {
        let write = Use::buffer(BufferName("lists"), (S::COMPUTE_SHADER, A::SHADER_WRITE));
        let read = Use::buffer(BufferName("lists"), (S::COMPUTE_SHADER | S::FRAGMENT_SHADER, A::SHADER_READ));
        let d = run(&[write, read, read]);
        assert!(d[1].is_some());
        assert_eq!(d[2], None, "already visible to these readers");
        // A write after the reads waits for them (no memory to make visible).
        let d = run(&[write, read, write]);
        let w = d[2].unwrap();
        assert_eq!(w.src_stages, S::COMPUTE_SHADER | S::FRAGMENT_SHADER);
    }

    #[test]
    fn a_render_pass_chains_itself_and_leaves_its_writes_visible_to_transfers() {
        let copy = Use::image(COLOUR, (S::TRANSFER, A::TRANSFER_READ), L::TRANSFER_SRC_OPTIMAL);
        let forward = Use {
            name: COLOUR.0,
            entry: Entry::Chained { stages: S::COLOR_ATTACHMENT_OUTPUT | S::TRANSFER },
            exit: Exit {
                stages: S::TRANSFER,
                writes: A::empty(),
                wrote: true,
                visible: A::TRANSFER_READ,
                layout: Some(L::TRANSFER_SRC_OPTIMAL),
            },
        };
        let meter = Use::image(COLOUR, (S::COMPUTE_SHADER, A::SHADER_READ), L::GENERAL);
        let d = run(&[copy, forward, copy]);
        assert_eq!(d[1], None, "the copy ends where the render pass's dependency begins");
        assert_eq!(d[2], None, "the render pass's outgoing dependency made it visible to the copy");
        let d = run(&[forward, meter, copy]);
        let m = d[1].unwrap();
        assert_eq!((m.src_stages, m.dst_stages, m.layout), (S::TRANSFER, S::COMPUTE_SHADER, Some((L::TRANSFER_SRC_OPTIMAL, L::GENERAL))));
        let c = d[2].unwrap();
        assert!(c.src_stages.contains(S::COMPUTE_SHADER));
        assert_eq!(c.layout, Some((L::GENERAL, L::TRANSFER_SRC_OPTIMAL)));
        // A compute use before a render pass that does not wait for compute: chained.
        let d = run(&[meter, forward]);
        assert_eq!(d[1].unwrap().src_stages, S::COMPUTE_SHADER);
    }
}
