// Transparent layers (glTF alphaMode BLEND): every transparent fragment in front of the
// opaque surface is kept, per pixel, as a node of a linked list — its depth, coverage and
// surface, unlit — and blended back to front where the pixel is finally shaded. Lighting
// the nodes there, in compute, gives them the opaque surfaces' lights, cluster lists,
// shading model and shadows, in every technique.
//
// Memory is a fixed budget: a pool of nodes (`--transparency-budget` per pixel on average)
// and a head per pixel. A fragment that finds the pool full is dropped and counted. A pixel
// blends its LAYER_KEEP nearest layers exactly, in order of depth (ties by object); farther
// ones are merged into one layer behind them (coverage 1 − Π(1 − α), α-weighted colour) and
// the pixel is counted. ml-cpu transparency.rs is the same rule on the CPU.
//
// Needs common.glsl; the includer defines LAYER_BINDING, the first of its three set-0
// bindings. Blending (blend_layers) also needs lighting.glsl and world_from_depth.

#ifndef MANYLIGHTS_LAYERS_GLSL
#define MANYLIGHTS_LAYERS_GLSL

// Whether the scene's transparent layers are built and blended (else these buffers are
// stand-ins and nothing reads them).
layout(constant_id = 40) const bool TRANSPARENT_LAYERS = false;

const uint LAYER_END = 0xffffffffu;
// Layers a pixel blends exactly (a register array per thread); beyond, merged.
const uint LAYER_KEEP = 32u;

// Per pixel (row-major): its nearest-drawn node, LAYER_END for none.
layout(std430, set = 0, binding = LAYER_BINDING) buffer TransparentHeadBuffer { uint layer_heads[]; };
// Two uvec4 a node: (depth, next, object, alpha) and the surface (octahedral normal snorm
// 2×16, albedo factor and occlusion unorm 4×8, roughness and metallic factors unorm 2×16,
// emissive factor unorm 4×8).
layout(std430, set = 0, binding = LAYER_BINDING + 1) buffer TransparentNodeBuffer { uvec4 layer_nodes[]; };
// x: nodes asked for this frame (beyond the pool's size: dropped); y: pixels that merged
// layers; z, w: unused.
layout(std430, set = 0, binding = LAYER_BINDING + 2) buffer TransparentCountBuffer { uvec4 layer_counts; };

uint layer_pixel(ivec2 p) {
    return uint(p.y) * frame.viewport.x + uint(p.x);
}

// Keep a transparent fragment of pixel `p`: false where the pool is full (it is counted).
bool store_layer(ivec2 p, float depth, uint object, float alpha, uvec4 surface) {
    uint node = atomicAdd(layer_counts.x, 1u);
    if (node >= uint(layer_nodes.length()) / 2u) {
        return false;
    }
    uint next = atomicExchange(layer_heads[layer_pixel(p)], node);
    layer_nodes[2u * node] = uvec4(floatBitsToUint(depth), next, object, floatBitsToUint(alpha));
    layer_nodes[2u * node + 1u] = surface;
    return true;
}

#ifdef MANYLIGHTS_LIGHTING_GLSL

// A node's lit colour at the pixel centre `frag_xy`.
vec3 shade_layer(uint node, vec2 frag_xy) {
    uvec4 a = layer_nodes[2u * node];
    uvec4 b = layer_nodes[2u * node + 1u];
    vec3 world = world_from_depth(frag_xy, uintBitsToFloat(a.x));
    vec3 n = oct_decode(unpackSnorm2x16(b.x));
    ObjectData o = objects[a.z];
    vec2 roughness_metallic = OBJECT_TEXTURES ? unpackUnorm2x16(b.z) : vec2(1.0);
    vec3 emissive_factor = OBJECT_TEXTURES ? unpackUnorm4x8(b.w).rgb : vec3(1.0);
    PointMaterial m = point_material(o.albedo_roughness, o.material, o.emissive, unpackUnorm4x8(b.y), roughness_metallic, emissive_factor);
    return shade_point(world, n, m.albedo, m.roughness, m.metallic, m.occlusion, m.emission, frag_xy);
}

// Whether node x lies in front of node y (nearer, or as near and of a lower object).
bool layer_before(uvec2 x, uvec2 y) {
    float dx = uintBitsToFloat(x.x), dy = uintBitsToFloat(y.x);
    return dx < dy || (dx == dy && x.y < y.y);
}

