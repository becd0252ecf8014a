// Vulkan's rasterization rules as the compute rasters apply them (triangle_raster.comp,
// omni_raster.glsl; docs/DESIGN.md#compute-raster): vertices snapped to the sub-pixel grid,
// integer edge functions at pixel centres, the top-left rule on edges.

#ifndef MANYLIGHTS_RASTER_RULES_GLSL
#define MANYLIGHTS_RASTER_RULES_GLSL

// The sub-pixel grid of the rasteriser we match: 8 bits, subPixelPrecisionBits of every device
// we run on (`manylights info` lists it).
const float SUBPIXEL = 256.0;

// The viewport transform (x = size/2 · x/w + size/2, y likewise) of a clip-space position
// into an image of `size` pixels starting at 0.
vec2 viewport_xy(vec4 c, vec2 size) {
    vec2 half_size = size * 0.5;
    return c.xy / c.w * half_size + half_size;
}

// The edge function of edge s → e at p (sub-pixel units): positive on the interior's side.
int edge_function(ivec2 s, ivec2 e, ivec2 p) {
    ivec2 d = e - s;
    return d.x * (p.y - s.y) - d.y * (p.x - s.x);
}

// The fill rule: a pixel centre on an edge belongs to the triangle only if the edge is a top
// or a left one — with the interior on the positive side (y down), a left edge runs upwards,
// a top edge is horizontal and runs right. 1 for the other edges: their zero is outside.
int fill_bias(ivec2 s, ivec2 e) {
    ivec2 d = e - s;
    return d.y < 0 || (d.y == 0 && d.x > 0) ? 0 : 1;
}

// Where a pixel's sample points lie, in sub-pixel units from its corner: the pixel centre
// (128) unless the includer samples more points a pixel (visibility_samples.glsl).
#ifndef RASTER_SAMPLE_LO
#define RASTER_SAMPLE_LO ivec2(128)
#define RASTER_SAMPLE_HI ivec2(128)
#endif

// The pixels with a sample point (the centre: 256 i + 128 in sub-pixel units) inside the box
// [lo, hi] of sub-pixel corners, within an image of `size` pixels (>> rounds towards −∞):
// first > last where none.
void centres_in_box(ivec2 lo, ivec2 hi, ivec2 size, out ivec2 first, out ivec2 last) {
    first = max((lo - RASTER_SAMPLE_HI + 255) >> 8, ivec2(0));
    last = min((hi - RASTER_SAMPLE_LO) >> 8, size - 1);
}

// A small triangle (box at most 64 pixels a side) set up for its pixels: corners snapped and
// taken relative to the box's corner `lo` (which keeps every product below 2^31), ordered so
// the interior lies on every edge's positive side, the fill rule's biases, the pixel centres
// in the box within the image.
struct SmallTriangle {
    ivec2 a, b, c, lo;
    int area; // twice the area, in sub-pixel units²: positive
    ivec3 bias;
    ivec2 first, last;
    bool swapped; // b and c were swapped to order it (their attributes must be too)
};

// Sets up the triangle with corners in pixels in an image of `size`; false where it covers
// nothing: zero area, or a back face (clockwise, y down) unless `both_faces`.
bool small_triangle(vec2 pa, vec2 pb, vec2 pc, ivec2 size, bool both_faces, out SmallTriangle t) {
    ivec2 a = ivec2(roundEven(pa * SUBPIXEL));
    ivec2 b = ivec2(roundEven(pb * SUBPIXEL));
    ivec2 c = ivec2(roundEven(pc * SUBPIXEL));
    ivec2 lo = min(a, min(b, c)), hi = max(a, max(b, c));
    t.lo = lo;
    t.a = a - lo;
    t.b = b - lo;
    t.c = c - lo;
    t.area = (t.b.x - t.a.x) * (t.c.y - t.a.y) - (t.b.y - t.a.y) * (t.c.x - t.a.x);
    // Front faces (counter-clockwise, y down) have a negative area: b and c swapped.
    t.swapped = t.area < 0;
    if (t.area == 0 || (!t.swapped && !both_faces)) {
        return false;
    }
    if (t.swapped) {
        ivec2 s = t.b;
        t.b = t.c;
        t.c = s;
        t.area = -t.area;
    }
    centres_in_box(lo, hi, size, t.first, t.last);
    t.bias = ivec3(fill_bias(t.b, t.c), fill_bias(t.c, t.a), fill_bias(t.a, t.b));
    return true;
}

// Whether the triangle covers the point `offset` sub-pixels from `pixel`'s corner; `w`: the
// edge functions there, the weights of corners a, b, c (summing to t.area).
bool small_covers_at(SmallTriangle t, ivec2 pixel, ivec2 offset, out ivec3 w) {
    ivec2 p = pixel * 256 + offset - t.lo;
    w = ivec3(edge_function(t.b, t.c, p), edge_function(t.c, t.a, p), edge_function(t.a, t.b, p));
    return all(greaterThanEqual(w - t.bias, ivec3(0)));
}

// Whether the triangle covers `pixel`'s centre (small_covers_at).
bool small_covers(SmallTriangle t, ivec2 pixel, out ivec3 w) {
    return small_covers_at(t, pixel, ivec2(128), w);
}

#endif
