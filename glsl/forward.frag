// Plain forward: every light for every fragment. The correctness oracle of the other methods,
// so it stays simple and evaluates at the highest precision the fragment stage has.
#include "surface.glsl"
#include "data_texture.glsl"
#include "light_data.glsl"
#include "light_model.glsl"

VARYING HIGHP vec3 v_viewPos;
VARYING vec3 v_normal;
VARYING vec2 v_uv;

void main() {
    vec3 N = normalize(v_normal);
    vec3 V = viewDirection(v_viewPos);
    // Two-sided surfaces: light the side the eye sees.
    if (dot(N, V) < 0.0) {
        N = -N;
    }
    MEDP vec3 albedo = surfaceAlbedo(v_uv);
    HIGHP vec3 color = u_ambient * albedo;
#if !NO_LIGHTS
#if GLSL_ES == 100
    // GLSL ES 1.00 Appendix A: constant loop bound, exit with break.
    for (int i = 0; i < MAX_LIGHTS; i++) {
        if (i >= u_lightCount) {
            break;
        }
        color += shadeLight(fetchLight(i), v_viewPos, N, V, albedo, u_specular, u_shininess);
    }
#else
    for (int i = 0; i < u_lightCount; i++) {
        color += shadeLight(fetchLight(i), v_viewPos, N, V, albedo, u_specular, u_shininess);
    }
#endif
#endif
    FRAG_COLOR = encodeOutput(color);
}
