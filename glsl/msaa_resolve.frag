// MSAA on ES 2.0 (GL_EXT_multisampled_render_to_texture): the driver averaged the samples into
// u_resolved when the multisampled framebuffer was flushed; this copies it texel for texel onto
// the destination (ES 2.0 has no blit). Nearest filtering at the pixel centre: an exact copy.
// The coordinate comes interpolated at highp (see msaa_resolve.vert); a device without
// fragment highp interpolates it at mediump, exact up to 1 024 pixels across.
uniform sampler2D u_resolved;
VARYING HIGHP vec2 v_uv;

void main() {
    FRAG_COLOR = TEXTURE2D(u_resolved, v_uv);
}
