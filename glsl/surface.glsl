// Material inputs, sRGB conversions and the output encoding.
uniform vec3 u_albedo;
#if HAS_SPECULAR
uniform vec3 u_specular;
uniform float u_shininess;
#endif
// Material opacity (1 for opaque objects; blended when below 1, and by the texture's alpha
// too with HAS_TEXTURE_ALPHA).
uniform float u_alpha;
uniform vec3 u_ambient;
// 1.0 for orthographic cameras (view direction +Z), 0.0 for perspective.
uniform float u_orthographic;
#if HAS_TEXTURE
uniform sampler2D u_albedoTex;
#endif

// A colour texel (base colour, emission) in linear RGB: LINEAR_TEXEL. Where colour textures
// are sRGB ones (SRGB_TEXTURES, the ES 3.0 level) the sampler decodes each texel before
// filtering, as glTF asks; else (ES 2.0) the filtered value is decoded here. Branches with one
// body: the variant stripper (shader_source::strip_feature_blocks) reads single-flag
// conditions.
#if SRGB_TEXTURES
#define LINEAR_TEXEL(c) (c)
#elif HAS_TEXTURE
vec3 srgbToLinear(vec3 c) {
    vec3 lo = c / 12.92;
    vec3 hi = pow((c + 0.055) / 1.055, vec3(2.4));
    return mix(lo, hi, step(vec3(0.04045), c));
}
#define LINEAR_TEXEL(c) srgbToLinear(c)
#elif HAS_EMISSIVE_MAP
vec3 srgbToLinear(vec3 c) {
    vec3 lo = c / 12.92;
    vec3 hi = pow((c + 0.055) / 1.055, vec3(2.4));
    return mix(lo, hi, step(vec3(0.04045), c));
}
#define LINEAR_TEXEL(c) srgbToLinear(c)
#endif

vec3 linearToSrgb(vec3 c) {
    vec3 lo = c * 12.92;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(lo, hi, step(vec3(0.0031308), c));
}

#include "surface_maps.glsl"

// −1 for an object placed by a mirroring transform, which turns its winding round on screen.
// A uniform rather than glFrontFace: SwiftShader's gl_FrontFacing ignores glFrontFace.
uniform float u_frontSign;

// The shading normal of the side the eye sees (a single-sided surface's back is culled): the interpolated unit
// normal N, normal-mapped in its own tangent frame, then reversed whole on a back face (glTF
// 2.0 §3.9.5). The side is the winding's (meshes are wound towards their normals): turned by
// N · V instead, a front face's normal leaning away near a silhouette lit it from behind.
// Mapping after the flip would mirror the map along the tangent.
vec3 shadingNormal(vec3 N, vec2 uv) {
    float side = gl_FrontFacing ? u_frontSign : -u_frontSign;
#if HAS_NORMAL_MAP
    N = surfaceNormal(N, uv);
#endif
    return N * side;
}

// The alpha the base colour texture (under HAS_TEXTURE_ALPHA or HAS_ALPHA_MASK) and COLOR_0
// (under HAS_VERTEX_ALPHA) give on top of the material's factor. Single-flag conditions, so
// that a variant without a texture holds no texture code (`strip_feature_blocks`).
#define TEXEL_ALPHA(uv) 1.0
#if HAS_TEXTURE
#if HAS_TEXTURE_ALPHA
#undef TEXEL_ALPHA
#define TEXEL_ALPHA(uv) TEXTURE2D(u_albedoTex, UV_ALBEDO(uv)).a
#elif HAS_ALPHA_MASK
#undef TEXEL_ALPHA
#define TEXEL_ALPHA(uv) TEXTURE2D(u_albedoTex, UV_ALBEDO(uv)).a
#endif
#endif
#if HAS_VERTEX_ALPHA
#define VERTEX_ALPHA v_color.a
#else
#define VERTEX_ALPHA 1.0
#endif

#if HAS_ALPHA_MASK
uniform float u_alphaCutoff;
// glTF MASK: the fragment is cut where the base colour texture's alpha times COLOR_0's is
// below the cutoff (the factor's alpha folded into it).
bool surfaceCut(vec2 uv) {
    return TEXEL_ALPHA(uv) * VERTEX_ALPHA < u_alphaCutoff;
}
#endif

#if (HAS_TEXTURE_ALPHA || HAS_VERTEX_ALPHA) && !HAS_ALPHA_MASK
#define HAS_SURFACE_OPACITY 1
// glTF BLEND: the base colour texture's alpha and COLOR_0's multiply the material's opacity.
float surfaceOpacity(vec2 uv) {
    return TEXEL_ALPHA(uv) * VERTEX_ALPHA;
}
#else
#define HAS_SURFACE_OPACITY 0
#endif

