// Every struct that Rust mirrors lives here (crates/ml-cpu/src/gpu_types.rs).
// Keep in sync: the test `gpu_layout` compares each Rust field offset and struct size with
// what SPIR-V reflection of the compiled shaders reports, so a moved field fails CI.
// Storage buffers are std430 (no 16-byte padding of scalars in arrays, no 64 KiB uniform cap:
// mistake 5 of docs/DESIGN.md#mistakes-we-avoid). There is no uniform block: the frame's
// values too are a read-only storage buffer (FrameBlock; why: opaque_uniform below).

#ifndef MANYLIGHTS_COMMON_GLSL
#define MANYLIGHTS_COMMON_GLSL

#extension GL_KHR_shader_subgroup_ballot : require

// Mesa's lavapipe (the CPU driver CI renders with) inlines, as constants, the push-constant and
// uniform-buffer values a branch or a loop count depends on alone, and compiles the shader anew
// at every pipeline bind and push of constants — a quarter of a second for a lighting shader,
// every frame (docs/DESIGN.md#shaders-on-lavapipe). So the frame's values live in a storage
// buffer, which it never inlines, and such push constants are read through `opaque_uniform`:
// a dynamically uniform value read through the subgroup's first invocation is the same value,
// hidden from that analysis. The test `no_branch_rests_on_uniforms_alone` checks every shader.
// Compute and fragment shaders only (the stages lavapipe runs subgroup operations in).
#define opaque_uniform(x) subgroupBroadcastFirst(x)


#define DEBUG_VIEW_NONE 0u
#define DEBUG_VIEW_CLUSTER_HEAT 1u
#define DEBUG_VIEW_GBUFFER_ALBEDO 2u
#define DEBUG_VIEW_GBUFFER_NORMAL 3u
#define DEBUG_VIEW_GBUFFER_MATERIAL 4u
#define DEBUG_VIEW_DEPTH 5u
#define DEBUG_VIEW_SHADOW_MAP 6u
#define DEBUG_VIEW_SHADOW_CUBE 7u
#define DEBUG_VIEW_MESHLETS 8u
#define DEBUG_VIEW_TRIANGLES 9u
#define DEBUG_VIEW_SHADOW_ATLAS 10u
#define DEBUG_VIEW_ALPHA 11u
#define DEBUG_VIEW_TRANSPARENCY_LAYERS 12u
#define DEBUG_VIEW_RAY_COST 13u
#define DEBUG_VIEW_AA 14u

// Per frame, one buffer per frame in flight (set 0, binding 0; read-only storage).
struct FrameUniforms {
    mat4 view;
    mat4 proj;           // Vulkan clip space: Y flipped, depth 0..1
    mat4 inv_view_proj;  // clip → world (deferred-compute rebuilds positions from depth)
    vec4 camera_pos;     // xyz: world position of the eye; w: 1 perspective, 0 orthographic
    uint light_count;
    float ambient;       // seed: colour = albedo * ambient + Lo
    float omni_texel;    // one texel of a point-light shadow cube face, in face units (2 / size)
    uint directional_count; // lights in directional_lights (scene_bindings.glsl)
    uvec4 cluster_dims;  // xyz: cluster grid size
    uvec4 viewport;      // xy: image size in pixels; z: the debug view shown (DEBUG_VIEW_*)
    vec4 cluster_slices; // x, y: slice = floor(log(depth) * x + y); z: heat-map top (lights)
    vec4 cluster_frustum; // x: near, y: far, z: proj[0][0], w: proj[1][1] (symmetric perspective)
    vec4 light_animation; // xyz: offset every light moves by this frame (the seed's animation)
    uvec4 cluster_build;  // x: light-index capacity (entries) of this frame's list (clustered-cpu)
    // The light grid (GPU techniques; light_grid/light_grid.glsl).
    vec4 light_grid_origin; // xyz: corner of cell (0, 0, 0) this frame; w: 1 / cell edge
    uvec4 light_grid_dims;  // xyz: cells per axis; w: cells in all (the wide lights' list)
    vec4 light_grid_reach;  // x: largest radius of a light in the cells; y: lights wider (0: none)
    // The blinn-phong model's other lights (docs/DESIGN.md#shading-models); the seed model
    // ignores them.
    mat4 shadow_view_proj;     // world → the sun's shadow-map clip space (depth 0..1)
    vec4 sun_direction;        // xyz: direction the sunlight travels; w: shadow-map texel (uv units)
    vec4 sun_strength;         // rgb: colour × strength; w: shadow-map texel in world units
    vec4 spot_position_range;  // xyz: position; w: range (no light beyond it)
    vec4 spot_direction_power; // xyz: unit direction; w: cone exponent
    vec4 spot_strength;        // rgb
    vec4 ambient_light;        // rgb: ambient colour
    vec4 texture_transform;    // the 2×2 transform of texture coordinates: columns xy and zw
    vec4 exposure;             // x: the factor lit colour is multiplied by before tone map and gamma (2^EV)
    vec4 shadow_rays;          // x: length of the sun's shadow rays (beyond the scene's box from any point in it)
};

