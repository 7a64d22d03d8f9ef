// Does this context evaluate mediump as fp16? 2048 + 1 is exact in fp32 but rounds back to
// 2048 in fp16 (11-bit significand). u_big is 2048.0 and u_one is 1.0, uniforms so nothing
// folds at compile time. The sum is read through fract() rather than by subtracting u_big
// again: compilers may reassociate (a + b) - a into b (Mesa does), which would hide fp16.
// Writes 1.0 in red when the sum survives (fp32), 0.0 when it does not (fp16).
uniform mediump float u_big;
uniform mediump float u_one;

void main() {
    mediump float sum = u_big + u_one;
    mediump float half_sum = sum * 0.5;
    FRAG_COLOR = vec4(clamp(fract(half_sum) * 2.0, 0.0, 1.0), 0.0, 0.0, 1.0);
}
