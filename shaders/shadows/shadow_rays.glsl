// Shadow rays (docs/DESIGN.md#shadow-rays): whether a triangle of the scene lies between a
// surface point and a light. A two-level hierarchy: the top level over the objects' world
// boxes, whose leaves are instances (world -> object space, their mesh's root), and a bottom
// level per mesh over its triangles in object space (ml_cpu::ray_bvh, which models this
// traversal on the CPU: keep the two in step). Any hit ends the search; both faces block.
//
// The includer declares (readonly): RayTopBuffer { RayNode ray_top[]; }, RayNodeBuffer
// { RayNode ray_nodes[]; }, RayTriangleBuffer { RayTriangle ray_triangles[]; } and
// RayInstanceBuffer { RayInstance ray_instances[]; }. With RAY_ALPHA_MASKS defined, also
// RayUvBuffer { vec2 ray_uvs[]; }, ObjectBuffer and alpha_mask.glsl: a masked object's
// triangles block only where its mask keeps the point.

#ifndef MANYLIGHTS_SHADOW_RAYS_GLSL
#define MANYLIGHTS_SHADOW_RAYS_GLSL

// Entries the traversal keeps on its stack (ml_cpu::ray_bvh::RAY_STACK: the renderer refuses
// a hierarchy whose RayScene::stack_needed exceeds it).
const uint RAY_STACK = 64u;
// Smallest |direction| the box test divides by (a zero component would give 0 * inf).
const float RAY_MIN_DIRECTION = 1e-30;
// Traversal steps (nodes visited, triangles tested) of this invocation's rays so far: the
// ray-cost debug view.
uint ray_steps = 0u;
// Rays this invocation has traced (the compute lightings add them up for the host).
uint rays_traced = 0u;

// 1 / d per axis, each |d| at least RAY_MIN_DIRECTION.
vec3 ray_inverse(vec3 d) {
    vec3 tiny = vec3(d.x < 0.0 ? -RAY_MIN_DIRECTION : RAY_MIN_DIRECTION, d.y < 0.0 ? -RAY_MIN_DIRECTION : RAY_MIN_DIRECTION,
                     d.z < 0.0 ? -RAY_MIN_DIRECTION : RAY_MIN_DIRECTION);
    return 1.0 / mix(d, tiny, lessThan(abs(d), vec3(RAY_MIN_DIRECTION)));
}

// Whether the segment o + t d, t in [0, 1], meets the box.
bool ray_enters(vec3 o, vec3 inv, vec3 lo, vec3 hi) {
    vec3 t0 = (lo - o) * inv;
    vec3 t1 = (hi - o) * inv;
    vec3 near3 = min(t0, t1);
    vec3 far3 = max(t0, t1);
    float near = max(max(max(near3.x, near3.y), near3.z), 0.0);
    float far = min(min(min(far3.x, far3.y), far3.z), 1.0);
    return near <= far;
}

// Whether the triangle crosses the segment o + t d at some 0 < t < 1 (Moller-Trumbore), and
// where: `bary`, the weights of its second and third corners.
bool ray_crosses(vec3 o, vec3 d, RayTriangle tri, out vec2 bary) {
    bary = vec2(0.0);
    vec3 p = cross(d, tri.e2);
    float det = dot(tri.e1, p);
    if (det == 0.0) {
        return false;
    }
    float inv_det = 1.0 / det;
    vec3 s = o - tri.v0;
    float u = dot(s, p) * inv_det;
    if (u < 0.0 || u > 1.0) {
        return false;
    }
    vec3 q = cross(s, tri.e1);
    float v = dot(d, q) * inv_det;
    if (v < 0.0 || u + v > 1.0) {
        return false;
    }
    float t = dot(tri.e2, q) * inv_det;
    bary = vec2(u, v);
    return t > 0.0 && t < 1.0;
}

// Whether triangle k of object `object`'s mesh, crossed at `bary`, is there: a masked
// object's mask keeps the point (ml_cpu::ray_bvh::WorldTriangles::kept).
bool ray_kept(uint k, uint object, vec2 bary) {
#ifdef RAY_ALPHA_MASKS
    uvec4 alpha_texture = objects[object].alpha_texture;
    if ((alpha_texture.x & OBJECT_MASKED) != 0u) {
        vec2 uv = ray_uvs[3u * k] * (1.0 - bary.x - bary.y) + ray_uvs[3u * k + 1u] * bary.x + ray_uvs[3u * k + 2u] * bary.y;
        return alpha_kept(objects[object].alpha, alpha_texture, transform_uv(objects[object].uv_transform, uv));
    }
#endif
    return true;
}