// The environment light (set 1 of every shading path; environment/environment.glsl): written
// once per environment — the coefficients by its prefilter on the GPU, the rest by the CPU.
struct EnvironmentData {
    vec4 sh[9];        // rgb: what a white Lambert surface reflects, Σ sh[k]·Y_k(n) (image frame)
    float sheen_albedo[256]; // the sheen's directional albedo E(n·v, roughness), 16×16 entries
                             // (material_lobes.glsl; there with or without an image)
    vec4 to_image[3];  // columns of the rotation from world directions to the image's
    vec4 params;       // x: intensity (0: no environment), y: the specular cube's last level
};

// Declares the frame's values as `frame`, at binding `b` of set 0: every shader reads them
// from a read-only storage buffer, never a uniform block (why: opaque_uniform above).
#define FRAME_BLOCK(b) layout(std430, set = 0, binding = b) readonly buffer FrameBlock { FrameUniforms frame; }

// A light infinitely far away (set 0, binding 19, std430 array; glTF and scene files, every
// model).
struct DirectionalLightData {
    vec4 direction; // xyz: unit direction the light travels
    vec4 color;     // rgb
};

// A radius-limited point light (set 0, binding 1, std430 array).
struct PointLight {
    vec4 position_radius; // xyz: world position, w: radius (no light at all beyond it)
    vec4 color;           // rgb: linear colour; a: its shadow cube's index + 1 (0: casts no shadow)
};

// A spot light's cone, parallel to the light buffer (set 0, binding 10; std430), for scenes
// with spot lights (SPOT_LIGHTS): factor = clamp(cos_to_axis · scale + offset, 0, 1)², glTF's
// smooth edge between the inner and outer cone angles; a point light has scale 0, offset 1.
struct LightCone {
    vec4 direction_scale; // xyz: unit axis (where the light points); w: 1 / (cos inner − cos outer)
    vec4 offset;          // x: −cos outer · scale
};

// Where a cluster's lights are in the light-index list (set 0, binding 2, std430 array).
struct ClusterRange {
    uint offset;
    uint count;
};

// What the light grid's build tells the CPU after the frame (host-visible).
struct LightGridFeedback {
    uint listed;       // lights in the lists (those within reach of a marked cell, and the wide)
    uint wide;         // lights every point tests
    uint max_count;    // most lights in one cell
    uint cells_marked; // cells that may hold a light a surface point tests
};

// The light grid's lists this frame and the work groups of the scan over them (device-local:
// the scan's indirect dispatches). Written by the scan over the marked cells.
struct LightGridDispatch {
    uint lists;          // the wide lights' list and one per marked cell
    uint _pad0;
    uint _pad1;
    uint _pad2;
    uvec4 block_groups;  // xyz: work groups over the lists' blocks (rows of 32768 along x)
};

// Per object (set 0, binding 4, std430 array, every shading path): where it is and what it
// is made of.
struct ObjectData {
    mat4 model;            // object space → world
    mat4 normal_matrix;    // upper 3×3: the inverse transpose of model's (normals, tangents)
    vec4 albedo_roughness; // rgb: albedo, a: roughness
    vec4 material;         // x: metallic, y: occlusion strength, z: normal scale (glTF)
    vec4 emissive;         // rgb: emissive factor (glTF)
    vec4 alpha;            // x: the alpha below which a point is cut out (OBJECT_MASKED); y: the
                           // base colour factor's alpha, 1 for OPAQUE (alpha_mask.glsl)
    uvec4 alpha_texture;   // x: OBJECT_* bits; y: its alpha texture's first byte in the
                           // alpha-mask buffer; z, w: that texture's width, height
    vec4 uv_transform[2];  // texture coordinates as the textures see them: uv' = M·uv + t,
                           // M's columns in [0].xy and [0].zw, t in [1].xy (transform_uv)
    vec4 lobes[4];         // glTF's PBR extensions (material_lobes.glsl): (dielectric F₀,
                           // specular factor), (clear coat, its roughness, unlit,
                           // transmission), (sheen colour, sheen roughness), (the volume's
                           // transmittance, 0)
};

