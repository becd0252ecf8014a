// Lighting from the visibility buffer (technique visibility; docs/DESIGN.md#visibility-buffer):
// per pixel, the id names the meshlet instance and the triangle; its three vertices are
// fetched and transformed as the raster transformed them, the pixel's perspective-correct
// barycentrics rebuilt, the attributes interpolated, the material evaluated (textures with
// the derivatives a fragment shader would have had), then the clustered light loop of the
// other paths. Position comes from depth, as in deferred-compute.
//
// Objects' own textures are bound per texture set (set 2): one dispatch per set, each
// shading the pixels of its objects (lavapipe cannot index sampler arrays per pixel).
//
// Whichever raster drew the visibility buffer: the includer (visibility_lighting.comp,
// visibility_lighting_buffer.comp) defines LIGHT_GRID and SURFACE_GRADIENTS, includes
// common.glsl and scene_bindings.glsl, and says where the depth and ids are: `float
// raster_depth(ivec2 pixel)`, `uint raster_id(ivec2 pixel)`.

#ifndef MANYLIGHTS_VISIBILITY_LIGHTING_GLSL
#define MANYLIGHTS_VISIBILITY_LIGHTING_GLSL

layout(local_size_x = 8, local_size_y = 8) in;

// Every mesh's vertices (geometry.rs Vertex: position, normal, uv, tangent; 12 floats).
layout(std430, set = 0, binding = 13) readonly buffer VertexBuffer { float vertex_data[]; };
layout(std430, set = 0, binding = 14) readonly buffer MeshletVertexBuffer { uint meshlet_vertices[]; };
layout(std430, set = 0, binding = 18) readonly buffer MeshletTriangleBuffer { uint meshlet_triangles[]; };
layout(std430, set = 0, binding = 15) readonly buffer MeshletBuffer { Meshlet meshlets[]; };
layout(std430, set = 0, binding = 16) readonly buffer MeshletInstanceBuffer { uvec2 meshlet_instances[]; };
layout(std430, set = 0, binding = 17) readonly buffer InstanceBuffer { Instance instances[]; };
layout(push_constant) uniform ShadingSetPushBlock { uvec4 texture_set; }; // x: the set this dispatch shades
#include "common/textures.glsl"
#include "common/surface.glsl"
#include "common/lighting.glsl"
#include "shading/compute_shading.glsl"
#include "visibility/meshlet_geometry.glsl"

struct Attributes {
    vec3 position;
    vec3 normal;
    vec2 uv;
    vec4 tangent;
};

Attributes vertex_at(uint i) {
    uint b = VERTEX_FLOATS * i;
#define F(k) vertex_data[b + k]
    return Attributes(vec3(F(0u), F(1u), F(2u)), vec3(F(3u), F(4u), F(5u)), vec2(F(6u), F(7u)), vec4(F(8u), F(9u), F(10u), F(11u)));
#undef F
}

// Perspective-correct barycentrics at pixel position `xy` of the triangle whose clip-space
// vertices are `c`: screen-space weights from the 2D edge functions, each divided by its
// vertex's w, normalised — what the rasteriser interpolates with.
vec3 barycentrics(vec4 c[3], vec2 xy) {
    vec2 ndc = xy / vec2(frame.viewport.xy) * 2.0 - 1.0;
    vec2 s0 = c[0].xy / c[0].w, s1 = c[1].xy / c[1].w, s2 = c[2].xy / c[2].w;
    float area = cross2(s1 - s0, s2 - s0);
    float l0 = cross2(s1 - ndc, s2 - ndc) / area;
    float l1 = cross2(s2 - ndc, s0 - ndc) / area;
    vec3 w = vec3(l0, l1, 1.0 - l0 - l1) / vec3(c[0].w, c[1].w, c[2].w);
    return w / (w.x + w.y + w.z);
}

// A colour per id (the meshlets and triangles debug views).
vec3 id_color(uint x) {
    x = x * 747796405u + 2891336453u;
    x = ((x >> ((x >> 28u) + 4u)) ^ x) * 277803737u;
    x = (x >> 22u) ^ x;
    return vec3(uvec3(x, x >> 8u, x >> 16u) & 255u) / 255.0;
}

