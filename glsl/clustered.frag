// Clustered (and tiled) forward: one geometry pass; each fragment finds its cell and loops
// over that cell's lights only.
#include "surface.glsl"
#include "data_texture.glsl"
#include "light_data.glsl"
#include "light_model.glsl"
#include "cluster_lookup.glsl"

VARYING HIGHP vec3 v_viewPos;
VARYING vec3 v_normal;
VARYING vec2 v_uv;

void main() {
    // A highp copy: gl_FragCoord may be mediump on ES 2.0, too coarse past 2048 pixels.
    HIGHP vec2 fragXY = gl_FragCoord.xy;
    HIGHP float viewDepth = -v_viewPos.z;
#if COUNT_EVALS
    // The loop below runs over the cell's list: its length is the evaluation count.
    FRAG_COLOR = encodeCount(float(clusterCell(fragXY, viewDepth).y));
#else
    vec3 N = normalize(v_normal);
    vec3 V = viewDirection(v_viewPos);
    if (dot(N, V) < 0.0) {
        N = -N;
    }
    MEDP vec3 albedo = surfaceAlbedo(v_uv);
    HIGHP vec3 color = u_ambient * albedo;
#if GLSL_ES == 100
    HIGHP vec2 cell = clusterCell(fragXY, viewDepth);
    // Appendix A: constant bound (the per-cell cap), exit with break.
    for (int n = 0; n < CELL_CAP; n++) {
        if (float(n) >= cell.y) {
            break;
        }
        color += shadeLight(fetchLight(lightIndexAt(cell.x + float(n))), v_viewPos, N, V, albedo, u_specular, u_shininess);
    }
#else
    uvec2 cell = clusterCell(fragXY, viewDepth);
    for (uint n = 0u; n < cell.y; n++) {
        color += shadeLight(fetchLight(lightIndexAt(cell.x + n)), v_viewPos, N, V, albedo, u_specular, u_shininess);
    }
#endif
    FRAG_COLOR = encodeOutput(color);
#endif
}
