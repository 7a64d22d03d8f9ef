// glTF surface inputs beyond the base colour, each compiled in only when the material uses
// it (CPU twin: src/scene/surface_maps.rs): texture transforms, vertex colours, normal maps,
// emission, ambient occlusion, the metallic-roughness texture.

#if HAS_TEXTURE_TRANSFORM
// KHR_texture_transform, applied per vertex in mesh.vert (the map is affine, so this is exact
// and costs no fragment uniforms): each texture's own coordinates, two per varying.
VARYING vec4 v_uvAlbedoNormal;
VARYING vec4 v_uvEmissiveOcclusion;
VARYING vec2 v_uvMetallicRoughness;
#define UV_ALBEDO(uv) v_uvAlbedoNormal.xy
#define UV_NORMAL(uv) v_uvAlbedoNormal.zw
#define UV_EMISSIVE(uv) v_uvEmissiveOcclusion.xy
#define UV_OCCLUSION(uv) v_uvEmissiveOcclusion.zw
#define UV_METALLIC_ROUGHNESS(uv) v_uvMetallicRoughness
#else
#define UV_ALBEDO(uv) (uv)
#define UV_NORMAL(uv) (uv)
#define UV_EMISSIVE(uv) (uv)
#define UV_OCCLUSION(uv) (uv)
#define UV_METALLIC_ROUGHNESS(uv) (uv)
#endif

#if HAS_VERTEX_COLOR
// COLOR_0: its linear RGB multiplies the base colour, its alpha (HAS_VERTEX_ALPHA) the opacity.
VARYING vec4 v_color;
#endif

#if HAS_NORMAL_MAP
// HIGHP: a sampler is lowp by default, and a lowp texel (fp16 on llvmpipe) tilts the normal by
// ~3e-4, which a bright light a millimetre above the surface turned into 226/255 (docs/gltf.md).
uniform HIGHP sampler2D u_normalTex;
uniform float u_normalScale;
// View-space tangent, bitangent sign in w.
VARYING vec4 v_tangent;

// The normal-mapped normal; N is the interpolated unit normal (of the front face).
vec3 surfaceNormal(vec3 N, vec2 uv) {
    vec3 t = v_tangent.xyz - N * dot(N, v_tangent.xyz);
    float len = length(t);
    if (len <= 0.0) {
        return N;
    }
    t /= len;
    vec3 b = cross(N, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
    vec3 m = TEXTURE2D(u_normalTex, UV_NORMAL(uv)).rgb * 2.0 - 1.0;
    m.xy *= u_normalScale;
    vec3 n = t * m.x + b * m.y + N * m.z;
    float l = length(n);
    return l > 0.0 ? n / l : N;
}
#endif

#if HAS_EMISSIVE
// Emitted radiance, added after the light sum.
uniform vec3 u_emissive;
#if HAS_EMISSIVE_MAP
uniform sampler2D u_emissiveTex;
#endif

vec3 surfaceEmission(vec2 uv) {
    vec3 e = u_emissive;
#if HAS_EMISSIVE_MAP
    e *= LINEAR_TEXEL(TEXTURE2D(u_emissiveTex, UV_EMISSIVE(uv)).rgb);
#endif
    return e;
}
#endif

#if HAS_OCCLUSION
// Ambient occlusion (red channel) scales the ambient term only: glTF applies it to indirect
// light, which the ambient term stands for here.
uniform sampler2D u_occlusionTex;
uniform float u_occlusionStrength;
#endif

// The ambient term of a surface of this albedo. The occlusion scales the albedo first: an
// ambient × albedo past the float range times an occlusion of 0 was inf · 0, NaN. In fp16 (no
// fragment highp) the uniform and the term are capped at FP16_MAX_AMBIENT: past fp16's
// 65 504 they would be infinity, white at any exposure.
#if HAS_OCCLUSION
// The factor the occlusion map scales the ambient term by.
float surfaceOcclusion(vec2 uv) {
    float ao = TEXTURE2D(u_occlusionTex, UV_OCCLUSION(uv)).r;
    return 1.0 + u_occlusionStrength * (ao - 1.0);
}
#endif

vec3 surfaceAmbient(vec3 albedo, vec2 uv) {
#if HAS_OCCLUSION
    albedo *= surfaceOcclusion(uv);
#endif
    vec3 a = u_ambient * albedo;
#if FP16_LIGHTS
    a = min(a, vec3(FP16_MAX_AMBIENT));
#endif
    return a;
}

#if METALLIC_ROUGHNESS
// (metallic, perceptual roughness) at uv: the glTF factors, times the metallic-roughness
// texture's B and G where the material has one (linear data).
uniform float u_metallic;
uniform float u_roughness;
#if HAS_MR_TEXTURE
uniform sampler2D u_metallicRoughnessTex;
#endif

vec2 surfaceMetallicRoughness(vec2 uv) {
    vec2 mr = vec2(u_metallic, u_roughness);
#if HAS_MR_TEXTURE
    mr *= TEXTURE2D(u_metallicRoughnessTex, UV_METALLIC_ROUGHNESS(uv)).bg;
#endif
    return mr;
}
#endif
