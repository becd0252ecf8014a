// Vulkan's rasterization rules as the compute rasters apply them (triangle_raster.comp,
// omni_raster.glsl; docs/DESIGN.md#compute-raster): vertices snapped to the sub-pixel grid,
// integer edge functions at pixel centres, the top-left rule on edges.

#ifndef MANYLIGHTS_RASTER_RULES_GLSL
#define MANYLIGHTS_RASTER_RULES_GLSL

// The sub-pixel grid of the rasteriser we match: 8 bits, subPixelPrecisionBits of every device
// we run on (`manylights info` lists it).
const float SUBPIXEL = 256.0;

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

#endif
