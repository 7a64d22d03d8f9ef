// Clustered (and tiled) forward: one geometry pass; each fragment finds its cell and loops
// over that cell's lights only.
#include "surface.glsl"
#include "data_texture.glsl"
#include "light_data.glsl"
#include "light_model.glsl"
#include "directional.glsl"
#include "cluster_lookup.glsl"

CENTROID VARYING HIGHP vec3 v_viewPos;
#if UNIFORM_LIGHT_LOOP
// The longest cell list of the frame (the loop bound of the driver workaround).
uniform HIGHP float u_longestList;
#endif
VARYING vec3 v_normal;
VARYING vec2 v_uv;

void main() {
#if HAS_ALPHA_MASK
    if (surfaceCut(v_uv)) {
        discard;
    }
#endif
#if GLSL_ES == 100
    // In highp from here: GLSL ES 1.00 declares gl_FragCoord mediump, whose pixel centres
    // (x.5) are exact only below 1024; a driver that keeps it in fp16 loses them past that.
    HIGHP vec2 fragXY = gl_FragCoord.xy - u_frameOrigin;
#else
    // The cell of the point shaded: the centroid (v_viewPos), not the pixel centre.
    HIGHP vec2 fragXY = shadedFrameXY(v_viewPos);
#endif
    HIGHP float viewDepth = -v_viewPos.z;
#if COUNT_EVALS
    // The loop below runs over the cell's list: its length is the evaluation count.
    FRAG_COLOR = encodeCount(float(clusterCell(fragXY, viewDepth).y));
#else
    vec3 N = normalize(v_normal);
    vec3 V = viewDirection(v_viewPos);
    N = shadingNormal(N, v_uv);
    MEDP vec3 albedo = surfaceAlbedo(v_uv);
    SurfaceParams surface = materialSurface(albedo, v_uv);
    HIGHP vec3 color = surfaceAmbient(albedo, v_uv);
#if HAS_DIRECTIONAL
    // Directional lights reach every cell: evaluated here, outside the cell's list.
    color += shadeDirectional(N, V, surface);
#endif
#if GLSL_ES == 100
    HIGHP vec2 cell = clusterCell(fragXY, viewDepth);
#if UNIFORM_LIGHT_LOOP
    // Driver workaround (Caps::needs_uniform_light_loop): every fragment runs to the frame's
    // longest list and keeps only its own lights, so no fragment of a quad leaves early. Past
    // its list a fragment reads its last entry again (or any, for an empty cell) and the select
    // drops the result, NaN included.
    for (int n = 0; n < CELL_CAP; n++) {
        if (float(n) >= u_longestList) {
            break;
        }
        HIGHP float pos = cell.x + min(float(n), max(cell.y - 1.0, 0.0));
        vec3 c = shadeLight(fetchLight(lightIndexAt(pos)), v_viewPos, N, V, surface);
        color += float(n) < cell.y ? c : vec3(0.0);
    }
#else
    // Appendix A: constant bound (the per-cell cap), exit with break.
    for (int n = 0; n < CELL_CAP; n++) {
        if (float(n) >= cell.y) {
            break;
        }
        color += shadeLight(fetchLight(lightIndexAt(cell.x + float(n))), v_viewPos, N, V, surface);
    }
#endif
#else
    uvec2 cell = clusterCell(fragXY, viewDepth);
    for (uint n = 0u; n < cell.y; n++) {
        color += shadeLight(fetchLight(lightIndexAt(cell.x + n)), v_viewPos, N, V, surface);
    }
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
