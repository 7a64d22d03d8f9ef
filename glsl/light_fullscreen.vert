// Deferred's full-screen light: one clip-space triangle for each instance's light, at the
// depth of its far end where its depth test bounds it (src/methods/deferred/proxy.rs).
ATTRIBUTE vec3 a_position;
#include "deferred_light_instance.glsl"

void main() {
    passLight();
    gl_Position = vec4(a_position.xy, a_proxy.z, 1.0);
}
