// Deferred's full-screen light: one clip-space triangle for each instance's light.
ATTRIBUTE vec3 a_position;
#include "deferred_light_instance.glsl"

void main() {
    passLight();
    gl_Position = vec4(a_position, 1.0);
}
