// One colour over the whole target: the clear of an sRGB multisampled target, drawn because
// SwiftShader 4.0's glClear fills only one sample of one (docs/drivers.md).
uniform vec4 u_color;

void main() {
    FRAG_COLOR = u_color;
}
