// Directional lights (a sun): up to MAX_DIRECTIONAL, the same at every point, so every pixel
// evaluates them from uniforms, outside the light lists (no position, no radius: nothing to
// cull or assign). CPU twin: scene::shading::shade_directional. Needs light_model.glsl.
#if HAS_DIRECTIONAL
uniform int u_directionalCount;
// Column i: the unit direction from a surface to light i, in view space (xyz); FP16_LIGHTS:
// w is k, below.
uniform HIGHP mat4 u_directionalToLight;
// Light i's radiance. FP16_LIGHTS: radiance / k² (the fp16-range form of light_struct.glsl),
// k² folded into the reflectance and the product capped at DIRECTIONAL_FP16_CAP, so four suns
// sum below fp16's 65 504 (no Inf, no Inf·0). An array of vec3, not a mat4, so that the
// fullest ES 2.0 variant packs into the 16 fragment uniform vectors every device has (§A.7).
uniform HIGHP vec3 u_directionalRadiance[MAX_DIRECTIONAL];

HIGHP vec3 shadeDirectional(vec3 N, vec3 V, SurfaceParams surface) {
    HIGHP vec3 sum = vec3(0.0);
    // GLSL ES 1.00 Appendix A: constant bound, uniform count, exit with break.
    for (int i = 0; i < MAX_DIRECTIONAL; i++) {
        if (i >= u_directionalCount) {
            break;
        }
        HIGHP vec4 toLight = u_directionalToLight[i];
        HIGHP vec3 L = toLight.xyz;
        if (dot(N, L) > 0.0) {
            HIGHP vec3 radiance = u_directionalRadiance[i];
            MEDP vec3 r = surfaceReflectance(L, N, V, surface);
#if FP16_LIGHTS
            HIGHP float k = toLight.w;
            sum += radiance * min(k * (k * r), vec3(DIRECTIONAL_FP16_CAP));
#else
            sum += radiance * r;
#endif
        }
    }
    return sum;
}
#endif