// The surface of visibility id `id` at the point `frag_xy` of pixel p, ready to shade: its
// point (`world`, rebuilt from `z`, its depth there, as every compute lighting and the light
// grid's marks rebuild it), normal and material.
void surface_of(ivec2 p, uint id, vec2 frag_xy, float z, out vec3 world, out vec3 n, out PointMaterial m, out uint flags) {
    uvec2 object_meshlet = meshlet_instances[id >> VISIBILITY_TRIANGLE_BITS];
    uint object = object_meshlet.x;
    Instance inst = instances[object];
    uvec3 corners = meshlet_triangle(meshlets[object_meshlet.y], id & ((1u << VISIBILITY_TRIANGLE_BITS) - 1u));
    ObjectData o = objects[object];
    Attributes v[3];
    vec4 c[3];
    for (int k = 0; k < 3; k++) {
        v[k] = vertex_at(corners[k]);
        v[k].uv = transform_uv(o.uv_transform, v[k].uv);
        vec3 corner = (o.model * vec4(v[k].position, 1.0)).xyz;
        c[k] = frame.proj * frame.view * vec4(corner, 1.0);
    }
    vec3 b = barycentrics(c, frag_xy);
    // Texture derivatives as a fragment shader's: differences across its 2×2 quad, the
    // triangle's attributes taken at the quad's pixels (extrapolated where the triangle does
    // not cover them, as helper invocations do) — the quad's first row and column, as
    // lavapipe derives them (coarse derivatives: one pair for the whole quad).
    mat3x2 uvs = mat3x2(v[0].uv, v[1].uv, v[2].uv);
    vec2 uv = uvs * b;
    vec2 q = vec2(p & ~1) + 0.5;
    vec3 b00 = barycentrics(c, q), b10 = barycentrics(c, q + vec2(1.0, 0.0)), b01 = barycentrics(c, q + vec2(0.0, 1.0));
    vec2 uv00 = uvs * b00;
    surface_uv_dx = uvs * b10 - uv00;
    surface_uv_dy = uvs * b01 - uv00;
    vec3 normal = mat3(o.normal_matrix) * (mat3(v[0].normal, v[1].normal, v[2].normal) * b);
    // A double-sided object's back face (its corners clockwise on screen: the homogeneous
    // determinant is the projected area's sign, also for corners behind the eye) is lit on
    // the side the viewer sees.
    if ((o.alpha_texture.x & OBJECT_DOUBLE_SIDED) != 0u && determinant(mat3(c[0].xyw, c[1].xyw, c[2].xyw)) > 0.0) {
        normal = -normal;
    }
    vec4 tangent = mat4(v[0].tangent, v[1].tangent, v[2].tangent, vec4(0.0)) * vec4(b, 0.0);
    tangent.xyz = mat3(o.model) * tangent.xyz;
    Surface s = surface_at(normal, tangent, uv, inst.surface.x, o.material, object);
    m = point_material(o.albedo_roughness, o.material, o.emissive, vec4(s.albedo_factor, s.occlusion), s.roughness_metallic, s.emissive_factor, s.normal_spread,
                       object, s.lobes);
    world = world_from_depth(frag_xy, z);
    n = s.normal;
    flags = o.alpha_texture.x;
}

// The texture set whose dispatch shades the surface of visibility id `id`.
uint texture_set_of(uint id) {
    return instances[meshlet_instances[id >> VISIBILITY_TRIANGLE_BITS].x].surface.y;
}

#if defined(RASTER_SAMPLES) && !defined(LINEAR_OUTPUT)
// Anti-aliased (docs/DESIGN.md#anti-aliasing): the pixel's samples grouped by the surface
// (visibility id) they hold, each surface shaded once (at shading_xy), and the pixel the mean
// of its samples' display-linear colours: each surface weighed by the samples it covers, the
// background likewise. Every lane shades its pixel's first surface; edge pixels hold more,
// and a lane shading its own would keep its subgroup waiting on the pixel with the most, so
// the others are dealt out: each round the subgroup's lanes list their pending surfaces, a
// lane each (as many as it has lanes), shade them and hand the colours back through shared
// memory. A surface is named by its first sample (its "leader"); the lane that shades it
// finds its samples again from the buffer. Shared memory is a slot per lane (the lighting
// is fast only with most of L1 left as cache). Surfaces whose textures another dispatch
// binds are that dispatch's: the first dispatch with a surface in the pixel (the first set's
// where none has) stores its share, the later ones add theirs.

#ifdef LAYERED_SAMPLES
// With transparent layers, each surface's linear colour is kept for their blend too.
#include "visibility/surface_colours.glsl"
#endif

// Per lane, the surface it shades this round (its pixel in the work group << 16 | leader
// sample), and then its colour × samples covered.
shared uint dealt[gl_WorkGroupSize.x * gl_WorkGroupSize.y];
shared vec3 dealt_colour[gl_WorkGroupSize.x * gl_WorkGroupSize.y];

