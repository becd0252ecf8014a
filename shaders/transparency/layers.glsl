// Transparent layers (glTF alphaMode BLEND): every transparent fragment in front of the
// opaque surface is kept, per pixel, as a node of a linked list — its depth, pixel, coverage
// and surface, unlit. Then, in compute, a thread per node lights it (`light_layer`: the
// opaque surfaces' lights, cluster lists, shading model and shadows, in every technique; the
// nodes lie in the order their fragments were drawn, so neighbouring threads share clusters)
// and a thread per pixel blends its layers back to front (`blend_layers`).
//
// Memory is a fixed budget: a pool of nodes (`--transparency-budget` per pixel on average)
// and a head per pixel. A fragment that finds the pool full is dropped and counted. A pixel
// blends its LAYER_KEEP nearest layers exactly, in order of depth (ties by object, then by
// their light); farther ones are merged into one layer behind them (coverage 1 − Π(1 − α),
// α-weighted colour) and the pixel is counted. ml-cpu transparency.rs is the same rule on
// the CPU.
//
// With anti-aliasing (VISIBILITY_SAMPLES > 1) a node also keeps the samples of its pixel its
// fragment covers in front of the opaque surface there; it is shaded where the opaque
// surfaces are (visibility_samples.glsl shading_xy), and the resolve blends each sample's
// layers over that sample's opaque surface (LAYER_SAMPLES).
//
// Needs common.glsl; the includer defines LAYER_BINDING, the first of its three set-0
// bindings. Lighting (light_layer) also needs lighting.glsl; blending, LAYER_BLENDING.

#ifndef MANYLIGHTS_LAYERS_GLSL
#define MANYLIGHTS_LAYERS_GLSL

#include "visibility/visibility_samples.glsl"
#include "common/shading_model.glsl"

const uint LAYER_END = 0xffffffffu;
// Layers a pixel blends exactly (an array per thread); beyond, merged.
const uint LAYER_KEEP = 32u;

// A node's object word: the object (ml-cpu limits.rs MAX_OBJECTS: 20 bits) and, with
// anti-aliasing, the samples its fragment covers above it (a bit each; at most
// LAYER_MAX_SAMPLES). Without, the fragment covers its pixel's centre.
const uint LAYER_OBJECT_BITS = 20u;
const uint LAYER_MAX_SAMPLES = 8u;

uint layer_object_word(uint object, uint covered) {
    return VISIBILITY_SAMPLES == 1u ? object : object | (covered << LAYER_OBJECT_BITS);
}

uint layer_object(uint word) {
    return word & ((1u << LAYER_OBJECT_BITS) - 1u);
}

uint layer_covered(uint word) {
    return VISIBILITY_SAMPLES == 1u ? 1u : word >> LAYER_OBJECT_BITS;
}

// Where node `a` (its first four words) is shaded: its pixel's centre, or the point
// visibility_samples.glsl shading_xy gives its samples.
vec2 layer_xy(uvec4 a) {
    ivec2 p = ivec2(a.w & 0xffffu, a.w >> 16);
    return VISIBILITY_SAMPLES == 1u ? vec2(p) + 0.5 : shading_xy(p, layer_covered(a.z));
}

// Per pixel (row-major): its nearest-drawn node, LAYER_END for none.
layout(std430, set = 0, binding = LAYER_BINDING) buffer TransparentHeadBuffer { uint layer_heads[]; };
// Two uvec4 a node: (depth, next, object, pixel y << 16 | x), then the surface (octahedral
// normal snorm 2×16, albedo factor and occlusion unorm 4×8, roughness and metallic factors
// unorm 2×8 with alpha unorm 16 above them, emissive factor and normal spread unorm 4×8),
// which lighting replaces by its light: (lit colour rgb, alpha) as floats or, for a surface
// that transmits light, (lit colour × alpha as floats, LAYER_TRANSMITS | what it lets
// through of the light behind, 10 bits a channel) — layer_light reads either. With
// LOBE_TEXTURES a third: the extensions' texels (pack_lobe_texels).
layout(std430, set = 0, binding = LAYER_BINDING + 1) buffer TransparentNodeBuffer { uvec4 layer_nodes[]; };

