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
    v_normal = u_normalMatrix * a_normal;
    v_uv = a_uv;
    gl_Position = u_projection * viewPos;
}
