// Deferred's light proxy: a unit sphere placed around each instance's light in view space.
ATTRIBUTE vec3 a_position;
#include "deferred_light_instance.glsl"

uniform mat4 u_projection;

void main() {
    passLight();
    gl_Position = u_projection * vec4(a_position * a_proxy.x + a_light0.xyz, 1.0);
}
