// The light model, shared by every method (CPU twin: src/scene/shading.rs).
// P, N, V in view space; N and V unit; the light's radius is > 0 (inactive lights are never
// uploaded). The surface's parameters come as a SurfaceParams so deferred shading can pass them
// from its G-buffer. Two BRDFs (src/scene/material.rs MaterialModel): Blinn-Phong, and with
// METALLIC_ROUGHNESS the glTF 2.0 metallic-roughness BRDF (CPU twin: src/scene/brdf.rs).
//
// Precision, mobile first. What fp16 cannot hold stays HIGHP: positions and light vectors
// (a light 300 m away), the spot term,
// N·H before a power of up to 4096, and the radiometric scale (radiance reaches 1e6). The
// colour factors (albedo, Ks, the diffuse cosine) are MEDP: mediump (fp16 on phones, and on
// llvmpipe, so the tests see it), or highp in the reference variant.
//
// Devices without fragment highp turn HIGHP into mediump too; the falloff is written so it
// survives that: nothing is squared before it is scaled to at most 1. The vector to the light
// is divided by its largest component m (s = (Lp − P)/m, 1 ≤ |s|² ≤ 3), the distance is
// d = m·|s|, and the window takes the ratio q = d/r before squaring it; 1/(d² + 1) is
// (1/d)²/(1 + (1/d)²) past d = 1. So neither d² (past 256 m) nor |Lp − P|² overflows fp16, and
// (d/r)² of a light with a large radius (d/r = 10⁻⁴ at r = 6 000) may underflow to 0 but no
// longer takes the direction to the light with it.
// Closer than this (largest component of the vector to the light) a light has no direction
// and contributes nothing, as exactly at it. 2^-13: above fp16's smallest normal (2^-14), so a
// driver that flushes subnormals never divides by one it treats as zero.
#define LIGHT_MIN_DISTANCE 1.220703125e-4

// What the BRDF reads. Blinn-Phong: albedo, Ks, Ns. Metallic-roughness: albedo (base colour),
// metallic, roughness (perceptual); in the deferred light pass a negative Ns marks it.
struct SurfaceParams {
    MEDP vec3 albedo;
    MEDP vec3 Ks;
    HIGHP float Ns;
    MEDP float metallic;
    MEDP float roughness;
};

// The material's parameters at uv (forward and clustered; deferred reads its G-buffer).
SurfaceParams materialSurface(MEDP vec3 albedo, vec2 uv) {
    SurfaceParams s;
    s.albedo = albedo;
#if HAS_SPECULAR
    s.Ks = u_specular;
    s.Ns = u_shininess;
#else
    s.Ks = vec3(0.0);
    s.Ns = 1.0;
#endif
#if METALLIC_ROUGHNESS
    vec2 mr = surfaceMetallicRoughness(uv);
    s.metallic = mr.x;
    s.roughness = mr.y;
#else
    s.metallic = 0.0;
    s.roughness = 1.0;
#endif
    return s;
}

// Lambert + Blinn-Phong, both times N·L (the colour factors at MEDP; N·H at HIGHP before the
// power). The specular lobe fades with N·L, as irradiance does: a light at grazing incidence (one
// lying on the surface) adds nothing rather than a full highlight gated by the sign of N·L,
// which rounding flips from pixel to pixel.
MEDP vec3 blinnPhong(HIGHP vec3 L, vec3 N, vec3 V, MEDP float nDotL, SurfaceParams s) {
#if HAS_SPECULAR
    HIGHP vec3 halfSum = L + V;
    // Zero where L = −V; the floor is a normal fp16 number (drivers flush subnormals to 0).
    HIGHP vec3 H = halfSum / max(length(halfSum), 1e-4);
    MEDP vec3 spec = s.Ks * pow(max(dot(N, H), 0.0), s.Ns);
#else
    MEDP vec3 spec = vec3(0.0);
#endif
    return (s.albedo + spec) * nDotL;
}

