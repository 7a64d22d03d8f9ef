// Frame position (pixels) of view-space point P in a view `viewport` pixels large whose half
// extents are `halfExtent`, per unit depth (perspective) or absolute (`orthographic` 1): where
// a point lies on screen, for finding its cell or storing its offset from the pixel centre.
HIGHP vec2 framePosition(HIGHP vec3 P, HIGHP vec2 halfExtent, HIGHP float orthographic,
                         HIGHP vec2 viewport) {
    HIGHP vec2 scale = mix(halfExtent * -P.z, halfExtent, orthographic);
    return (P.xy / scale * 0.5 + 0.5) * viewport;
}