// Whether a triangle of a leaf's `count` triangles from `first` (of object `object`) crosses
// the segment where it is there.
bool ray_leaf_triangles(uint first, uint count, uint object, vec3 o, vec3 d) {
    for (uint k = first; k < first + count; ++k) {
        ray_steps++;
        vec2 bary;
        if (ray_crosses(o, d, ray_triangles[k], bary) && ray_kept(k, object, bary)) {
            return true;
        }
    }
    return false;
}

// What a traversal stack entry is (its top two bits): a node of the top level, a node of a
// mesh's hierarchy, an instance to enter, or the end of an instance (back to the world
// segment). The low 30 bits: the node's or the instance's index.
const uint RAY_TOP_NODE = 0u;
const uint RAY_MESH_NODE = 1u << 30;
const uint RAY_ENTER = 2u << 30;
const uint RAY_LEAVE = 3u << 30;
const uint RAY_INDEX = (1u << 30) - 1u;

// Whether a triangle crosses the segment from `origin` to `target` strictly between them.
// Both levels in one loop with one stack, so that the invocations of a subgroup step through
// the top level and their meshes together rather than waiting for each other's meshes.
bool ray_occluded(vec3 origin, vec3 target) {
    rays_traced++;
    vec3 world_d = target - origin;
    vec3 world_inv = ray_inverse(world_d);
    vec3 o = origin, d = world_d, inv = world_inv;
    uint object = 0u;
    uint stack[RAY_STACK];
    uint depth = 0u;
    uint entry = RAY_TOP_NODE;
    while (true) {
        uint kind = entry & ~RAY_INDEX, index = entry & RAY_INDEX;
        if (kind == RAY_ENTER) {
            // Into the instance's object space, the way back on the stack.
            RayInstance inst = ray_instances[index];
            o = vec3(dot(inst.to_object[0].xyz, origin) + inst.to_object[0].w, dot(inst.to_object[1].xyz, origin) + inst.to_object[1].w,
                     dot(inst.to_object[2].xyz, origin) + inst.to_object[2].w);
            d = vec3(dot(inst.to_object[0].xyz, world_d), dot(inst.to_object[1].xyz, world_d), dot(inst.to_object[2].xyz, world_d));
            inv = ray_inverse(d);
            object = inst.object;
            stack[depth++] = RAY_LEAVE;
            entry = RAY_MESH_NODE | inst.root;
            continue;
        }
        if (kind == RAY_LEAVE) {
            o = origin;
            d = world_d;
            inv = world_inv;
            if (depth == 0u) {
                break;
            }
            entry = stack[--depth];
            continue;
        }
        bool mesh = kind == RAY_MESH_NODE;
        RayNode n = mesh ? ray_nodes[index] : ray_top[index];
        ray_steps++;
        bool left = ray_enters(o, inv, n.left_min, n.left_max);
        bool right = ray_enters(o, inv, n.right_min, n.right_max);
        if (!mesh) {
            // The top level: the children to visit on the stack, and above them the instances
            // of the leaves entered, which are thus entered first (the stack stays within the
            // top level's depth + 1, the instances of two leaves, and one mesh's traversal).
            if (left && n.left_count == 0u) {
                stack[depth++] = RAY_TOP_NODE | n.left_child;
            }
            if (right && n.right_count == 0u) {
                stack[depth++] = RAY_TOP_NODE | n.right_child;
            }
            for (uint k = 0u; left && k < n.left_count; ++k) {
                stack[depth++] = RAY_ENTER | (n.left_child + k);
            }
            for (uint k = 0u; right && k < n.right_count; ++k) {
                stack[depth++] = RAY_ENTER | (n.right_child + k);
            }
            if (depth == 0u) {
                break;
            }
            entry = stack[--depth];
            continue;
        }
        if (left && n.left_count != 0u) {
            if (ray_leaf_triangles(n.left_child, n.left_count, object, o, d)) {
                return true;
            }
            left = false;
        }
        if (right && n.right_count != 0u) {
            if (ray_leaf_triangles(n.right_child, n.right_count, object, o, d)) {
                return true;
            }
            right = false;
        }
        if (left && right) {
            stack[depth++] = RAY_MESH_NODE | n.right_child;
            entry = RAY_MESH_NODE | n.left_child;
        } else if (left || right) {
            entry = RAY_MESH_NODE | (left ? n.left_child : n.right_child);
        } else {
            // A mesh's stack always holds its way back (RAY_LEAVE) below its nodes.
            entry = stack[--depth];
        }
    }
    return false;
}

#endif
