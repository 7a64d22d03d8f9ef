// Deferred, pass 3: ambient (occluded as the geometry pass says) plus the accumulation (its
// emission, then the lights), encoded like every other method. Directional lights are shaded
// here, with the BRDF chosen per pixel as in the light pass.
#define PER_PIXEL_MODEL 1
#include "surface.glsl"
#include "light_struct.glsl"
#include "light_model.glsl"
#include "directional.glsl"
#include "deferred_common.glsl"

uniform HIGHP sampler2D u_accum;
// The light pass added radiance pre-exposed (times a power of two, deferred.rs
// accumulation_scale) so a half-float accumulation holds it; this undoes it.
uniform HIGHP float u_accumToRadiance;
// The geometry pass's depth, written into the target's depth buffer (see deferred.rs).
uniform HIGHP sampler2D u_gDepth;
// The viewport's lower-left corner in the target: the G-buffer's pixel (0, 0).
uniform HIGHP vec2 u_frameOrigin;

void main() {
    HIGHP vec2 frameXY = gl_FragCoord.xy - u_frameOrigin;
    ivec2 px = ivec2(frameXY);
    if (noSurface(texelFetch(u_gNormalDepth, px, 0).z)) {
        discard;
    }
    gl_FragDepth = texelFetch(u_gDepth, px, 0).r;
#if COUNT_EVALS
    // The count's channels added (each exact in half floats up to 2 048: deferred.rs).
    FRAG_COLOR = encodeCount(dot(texelFetch(u_accum, px, 0), vec4(1.0)));
#else
    HIGHP vec4 accum = texelFetch(u_accum, px, 0);
    HIGHP vec4 albedoOffset = texelFetch(u_gAlbedo, px, 0);
    MEDP vec3 albedo = albedoOffset.rgb;
    // The ambient term, scaled by the occlusion the geometry pass left in alpha (on the
    // albedo first: an ambient × albedo past the float range times 0 was NaN).
    HIGHP vec3 color = u_ambient * (albedo * accum.a) + accum.rgb * u_accumToRadiance;
#if HAS_DIRECTIONAL
    // Directional lights light every pixel: here, once, rather than as a light volume. The
    // surface point comes back from the G-buffer as in the light pass.
    HIGHP vec4 nd = texelFetch(u_gNormalDepth, px, 0);
    HIGHP vec3 P = viewPosition(frameXY + vec2(nd.w, albedoOffset.a), nd.z);
#if HAS_SPECULAR
    vec4 spec = texelFetch(u_gSpecular, px, 0);
#else
    vec4 spec = vec4(0.0, 0.0, 0.0, 1.0);
#endif
    SurfaceParams surface;
    surface.albedo = albedo;
    surface.Ks = spec.rgb;
    surface.Ns = spec.a;
    surface.metallic = spec.r;
    surface.roughness = spec.g;
    color += shadeDirectional(octDecode(nd.xy), viewDirection(P), surface);
#endif
    FRAG_COLOR = encodeOutput(color);
#endif
}
