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

// Nodes a traversal keeps to visit (ml_cpu::ray_bvh::RAY_STACK: the renderer refuses a
// hierarchy deeper than this).
const uint RAY_STACK = 64u;
// Smallest |direction| the box test divides by (a zero component would give 0 * inf).
const float RAY_MIN_DIRECTION = 1e-30;
// Traversal steps (nodes visited, triangles tested) of this invocation's rays so far: the
// ray-cost debug view.
uint ray_steps = 0u;

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

// The traversal of one level: NODES the node array, LEAF(first, count) tests a leaf's
// primitives and returns true on a hit. Both children of a node are tested from its one read;
// where both are entered, one is kept on the stack and the other visited next.
#define RAY_TRAVERSE(NODES, ROOT, O, INV, LEAF)                                                      \
    {                                                                                                \
        uint stack_[RAY_STACK];                                                                      \
        uint depth_ = 0u;                                                                            \
        uint node_ = ROOT;                                                                           \
        while (true) {                                                                               \
            RayNode n_ = NODES[node_];                                                               \
            ray_steps++;                                                                             \
            bool left_ = ray_enters(O, INV, n_.left_min, n_.left_max);                               \
            bool right_ = ray_enters(O, INV, n_.right_min, n_.right_max);                            \
            if (left_ && n_.left_count != 0u) {                                                      \
                if (LEAF(n_.left_child, n_.left_count)) {                                            \
                    return true;                                                                     \
                }                                                                                    \
                left_ = false;                                                                       \
            }                                                                                        \
            if (right_ && n_.right_count != 0u) {                                                    \
                if (LEAF(n_.right_child, n_.right_count)) {                                          \
                    return true;                                                                     \
                }                                                                                    \
                right_ = false;                                                                      \
            }                                                                                        \
            if (left_ && right_) {                                                                   \
                stack_[depth_++] = n_.right_child;                                                   \
                node_ = n_.left_child;                                                               \
            } else if (left_ || right_) {                                                            \
                node_ = left_ ? n_.left_child : n_.right_child;                                      \
            } else if (depth_ == 0u) {                                                               \
                break;                                                                               \
            } else {                                                                                 \
                node_ = stack_[--depth_];                                                            \
            }                                                                                        \
        }                                                                                            \
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

// Whether a triangle of instance `inst`'s mesh crosses the world segment origin + t d.
bool ray_instance_occludes(RayInstance inst, vec3 origin, vec3 d) {
    vec3 o = vec3(dot(inst.to_object[0].xyz, origin) + inst.to_object[0].w, dot(inst.to_object[1].xyz, origin) + inst.to_object[1].w,
                  dot(inst.to_object[2].xyz, origin) + inst.to_object[2].w);
    vec3 od = vec3(dot(inst.to_object[0].xyz, d), dot(inst.to_object[1].xyz, d), dot(inst.to_object[2].xyz, d));
    vec3 inv = ray_inverse(od);
#define RAY_MESH_LEAF(first, count) ray_leaf_triangles(first, count, inst.object, o, od)
    RAY_TRAVERSE(ray_nodes, inst.root, o, inv, RAY_MESH_LEAF)
#undef RAY_MESH_LEAF
    return false;
}

// Whether an instance of a leaf's `count` from `first` blocks the world segment.
bool ray_leaf_instances(uint first, uint count, vec3 origin, vec3 d) {
    for (uint k = first; k < first + count; ++k) {
        if (ray_instance_occludes(ray_instances[k], origin, d)) {
            return true;
        }
    }
    return false;
}

// Whether a triangle crosses the segment from `origin` to `target` strictly between them.
bool ray_occluded(vec3 origin, vec3 target) {
    vec3 d = target - origin;
    vec3 inv = ray_inverse(d);
#define RAY_TOP_LEAF(first, count) ray_leaf_instances(first, count, origin, d)
    RAY_TRAVERSE(ray_top, 0u, origin, inv, RAY_TOP_LEAF)
#undef RAY_TOP_LEAF
    return false;
}

#endif
