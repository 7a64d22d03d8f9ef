// Depth prepass: only the depth buffer matters (colour writes are masked off).
void main() {
    FRAG_COLOR = vec4(0.0);
}
