// The transparent layers' build in compute, for transparent objects of few triangles (glass
// panes, windows, cards): the H100 runs fragment shaders on 4 of its 132 SMs, so a pane across
// the view appended through them costs 2M fragments at that rate. A dispatch per object over
// the pixels its box may cover (found on the CPU), a work group per 8×8 pixels: its threads set up up to 64 of the object's triangles at a time
// (clip-space positions, attributes) in shared memory, then each pixel tests them all.
//
// Triangles are rasterised in homogeneous coordinates (no clipping: a triangle crossing the
// eye plane still covers exactly its visible part): with M = (x, y, w) of the three vertices as
// columns, the rows of adj(M) are edge functions whose values at the pixel's (x, y, 1),
// normalised, are its perspective-correct barycentrics; the pixel is inside where all three
// have the sign of det(M). A pixel on an edge shared by two triangles belongs to one of them
// (the two edge functions are exact negatives of each other; the sign of their x, then y,
// coefficient decides). Depth and attributes are interpolated with those barycentrics; the
// texture gradients are their differences one pixel to the right and one down.
//
// The includer defines OPAQUE_DEPTH_BUFFER for the compute raster's 64-bit buffer.
#define SURFACE_GRADIENTS 1
#include "common/common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

#include "common/scene_bindings.glsl"
#include "common/textures.glsl"
#include "common/surface.glsl"
#define ALPHA_MASK_BINDING 11
#include "common/alpha_mask.glsl"
#define LAYER_BINDING 14
#include "transparency/layers.glsl"
#include "transparency/opaque_depth.glsl"

// The object's mesh (gpu_mesh.rs): 12 floats a vertex (position, normal, uv, tangent), and
// three indices a triangle.
layout(std430, set = 3, binding = 0) readonly buffer MeshVertexBuffer { float mesh_vertices[]; };
layout(std430, set = 3, binding = 1) readonly buffer MeshIndexBuffer { uint mesh_indices[]; };
// ObjectPush (ids.z: the mesh's triangles; ids.w: the first pixel of the object's screen
// rectangle, y << 16 | x, which the dispatch covers).
layout(push_constant) uniform PushBlock { ObjectPush object; };

const uint CHUNK = 64u;
shared vec4 tri_clip[CHUNK][3];    // (x, y, z, w) in clip space
shared vec3 tri_normal[CHUNK][3];  // world space
shared vec4 tri_uv[CHUNK][3];      // xy: the textures' coordinates
shared vec4 tri_tangent[CHUNK][3]; // world space, w: handedness
shared uint tri_kept[CHUNK];       // whether the triangle faces a way it is drawn

struct Vtx {
    vec3 position;
    vec3 normal;
    vec2 uv;
    vec4 tangent;
};

Vtx mesh_vertex(uint i) {
    uint b = 12u * i;
    Vtx v;
    v.position = vec3(mesh_vertices[b], mesh_vertices[b + 1u], mesh_vertices[b + 2u]);
    v.normal = vec3(mesh_vertices[b + 3u], mesh_vertices[b + 4u], mesh_vertices[b + 5u]);
    v.uv = vec2(mesh_vertices[b + 6u], mesh_vertices[b + 7u]);
    v.tangent = vec4(mesh_vertices[b + 8u], mesh_vertices[b + 9u], mesh_vertices[b + 10u], mesh_vertices[b + 11u]);
    return v;
}

