// Finds a fragment's cell in the cascaded grid and reads its light list
// (grid: src/cluster/grid.rs; texels: src/cluster/pack_grid.rs). Needs data_texture.glsl.
// Tiled forward uses the same code with a one-cascade, one-slice grid.
uniform HIGHP vec2 u_viewport;
// The viewport's lower-left corner in the framebuffer: the frame's pixel (0, 0) (ES 2.0,
// whose cells are the pixel centre's).
uniform HIGHP vec2 u_frameOrigin;
// t = (f(d) - x) * y, with f = log2 when z > 0.5 (perspective) and f(d) = d otherwise.
uniform HIGHP vec3 u_depthMap;
uniform HIGHP float u_cascadeCount;
#if GLSL_ES == 100
uniform HIGHP sampler2D u_grid;
uniform HIGHP sampler2D u_indices;
// x: 1 / grid texture rows, y: 1 / index texture rows.
uniform HIGHP vec2 u_gridInvHeight;
#else
uniform HIGHP usampler2D u_grid;
uniform HIGHP usampler2D u_indices;
// The view's half extents, per unit depth (perspective) or absolute (z = 1: orthographic).
uniform HIGHP vec3 u_cellProjection;
#include "frame_position.glsl"

// Frame position (pixels) of view-space point P: the cell of the point a fragment shades.
// With MSAA a partly covered pixel shades at its centroid, which may lie in the next column
// or row of cells when a cell border cuts the pixel (its centre's cell lacks the lights there).
HIGHP vec2 shadedFrameXY(HIGHP vec3 P) {
    return framePosition(P, u_cellProjection.xy, u_cellProjection.z, u_viewport);
}
#endif

HIGHP float clusterT(HIGHP float viewDepth) {
    HIGHP float f = u_depthMap.z > 0.5 ? log2(max(viewDepth, 1e-30)) : viewDepth;
    return (f - u_depthMap.x) * u_depthMap.y;
}

#if GLSL_ES == 100
// A grid texel's 32-bit big-endian list start.
HIGHP float listStart(HIGHP vec4 t) {
    return ((byteOf(t.x) * 256.0 + byteOf(t.y)) * 256.0 + byteOf(t.z)) * 256.0 + byteOf(t.w);
}

// (offset, count) of the fragment's cell. fragXY is a highp copy of gl_FragCoord.xy.
HIGHP vec2 clusterCell(HIGHP vec2 fragXY, HIGHP float viewDepth) {
    HIGHP float t = clusterT(viewDepth);
    HIGHP float k = clamp(floor(t), 0.0, u_cascadeCount - 1.0);
    vec4 a = dataTexel(u_grid, 2.0 * k, u_gridInvHeight.x);
    vec4 b = dataTexel(u_grid, 2.0 * k + 1.0, u_gridInvHeight.x);
    HIGHP float tilesX = u16Of(a.xy);
    HIGHP float tilesY = u16Of(a.zw);
    HIGHP float slices = byteOf(b.x);
    HIGHP float first = byteOf(b.y) * 65536.0 + byteOf(b.z) * 256.0 + byteOf(b.w);
    HIGHP float s = clamp(floor((t - k) * slices), 0.0, slices - 1.0);
    HIGHP float x = clamp(floor(fragXY.x * tilesX / u_viewport.x), 0.0, tilesX - 1.0);
    HIGHP float y = clamp(floor(fragXY.y * tilesY / u_viewport.y), 0.0, tilesY - 1.0);
    HIGHP float texel = 2.0 * u_cascadeCount + first + (s * tilesY + y) * tilesX + x;
    // The cell's list starts at its texel's 32-bit big-endian number and ends at the next's
    // (at most 2^24: exact in a highp float).
    HIGHP float start = listStart(dataTexel(u_grid, texel, u_gridInvHeight.x));
    HIGHP float end = listStart(dataTexel(u_grid, texel + 1.0, u_gridInvHeight.x));
    return vec2(start, end - start);
}

// The light number at position `pos` of the index list (two 16-bit indices per texel).
int lightIndexAt(HIGHP float pos) {
    HIGHP float texel = floor(pos * 0.5);
    vec4 t = dataTexel(u_indices, texel, u_gridInvHeight.y);
    HIGHP vec2 pair = (pos - 2.0 * texel) > 0.5 ? t.zw : t.xy;
    return int(u16Of(pair));
}
#else
// (offset, count) of the fragment's cell: cascade k's table is texel 2k (tiles_x | tiles_y
// << 16) and 2k+1 (slices | first cell << 8); a cell's texel holds where its list starts,
// the next texel where it ends.
uvec2 clusterCell(HIGHP vec2 fragXY, HIGHP float viewDepth) {
    HIGHP float t = clusterT(viewDepth);
    int k = int(clamp(floor(t), 0.0, u_cascadeCount - 1.0));
    uint a = texelFetch(u_grid, dataCoord(2 * k), 0).x;
    uint b = texelFetch(u_grid, dataCoord(2 * k + 1), 0).x;
    uint tilesX = a & 0xFFFFu;
    uint tilesY = a >> 16u;
    HIGHP float slices = float(b & 0xFFu);
    uint first = b >> 8u;
    int s = int(clamp(floor((t - float(k)) * slices), 0.0, slices - 1.0));
    int x = int(clamp(floor(fragXY.x * float(tilesX) / u_viewport.x), 0.0, float(tilesX) - 1.0));
    int y = int(clamp(floor(fragXY.y * float(tilesY) / u_viewport.y), 0.0, float(tilesY) - 1.0));
    int texel = 2 * int(u_cascadeCount) + int(first) + (s * int(tilesY) + y) * int(tilesX) + x;
    uint start = texelFetch(u_grid, dataCoord(texel), 0).x;
    uint end = texelFetch(u_grid, dataCoord(texel + 1), 0).x;
    return uvec2(start, end - start);
}

// The light number at position `pos` of the index list (four 16-bit indices per texel).
int lightIndexAt(uint pos) {
    uvec4 t = texelFetch(u_indices, dataCoord(int(pos >> 2u)), 0);
    return int(t[pos & 3u]);
}
#endif