vec3 surfaceAlbedo(vec2 uv) {
    vec3 albedo = u_albedo;
#if HAS_TEXTURE
    albedo *= LINEAR_TEXEL(TEXTURE2D(u_albedoTex, UV_ALBEDO(uv)).rgb);
#endif
#if HAS_VERTEX_COLOR
    albedo *= v_color.rgb;
#endif
    return albedo;
}

#if !OUTPUT_HDR
// 2^exposure (stops), applied before the tone map (1 by default).
uniform HIGHP float u_exposure;
#endif

#if TONEMAP
// Exposed linear radiance → [0, 1] (CPU twin: scene::shading::tone_map). The input is capped
// at 1000 first: every curve is 1 to within 0.2/255 there, and the polynomials below would
// overflow fp16 on a device without highp long before infinity.
HIGHP vec3 toneMap(HIGHP vec3 c) {
    c = clamp(c, 0.0, 1000.0);
#if TONEMAP == 1
    // Reinhard.
    return c / (1.0 + c);
#elif TONEMAP == 2
    // ACES filmic, Narkowicz's fit. It reaches 1 at c = 7.24, so c is capped at 8 first: the
    // result is the same, and the squares cannot overflow fp16 (at c = 165 they would).
    c = min(c, 8.0);
    return clamp((c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14), 0.0, 1.0);
#else
    // Khronos PBR Neutral.
    HIGHP float x = min(c.r, min(c.g, c.b));
    HIGHP float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    HIGHP float peak = max(c.r, max(c.g, c.b));
    if (peak < 0.76) {
        return c;
    }
    HIGHP float newPeak = 1.0 - 0.24 * 0.24 / (peak - 0.52);
    c *= newPeak / peak;
    HIGHP float g = 1.0 - 1.0 / (0.15 * (peak - newPeak) + 1.0);
    return mix(c, vec3(newPeak), g);
#endif
}
#endif

// Linear radiance → what the framebuffer stores: exposed and tone-mapped when asked, clamped,
// then sRGB-encoded unless OUTPUT_LINEAR.
vec4 encodeOutput(vec3 color) {
#if OUTPUT_HDR
    // Float targets: unclamped, so NaN and Inf stay visible to the stability tests.
    return vec4(color, u_alpha);
#else
#if FP16_LIGHTS
    // A sum past fp16's largest value is infinity (NaN through a tone map's ∞/∞): taken as
    // that value instead, which pre-exposed shows white anyway.
    color = min(color, vec3(65504.0));
#endif
    HIGHP vec3 exposed = color * u_exposure;
#if TONEMAP
    exposed = toneMap(exposed);
#endif
#if OUTPUT_LINEAR
    return vec4(clamp(exposed, 0.0, 1.0), u_alpha);
#else
    return vec4(linearToSrgb(clamp(exposed, 0.0, 1.0)), u_alpha);
#endif
#endif
}

#if COUNT_HEATMAP
// Lights at which the heatmap's colour map tops out.
uniform float u_heatScale;
#endif

#if COUNT_EVALS || COUNT_REACHING
// A light count written exactly into an RGBA8 target: low, middle and high byte in r, g, b;
// alpha 1 marks a covered pixel (the target is cleared to 0). Read back by the renderer.
// The heatmap variant draws it through viridis instead (five stops, as in
// src/metrics/heatmap.rs's picture of the same counts), for looking at.
vec4 encodeCount(HIGHP float n) {
#if COUNT_HEATMAP
    float t = clamp(n / u_heatScale, 0.0, 1.0) * 4.0;
    vec3 c = mix(vec3(0.267, 0.005, 0.329), vec3(0.230, 0.322, 0.546), clamp(t, 0.0, 1.0));
    c = mix(c, vec3(0.128, 0.567, 0.551), clamp(t - 1.0, 0.0, 1.0));
    c = mix(c, vec3(0.369, 0.789, 0.383), clamp(t - 2.0, 0.0, 1.0));
    c = mix(c, vec3(0.993, 0.906, 0.144), clamp(t - 3.0, 0.0, 1.0));
#if OUTPUT_LINEAR
    // The map's colours are sRGB values: a target that encodes (or a linear read-back) is
    // given them decoded.
    c = mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
#endif
    return vec4(c, 1.0);
#else
    // Byte by byte: 65 536 is past fp16 where HIGHP is mediump.
    HIGHP float above = floor(n / 256.0);
    HIGHP float high = floor(above / 256.0);
    HIGHP float middle = above - high * 256.0;
    return vec4(n - above * 256.0, middle, high, 255.0) / 255.0;
#endif
}
#endif

// Unit direction from the surface to the eye, in view space.
vec3 viewDirection(vec3 viewPos) {
    return normalize(mix(-viewPos, vec3(0.0, 0.0, 1.0), u_orthographic));
}