// uvec4s a node (transparency/layer_buffers.rs node_bytes). A branch, not `?:` on the
// constant: the build's reflection evaluates no constant select.
uint layer_node_words() {
    if (LOBE_TEXTURES) {
        return 3u;
    }
    return 2u;
}
#define LAYER_NODE_WORDS layer_node_words()
// x: nodes asked for this frame (beyond the pool's size: dropped); y: pixels that merged
// layers; z, w: triangles the per-triangle build listed for a work group each, and for the
// tiles (transparent_build_triangles.glsl).
layout(std430, set = 0, binding = LAYER_BINDING + 2) buffer TransparentCountBuffer { uvec4 layer_counts; };

uint layer_pixel(ivec2 p) {
    return uint(p.y) * frame.viewport.x + uint(p.x);
}

// Nodes in the pool.
uint layer_capacity() {
    return uint(layer_nodes.length()) / LAYER_NODE_WORDS;
}

// The surface of a node as the build packs it (`alpha` in [0, 1]).
uvec4 pack_layer_surface(vec3 normal, vec4 albedo_occlusion, vec2 roughness_metallic, float alpha, vec4 emissive_spread) {
    uint material = packUnorm4x8(vec4(roughness_metallic, 0.0, 0.0)) & 0xffffu;
    return uvec4(packSnorm2x16(oct_encode(normal)), packUnorm4x8(albedo_occlusion), material | (packUnorm2x16(vec2(alpha, 0.0)) << 16),
                 packUnorm4x8(emissive_spread));
}

// A node's surface: pack_layer_surface's and (LOBE_TEXTURES) the extensions' texels
// (shading_model.glsl pack_lobe_texels).
struct LayerSurface {
    uvec4 surface;
    uvec4 lobes;
};

// Node `node` (of the pool) made pixel `p`'s fragment at `depth` of `object` covering the
// samples `covered`, before `next`.
void write_layer(uint node, ivec2 p, float depth, uint next, uint object, uint covered, LayerSurface surface) {
    layer_nodes[LAYER_NODE_WORDS * node] = uvec4(floatBitsToUint(depth), next, layer_object_word(object, covered), uint(p.y) << 16 | uint(p.x));
    layer_nodes[LAYER_NODE_WORDS * node + 1u] = surface.surface;
    if (LOBE_TEXTURES) {
        layer_nodes[LAYER_NODE_WORDS * node + 2u] = surface.lobes;
    }
}

// A lit node's last word holds this bit where it transmits light (never in an alpha's float,
// whose sign is +).
const uint LAYER_TRANSMITS = 0x80000000u;

// What a lit node does to the light behind it: `light` added, `through` of it let through
// per channel, `weight` its share that lets nothing through (the merge's weights).
struct LayerLight {
    vec3 light;
    vec3 through;
    float weight;
};

LayerLight layer_light(uint node) {
    uvec4 w = layer_nodes[LAYER_NODE_WORDS * node + 1u];
    vec3 c = uintBitsToFloat(w.xyz);
    if ((w.w & LAYER_TRANSMITS) == 0u) {
        float a = uintBitsToFloat(w.w);
        return LayerLight(c * a, vec3(1.0 - a), a);
    }
    vec3 through = vec3(uvec3(w.w, w.w >> 10, w.w >> 20) & 1023u) / 1023.0;
    return LayerLight(c, through, 1.0 - min(through.r, min(through.g, through.b)));
}

#ifdef MANYLIGHTS_LIGHTING_GLSL

