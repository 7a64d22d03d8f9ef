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
// The accumulation buffer's start: what the surface adds besides the lights (its ambient
// term, occlusion included, and emission), so the composite's sum equals forward's.
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
    // The whole ambient term here, in f32 from the albedo forward shades with: added back in
    // the composite from the G-buffer's 11-bit albedo, an occluded term written as its
    // difference from ambient × albedo did not cancel (6/255 from forward), and in a half-float
    // accumulation each light was rounded at that difference's magnitude. The count variants'
    // accumulation starts at exactly 0.
#if COUNT_EVALS || COUNT_REACHING
    vec3 extra = vec3(0.0);
#else
    vec3 extra = surfaceAmbient(albedo, v_uv);
#endif
#if HAS_EMISSIVE
    extra += surfaceEmission(v_uv);
#endif
    o_extra = vec4(extra * u_accumScale, 0.0);
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
