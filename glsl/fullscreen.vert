// A clip-space triangle or quad passed through unchanged (probes and full-screen passes).
ATTRIBUTE vec3 a_position;

void main() {
    gl_Position = vec4(a_position, 1.0);
}
