// Deferred, pass 1 (ES 3.0 multiple render targets): the surface attributes the light pass
// needs. Layout and bytes per pixel are documented in src/methods/deferred.rs.
#include "surface.glsl"
#include "deferred_common.glsl"

CENTROID VARYING HIGHP vec3 v_viewPos;
VARYING vec3 v_normal;
VARYING vec2 v_uv;

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out HIGHP vec4 o_normalDepth;
layout(location = 2) out vec4 o_specular;
// The accumulation buffer's start: the surface's emission, and its ambient occlusion in
// alpha, so the composite's sum equals forward's.
layout(location = 3) out vec4 o_extra;
// The light pass's pre-exposure (deferred.rs accumulation_scale), which the composite undoes.
uniform HIGHP float u_accumScale;

void main() {
#if HAS_ALPHA_MASK
    if (surfaceCut(v_uv)) {
        discard;
    }
#endif
    vec3 N = normalize(v_normal);
    // The side the eye sees (a back face only on a double-sided surface).
    N = shadingNormal(N, v_uv);
    // The surface point as its depth and its window offset from the pixel centre (see
    // windowPosition): the light pass shades the very point forward shades.
    HIGHP vec2 offset = windowPosition(v_viewPos) - gl_FragCoord.xy;
    vec3 albedo = surfaceAlbedo(v_uv);
    o_albedo = vec4(albedo, offset.y);
    // What the surface adds besides the lights: emission in colour, and the ambient term's
    // occlusion in alpha, which the composite scales ambient × albedo by (the lights add 0
    // there). Written as its difference from ambient × albedo, an occluded term did not cancel
    // against the composite's from the G-buffer's 11-bit albedo (6/255 from forward); started
    // at the whole term, a half-float accumulation rounded each of thousands of faint lights
    // at its size. The count variants' accumulation starts at exactly 0.
#if COUNT_EVALS || COUNT_REACHING
    o_extra = vec4(0.0);
#else
    vec3 extra = vec3(0.0);
#if HAS_EMISSIVE
    extra = surfaceEmission(v_uv);
#endif
    float occlusion = 1.0;
#if HAS_OCCLUSION
    occlusion = surfaceOcclusion(v_uv);
#endif
    o_extra = vec4(extra * u_accumScale, occlusion);
#endif
    // Any view depth marks a covered pixel (the buffer is cleared to −10³⁰: noSurface).
    o_normalDepth = vec4(octEncode(N), -v_viewPos.z, offset.x);
#if METALLIC_ROUGHNESS
    // Metallic-roughness: (metallic, roughness, 0, −1); the negative exponent marks the model.
    o_specular = vec4(surfaceMetallicRoughness(v_uv), 0.0, -1.0);
#elif HAS_SPECULAR
    o_specular = vec4(u_specular, u_shininess);
#else
    o_specular = vec4(0.0, 0.0, 0.0, 1.0);
#endif
}
