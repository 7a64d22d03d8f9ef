// Reading the G-buffer back (deferred light and composite passes).
uniform HIGHP sampler2D u_gAlbedo;
uniform HIGHP sampler2D u_gNormalDepth;
uniform HIGHP sampler2D u_gSpecular;
uniform HIGHP vec2 u_viewport;
// View-space half extents per unit depth (perspective) or absolute (orthographic).
uniform HIGHP vec2 u_halfExtent;

// The view-space surface point of this pixel: on the ray through the pixel centre, at the
// stored view depth (forward's interpolated position, up to rounding).
HIGHP vec3 viewPosition(HIGHP vec2 fragXY, HIGHP float depth) {
    HIGHP vec2 ndc = fragXY / u_viewport * 2.0 - 1.0;
    HIGHP vec2 scale = mix(u_halfExtent * depth, u_halfExtent, u_orthographic);
    return vec3(ndc * scale, -depth);
}