// The samples of pixel p holding the same surface as sample `leader` (a bit each), and the
// mean of their depths.
uint samples_of(ivec2 p, uint leader, out float depth) {
    uvec2 l = raster_sample(p, leader);
    uint members = 0u;
    float depths = 0.0;
    [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        uvec2 v = raster_sample(p, k);
        if (visibility_buffer_depth(v) < 1.0 && visibility_buffer_id(v) == l.x) {
            members |= 1u << k;
            depths += visibility_buffer_depth(v);
        }
    }
    depth = depths / float(bitCount(members));
    return members;
}

// The colour of the surface whose first sample is `leader` in pixel p, shaded (or a debug
// view's), times the samples it covers. Its point is the mean of its samples' positions at
// the mean of their depths (depth is affine in the image over a triangle: the triangle's
// point there), as the light grid's marks find it (light_grid_mark.glsl surface_walk).
vec3 surface_display(ivec2 p, uint leader) {
    float depth;
    uint members = samples_of(p, leader, depth);
    uint id = visibility_buffer_id(raster_sample(p, leader));
    uint view = frame.viewport.z;
    vec3 display;
    if (view == DEBUG_VIEW_MESHLETS || view == DEBUG_VIEW_TRIANGLES) {
        display = pow(id_color(view == DEBUG_VIEW_MESHLETS ? id >> VISIBILITY_TRIANGLE_BITS : id), vec3(2.2));
    } else {
        vec2 xy = shading_xy(p, members);
        vec3 world, n;
        PointMaterial m;
        uint flags;
        surface_of(p, id, xy, depth, world, n, m, flags);
        bool debug;
        vec3 shaded = shade_linear(xy, world, n, m, flags, debug);
#ifdef LAYERED_SAMPLES
        store_surface_colour(p, leader, shaded);
#endif
        display = display_of(shaded, debug);
    }
    return display * float(bitCount(members));
}

// Per pixel of the work group, what its resolve needs of its samples, kept here while it
// shades (registers held across the shading would cost the lighting occupancy): the surfaces,
// the background's samples and the surfaces this dispatch shades, 5 bits each, and the first
// texture set among its surfaces above them.
shared uint pixel_state[gl_WorkGroupSize.x * gl_WorkGroupSize.y];

// The pixel of the work group numbered `pixel` (gl_LocalInvocationIndex's numbering).
ivec2 group_pixel(uint pixel) {
    return ivec2(gl_WorkGroupID.xy * gl_WorkGroupSize.xy + uvec2(pixel % gl_WorkGroupSize.x, pixel / gl_WorkGroupSize.x));
}

