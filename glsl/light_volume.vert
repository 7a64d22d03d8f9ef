// A unit-sphere proxy placed around a light in view space.
ATTRIBUTE vec3 a_position;

uniform HIGHP vec4 u_volume;
uniform mat4 u_projection;

void main() {
    gl_Position = u_projection * vec4(a_position * u_volume.w + u_volume.xyz, 1.0);
}