// Light node `node` where it lies and keep its light (layer_light) in place of its surface.
void light_layer(uint node) {
    uvec4 a = layer_nodes[LAYER_NODE_WORDS * node];
    uvec4 b = layer_nodes[LAYER_NODE_WORDS * node + 1u];
    vec2 frag_xy = layer_xy(a);
    vec3 world = world_from_depth(frag_xy, uintBitsToFloat(a.x));
    vec3 n = oct_decode(unpackSnorm2x16(b.x));
    uint object = layer_object(a.z);
    ObjectData o = objects[object];
    vec2 roughness_metallic = OBJECT_TEXTURES ? unpackUnorm4x8(b.z).xy : vec2(1.0);
    vec4 emissive_spread = OBJECT_TEXTURES ? unpackUnorm4x8(b.w) : vec4(1.0, 1.0, 1.0, 0.0);
    LobeTexels t = LOBE_TEXTURES ? unpack_lobe_texels(layer_nodes[LAYER_NODE_WORDS * node + 2u]) : no_lobe_texels(n);
    PointMaterial m = point_material(o.albedo_roughness, o.material, o.emissive, unpackUnorm4x8(b.y), roughness_metallic, emissive_spread.rgb,
                                     emissive_spread.a, object, t);
    vec3 color = shade_point(world, n, m, frag_xy);
    float alpha = unpackUnorm2x16(b.z).y;
    if (MATERIAL_LOBES) {
        if (m.coat.w > 0.0) {
            // Transmission: its covered share lets through what lobed_transmittance says.
            // The volume's transmittance over the object's thickness, to the power of the
            // thickness texel (colour^(thickness·texel / distance)).
            vec3 volume = pow(o.lobes[3].rgb, vec3(m.thickness));
            vec3 coat_n = LOBE_TEXTURES ? m.coat_normal : n;
            vec3 through = lobed_transmittance(n, toward_eye(world), m.albedo, m.metallic, m.specular, m.coat, coat_n, volume);
            uvec3 q = uvec3(round(clamp(1.0 - alpha + alpha * through, 0.0, 1.0) * 1023.0));
            layer_nodes[LAYER_NODE_WORDS * node + 1u] = uvec4(floatBitsToUint(color * alpha), LAYER_TRANSMITS | q.r | q.g << 10 | q.b << 20);
            return;
        }
    }
    layer_nodes[LAYER_NODE_WORDS * node + 1u] = uvec4(floatBitsToUint(color), floatBitsToUint(alpha));
}

#endif

// Blending, for the resolve (which defines LAYER_BLENDING and includes shading_model.glsl,
// clusters/cluster.glsl and common/background.glsl, for `encode_output`, `heat` and the
// background).
#ifdef LAYER_BLENDING

// The object word of node `node`.
uint layer_object_of(uint node) {
    return layer_nodes[LAYER_NODE_WORDS * node].z;
}

// Whether layer x lies in front of layer y, each (depth bits, node) of a lit node: nearer; as
// near, of a lower object; of the same object too, of the lower light (its words in order) —
// two triangles of one mesh meeting at a pixel's point are ordered by what they are, not by
// the order their fragments happened to be listed in, which varies with the build and the
// run; layers equal in all of that blend the same either way. Read from the nodes: ties are
// rare.
bool layer_before(uvec2 x, uvec2 y) {
    float dx = uintBitsToFloat(x.x), dy = uintBitsToFloat(y.x);
    if (dx != dy) {
        return dx < dy;
    }
    uint ox = layer_object(layer_object_of(x.y)), oy = layer_object(layer_object_of(y.y));
    if (ox != oy) {
        return ox < oy;
    }
    uvec4 lx = layer_nodes[LAYER_NODE_WORDS * x.y + 1u], ly = layer_nodes[LAYER_NODE_WORDS * y.y + 1u];
    for (uint i = 0u; i < 4u; i++) {
        if (lx[i] != ly[i]) {
            return lx[i] < ly[i];
        }
    }
    return false;
}

// A pixel's nearest LAYER_KEEP layers, sorted (sort_layers), in [lo, hi) of a double-ended
// array that starts in its middle: (depth bits, node) each, eight bytes a layer to move (the
// sort's cost is its moves through per-thread memory; the object word, for ties and
// coverage, is read from the node where needed).
uvec2 sorted_layers[2u * LAYER_KEEP];

// What a pixel keeps of its layers: the nearest sorted into sorted_layers [lo, hi); the
// farther ones merged (`merged`: their weighted mean colour, `merged_through`: what they let
// through together, Π over them); `count`: its layers.
struct SortedLayers {
    uint lo;
    uint hi;
    uint count;
    vec3 merged;
    vec3 merged_through;
};