#if METALLIC_ROUGHNESS
// glTF 2.0 Appendix B (GGX, height-correlated Smith, Schlick, the spec's dielectric/metal mix)
// times π·N·L; every step written to survive fp16 (docs/precision.md, "Metallic-roughness"):
// - perceptual roughness ≥ 0.089: α² ≥ 6.3e-5, a normal fp16 number, and the peak 1/α fits;
// - (N·H)²(α² − 1) + 1 as α²(N·H)² + |N×H|²: 1 − (N·H)² cancels to 0 in fp16 near N = H;
// - π·D as k², k = α / that (≤ 1/α), never squaring the small denominator;
// - Vis·N·L in one quotient (Vis alone grows without bound at grazing angles), N·V ≥ 1e-4;
// - the lobe capped at 16384 as min(k·Vis·N·L, 16384/k)·k, so no product overflows.
// The lobe runs at HIGHP (fp16 only where the device has no fragment highp), colours at MEDP.
MEDP vec3 metallicRoughness(HIGHP vec3 L, vec3 N, vec3 V, MEDP float nDotL, SurfaceParams s) {
    HIGHP vec3 halfSum = L + V;
    HIGHP vec3 H = halfSum / max(length(halfSum), 1e-4);
    HIGHP float nDotV = max(dot(N, V), 1e-4);
    HIGHP float nDotH = clamp(dot(N, H), 0.0, 1.0);
    MEDP float vDotH = clamp(dot(V, H), 0.0, 1.0);
    HIGHP float r = clamp(s.roughness, 0.089, 1.0);
    HIGHP float a = r * r;
    HIGHP float a2 = a * a;
    HIGHP vec3 NxH = cross(N, H);
    HIGHP float k = a / max(a2 * nDotH * nDotH + dot(NxH, NxH), a2);
    HIGHP float lambdaV = sqrt(nDotV * nDotV * (1.0 - a2) + a2);
    HIGHP float lambdaL = sqrt(nDotL * nDotL * (1.0 - a2) + a2);
    HIGHP float visCos = 0.5 / (lambdaV + nDotV * lambdaL / nDotL);
    HIGHP float lobe = min(k * visCos, 16384.0 / k) * k;
    MEDP float x = 1.0 - vDotH;
    MEDP float x2 = x * x;
    MEDP float x5 = x2 * x2 * x;
    // A base colour past 1 (glTF's range) reflects at most all: F0 > 1 times the capped lobe
    // is past fp16 (Inf, then NaN where the spot or falloff is 0).
    MEDP vec3 f0 = mix(vec3(0.04), min(s.albedo, vec3(1.0)), s.metallic);
    MEDP vec3 fresnel = f0 + (1.0 - f0) * x5;
    MEDP float dielectric = 0.04 + 0.96 * x5;
    MEDP vec3 diffuse = s.albedo * ((1.0 - s.metallic) * (1.0 - dielectric) * nDotL);
    return diffuse + fresnel * lobe;
}
#endif

// The BRDF times N·L for unit L (to the light), N, V (to the eye) where N·L > 0: what the
// light's radiance × falloff × spot is multiplied by. Shared by every light type.
MEDP vec3 surfaceReflectance(HIGHP vec3 L, vec3 N, vec3 V, SurfaceParams s) {
    MEDP float nDotL = dot(N, L);
#if METALLIC_ROUGHNESS && defined(PER_PIXEL_MODEL)
    if (s.Ns < 0.0) {
        return metallicRoughness(L, N, V, nDotL, s);
    }
    return blinnPhong(L, N, V, nDotL, s);
#elif METALLIC_ROUGHNESS
    return metallicRoughness(L, N, V, nDotL, s);
#else
    return blinnPhong(L, N, V, nDotL, s);
#endif
}