// The texture coordinates an object's textures see at mesh coordinates `uv`: its
// ObjectData.uv_transform (glTF's texture transform) applied. Affine, so it commutes with
// interpolation: applied per vertex, it holds for every point between.
vec2 transform_uv(vec4 transform[2], vec2 uv) {
    return mat2(transform[0].xy, transform[0].zw) * uv + transform[1].xy;
}

// Bits of ObjectData.alpha_texture.x (gpu_types.rs OBJECT_*).
const uint OBJECT_MASKED = 1u;        // alpha-tested (glTF MASK, and BLEND at one half)
const uint OBJECT_DOUBLE_SIDED = 2u;  // drawn from both sides, the normal toward the viewer
const uint OBJECT_BLENDED = 4u;       // transparent: BLEND or transmitting (layers, alpha view)
const uint OBJECT_ALPHA_TEXTURE = 8u; // its alpha comes from a texture too
const uint OBJECT_CORE = 16u;         // transparent where its alpha is below 1 only (blended_cores.glsl)
const uint OBJECT_ALPHA_WRAP_SHIFT = 8u; // wrap u (2 bits), then wrap v
const uint OBJECT_ALPHA_NEAREST = 4096u;
const uint OBJECT_ALPHA_BLOCK_SHIFT = 13u; // log2 of the alpha blocks' side, 4 bits

// Per draw, by push constants: the object's index and, again, its material — the forward
// fragment shaders read it here (reading it from the object buffer made the seed forward
// pass at 4,096 lights 345 ms instead of 332.5 on the H100, measured); the deferred lighting
// reads the object buffer.
struct ObjectPush {
    uvec4 ids;             // x: index in the object buffer; y: bit i set where the object has
                           // its own texture i (surface.glsl, set 2)
    vec4 albedo_roughness;
    vec4 material;         // as ObjectData's
    vec4 emissive;
};

// A transparent object whose layers the compute build makes this frame
// (transparency/transparent_build_compute.glsl).
struct LayerObject {
    uvec4 ids;   // x: index in the object buffer; y: its own textures (ObjectPush.ids.y); z: its
                 // mesh's first index in the build's index buffer; w: its triangles
    uvec4 place; // x: its mesh's first vertex in the build's vertex buffer; y, z: the first
                 // pixel and the end of the rectangle its box may cover (y << 16 | x); w: unused
};

// Push constants of the sun's shadow pass (blinn-phong): the object's and the light's matrix.
struct ShadowPush {
    mat4 model;
    mat4 light_view_proj;
};

// Push constants of the point-light shadow passes (omni_shadow.vert), in the light's frame
// measured in radii (so the stored depth, distance / radius, is just a length):
// `model_to_light` = scale(1 / radius) · translate(−light) · model; `view_proj` — copy and
// direct: the face's rotation and projection (the seed's view by push constant); multiview
// and layered: the projection alone (the rotation comes from the view or instance index).
struct OmniShadowPush {
    mat4 view_proj;
    mat4 model_to_light;
};

// Push constants of the compute-vs-fragment probe (stage_probe.glsl): the same light loop
// over the same pixels as a fragment shader and as a compute shader.
struct StageProbePush {
    uvec4 size_lights; // xy: pixels; z: lights every pixel sums
};

// A meshlet of a mesh (≤ 64 vertices, ≤ 124 triangles), in object space (meshlets.rs; std430).
struct Meshlet {
    vec4 center_radius;    // bounding sphere
    vec4 cone_axis_cutoff; // back-face cone: only back faces seen where dot(normalize(apex − eye), axis) ≥ cutoff
    vec4 cone_apex;        // xyz
    uvec4 triangles;       // x: first triangle in the meshlet triangle buffer; y: triangles;
                           // z: first vertex in the meshlet vertex buffer; w: vertices
};

// A visibility id's low bits: the triangle in its meshlet (meshlets.rs TRIANGLE_BITS).
const uint VISIBILITY_TRIANGLE_BITS = 7u;
// Floats of a vertex in a vertex buffer read as storage (geometry.rs Vertex: position,
// normal, uv, tangent).
const uint VERTEX_FLOATS = 12u;
// A compacted index's low bits: the vertex in its meshlet (meshlets.rs VERTEX_BITS); the
// high bits are the draw slot.
const uint INDEX_VERTEX_BITS = 6u;

// The passes that loop over lists dispatch at most this many work groups (the least
// maxComputeWorkGroupCount a device may have).
const uint MAX_GROUPS = 65535u;

