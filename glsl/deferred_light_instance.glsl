// Deferred's light pass, vertex side: one instance a light, its values read at attribute
// locations 6 to 9 (LIGHT_LOCATION in src/methods/deferred/light_instances.rs), in the same
// layout as the varyings they are passed on as; the spot terms last, a variant without spots
// reads (and its instances hold) none.
#include "deferred_light_varyings.glsl"

layout(location = 6) in HIGHP vec4 a_light0;
layout(location = 7) in vec4 a_light1;
layout(location = 8) in vec4 a_proxy;
#if HAS_SPOT
layout(location = 9) in vec4 a_light2;
#endif

void passLight() {
    v_light0 = a_light0;
    v_light1 = a_light1;
    v_proxy = a_proxy;
#if HAS_SPOT
    v_light2 = a_light2;
#endif
}