// Pixel `p`'s layers sorted (the nearest LAYER_KEEP) and merged (the rest).
SortedLayers sort_layers(ivec2 p) {
    SortedLayers s = SortedLayers(LAYER_KEEP, LAYER_KEEP, 0u, vec3(0.0), vec3(1.0));
    // A list holds its pixel's layers in the reverse of the order they were drawn, so they
    // often come nearest-first or farthest-first; either way each one goes to an end of the
    // array, without moving the others (an array filled from one end would move them all for
    // one of the two).
    uint lo = LAYER_KEEP, hi = LAYER_KEEP, count = 0u;
    // What is merged behind them: Π through, Σ weight, Σ light.
    vec3 through = vec3(1.0);
    float weight = 0.0;
    vec3 weighted = vec3(0.0);
    uint capacity = layer_capacity();
    for (uint node = layer_heads[layer_pixel(p)]; node != LAYER_END && count < capacity; count++) {
        uvec4 a = layer_nodes[LAYER_NODE_WORDS * node];
        uvec2 key = uvec2(a.x, node);
        uint merged_node = LAYER_END;
        if (hi - lo == LAYER_KEEP) {
            if (layer_before(key, sorted_layers[hi - 1u])) {
                hi--;
                merged_node = sorted_layers[hi].y;
            } else {
                merged_node = node;
            }
        }
        if (merged_node != node) {
            // Its place i: layers [lo, i) not after it, [i, hi) after it. The ends first (lists
            // often come farthest- or nearest-first), then a binary search: reads are the
            // sort's cost.
            uint i = hi;
            if (lo != hi && layer_before(key, sorted_layers[hi - 1u])) {
                uint below = lo + 1u;
                i = layer_before(key, sorted_layers[lo]) ? lo : hi - 1u;
                while (below < i) {
                    uint middle = (below + i) >> 1u;
                    if (layer_before(key, sorted_layers[middle])) {
                        i = middle;
                    } else {
                        below = middle + 1u;
                    }
                }
            }
            // Make room on the shorter side that has it (one always has: at most
            // LAYER_KEEP - 1 layers are kept here, and lo never passes the middle).
            if (hi < 2u * LAYER_KEEP && (lo == 0u || hi - i <= i - lo)) {
                for (uint k = hi; k > i; k--) {
                    sorted_layers[k] = sorted_layers[k - 1u];
                }
                hi++;
            } else {
                for (uint k = lo; k < i; k++) {
                    sorted_layers[k - 1u] = sorted_layers[k];
                }
                lo--;
                i--;
            }
            sorted_layers[i] = key;
        }
        if (merged_node != LAYER_END) {
            LayerLight l = layer_light(merged_node);
            through *= l.through;
            weight += l.weight;
            weighted += l.light;
        }
        node = a.y;
    }
    s.lo = lo;
    s.hi = hi;
    s.count = count;
    if (count > LAYER_KEEP) {
        atomicAdd(layer_counts.y, 1u);
        s.merged = weight > 0.0 ? weighted / weight : vec3(0.0);
        s.merged_through = through;
    }
    return s;
}

// The sorted layers `s` whose bit `layers` has (bit i: sorted_layers[s.lo + i]; all ones: every
// one), and the merged ones, blended over `under` (linear) back to front; `transmittance`:
// how much of `under` still shows, per channel.
vec3 blend_sorted(SortedLayers s, uint layers, vec3 under, out vec3 transmittance) {
    vec3 color = mix(under, s.merged, 1.0 - s.merged_through);
    transmittance = s.merged_through;
    for (uint i = s.hi; i > s.lo; i--) {
        if ((layers & (1u << (i - 1u - s.lo))) == 0u) {
            continue;
        }
        LayerLight l = layer_light(sorted_layers[i - 1u].y);
        color = l.light + color * l.through;
        transmittance *= l.through;
    }
    return color;
}

