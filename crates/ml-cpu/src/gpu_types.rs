//! Rust mirrors of the structs in `shaders/common/common.glsl`. Field names equal the GLSL
//! member names so that the `gpu_layout` test can match them against SPIR-V reflection.

use bytemuck::{Pod, Zeroable};

/// Where each field of a mirrored struct starts, for the layout test.
pub trait GpuLayout {
    /// The GLSL struct name.
    const GLSL_NAME: &'static str;
    /// (member name, byte offset) in declaration order.
    fn field_offsets() -> Vec<(&'static str, usize)>;
}

macro_rules! gpu_struct {
    ($(#[$meta:meta])* $name:ident { $($(#[$fmeta:meta])* $field:ident : $ty:ty,)* }) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
        pub struct $name { $($(#[$fmeta])* pub $field: $ty,)* }
        impl GpuLayout for $name {
            const GLSL_NAME: &'static str = stringify!($name);
            fn field_offsets() -> Vec<(&'static str, usize)> {
                vec![$((stringify!($field), std::mem::offset_of!($name, $field)),)*]
            }
        }
    };
}

gpu_struct!(
    /// Per-frame values (a read-only storage buffer; every member 16-byte friendly, so std140
    /// and std430 would place them alike).
    FrameUniforms {
        view: [[f32; 4]; 4],
        proj: [[f32; 4]; 4],
        inv_view_proj: [[f32; 4]; 4],
        camera_pos: [f32; 4],
        light_count: u32,
        ambient: f32,
        /// One texel of a point-light shadow cube face in face units: 2 / size.
        omni_texel: f32,
        /// Lights in the directional-light buffer.
        directional_count: u32,
        /// xyz: cluster grid size.
        cluster_dims: [u32; 4],
        /// xy: image size in pixels; z: the debug view shown (DEBUG_VIEW_* in common.glsl,
        /// generated as ml_shaders::debug_view).
        viewport: [u32; 4],
        /// x, y: slice = ⌊ln(depth)·x + y⌋; z: lights per cluster at the top of the heat map.
        cluster_slices: [f32; 4],
        /// near, far, `projection[0][0]`, `projection[1][1]`.
        cluster_frustum: [f32; 4],
        /// xyz: the offset every light moves by this frame (animated on the GPU by clustered-gpu).
        light_animation: [f32; 4],
        /// x: light-index capacity (entries) of this frame's list (clustered-cpu).
        cluster_build: [u32; 4],
        /// The light grid (`light_grid`): xyz the corner of cell (0, 0, 0) this frame, w
        /// 1 / cell edge.
        light_grid_origin: [f32; 4],
        /// xyz: cells per axis; w: cells in all (the index of the wide lights' list).
        light_grid_dims: [u32; 4],
        /// x: the largest radius of a light in the cells; y: lights wider than it (every point
        /// tests them; 0: none).
        light_grid_reach: [f32; 4],
        /// The blinn-phong model's other lights; see common.glsl.
        shadow_view_proj: [[f32; 4]; 4],
        sun_direction: [f32; 4],
        sun_strength: [f32; 4],
        spot_position_range: [f32; 4],
        spot_direction_power: [f32; 4],
        spot_strength: [f32; 4],
        ambient_light: [f32; 4],
        texture_transform: [f32; 4],
        /// x: the factor lit colour is multiplied by before tone map and gamma, 2^EV.
        exposure: [f32; 4],
        /// x: length of the sun's shadow rays (beyond the scene's box from any point in it).
        shadow_rays: [f32; 4],
    }
);

gpu_struct!(
    /// One radius-limited point light (std430 array element, 32 bytes).
    PointLight {
        /// xyz world position, w radius.
        position_radius: [f32; 4],
        /// rgb linear colour; a: the index of its shadow cube + 1 (0: casts no shadow).
        color: [f32; 4],
    }
);

gpu_struct!(
    /// The environment light (std430; see common.glsl): the prefilter writes `sh`, the CPU the
    /// rest.
    EnvironmentData {
        /// rgb: what a white Lambert surface reflects is the sum of `sh[k]·Y_k(n)` (the image's frame).
        sh: [[f32; 4]; 9],
        /// The sheen's directional albedo (`material_lobes::SHEEN_ALBEDO`), with or without an
        /// environment.
        sheen_albedo: [[f32; 16]; 16],
        /// Columns of the rotation from world directions to the image's.
        to_image: [[f32; 4]; 3],
        /// x: intensity (0: no environment); y: the specular cube's last mip level.
        params: [f32; 4],
    }
);

gpu_struct!(
    /// A light infinitely far away (std430; see common.glsl).
    DirectionalLightData {
        /// xyz: unit direction the light travels.
        direction: [f32; 4],
        /// rgb.
        color: [f32; 4],
    }
);

gpu_struct!(
    /// A spot light's cone (std430), parallel to the light buffer; see common.glsl.
    LightCone {
        /// xyz: unit axis; w: 1 / (cos inner − cos outer).
        direction_scale: [f32; 4],
        /// x: −cos outer · scale.
        offset: [f32; 4],
    }
);

impl LightCone {
    /// The cone of a point light: no cone (factor 1 everywhere).
    pub const NONE: LightCone = LightCone { direction_scale: [0.0, 0.0, 1.0, 0.0], offset: [1.0, 0.0, 0.0, 0.0] };

    /// glTF's spot: full light within `inner` radians of `axis`, none beyond `outer`.
    pub fn spot(axis: glam::Vec3, inner: f32, outer: f32) -> LightCone {
        let (ci, co) = (inner.cos(), outer.cos());
        let scale = 1.0 / (ci - co).max(1e-3);
        let a = axis.normalize();
        LightCone { direction_scale: [a.x, a.y, a.z, scale], offset: [-co * scale, 0.0, 0.0, 0.0] }
    }
}

gpu_struct!(
    /// Where a cluster's lights are in the light-index list (std430, 8 bytes).
    ClusterRange {
        offset: u32,
        count: u32,
    }
);

gpu_struct!(
    /// What the light grid's build reports back after a frame.
    LightGridFeedback {
        /// Lights in the lists: those in a marked cell, and the wide ones.
        listed: u32,
        /// Lights every point tests.
        wide: u32,
        /// Most lights in one cell.
        max_count: u32,
        /// Cells that may hold a light a surface point tests.
        cells_marked: u32,
    }
);

gpu_struct!(
    /// The light grid's lists this frame and the work groups of the scan over them (the
    /// scan's indirect dispatches; device-local).
    LightGridDispatch {
        /// The wide lights' list and one per marked cell.
        lists: u32,
        _pad0: u32,
        _pad1: u32,
        _pad2: u32,
        /// xyz: work groups over the lists' blocks.
        block_groups: [u32; 4],
    }
);

gpu_struct!(
    /// One object of the object buffer (std430).
    ObjectData {
        /// Object space → world.
        model: [[f32; 4]; 4],
        /// Upper 3×3: the inverse transpose of model's.
        normal_matrix: [[f32; 4]; 4],
        albedo_roughness: [f32; 4],
        /// x: metallic, y: occlusion strength, z: normal scale.
        material: [f32; 4],
        /// rgb: emissive factor.
        emissive: [f32; 4],
        /// x: the alpha below which a point is dropped (`OBJECT_MASKED`); y: the base colour
        /// factor's alpha (1 for OPAQUE, whose alpha is ignored).
        alpha: [f32; 4],
        /// x: `OBJECT_*` bits; y: where its alpha texture's texel (0, 0) is in the alpha-mask
        /// buffer (bytes); z, w: its width and height (`alpha_mask::AlphaMasks`).
        alpha_texture: [u32; 4],
        /// The texture transform, uv' = M·uv + t: M's columns in xy and zw of the first, t in
        /// xy of the second.
        uv_transform: [[f32; 4]; 2],
        /// glTF's PBR extensions (`MaterialLobes::vectors`).
        lobes: [[f32; 4]; 4],
    }
);

/// `ObjectData::alpha_texture.x` bits (common.glsl OBJECT_*).
pub const OBJECT_MASKED: u32 = 1;
pub const OBJECT_DOUBLE_SIDED: u32 = 2;
/// Transparent (`MaterialExtras::transparent`: BLEND, or transmitting): blended in per-pixel
/// layers where the render blends them (then the opaque passes skip it); else, and in every
/// shadow, BLEND is cut as a mask at one half and a transmitting OPAQUE surface is opaque.
pub const OBJECT_BLENDED: u32 = 4;
/// Its alpha comes from a texture too (else from the factor alone).
pub const OBJECT_ALPHA_TEXTURE: u32 = 8;
/// Transparent only where its alpha is below 1 (BLEND, transmitting nothing, factor 1): the
/// visibility rasters may draw its points of alpha 1 as opaque (blended_cores.glsl).
pub const OBJECT_CORE: u32 = 16;
/// The alpha texture's wrap modes (`Wrap` as 0 repeat, 1 mirrored repeat, 2 clamp): u at this
/// bit, v two bits above; and nearest filtering at `OBJECT_ALPHA_NEAREST`.
pub const OBJECT_ALPHA_WRAP_SHIFT: u32 = 8;
pub const OBJECT_ALPHA_NEAREST: u32 = 1 << 12;
/// log2 of the side of the alpha texture's blocks (`alpha_mask::block_side`), 4 bits from here.
pub const OBJECT_ALPHA_BLOCK_SHIFT: u32 = 13;

gpu_struct!(
    /// Per-draw push constants (the material again: see common.glsl).
    ObjectPush {
        /// x: index of the object in the object buffer; y: which textures it has of its own
        /// (`ObjectTextures::bits`).
        ids: [u32; 4],
        albedo_roughness: [f32; 4],
        material: [f32; 4],
        emissive: [f32; 4],
    }
);

gpu_struct!(
    /// A transparent object whose layers the compute build makes this frame (see common.glsl).
    LayerObject {
        /// Its index in the object buffer, its own textures (`ObjectTextures::bits`), its
        /// mesh's first index in the build's index buffer, its triangles.
        ids: [u32; 4],
        /// Its mesh's first vertex in the build's vertex buffer; the first pixel and the end of
        /// the rectangle its box may cover (`y << 16 | x`); unused.
        place: [u32; 4],
    }
);

gpu_struct!(
    /// Push constants of the sun's shadow pass (blinn-phong).
    ShadowPush {
        model: [[f32; 4]; 4],
        light_view_proj: [[f32; 4]; 4],
    }
);

gpu_struct!(
    /// Push constants of the point-light shadow passes (omni_shadow.vert): copy and direct
    /// carry the face's rotation and projection, multiview and layered the projection alone;
    /// `model_to_light` = scale(1 / radius) · translate(−light) · model.
    OmniShadowPush {
        view_proj: [[f32; 4]; 4],
        model_to_light: [[f32; 4]; 4],
    }
);

gpu_struct!(
    /// Push constants of the compute shadow raster (omni_raster.glsl).
    OmniRasterPush {
        /// Every face's projection (90°, depth 0..1), in the light's frame measured in radii.
        projection: [[f32; 4]; 4],
        /// x: texels per face side; y: shadowed lights; z: the largest triangle one thread
        /// draws (bounding box, texels a side); w: meshlet instances.
        sizes: [u32; 4],
        /// x: (meshlet instance, face) pairs the pair list holds; y: large triangles it holds.
        capacity: [u32; 4],
    }
);

gpu_struct!(
    /// The counts of a frame's compute shadow raster (`OmniRasterCounters` in common.glsl).
    OmniRasterCounters {
        /// x: the raster's work groups (at most 65535); y, z: 1; w: pairs listed.
        pairs: [u32; 4],
        /// x: the large-triangle raster's work groups; y, z: 1; w: large triangles listed.
        large: [u32; 4],
        /// x: triangles drawn by one thread; y: of those, large ones (the list was full);
        /// z: texels covered; w: (meshlet, face) pairs the culling's thread drew (the pair
        /// list was full).
        drawn: [u32; 4],
    }
);

gpu_struct!(
    /// One shadowed light's faces in the shadow atlas (`ShadowCubeTiles` in common.glsl).
    ShadowCubeTiles {
        /// Per cube face: the index of its texel (0, 0) in the Z-ordered atlas; NO_TILE where
        /// it has none (common.glsl, generated as ml_shaders::common::NO_TILE).
        base: [u32; 6],
        /// Texels a side of each of its faces.
        size: u32,
        /// Bit i: face i is drawn this frame.
        redraw: u32,
    }
);

gpu_struct!(
    /// Push constants of the compute-vs-fragment probe (stage_probe.glsl).
    StageProbePush {
        /// xy: pixels; z: lights every pixel sums.
        size_lights: [u32; 4],
    }
);

gpu_struct!(
    /// A meshlet of a mesh, in object space (`meshlets.rs`; std430, 64 bytes).
    Meshlet {
        /// xyz: centre of the bounding sphere; w: its radius.
        center_radius: [f32; 4],
        /// xyz: the back-face cone's axis; w: its cutoff (every triangle faces away from an
        /// eye where dot(normalize(apex − eye), axis) ≥ cutoff).
        cone_axis_cutoff: [f32; 4],
        /// xyz: the cone's apex.
        cone_apex: [f32; 4],
        /// x: first triangle in the meshlet triangle buffer; y: triangles; z: first vertex in
        /// the meshlet vertex buffer; w: vertices.
        triangles: [u32; 4],
    }
);

/// `Instance::meshlets.w` bits.
pub const INSTANCE_CONE_CULLING: u32 = 1;
pub const INSTANCE_MIRRORED: u32 = 2;
/// Drawn from both sides: neither cone nor triangle back-face culling.
pub const INSTANCE_DOUBLE_SIDED: u32 = 4;
/// Some of its points are cut out (alpha-tested where drawn; occludes only where kept).
pub const INSTANCE_MASKED: u32 = 8;

gpu_struct!(
    /// An object as the meshlet culling sees it (same index as the object buffer; std430).
    Instance {
        /// xyz: centre of the world-space bounding sphere; w: its radius.
        bounds: [f32; 4],
        /// x: the largest factor by which its transform stretches lengths (meshlet spheres
        /// grow by it).
        scale: [f32; 4],
        /// x: first meshlet of its mesh; y: meshlet count; z: its first meshlet-instance id;
        /// w: `INSTANCE_*` bits.
        meshlets: [u32; 4],
        /// x: which textures it has of its own (`ObjectTextures::bits`); y: its texture set
        /// (which descriptor set holds them).
        surface: [u32; 4],
    }
);

gpu_struct!(
    /// VkDrawIndexedIndirectCommand (`DrawIndexedCommand` in common.glsl; 20 bytes).
    DrawIndexedCommand {
        index_count: u32,
        instance_count: u32,
        first_index: u32,
        vertex_offset: i32,
        first_instance: u32,
    }
);

gpu_struct!(
    /// The counts of a frame's culling (`CullCounters` in common.glsl).
    CullCounters {
        /// x: instances that passed the frustum test; y, z: 1 (an indirect dispatch).
        dispatch: [u32; 4],
        /// Per phase: x: meshlets drawn; y, z: 1 (the triangle culling's indirect dispatch).
        meshlets: [[u32; 4]; 2],
        /// x, y: triangles of the early and late phase's meshlets; z, w: of those, drawn.
        triangles: [u32; 4],
        /// x: meshlets tested early; y: late; z: instances tested.
        tested: [u32; 4],
        /// The compute raster's: x, y: triangles it drew in the early, late phase; z: pixels
        /// it covered (every covered pixel of every triangle, hidden or not); w: large
        /// triangles drawn in place by the thread that found them (the lists full).
        rasterized: [u32; 4],
        /// Per phase: the compacted triangles' indexed draw.
        draws: [DrawIndexedCommand; 2],
        /// std430 aligns the next uvec4 to 16 bytes.
        _pad0: [u32; 2],
        /// The compute raster, per phase: the large-triangle pass's work groups (x: bins
        /// listed, at most 65535; y, z: 1; an indirect dispatch).
        large: [[u32; 4]; 2],
        /// x, y: bins listed early, late; z, w: large triangles found early, late (past the
        /// lists' capacity too).
        binned: [u32; 4],
        /// The compute raster, transparent objects' cores: x: soft samples listed for the
        /// layers' build (past the list's room too); y: 1 where the
        /// per-triangle build must build the cores instead (a core triangle too large for
        /// the list, or the list full).
        candidates: [u32; 4],
        /// The candidates' build's work groups (x, at most 65535; y, z: 1).
        candidate_groups: [u32; 4],
    }
);

gpu_struct!(
    /// A large triangle of the compute raster, clipped and set up once (GPU only; mirrored
    /// for its size, which the list is allocated by).
    LargeTriangle {
        /// x: corners of the clipped polygon (3 to 8); y: visibility id; z: its object where
        /// masked (else u32::MAX); w: its instance's `INSTANCE_*` bits.
        head: [u32; 4],
        /// Corner 2k in xy, 2k + 1 in zw: in the image, snapped to the sub-pixel grid.
        corners: [[i32; 4]; 4],
        /// Each corner's depth z/w.
        depths: [[f32; 4]; 2],
        /// Masked: the unclipped triangle's clip-space corners (the alpha test's barycentrics).
        surface_clip: [[f32; 4]; 3],
        /// Masked: its corners' texture coordinates (a in xy, b in zw of the first; c in xy).
        surface_uv: [[f32; 4]; 2],
    }
);

gpu_struct!(
    /// Push constants of the culling passes.
    CullPush {
        /// x: phase (0 early, 1 late); y: culling on (1) or off; z: depth-pyramid levels;
        /// w: draw capacity (the late phase's draw slots start there).
        mode: [u32; 4],
        /// x: the scene's triangles (the late phase's triangle ids start there); y: the
        /// compute raster's largest triangle (bounding box, pixels a side; 0: hardware raster);
        /// z: the large triangles' bin list's capacity; w: 1 where they are drawn in compute,
        /// 0 by the hardware.
        triangles: [u32; 4],
    }
);

gpu_struct!(
    /// A node of a two-wide BVH for shadow rays (ray_bvh.rs): both children's boxes, so that
    /// one read tests both. A child with count 0 is a node (its index in the same buffer), else
    /// a leaf of `count` primitives from index `child`: triangles in a mesh's bottom level,
    /// instances in the top level.
    RayNode {
        left_min: [f32; 3],
        left_child: u32,
        left_max: [f32; 3],
        left_count: u32,
        right_min: [f32; 3],
        right_child: u32,
        right_max: [f32; 3],
        right_count: u32,
    }
);

gpu_struct!(
    /// A triangle of a mesh's bottom level, in object space: a corner and the two edges from it
    /// (what the ray test reads).
    RayTriangle {
        v0: [f32; 3],
        /// Its index in its mesh's index list (triangle i: indices 3i..3i+3).
        source: u32,
        e1: [f32; 3],
        pad0: u32,
        e2: [f32; 3],
        pad1: u32,
    }
);

gpu_struct!(
    /// An object in the shadow rays' top level: world → object space (the rows of an affine
    /// map) and its mesh's bottom level.
    RayInstance {
        to_object: [[f32; 4]; 3],
        /// Its mesh's root node in the bottom levels' nodes.
        root: u32,
        /// Its index in the scene's objects.
        object: u32,
        pad0: u32,
        pad1: u32,
    }
);
