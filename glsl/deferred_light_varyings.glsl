// Deferred's light pass: the light of the instance being drawn, passed unchanged from the
// proxy's vertices to its fragments (packed by src/methods/deferred/light_instances.rs).
// x y z: view-space position, w: radius.
flat VARYING HIGHP vec4 v_light0;
// rgb: radiance (pre-exposed), a: spot scale.
flat VARYING vec4 v_light1;
#if HAS_SPOT
// xyz: spot axis, w: spot offset.
flat VARYING vec4 v_light2;
#endif
// x: the proxy sphere's radius, y: the count channel this light adds 1 to (0 to 3), z: the
// full-screen triangle's normalized device depth.
flat VARYING vec4 v_proxy;
