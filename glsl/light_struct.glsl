// A light as the light model reads it (view space; see GpuLight in src/cluster/pack.rs).
struct Light {
    vec3 position;
    float radius;
    vec3 radiance;
#if FP16_LIGHTS
    // Devices without fragment highp: radiance is stored divided by radianceRoot², which
    // the light model multiplies back into the falloff (src/cluster/pack.rs).
    float radianceRoot;
#endif
#if HAS_SPOT
    float spotScale;
    vec3 direction;
    float spotOffset;
#endif
};
