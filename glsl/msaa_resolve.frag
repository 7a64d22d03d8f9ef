// MSAA on ES 2.0 (GL_EXT_multisampled_render_to_texture): the driver averaged the samples into
// u_resolved when the multisampled framebuffer was flushed; this copies it texel for texel onto
// the destination (ES 2.0 has no blit). Nearest filtering at the pixel centre: an exact copy.
// The coordinate is highp where the stage has it: fp16 keeps 11 bits, a step of half a texel
// at 2 048 pixels, too coarse to be sure of the texel at wide targets.
uniform sampler2D u_resolved;
uniform HIGHP vec2 u_invSize;

void main() {
    HIGHP vec2 uv = gl_FragCoord.xy * u_invSize;
    FRAG_COLOR = TEXTURE2D(u_resolved, uv);
}