// Every lane of the subgroup calls it (subgroup operations); pixels outside the image have
// no surfaces.
void shade_samples(ivec2 p, bool inside) {
    uint set = opaque_uniform(texture_set.x);
    uint leaders = 0u;
    {
        uvec2 v[VISIBILITY_SAMPLES];
        [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
            v[k] = inside ? raster_sample(p, k) : uvec2(0u, 0xffffffffu);
        }
        // The pixel's surfaces by their leaders: those of this dispatch's set to shade.
        uint grouped = 0u, surfaces = 0u, background = 0u, first_set = 0xffffu;
        [[unroll]] for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
            if ((grouped & (1u << k)) != 0u) {
                continue;
            }
            bool drawn = visibility_buffer_depth(v[k]) < 1.0;
            uint id = visibility_buffer_id(v[k]);
            uint members = 0u;
            [[unroll]] for (uint j = k; j < VISIBILITY_SAMPLES; j++) {
                bool drawn_j = visibility_buffer_depth(v[j]) < 1.0;
                if (drawn_j == drawn && (!drawn || visibility_buffer_id(v[j]) == id)) {
                    members |= 1u << j;
                }
            }
            grouped |= members;
            if (!drawn) {
                background += uint(bitCount(members));
                continue;
            }
            surfaces++;
            uint surface_set = texture_set_of(id);
            first_set = min(first_set, surface_set);
            if (surface_set == set) {
                leaders |= 1u << k;
            }
        }
        pixel_state[gl_LocalInvocationIndex] = surfaces | (background << 5u) | (uint(bitCount(leaders)) << 10u) | (first_set << 16u);
    }
    // Round 0: each lane its own first surface. Then the others, dealt out. `item`: the pixel
    // << 16 | the leader of the surface a lane shades (NO_ITEM: none).
    const uint NO_ITEM = 0xffffffffu;
    uint item = leaders != 0u ? (gl_LocalInvocationIndex << 16u) | uint(findLSB(leaders)) : NO_ITEM;
    leaders &= leaders - 1u;
    uint own = gl_SubgroupID * gl_SubgroupSize;
    vec3 sum = vec3(0.0);
    uint first_slot = 0u, slots = 0u;
    for (bool round0 = true;; round0 = false) {
        vec3 colour = item != NO_ITEM ? surface_display(group_pixel(item >> 16u), item & 0xffffu) : vec3(0.0);
        if (round0) {
            sum = colour;
        } else {
            dealt_colour[own + gl_SubgroupInvocationID] = colour;
        }
        subgroupMemoryBarrierShared();
        subgroupBarrier();
        // Collect what was shaded for this pixel last round.
        for (uint i = 0u; i < slots; i++) {
            sum += dealt_colour[own + first_slot + i];
        }
        // Deal the next round: each lane's pending surfaces after those of the lanes before it.
        uint pending = uint(bitCount(leaders));
        uint total = subgroupAdd(pending);
        if (total == 0u) {
            break;
        }
        first_slot = subgroupExclusiveAdd(pending);
        slots = first_slot < gl_SubgroupSize ? min(pending, gl_SubgroupSize - first_slot) : 0u;
        subgroupBarrier();
        for (uint i = 0u; i < slots; i++) {
            dealt[own + first_slot + i] = (gl_LocalInvocationIndex << 16u) | uint(findLSB(leaders));
            leaders &= leaders - 1u;
        }
        subgroupMemoryBarrierShared();
        subgroupBarrier();
        item = gl_SubgroupInvocationID < total ? dealt[own + gl_SubgroupInvocationID] : NO_ITEM;
    }
    uint state = pixel_state[gl_LocalInvocationIndex];
    uint surfaces = state & 31u, background = (state >> 5u) & 31u, shaded = (state >> 10u) & 31u, first_set = state >> 16u;
    // The surfaces shaded, for the report (ray_count.y; the host zeroes it before the frame).
    uint counted = subgroupAdd(shaded);
    if (subgroupElect() && counted != 0u) {
        atomicAdd(ray_count.y, counted);
    }
    if (!inside) {
        return;
    }
    bool first = surfaces == 0u ? set == 0u : first_set == set;
    if (frame.viewport.z == DEBUG_VIEW_AA) {
        // Surfaces shaded in the pixel: none the background; one blue, two cyan, three green,
        // four yellow, five and more red.
        if (first) {
            vec4 c = surfaces == 0u ? CLEAR_COLOR : vec4(heat(min(float(surfaces), 5.0) / 5.0), 1.0);
            imageStore(out_image, p, c);
        }
        return;
    }
    sum /= float(VISIBILITY_SAMPLES);
    if (first) {
        imageStore(out_image, p, vec4(encode_over_background(sum, float(background) / float(VISIBILITY_SAMPLES), background_linear(p)), 1.0));
    } else if (shaded != 0u) {
        imageStore(out_image, p, vec4(encode_gamma(sum + pow(imageLoad(out_image, p).rgb, vec3(2.2))), 1.0));
    }
}
#endif

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    bool inside = p.x < int(frame.viewport.x) && p.y < int(frame.viewport.y);
#if defined(RASTER_SAMPLES) && !defined(LINEAR_OUTPUT)
    // The same for the whole dispatch (a constant): every thread of a work group takes it.
    if (VISIBILITY_SAMPLES != 1u) {
        shade_samples(p, inside);
        return;
    }
#endif
    if (!inside) {
        return;
    }
    float z = raster_depth(p);
    if (z >= 1.0) {
        // The background, once: by the first set's dispatch.
        if (opaque_uniform(texture_set.x) == 0u) {
            store_background(p);
        }
        return;
    }
    uint id = raster_id(p);
    if (texture_set_of(id) != texture_set.x) {
        return;
    }
    uint view = frame.viewport.z;
    if (view == DEBUG_VIEW_MESHLETS || view == DEBUG_VIEW_TRIANGLES) {
        imageStore(out_image, p, vec4(id_color(view == DEBUG_VIEW_MESHLETS ? id >> VISIBILITY_TRIANGLE_BITS : id), 1.0));
        return;
    }
    if (view == DEBUG_VIEW_AA) {
        // One surface per pixel without anti-aliasing.
        imageStore(out_image, p, vec4(heat(0.2), 1.0));
        return;
    }
    vec2 frag_xy = vec2(p) + 0.5;
    vec3 world, n;
    PointMaterial m;
    uint flags;
    surface_of(p, id, frag_xy, z, world, n, m, flags);
    shade_and_store(p, frag_xy, world, n, m, flags);
}

#endif
