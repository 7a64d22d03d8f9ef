// The light model, shared by every method (CPU twin: src/scene/shading.rs).
// P, N, V in view space; N and V unit; the light's radius is > 0 (inactive lights are never
// uploaded). Ks and Ns are parameters so deferred shading can pass them from its G-buffer.
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

// What the surface reflects towards V of unit irradiance from the unit direction L (surface to
// light): albedo·N·L plus the specular lobe, zero where N·L ≤ 0. Every kind of light scales
// this (point and spot lights below, directional lights in directional.glsl); CPU twin:
// scene::shading::reflected.
MEDP vec3 reflected(HIGHP vec3 L, vec3 N, vec3 V, MEDP vec3 albedo, MEDP vec3 Ks, HIGHP float Ns) {
    MEDP float nDotL = dot(N, L);
    if (nDotL <= 0.0) {
        return vec3(0.0);
    }
#if HAS_SPECULAR
    HIGHP vec3 halfSum = L + V;
    HIGHP vec3 H = halfSum / max(length(halfSum), 1e-6);
    MEDP vec3 spec = Ks * pow(max(dot(N, H), 0.0), Ns);
#else
    MEDP vec3 spec = vec3(0.0);
#endif
    return albedo * nDotL + spec;
}

// A point or spot light: the falloff described above, the spot cone, then reflected().
vec3 shadeLight(Light light, HIGHP vec3 P, vec3 N, vec3 V, MEDP vec3 albedo, MEDP vec3 Ks, HIGHP float Ns) {
    HIGHP vec3 toLight = light.position - P;
    HIGHP float m = max(max(abs(toLight.x), abs(toLight.y)), abs(toLight.z));
    // Beyond the radius (|Lp − P| ≥ m), or exactly at the light (no direction: no contribution).
    if (m >= light.radius || m <= 0.0) {
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
#if FP16_LIGHTS
    // Radiance came divided by k² (light_struct.glsl): k² goes into the falloff as (k/d)², and
    // the product is capped where only a saturated pixel could come out (no Inf, no Inf·0).
    HIGHP float k = light.radianceRoot;
    HIGHP float kInv = k * inv;
    HIGHP float falloff = min(w * w * (inv < 1.0 ? kInv * kInv / (1.0 + inv * inv) : k * k / (d * d + 1.0)), 60000.0);
#else
    HIGHP float falloff = w * w * (inv < 1.0 ? inv * inv / (1.0 + inv * inv) : 1.0 / (d * d + 1.0));
#endif
    HIGHP vec3 L = s * invLen;
    if (falloff <= 0.0 || dot(N, L) <= 0.0) {
        return vec3(0.0);
    }
#if HAS_SPOT
    // 1 − cos of the angle off the axis as half the squared chord |L + axis|²: small and
    // accurate for narrow cones even in fp16 (see Light::spot_scale_offset).
    HIGHP vec3 chord = L + light.direction;
    HIGHP float t = clamp(light.spotOffset - 0.5 * light.spotScale * dot(chord, chord), 0.0, 1.0);
    HIGHP float spot = t * t * (3.0 - 2.0 * t);
#else
    HIGHP float spot = 1.0;
#endif
    return light.radiance * (falloff * spot) * reflected(L, N, V, albedo, Ks, Ns);
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
    HIGHP vec3 s = m > 0.0 ? toLight / m : vec3(0.0);
    if (m / light.radius * length(s) >= 1.0) {
        return false;
    }
#if HAS_SPOT
    HIGHP vec3 L = m > 0.0 ? normalize(s) : vec3(0.0);
    HIGHP vec3 chord = L + light.direction;
    return light.spotOffset - 0.5 * light.spotScale * dot(chord, chord) > 0.0;
#else
    return true;
#endif
}
#endif
