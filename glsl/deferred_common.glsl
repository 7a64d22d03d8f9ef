// The G-buffer's surface point and normal (written by gbuffer.frag, read back by the deferred
// light and composite passes; layout in src/gl/gbuffer.rs).
#include "frame_position.glsl"
uniform HIGHP sampler2D u_gAlbedo;
uniform HIGHP sampler2D u_gNormalDepth;
uniform HIGHP sampler2D u_gSpecular;
uniform HIGHP vec2 u_viewport;
// View-space half extents per unit depth (perspective) or absolute (orthographic).
uniform HIGHP vec2 u_halfExtent;

// The normal buffer's depth where no surface was drawn (src/gl/gbuffer.rs clears it so): a
// surface may lie at or behind the eye plane (an orthographic camera with near 0).
bool noSurface(HIGHP float depth) {
    return depth < -1.0e29;
}

// The view-space point at window position windowXY (pixels) and view depth.
HIGHP vec3 viewPosition(HIGHP vec2 windowXY, HIGHP float depth) {
    HIGHP vec2 ndc = windowXY / u_viewport * 2.0 - 1.0;
    HIGHP vec2 scale = mix(u_halfExtent * depth, u_halfExtent, u_orthographic);
    return vec3(ndc * scale, -depth);
}

// Window position (pixels) of view-space point P: the inverse of viewPosition. The G-buffer
// keeps P as its depth and its offset from the pixel centre, because the interpolated position
// forward shades need not lie on the centre's ray (rasterizers snap vertices to 1/16 to 1/256
// of a pixel), and lights with steep falloff show the difference.
HIGHP vec2 windowPosition(HIGHP vec3 P) {
    return framePosition(P, u_halfExtent, u_orthographic, u_viewport);
}

HIGHP vec2 signNotZero(HIGHP vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// A unit vector as two numbers (octahedral mapping), exact to f32 rounding.
HIGHP vec2 octEncode(HIGHP vec3 n) {
    HIGHP vec2 p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    return n.z >= 0.0 ? p : (1.0 - abs(p.yx)) * signNotZero(p);
}

HIGHP vec3 octDecode(HIGHP vec2 e) {
    HIGHP vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) {
        n.xy = (1.0 - abs(n.yx)) * signNotZero(n.xy);
    }
    return normalize(n);
}
