#version 450
#extension GL_GOOGLE_include_directive : require
// The compute shadow raster, step 1 (omni_raster.glsl): a thread per (meshlet instance,
// shadowed light) tests the meshlet's bounding sphere against the light's sphere and each
// cube face's 90° pyramid, and lists a (meshlet instance, cube layer) pair per face it may
// reach — the per-face culling the graphics modes do per object, here per meshlet (with
// ORTHO_VIEW: against the view's box; in the shadow atlas, only the faces drawn this frame).
// No back-face cone: shadow passes draw both faces (a caster need not be closed).
#include "common/common.glsl"

layout(local_size_x = 64) in;

#include "shadows/omni_raster.glsl"

// The faces (bit i: face i) whose pyramid a sphere at `c` (relative to the light) of radius
// `r` may reach: conservative, from the four planes that bound each pyramid
// (ml_cpu::omni_shadow::sphere_faces).
uint sphere_faces(vec3 c, float r) {
    float reach = r * 1.41421356;
    uint mask = 0u;
    for (int face = 0; face < 6; face++) {
        int axis = face / 2;
        float along = (face % 2 == 0 ? 1.0 : -1.0) * c[axis];
        bool inside = true;
        for (int o = 0; o < 3; o++) {
            if (o != axis && along - abs(c[o]) < -reach) {
                inside = false;
            }
        }
        if (inside) {
            mask |= 1u << uint(face);
        }
    }
    return mask;
}

// Whether a sphere at `c` (world) of radius `r` may reach the orthographic view whose
// view-projection is `p`: each clip axis stretches the sphere by its row's length.
bool sphere_in_box(mat4 p, vec3 c, float r) {
    vec3 centre = (p * vec4(c, 1.0)).xyz;
    vec3 reach = r * vec3(length(vec3(p[0][0], p[1][0], p[2][0])), length(vec3(p[0][1], p[1][1], p[2][1])), length(vec3(p[0][2], p[1][2], p[2][2])));
    return all(lessThanEqual(abs(centre.xy), 1.0 + reach.xy)) && centre.z >= -reach.z && centre.z <= 1.0 + reach.z;
}

void main() {
    uint light = ATLAS ? redrawn_lights[gl_WorkGroupID.y] : gl_WorkGroupID.y;
    vec4 l = shadow_lights[light];
    for (uint id = gl_GlobalInvocationID.x; id < opaque_uniform(omni.sizes.w); id += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        uvec2 object_meshlet = meshlet_instances[id];
        Meshlet m = meshlets[object_meshlet.y];
        vec3 c = (objects[object_meshlet.x].model * vec4(m.center_radius.xyz, 1.0)).xyz - l.xyz;
        float r = m.center_radius.w * instances[object_meshlet.x].scale.x;
        if (ORTHO_VIEW) {
            if (sphere_in_box(omni.projection, c, r)) {
                uint at = atomicAdd(counters.pairs.w, 1u);
                atomicMax(counters.pairs.x, min(at + 1u, MAX_GROUPS));
                pairs[at] = uvec2(id, light);
            }
            continue;
        }
        if (length(c) > l.w + r) {
            continue;
        }
        uint faces = sphere_faces(c, r);
        if (ATLAS) {
            // Faces the light keeps from last frame (or that no visible pixel samples) are not drawn.
            faces &= cube_tiles[light].redraw;
        }
        uint n = bitCount(faces);
        if (n == 0u) {
            continue;
        }
        // Pairs past the list's capacity are drawn here (the cube array's list holds six per
        // meshlet instance and light: it never fills).
        uint at = atomicAdd(counters.pairs.w, n);
        atomicMax(counters.pairs.x, min(min(at + n, omni.capacity.x), MAX_GROUPS));
        for (; faces != 0u; faces &= faces - 1u) {
            uint layer = light * 6u + uint(findLSB(faces));
            if (at < opaque_uniform(omni.capacity.x)) {
                pairs[at] = uvec2(id, layer);
            } else {
                atomicAdd(counters.drawn.z, raster_meshlet_alone(id, layer));
                atomicAdd(counters.drawn.w, 1u);
            }
            at++;
        }
    }
}
