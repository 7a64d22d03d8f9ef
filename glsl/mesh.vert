// Shared vertex stage of every geometry pass: view-space position and normal.
// u_modelView is computed on the CPU in f64 with the camera subtracted, so objects far from
// the origin keep full precision here.
ATTRIBUTE vec3 a_position;
ATTRIBUTE vec3 a_normal;
ATTRIBUTE vec2 a_uv;

uniform mat4 u_modelView;
uniform mat3 u_normalMatrix;
uniform mat4 u_projection;

VARYING vec3 v_viewPos;
// The depth prepass and the shading pass are different programs: `invariant` guarantees they
// compute bit-identical depths, so the shading pass's LEQUAL test passes exactly once.
invariant gl_Position;

VARYING vec3 v_normal;
VARYING vec2 v_uv;

void main() {
    vec4 viewPos = u_modelView * vec4(a_position, 1.0);
    v_viewPos = viewPos.xyz;
    // Unit length here, in the vertex stage's highp, divided by its largest component first:
    // a normal the normal matrix squashes (an object scaled 10⁹ along its normal, or to 10⁻⁹
    // across it) is 10⁻⁹ long, which a mediump varying (fp16) flushes to zero.
    vec3 n = u_normalMatrix * a_normal;
    float largest = max(max(abs(n.x), abs(n.y)), abs(n.z));
    v_normal = largest > 0.0 ? normalize(n / largest) : vec3(0.0);
    v_uv = a_uv;
    gl_Position = u_projection * viewPos;
}
