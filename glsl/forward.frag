// Plain forward: every light for every fragment. The correctness oracle of the other methods,
// so it stays simple; its reference variant evaluates at the highest precision the fragment
// stage has.
#include "surface.glsl"
#include "data_texture.glsl"
#include "light_data.glsl"
#include "light_model.glsl"
#include "directional.glsl"

CENTROID VARYING HIGHP vec3 v_viewPos;
VARYING vec3 v_normal;
VARYING vec2 v_uv;

void main() {
#if HAS_ALPHA_MASK
    if (surfaceCut(v_uv)) {
        discard;
    }
#endif
#if COUNT_REACHING
    // The lower bound of culling: lights whose sphere (and cone) contains this point.
    HIGHP float reaching = 0.0;
#if GLSL_ES == 100
    for (int i = 0; i < MAX_LIGHTS; i++) {
        if (i >= u_lightCount) {
            break;
        }
        reaching += lightReaches(fetchLight(i), v_viewPos) ? 1.0 : 0.0;
    }
#else
    for (int i = 0; i < u_lightCount; i++) {
        reaching += lightReaches(fetchLight(i), v_viewPos) ? 1.0 : 0.0;
    }
#endif
    FRAG_COLOR = encodeCount(reaching);
#elif COUNT_EVALS
    // Every light is evaluated for every fragment.
#if NO_LIGHTS
    FRAG_COLOR = encodeCount(0.0);
#else
    FRAG_COLOR = encodeCount(float(u_lightCount));
#endif
#else
    vec3 N = normalize(v_normal);
    vec3 V = viewDirection(v_viewPos);
    // The side the eye sees (a back face only on a double-sided surface).
    N = shadingNormal(N, v_uv);
    MEDP vec3 albedo = surfaceAlbedo(v_uv);
    SurfaceParams surface = materialSurface(albedo, v_uv);
    HIGHP vec3 color = surfaceAmbient(albedo, v_uv);
#if HAS_DIRECTIONAL
    color += shadeDirectional(N, V, surface);
#endif
#if !NO_LIGHTS
#if GLSL_ES == 100
    // GLSL ES 1.00 Appendix A: constant loop bound, exit with break.
    for (int i = 0; i < MAX_LIGHTS; i++) {
        if (i >= u_lightCount) {
            break;
        }
        color += shadeLight(fetchLight(i), v_viewPos, N, V, surface);
    }
#else
    for (int i = 0; i < u_lightCount; i++) {
        color += shadeLight(fetchLight(i), v_viewPos, N, V, surface);
    }
#endif
#endif
#if HAS_EMISSIVE
    color += surfaceEmission(v_uv);
#endif
    FRAG_COLOR = encodeOutput(color);
#if HAS_SURFACE_OPACITY
    FRAG_COLOR.a *= surfaceOpacity(v_uv);
#endif
#endif
}
