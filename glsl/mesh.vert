// Shared vertex stage of every geometry pass: view-space position and normal.
// u_modelView is computed on the CPU in f64 with the camera subtracted, so objects far from
// the origin keep full precision here.
// The depth prepass compiles this stage without the surface-input switches.
#ifndef HAS_VERTEX_COLOR
#define HAS_VERTEX_COLOR 0
#endif
#ifndef HAS_NORMAL_MAP
#define HAS_NORMAL_MAP 0
#endif
#ifndef HAS_TEXTURE_TRANSFORM
#define HAS_TEXTURE_TRANSFORM 0
#endif
#ifndef HAS_SECOND_UVS
#define HAS_SECOND_UVS 0
#endif
#if HAS_SECOND_UVS && !HAS_TEXTURE_TRANSFORM
#error "the second coordinate set is read through the per-texture coordinates"
#endif
ATTRIBUTE vec3 a_position;
ATTRIBUTE vec3 a_normal;
ATTRIBUTE vec2 a_uv;

uniform mat4 u_modelView;
uniform mat3 u_normalMatrix;
uniform mat4 u_projection;

// Centroid (ES 3.0): with MSAA a pixel an edge crosses is shaded at a point of the triangle,
// not at the pixel's centre off it, where the position runs far past the scene (and its cells).
CENTROID VARYING vec3 v_viewPos;
// The depth prepass and the shading pass are different programs: `invariant` guarantees they
// compute bit-identical depths, so the shading pass's LEQUAL test passes exactly once.
invariant gl_Position;

VARYING vec3 v_normal;
VARYING vec2 v_uv;
#if HAS_VERTEX_COLOR
ATTRIBUTE vec4 a_color;
VARYING vec4 v_color;
#endif
#if HAS_NORMAL_MAP
ATTRIBUTE vec4 a_tangent;
// −1 when the model-view matrix mirrors (flips the bitangent's handedness), else 1.
uniform float u_tangentSign;
VARYING vec4 v_tangent;
#endif
#if HAS_TEXTURE_TRANSFORM
// Each texture's KHR_texture_transform: uv' = (M · (uv, 1)).xy (see surface_maps.glsl).
uniform mat3 u_albedoUvTransform;
uniform mat3 u_normalUvTransform;
uniform mat3 u_emissiveUvTransform;
uniform mat3 u_occlusionUvTransform;
uniform mat3 u_metallicRoughnessUvTransform;
VARYING vec4 v_uvAlbedoNormal;
VARYING vec4 v_uvEmissiveOcclusion;
VARYING vec2 v_uvMetallicRoughness;
#if HAS_SECOND_UVS
// glTF TEXCOORD_1, and the set (0 or 1) each texture reads.
ATTRIBUTE vec2 a_uv1;
uniform float u_albedoUvSet;
uniform float u_normalUvSet;
uniform float u_emissiveUvSet;
uniform float u_occlusionUvSet;
uniform float u_metallicRoughnessUvSet;
#define SET_UV(set) vec3((set) > 0.5 ? a_uv1 : a_uv, 1.0)
#else
#define SET_UV(set) vec3(a_uv, 1.0)
#endif
#endif

void main() {
    vec4 viewPos = u_modelView * vec4(a_position, 1.0);
    v_viewPos = viewPos.xyz;
    // Unit length here, in the vertex stage's highp, divided by its largest component first:
    // a normal the normal matrix squashes (an object scaled 10⁹ along its normal, or to 10⁻⁹
    // across it) is 10⁻⁹ long, which a mediump varying (fp16) flushes to zero.
    vec3 n = u_normalMatrix * a_normal;
    float largest = max(max(abs(n.x), abs(n.y)), abs(n.z));
    v_normal = largest > 0.0 ? normalize(n / largest) : vec3(0.0);
    v_uv = a_uv;
#if HAS_TEXTURE_TRANSFORM
    v_uvAlbedoNormal = vec4((u_albedoUvTransform * SET_UV(u_albedoUvSet)).xy,
                            (u_normalUvTransform * SET_UV(u_normalUvSet)).xy);
    v_uvEmissiveOcclusion = vec4((u_emissiveUvTransform * SET_UV(u_emissiveUvSet)).xy,
                                 (u_occlusionUvTransform * SET_UV(u_occlusionUvSet)).xy);
    v_uvMetallicRoughness =
        (u_metallicRoughnessUvTransform * SET_UV(u_metallicRoughnessUvSet)).xy;
#endif
#if HAS_VERTEX_COLOR
    v_color = a_color;
#endif
#if HAS_NORMAL_MAP
    // Tangents lie in the surface: they turn with the model-view matrix itself (normals with
    // its inverse transpose), made unit here in highp as the normal is.
    vec3 t = (u_modelView * vec4(a_tangent.xyz, 0.0)).xyz;
    float tl = max(max(abs(t.x), abs(t.y)), abs(t.z));
    v_tangent = vec4(tl > 0.0 ? normalize(t / tl) : vec3(0.0), a_tangent.w * u_tangentSign);
#endif
    gl_Position = u_projection * viewPos;
}
