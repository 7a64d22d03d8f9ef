// Deferred, pass 2: one light, drawn as a proxy volume (or a full-screen triangle when the eye
// is inside it) instanced light by light, added to the accumulation buffer.
// Materials of both models share the G-buffer: the BRDF is chosen per pixel.
#define PER_PIXEL_MODEL 1
#include "surface.glsl"
#include "light_struct.glsl"
#include "light_model.glsl"
#include "deferred_common.glsl"
#include "deferred_light_varyings.glsl"

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    HIGHP vec4 nd = texelFetch(u_gNormalDepth, px, 0);
    if (noSurface(nd.z)) {
        discard;
    }
#if COUNT_EVALS
    // One evaluation of this light here, summed by the additive blend in its channel.
    FRAG_COLOR = vec4(equal(vec4(v_proxy.y), vec4(0.0, 1.0, 2.0, 3.0)));
#else
    HIGHP vec4 albedoOffset = texelFetch(u_gAlbedo, px, 0);
    HIGHP vec3 P = viewPosition(gl_FragCoord.xy + vec2(nd.w, albedoOffset.a), nd.z);
#if HAS_SPECULAR
    vec4 spec = texelFetch(u_gSpecular, px, 0);
#else
    // No specular target: no material has a lobe.
    vec4 spec = vec4(0.0, 0.0, 0.0, 1.0);
#endif
    Light light;
    light.position = v_light0.xyz;
    light.radius = v_light0.w;
    light.radiance = v_light1.rgb;
#if HAS_SPOT
    light.spotScale = v_light1.a;
    light.direction = v_light2.xyz;
    light.spotOffset = v_light2.w;
#endif
    SurfaceParams surface;
    surface.albedo = albedoOffset.rgb;
    surface.Ks = spec.rgb;
    surface.Ns = spec.a;
    surface.metallic = spec.r;
    surface.roughness = spec.g;
    // Alpha 0: the accumulation's alpha is the geometry pass's occlusion.
    FRAG_COLOR = vec4(shadeLight(light, P, octDecode(nd.xy), viewDirection(P), surface), 0.0);
#endif
}