// Bits of Instance.meshlets.w.
const uint INSTANCE_CONE_CULLING = 1u; // rotation, uniform scale, mirror: cones hold
const uint INSTANCE_MIRRORED = 2u;     // a mirror turns the cones around
const uint INSTANCE_DOUBLE_SIDED = 4u; // both sides drawn: no cone or back-face culling
const uint INSTANCE_MASKED = 8u;       // alpha-tested where drawn

// An object as the meshlet culling sees it (same index as the object buffer; std430).
struct Instance {
    vec4 bounds;    // world-space bounding sphere
    vec4 scale;     // x: the largest stretch of its transform (meshlet spheres grow by it)
    uvec4 meshlets; // x: first meshlet; y: meshlet count; z: first meshlet-instance id; w: INSTANCE_*
    uvec4 surface;  // x: its own textures (TEXTURE_* bits); y: its texture set
};

// VkDrawIndexedIndirectCommand.
struct DrawIndexedCommand {
    uint index_count;
    uint instance_count;
    uint first_index;
    int vertex_offset;
    uint first_instance;
};

// The counts of a frame's culling (std430): the culling's indirect dispatches read `dispatch`
// and `meshlets`, the raster passes their phase's draw; the CPU reads the rest after the frame.
struct CullCounters {
    uvec4 dispatch;              // x: instances that passed the frustum test (meshlet-culling work groups), y, z: 1
    uvec4 meshlets[2];           // per phase: x: meshlets drawn (triangle-culling work groups), y, z: 1
    uvec4 triangles;             // x, y: triangles of the early, late phase's meshlets; z, w: of those, drawn
    uvec4 tested;                // x: meshlets tested early, y: late; z: instances tested
    uvec4 rasterized;            // compute raster: x, y: triangles it drew early, late; z: pixels it
                                 // covered; w: large triangles drawn in place (the lists full)
    DrawIndexedCommand draws[2]; // per phase: the compacted triangles (index_count = 3 × drawn)
    uint _pad0[2];               // (where std430 would pad anyway: large is 16-byte aligned)
    uvec4 large[2];              // compute raster, per phase: the large-triangle pass's work
                                 // groups (bins listed, at most MAX_GROUPS), 1, 1
    uvec4 binned;                // x, y: bins listed early, late; z, w: large triangles found early,
                                 // late (past the lists' capacity too)
    uvec4 candidates;            // compute raster, transparent cores: x: soft samples listed for
                                 // the layers (past the list's room too); y: 1 where the
                                 // per-triangle build must build the cores instead
    uvec4 candidate_groups;      // the candidates' build's work groups (at most 65535), 1, 1
};

// The compute raster's 64-bit buffer, a pixel read as uvec2: x: the visibility id; y: the
// depth's bits, all ones where nothing was drawn (depth 1 and id 0 then, as the hardware
// raster clears its images).
float visibility_buffer_depth(uvec2 pixel) {
    return pixel.y == 0xffffffffu ? 1.0 : uintBitsToFloat(pixel.y);
}

uint visibility_buffer_id(uvec2 pixel) {
    return pixel.y == 0xffffffffu ? 0u : pixel.x;
}

// A large triangle of the compute raster (visibility_polygon.glsl), clipped and set up once
// by the thread that found it; the bins it is listed by point at it.
struct LargeTriangle {
    uvec4 head;       // x: corners of the clipped polygon (3 to 8); y: visibility id; z: its
                      // object where masked (else NOT_MASKED); w: its instance's INSTANCE_* bits
    ivec4 corners[4]; // corner 2k in xy, 2k + 1 in zw: in the image, snapped to the sub-pixel grid
    vec4 depths[2];   // each corner's depth z/w, corner k in component k
    vec4 surface_clip[3]; // masked: the unclipped triangle's clip-space corners
    vec4 surface_uv[2];   // masked: its corners' texture coordinates (a xy, b zw; c xy)
};
#define NOT_MASKED 0xffffffffu

// Push constants of the culling passes.
struct CullPush {
    uvec4 mode;      // x: phase (0: early, 1: late); y: 1 culling on, 0 everything drawn;
                     // z: depth-pyramid levels; w: draw capacity (late draw slots start there)
    uvec4 triangles; // x: the scene's triangles (the late phase's triangle ids start there);
                     // y: compute raster: the largest triangle it draws (bounding box, pixels a
                     // side), 0 with the hardware raster; z: the large triangles' bin list's
                     // capacity; w: 1 where they are drawn in compute, 0 by the hardware
};

// Push constants of the compute shadow raster (omni_raster.glsl).
struct OmniRasterPush {
    mat4 projection; // every face's: 90°, near NEAR_FRACTION, far 1 (the light's frame, in radii)
    uvec4 sizes;     // x: texels per face side; y: shadowed lights; z: the largest triangle one
                     // thread draws (bounding box, texels a side); w: meshlet instances
    uvec4 capacity;  // x: (meshlet instance, face) pairs the pair list holds; y: large triangles
                     // (in the shadow atlas sizes.x is unused: each light's tiles say)
};