// Whether a pixel where edge function `e` (coefficients `c`, both with the triangle's sign
// applied) is 0 belongs to this triangle.
bool edge_owns(float e, vec2 c) {
    return e > 0.0 || (e == 0.0 && (c.x > 0.0 || (c.x == 0.0 && c.y > 0.0)));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy) + ivec2(object.ids.w & 0xffffu, object.ids.w >> 16);
    bool in_image = p.x < int(frame.viewport.x) && p.y < int(frame.viewport.y);
    uint o = object.ids.x;
    // Only the fields each step needs (the whole ObjectData per thread would be 240 bytes of
    // reads in every dispatch).
    float base_alpha = objects[o].alpha.y;
    uvec4 alpha_texture = objects[o].alpha_texture;
    bool double_sided = (alpha_texture.x & OBJECT_DOUBLE_SIDED) != 0u;
    mat4 view_proj = frame.proj * frame.view;
    vec2 to_ndc = 2.0 / vec2(frame.viewport.xy);
    vec3 q = vec3((vec2(p) + 0.5) * to_ndc - 1.0, 1.0);
    float opaque = in_image ? opaque_depth_at(p) : 0.0;
    uint triangles = object.ids.z;
    for (uint base = 0u; base < triangles; base += CHUNK) {
        uint t = base + gl_LocalInvocationIndex;
        if (t < triangles) {
            mat4 model = objects[o].model;
            mat3 normal_matrix = mat3(objects[o].normal_matrix);
            vec4 uv_transform[2] = objects[o].uv_transform;
            for (uint k = 0u; k < 3u; k++) {
                Vtx v = mesh_vertex(mesh_indices[3u * t + k]);
                vec3 world = (model * vec4(v.position, 1.0)).xyz;
                tri_clip[gl_LocalInvocationIndex][k] = view_proj * vec4(world, 1.0);
                tri_normal[gl_LocalInvocationIndex][k] = normal_matrix * v.normal;
                tri_uv[gl_LocalInvocationIndex][k] = vec4(transform_uv(uv_transform, v.uv), 0.0, 0.0);
                tri_tangent[gl_LocalInvocationIndex][k] = vec4(mat3(model) * v.tangent.xyz, v.tangent.w);
            }
        }
        barrier();
        uint count = min(CHUNK, triangles - base);
        for (uint i = 0u; i < count && in_image; i++) {
            vec3 a = tri_clip[i][0].xyw, b = tri_clip[i][1].xyw, c = tri_clip[i][2].xyw;
            vec3 r0 = cross(b, c), r1 = cross(c, a), r2 = cross(a, b);
            float det = dot(a, r0);
            // Front faces wind counter-clockwise as the pipelines see them (Y-flipped
            // projection): det < 0 here.
            bool front = det < 0.0;
            if (det == 0.0 || (!front && !double_sided)) {
                continue;
            }
            float s = sign(det);
            vec3 e = vec3(dot(r0, q), dot(r1, q), dot(r2, q)) * s;
            if (!(edge_owns(e.x, r0.xy * s) && edge_owns(e.y, r1.xy * s) && edge_owns(e.z, r2.xy * s))) {
                continue;
            }
            float sum = e.x + e.y + e.z;
            if (sum <= 0.0) {
                continue;
            }
            vec3 w = e / sum;
            vec3 zs = vec3(tri_clip[i][0].z, tri_clip[i][1].z, tri_clip[i][2].z);
            vec3 ws = vec3(tri_clip[i][0].w, tri_clip[i][1].w, tri_clip[i][2].w);
            float depth = dot(w, zs) / dot(w, ws);
            if (!(depth >= 0.0 && depth <= 1.0) || depth >= opaque) {
                continue;
            }
            vec2 uv = w.x * tri_uv[i][0].xy + w.y * tri_uv[i][1].xy + w.z * tri_uv[i][2].xy;
            float alpha = base_alpha;
            if ((alpha_texture.x & OBJECT_ALPHA_TEXTURE) != 0u) {
                alpha *= texture_alpha(alpha_texture, uv);
            }
            if (alpha <= 0.0) {
                continue;
            }
            // The texture coordinates one pixel to the right and one down.
            vec3 ex = (vec3(dot(r0, q + vec3(to_ndc.x, 0.0, 0.0)), dot(r1, q + vec3(to_ndc.x, 0.0, 0.0)), dot(r2, q + vec3(to_ndc.x, 0.0, 0.0))));
            vec3 ey = (vec3(dot(r0, q + vec3(0.0, to_ndc.y, 0.0)), dot(r1, q + vec3(0.0, to_ndc.y, 0.0)), dot(r2, q + vec3(0.0, to_ndc.y, 0.0))));
            vec3 wx = ex / (ex.x + ex.y + ex.z), wy = ey / (ey.x + ey.y + ey.z);
            surface_uv_dx = wx.x * tri_uv[i][0].xy + wx.y * tri_uv[i][1].xy + wx.z * tri_uv[i][2].xy - uv;
            surface_uv_dy = wy.x * tri_uv[i][0].xy + wy.y * tri_uv[i][1].xy + wy.z * tri_uv[i][2].xy - uv;
            vec3 n = w.x * tri_normal[i][0] + w.y * tri_normal[i][1] + w.z * tri_normal[i][2];
            vec4 tangent = w.x * tri_tangent[i][0] + w.y * tri_tangent[i][1] + w.z * tri_tangent[i][2];
            Surface sf = surface_at(front ? n : -n, tangent, uv, object.ids.y, object.material);
            uvec4 surface = pack_layer_surface(sf.normal, vec4(sf.albedo_factor, sf.occlusion), sf.roughness_metallic, min(alpha, 1.0), sf.emissive_factor);
            store_layer(p, depth, o, surface);
        }
        barrier();
    }
}
