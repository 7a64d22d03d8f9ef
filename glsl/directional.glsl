// Directional lights (a sun): up to MAX_DIRECTIONAL, the same at every point, so every pixel
// evaluates them from uniforms, outside the light lists (no position, no radius: nothing to
// cull or assign). CPU twin: scene::shading::shade_directional. Needs light_model.glsl.
#if HAS_DIRECTIONAL
uniform int u_directionalCount;
// Column i: the unit direction from a surface to light i, in view space.
uniform HIGHP mat4 u_directionalToLight;
// Column i: light i's radiance (rgb). FP16_LIGHTS: rgb is radiance / k² and w is k (the
// fp16-range form of light_struct.glsl), k² folded into the reflectance and the product capped
// at DIRECTIONAL_FP16_CAP, so four suns sum below fp16's 65 504 (no Inf, no Inf·0).
uniform HIGHP mat4 u_directionalRadiance;

HIGHP vec3 shadeDirectional(vec3 N, vec3 V, SurfaceParams surface) {
    HIGHP vec3 sum = vec3(0.0);
    // GLSL ES 1.00 Appendix A: constant bound, uniform count, exit with break.
    for (int i = 0; i < MAX_DIRECTIONAL; i++) {
        if (i >= u_directionalCount) {
            break;
        }
        HIGHP vec3 L = u_directionalToLight[i].xyz;
        if (dot(N, L) > 0.0) {
            HIGHP vec4 radiance = u_directionalRadiance[i];
            MEDP vec3 r = surfaceReflectance(L, N, V, surface);
#if FP16_LIGHTS
            sum += radiance.rgb * min(radiance.w * (radiance.w * r), vec3(DIRECTIONAL_FP16_CAP));
#else
            sum += radiance.rgb * r;
#endif
        }
    }
    return sum;
}
#endif
