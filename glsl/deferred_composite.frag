// Deferred, pass 3: ambient plus the accumulated lights, encoded like every other method.
#include "surface.glsl"
#include "deferred_common.glsl"

uniform HIGHP sampler2D u_accum;
// The geometry pass's depth, written into the target's depth buffer (see deferred.rs).
uniform HIGHP sampler2D u_gDepth;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    if (texelFetch(u_gNormalDepth, px, 0).z <= 0.0) {
        discard;
    }
    gl_FragDepth = texelFetch(u_gDepth, px, 0).r;
#if COUNT_EVALS
    FRAG_COLOR = encodeCount(texelFetch(u_accum, px, 0).r);
#else
    vec3 albedo = texelFetch(u_gAlbedo, px, 0).rgb;
    vec3 color = u_ambient * albedo + texelFetch(u_accum, px, 0).rgb;
    FRAG_COLOR = encodeOutput(color);
#endif
}
