// Deferred, pass 1 (ES 3.0 multiple render targets): the surface attributes the light pass
// needs. Layout and bytes per pixel are documented in src/methods/deferred.rs.
#include "surface.glsl"

VARYING HIGHP vec3 v_viewPos;
VARYING vec3 v_normal;
VARYING vec2 v_uv;

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out HIGHP vec4 o_normalDepth;
layout(location = 2) out vec4 o_specular;

void main() {
    vec3 N = normalize(v_normal);
    vec3 V = viewDirection(v_viewPos);
    // Two-sided, as in the forward shaders: store the side the eye sees.
    if (dot(N, V) < 0.0) {
        N = -N;
    }
    o_albedo = vec4(surfaceAlbedo(v_uv), 1.0);
    // View depth > 0 marks a covered pixel (the buffer is cleared to 0).
    o_normalDepth = vec4(N, -v_viewPos.z);
#if HAS_SPECULAR
    o_specular = vec4(u_specular, u_shininess);
#else
    o_specular = vec4(0.0, 0.0, 0.0, 1.0);
#endif
}
