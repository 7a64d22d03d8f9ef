// The full-screen triangle of the ES 2.0 MSAA copy, with the texture coordinate interpolated
// at highp: GLSL ES 1.00 declares gl_FragCoord mediump, and at fp16 a pixel centre past 1 024
// pixels is not representable (the copy could take the neighbouring texel).
// u_framePart: the frame's part of the texture (1, 1 but where a context refusing other sizes
// gave the frame a power-of-two one).
ATTRIBUTE vec3 a_position;
uniform HIGHP vec2 u_framePart;
VARYING HIGHP vec2 v_uv;

void main() {
    v_uv = (a_position.xy * 0.5 + 0.5) * u_framePart;
    gl_Position = vec4(a_position, 1.0);
}
