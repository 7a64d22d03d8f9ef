// Reads light records from the light data texture (layout: src/cluster/pack/lights.rs).
// LIGHT_TEXELS and LIGHTS_RGBA8 come from Rust as #defines. Needs data_texture.glsl.
uniform HIGHP sampler2D u_lights;
uniform int u_lightCount;
#if GLSL_ES == 100
// 1 / texture height in rows (ES 2.0 addresses texel centres with normalised coordinates).
uniform HIGHP float u_lightTexInvHeight;
#endif
#if LIGHTS_RGBA8
// x: positions are fixed point over [-x, x]; y: radii over [0, y].
uniform HIGHP vec2 u_lightRanges;
#endif

#include "light_struct.glsl"

#if GLSL_ES == 100
// Texel k of light i, its row and column found from the light number without forming the
// texel number i·LIGHT_TEXELS + k: where HIGHP is mediump (no fragment highp), fp16 holds
// integers exactly only up to 2048, and light 512's texels are already past that.
HIGHP vec4 lightTexel(HIGHP float i, HIGHP float k) {
    HIGHP float perRow = float(DATA_WIDTH / LIGHT_TEXELS);
    HIGHP float row = floor(i / perRow);
    return dataTexelAt(u_lights, (i - row * perRow) * float(LIGHT_TEXELS) + k, row, u_lightTexInvHeight);
}
#define LIGHT_TEXEL(base, k) lightTexel(float(base), float(k))
#else
#define LIGHT_TEXEL(base, k) texelFetch(u_lights, dataCoord((base) * LIGHT_TEXELS + (k)), 0)
#endif

#if LIGHTS_RGBA8
// Two bytes (as 0..1 channels) → 0..1 with 16 bits, without forming the 16-bit integer:
// where HIGHP is mediump, 65 535 is past fp16's largest value, and so is any constant the
// compiler folds from it. 0.0039063096 is 256 / 65 535.
HIGHP float unpack16(vec2 bytes) {
    return (byteOf(bytes.x) + byteOf(bytes.y) * (1.0 / 256.0)) * 0.0039063096;
}

// unpack16 · 2 − 1 formed about the centre (127.998046875 = 32 767.5 / 256), so that in fp16
// a coordinate near the middle of the range keeps its low byte, as a float texel keeps a small
// value's bits; 0.0078126192 is 512 / 65 535. Exact in highp; fp16 rounds both constants
// (to 128 and 2⁻⁷), which moves the ends by at most one 16-bit step.
HIGHP float unpackSigned16(vec2 bytes) {
    return ((byteOf(bytes.x) - 127.998046875) + byteOf(bytes.y) * (1.0 / 256.0)) * 0.0078126192;
}
#endif

// Spot data is only read when the scene has spot lights (HAS_SPOT); otherwise the variant
// fetches fewer texels and has no cone code at all.
Light fetchLight(int i) {
    Light light;
    vec4 t0 = LIGHT_TEXEL(i, 0);
    vec4 t1 = LIGHT_TEXEL(i, 1);
#if LIGHTS_RGBA8
    vec4 t2 = LIGHT_TEXEL(i, 2);
    light.position = vec3(unpackSigned16(t0.xy), unpackSigned16(t0.zw), unpackSigned16(t1.xy)) * u_lightRanges.x;
    light.radius = unpack16(t1.zw) * u_lightRanges.y;
    vec4 rgbe = floor(t2 * 255.0 + 0.5);
#if FP16_LIGHTS
    // The fp16-range form (see light_struct.glsl): the exponent split as 2e + rest, e ≥ 0,
    // at most 15 (2^16 is past fp16). Past 2^30 (a rest above 0) the brightest channel is
    // taken as 2^30, the others scaled alike, as fp16_radiance takes them.
    HIGHP float e = clamp(ceil((rgbe.a - 128.0) * 0.5), 0.0, 15.0);
    HIGHP float rest = rgbe.a - 128.0 - 2.0 * e;
    light.radiance = rest > 0.0
        ? rgbe.rgb / max(max(rgbe.r, rgbe.g), max(rgbe.b, 1.0))
        : rgbe.rgb / 255.0 * exp2(rest);
    light.radianceRoot = exp2(e);
#else
    light.radiance = rgbe.rgb / 255.0 * exp2(rgbe.a - 128.0);
#endif
#if HAS_SPOT
    vec4 t3 = LIGHT_TEXEL(i, 3);
    vec4 t4 = LIGHT_TEXEL(i, 4);
    vec4 t5 = LIGHT_TEXEL(i, 5);
    vec3 dir = vec3(unpack16(t3.xy), unpack16(t3.zw), unpack16(t4.xy)) * 2.0 - 1.0;
    // An omni light's stored direction decodes to zero; its floor is a normal fp16 number,
    // since NVIDIA flushes fp16 subnormals (1e-6 became 0, and 0 / 0 unlit every light).
    light.direction = dir / max(length(dir), 1e-4);
    // 1 − cos α as 2 sin²(α/2) from the stored sin(α/2), as spot_terms_from_half_sines does:
    // arithmetic only (GLSL ES leaves sin's precision to the implementation). A cone turned
    // round (t4.z 128/255: axis reversed) stores cos(α/2): 1 + cos α as 2 cos²(α/2), and its
    // scale negated (spot_terms_from_half_cosines).
    float halfOuter = unpack16(t5.xy);
    float halfInner = unpack16(t5.zw);
    float edgeInner = 2.0 * halfInner * halfInner;
    float edgeOuter = 2.0 * halfOuter * halfOuter;
    bool omni = t4.z > 0.75;
    bool turned = t4.z > 0.25 && !omni;
    float width = turned ? edgeInner - edgeOuter : edgeOuter - edgeInner;
    float scale = 1.0 / max(width, SPOT_MIN_COS_DELTA);
    light.spotScale = omni ? 0.0 : (turned ? -scale : scale);
    light.spotOffset = omni ? 1.0 : (turned ? 1.0 - edgeInner * scale : 1.0 + edgeInner * scale);
#endif
#else
    light.position = t0.xyz;
    light.radius = t0.w;
    light.radiance = t1.rgb;
#if FP16_LIGHTS
    light.radianceRoot = t1.a;
#endif
#if HAS_SPOT
    vec4 t2 = LIGHT_TEXEL(i, 2);
    light.direction = t2.xyz;
    light.spotOffset = t2.w;
#if FP16_LIGHTS
    light.spotScale = LIGHT_TEXEL(i, 3).x;
#else
    light.spotScale = t1.w;
#endif
#endif
#endif
    return light;
}