// Pixel `p`'s layers blended over `under` (linear; black for the background) back to front;
// `transmittance`: how much of `under` still shows, `count`: its layers.
vec3 blend_layers(ivec2 p, vec2 frag_xy, vec3 under, out float transmittance, out uint count) {
    transmittance = 1.0;
    count = 0u;
    uint head = layer_heads[layer_pixel(p)];
    if (head == LAYER_END) {
        return under;
    }
    // The nearest LAYER_KEEP, sorted: (depth bits, object) keys and node indices.
    uvec2 keys[LAYER_KEEP];
    uint nodes[LAYER_KEEP];
    uint kept = 0u;
    // What is merged behind them: Π(1 − α), Σα, Σα·colour.
    float uncovered = 1.0, weight = 0.0;
    vec3 weighted = vec3(0.0);
    uint capacity = uint(layer_nodes.length()) / 2u;
    for (uint node = head; node != LAYER_END && count < capacity; count++) {
        uvec4 a = layer_nodes[2u * node];
        uvec2 key = a.xz;
        uint merged_node = LAYER_END;
        if (kept == LAYER_KEEP) {
            if (layer_before(key, keys[LAYER_KEEP - 1u])) {
                merged_node = nodes[LAYER_KEEP - 1u];
                kept--;
            } else {
                merged_node = node;
            }
        }
        if (merged_node != node) {
            // Insertion: shift the farther ones back.
            uint i = kept;
            while (i > 0u && layer_before(key, keys[i - 1u])) {
                keys[i] = keys[i - 1u];
                nodes[i] = nodes[i - 1u];
                i--;
            }
            keys[i] = key;
            nodes[i] = node;
            kept++;
        }
        if (merged_node != LAYER_END) {
            float alpha = uintBitsToFloat(layer_nodes[2u * merged_node].w);
            uncovered *= 1.0 - alpha;
            weight += alpha;
            weighted += alpha * shade_layer(merged_node, frag_xy);
        }
        node = a.y;
    }
    vec3 color = under;
    if (count > LAYER_KEEP) {
        atomicAdd(layer_counts.y, 1u);
        vec3 mean = weight > 0.0 ? weighted / weight : vec3(0.0);
        color = mix(color, mean, 1.0 - uncovered);
        transmittance = uncovered;
    }
    for (uint i = kept; i > 0u; i--) {
        uint node = nodes[i - 1u];
        float alpha = uintBitsToFloat(layer_nodes[2u * node].w);
        color = shade_layer(node, frag_xy) * alpha + color * (1.0 - alpha);
        transmittance *= 1.0 - alpha;
    }
    return color;
}

// The transparency-layers debug view: layers per pixel on a log scale up to LAYER_KEEP; white
// where some were merged.
vec4 layer_count_color(uint count) {
    if (count > LAYER_KEEP) {
        return vec4(1.0);
    }
    return vec4(heat(log2(1.0 + float(count)) / log2(1.0 + float(LAYER_KEEP))), 1.0);
}

// What the colour target shows at pixel `p` whose opaque surface has lit colour `under`
// (`background`: none; the background colour is a backdrop in the output's encoding, not
// light in the scene, so the layers are blended over black and laid over it there).
vec4 layered_output(ivec2 p, vec2 frag_xy, vec3 under, bool background, float exposure) {
    float transmittance = 1.0;
    uint count = 0u;
    vec3 color = under;
    // (Not `!TRANSPARENT_LAYERS`: a negated specialization constant is an expression that
    // the build's reflection does not evaluate.)
    if (TRANSPARENT_LAYERS) {
        color = blend_layers(p, frag_xy, background ? vec3(0.0) : under, transmittance, count);
    } else {
        return background ? CLEAR_COLOR : vec4(encode_output(under, exposure), 1.0);
    }
    if (frame.cluster_dims.w == DEBUG_VIEW_TRANSPARENCY_LAYERS) {
        return layer_count_color(count);
    }
    if (!background) {
        return vec4(encode_output(color, exposure), 1.0);
    }
    return vec4(encode_output(color, exposure) + transmittance * CLEAR_COLOR.rgb, 1.0);
}

#endif

#endif