vec3 shadeLight(Light light, HIGHP vec3 P, vec3 N, vec3 V, SurfaceParams surface) {
    HIGHP vec3 toLight = light.position - P;
    HIGHP float m = max(max(abs(toLight.x), abs(toLight.y)), abs(toLight.z));
    // Beyond the radius (|Lp − P| ≥ m), or at the light (no direction: no contribution).
    if (m >= light.radius || m <= LIGHT_MIN_DISTANCE) {
        return vec3(0.0);
    }
    HIGHP vec3 s = toLight / m;
    HIGHP float invLen = inversesqrt(dot(s, s));
    HIGHP float q = m / light.radius / invLen;
    if (q >= 1.0) {
        return vec3(0.0);
    }
    // Windowed inverse square: w² / (d² + 1) with w = 1 − (d/r)⁴, exactly zero at the radius.
    HIGHP float q2 = q * q;
    HIGHP float w = 1.0 - q2 * q2;
    // 1 / max(d, 1), without forming d where it is large (1/m is small there).
    HIGHP float inv = min(invLen / m, 1.0);
    // Read only where d ≤ 1.
    HIGHP float d = m / invLen;
    HIGHP vec3 L = s * invLen;
    if (dot(N, L) <= 0.0) {
        return vec3(0.0);
    }
#if HAS_SPOT
    // 1 − cos of the angle off the axis as half the squared chord |L + axis|²: small and
    // accurate for narrow cones even in fp16 (see Light::spot_scale_offset). A cone wider than
    // 90° comes with its axis, scale and offset turned round (pack/lights.rs), so the chord is
    // measured from the back axis, where its edge lies.
    HIGHP vec3 chord = L + light.direction;
    HIGHP float t = clamp(light.spotOffset - 0.5 * light.spotScale * dot(chord, chord), 0.0, 1.0);
    HIGHP float spot = t * t * (3.0 - 2.0 * t);
#else
    HIGHP float spot = 1.0;
#endif
#if FP16_LIGHTS
    // Radiance came divided by k² (light_struct.glsl): the falloff takes it back as (w·k·g)²,
    // g = 1/√(d² + 1), with the spot's root in it, capped in the root where only a saturated
    // pixel could come out (k² is past fp16 from k = 2⁸ on; 244² < 60000; no Inf, no Inf·0).
    // The spot goes in before the cap: the faint edge of a bright spot is not saturated.
    HIGHP float g = inv < 1.0 ? inv * inversesqrt(1.0 + inv * inv) : inversesqrt(d * d + 1.0);
    HIGHP float root = min(w * (light.radianceRoot * g) * sqrt(spot), 244.0);
    HIGHP float falloff = root * root;
#else
    HIGHP float falloff = w * w * (inv < 1.0 ? inv * inv / (1.0 + inv * inv) : 1.0 / (d * d + 1.0)) * spot;
#endif
    if (falloff <= 0.0) {
        return vec3(0.0);
    }
    MEDP vec3 reflectance = surfaceReflectance(L, N, V, surface);
#if FP16_LIGHTS
    // fp16 everywhere: falloff (≤ 60000) × reflectance (≤ 16384 + the base colour) is capped
    // before it could overflow; radiance is ≤ 1 here, so only a pixel far past saturation is
    // changed.
    return light.radiance * (min(vec3(falloff), 60000.0 / max(reflectance, vec3(1.0))) * reflectance);
#else
    return light.radiance * falloff * reflectance;
#endif
}

#if COUNT_REACHING
// Whether the light can contribute at P at all, whatever the surface's orientation: P inside
// its sphere and (spots) inside its cone. What a perfect per-pixel culler would keep.
bool lightReaches(Light light, HIGHP vec3 P) {
    // As shadeLight: scaled by the largest component before anything is squared.
    HIGHP vec3 toLight = light.position - P;
    HIGHP float m = max(max(abs(toLight.x), abs(toLight.y)), abs(toLight.z));
    if (m >= light.radius) {
        return false;
    }
    // At the light (the cone's apex) there is no direction: it reaches, whichever way its
    // cone's terms are written (from the front or turned round, they disagree at L = 0).
    if (m <= LIGHT_MIN_DISTANCE) {
        return true;
    }
    HIGHP vec3 s = toLight / m;
    if (m / light.radius * length(s) >= 1.0) {
        return false;
    }
#if HAS_SPOT
    HIGHP vec3 L = normalize(s);
    HIGHP vec3 chord = L + light.direction;
    return light.spotOffset - 0.5 * light.spotScale * dot(chord, chord) > 0.0;
#else
    return true;
#endif
}
#endif