// The counts of a frame's compute shadow raster.
struct OmniRasterCounters {
    uvec4 pairs; // x: the raster's work groups (at most 65535; each loops); y, z: 1; w: pairs listed
    uvec4 large; // x: the large-triangle raster's work groups, likewise; y, z: 1; w: large triangles
                 // listed (those past the list's capacity are drawn by their own thread)
    uvec4 drawn; // x: triangles drawn by one thread; y: of those, large (the list was full);
                 // z: texels covered; w: (meshlet, face) pairs drawn by the culling's thread
                 // (the pair list was full)
};

// A node of a two-wide BVH for shadow rays (shadows/shadow_rays.glsl): both children's
// boxes, so that one read tests both. A child with count 0 is a node (its index in the same
// buffer), else a leaf of `count` primitives from index `child`: triangles in a mesh's bottom
// level, instances in the top level.
struct RayNode {
    vec3 left_min;
    uint left_child;
    vec3 left_max;
    uint left_count;
    vec3 right_min;
    uint right_child;
    vec3 right_max;
    uint right_count;
};

// A triangle of a mesh's bottom level, in object space: a corner and the edges from it.
struct RayTriangle {
    vec3 v0;
    uint source; // its index in its mesh's index list
    vec3 e1;
    uint pad0;
    vec3 e2;
    uint pad1;
};

// An object in the shadow rays' top level: world -> object space (rows of an affine map) and
// its mesh's bottom level.
struct RayInstance {
    vec4 to_object[3];
    uint root;   // its mesh's root node in the bottom levels' nodes
    uint object; // its index in the scene's objects
    uint pad0;
    uint pad1;
};

// One shadowed light's faces in the shadow atlas (omni_shadow.glsl, omni_raster.glsl): the
// atlas holds depths in Z-order, a face's texel (x, y) at base[face] + morton(x, y).
struct ShadowCubeTiles {
    uint base[6]; // per cube face: its texel (0, 0) in the atlas; NO_TILE where it has none
    uint size;    // texels a side of each of its faces
    uint redraw;  // bit i: face i is drawn this frame (the others keep their texels)
};
#define NO_TILE 0xffffffffu

// Where texel `t` of a face lies in the Z-ordered atlas, from the face's texel (0, 0): x in
// the even bits, y in the odd (ml_cpu::shadow_atlas::morton_encode).
uint atlas_texel(uint base, uvec2 t) {
    uvec2 v = t & 0xffffu;
    v = (v | (v << 8u)) & 0x00ff00ffu;
    v = (v | (v << 4u)) & 0x0f0f0f0fu;
    v = (v | (v << 2u)) & 0x33333333u;
    v = (v | (v << 1u)) & 0x55555555u;
    return base + (v.x | (v.y << 1u));
}

// Background of pixels no object covers, as stored in the 8-bit target. Keep in sync with
// mesh_raster.rs CLEAR_COLOR.
const vec4 CLEAR_COLOR = vec4(0.02, 0.02, 0.02, 1.0);

// Linear colour → what the 8-bit target stores: the seed's gamma 1/2.2 (values above 1 clip).
// The pbr model tone-maps first (encode_output in shading_model.glsl); debug views use this.
vec3 encode_gamma(vec3 linear) {
    return pow(linear, vec3(1.0 / 2.2));
}

// A pixel's samples resolved in the display's linear light — `surfaces`: their colours' sum
// over every sample divided by the sample count; `share`: the share of samples no surface
// holds, which show `background` (display-linear: background.glsl) — as the 8-bit target
// stores it (anti-aliasing).
vec3 encode_over_background(vec3 surfaces, float share, vec3 background) {
    return encode_gamma(surfaces + share * background);
}

// Octahedral encoding of a unit normal into [-1, 1]² (the G-buffer keeps it in 2 floats).
vec2 oct_encode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 p = n.xy;
    if (n.z < 0.0) {
        p = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    }
    return p;
}

vec3 oct_decode(vec2 p) {
    vec3 n = vec3(p, 1.0 - abs(p.x) - abs(p.y));
    if (n.z < 0.0) {
        n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    }
    return normalize(n);
}

// The z of the cross product of two 2D vectors: twice the signed area of the triangle they
// span (the edge function of the visibility passes).
float cross2(vec2 a, vec2 b) {
    return a.x * b.y - a.y * b.x;
}

#endif
