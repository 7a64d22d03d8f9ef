// Does this context evaluate mediump as fp16? 2048 + 1 is exact in fp32 but rounds back to
// 2048 in fp16 (11-bit significand). Writes 1.0 in red when the sum survives (fp32), 0.0 when
// it does not (fp16). u_big is 2048.0 and u_one is 1.0, uniforms so nothing folds at compile time.
uniform mediump float u_big;
uniform mediump float u_one;

void main() {
    mediump float sum = u_big + u_one;
    mediump float survived = sum - u_big;
    FRAG_COLOR = vec4(clamp(survived, 0.0, 1.0), 0.0, 0.0, 1.0);
}
