// A light as the light model reads it (view space; see GpuLight in src/cluster/pack.rs).
struct Light {
    vec3 position;
    float radius;
    vec3 radiance;
#if HAS_SPOT
    float spotScale;
    vec3 direction;
    float spotOffset;
#endif
};