// Pixel `p`'s lit layers blended over `under` (linear; black for the background) back to
// front; `transmittance`: how much of `under` still shows, `count`: its layers.
vec3 blend_layers(ivec2 p, vec3 under, out vec3 transmittance, out uint count) {
    SortedLayers s = sort_layers(p);
    count = s.count;
    return blend_sorted(s, 0xffffffffu, under, transmittance);
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
vec4 layered_output(ivec2 p, vec3 under, bool background, float exposure) {
    vec3 transmittance;
    uint count;
    vec3 color = blend_layers(p, background ? vec3(0.0) : under, transmittance, count);
    if (frame.viewport.z == DEBUG_VIEW_TRANSPARENCY_LAYERS) {
        return layer_count_color(count);
    }
    if (!background) {
        return vec4(encode_output(color, exposure), 1.0);
    }
    return vec4(encode_output(color, exposure) + transmittance * background_stored(p).rgb, 1.0);
}

#ifdef LAYER_SAMPLES
// Anti-aliased (docs/DESIGN.md#anti-aliasing): the includer binds the opaque samples
// (`uvec2 opaque_sample(ivec2 p, uint k)`, opaque_depth.glsl) and `vec3 surface_colour(ivec2
// p, uint leader)`, the linear colour the lighting gave the opaque surface whose first sample
// is `leader`. Each sample gets its own layers — those whose fragment covers it — over its
// own opaque surface (or the background), tone-mapped; the pixel is the mean of its samples
// in the display's linear light, as without layers. Samples with the same surface and the
// same layers are blended once.

vec4 layered_samples_output(ivec2 p, float exposure) {
    SortedLayers s = sort_layers(p);
    if (frame.viewport.z == DEBUG_VIEW_TRANSPARENCY_LAYERS) {
        return layer_count_color(s.count);
    }
    vec3 background = background_linear(p);
    // Each sample's opaque surface and layers, found once.
    // over[k]: which sorted layers cover sample k (bit i: sorted_layers[s.lo + i]), each
    // layer's coverage read from its node once.
    uvec2 v[VISIBILITY_SAMPLES];
    uint over[VISIBILITY_SAMPLES];
    for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        v[k] = opaque_sample(p, k);
        over[k] = 0u;
    }
    for (uint i = s.lo; i < s.hi; i++) {
        uint covered = layer_covered(layer_object_of(sorted_layers[i].y));
        for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
            over[k] |= ((covered >> k) & 1u) << (i - s.lo);
        }
    }
    vec3 sum = vec3(0.0);
    uint done = 0u;
    for (uint k = 0u; k < VISIBILITY_SAMPLES; k++) {
        if ((done & (1u << k)) != 0u) {
            continue;
        }
        bool drawn = visibility_buffer_depth(v[k]) < 1.0;
        uint id = visibility_buffer_id(v[k]);
        uint layers = over[k];
        // The samples like k: the same surface (or the background) and the same layers; the
        // surface's first sample (its leader, where the lighting left its colour).
        uint members = 0u, leader = k;
        for (uint j = k; j < VISIBILITY_SAMPLES; j++) {
            uvec2 u = v[j];
            bool same_surface = drawn ? visibility_buffer_depth(u) < 1.0 && visibility_buffer_id(u) == id : visibility_buffer_depth(u) >= 1.0;
            if (same_surface && over[j] == layers) {
                members |= 1u << j;
            }
        }
        for (uint j = 0u; j < k && drawn; j++) {
            uvec2 u = v[j];
            if (visibility_buffer_depth(u) < 1.0 && visibility_buffer_id(u) == id) {
                leader = j;
                break;
            }
        }
        done |= members;
        vec3 transmittance;
        vec3 color = blend_sorted(s, layers, drawn ? surface_colour(p, leader) : vec3(0.0), transmittance);
        vec3 display = display_linear(color, exposure);
        if (!drawn) {
            display += transmittance * background;
        }
        sum += display * float(bitCount(members));
    }
    return vec4(encode_gamma(sum / float(VISIBILITY_SAMPLES)), 1.0);
}
#endif

#endif

#endif
