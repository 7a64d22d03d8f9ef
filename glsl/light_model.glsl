// The light model, shared by every method (CPU twin: src/scene/shading.rs).
// P, N, V in view space; N and V unit; the light's radius is > 0 (inactive lights are never
// uploaded). Ks and Ns are parameters so deferred shading can pass them from its G-buffer.
vec3 shadeLight(Light light, vec3 P, vec3 N, vec3 V, vec3 albedo, vec3 Ks, float Ns) {
    vec3 toLight = light.position - P;
    float d2 = dot(toLight, toLight);
    float d = sqrt(d2);
    float ratio = d / light.radius;
    float q = ratio * ratio;
    q = q * q;
    // Windowed inverse square: exactly zero at and beyond the radius.
    float w = clamp(1.0 - q, 0.0, 1.0);
    float falloff = w * w / (d2 + 1.0);
    vec3 L = toLight / max(d, 1e-6);
    float nDotL = dot(N, L);
    if (falloff <= 0.0 || nDotL <= 0.0) {
        return vec3(0.0);
    }
#if HAS_SPOT
    float t = clamp(dot(-L, light.direction) * light.spotScale + light.spotOffset, 0.0, 1.0);
    float spot = t * t * (3.0 - 2.0 * t);
#else
    float spot = 1.0;
#endif
#if HAS_SPECULAR
    vec3 halfSum = L + V;
    vec3 H = halfSum / max(length(halfSum), 1e-6);
    vec3 spec = Ks * pow(max(dot(N, H), 0.0), Ns);
#else
    vec3 spec = vec3(0.0);
#endif
    return light.radiance * (falloff * spot) * (albedo * nDotL + spec);
}
