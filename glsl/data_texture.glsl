// Reading data textures (layouts: src/cluster/pack.rs, src/cluster/pack_grid.rs).
// DATA_WIDTH is a power of two, so row/column arithmetic on texel numbers is exact.

// An RGBA8 channel (0..1) back to its byte.
HIGHP float byteOf(HIGHP float channel) {
    return floor(channel * 255.0 + 0.5);
}

// Two RGBA8 channels (high byte first) → 0..65535.
HIGHP float u16Of(HIGHP vec2 channels) {
    return byteOf(channels.x) * 256.0 + byteOf(channels.y);
}

#if GLSL_ES == 100
// ES 2.0: the texel at column `col`, row `row`, read at its centre. `invHeight` is 1 / the
// texture's allocated rows (a power of two, like DATA_WIDTH, so the coordinates are exact).
HIGHP vec4 dataTexelAt(HIGHP sampler2D tex, HIGHP float col, HIGHP float row, HIGHP float invHeight) {
    return texture2D(tex, vec2((col + 0.5) / float(DATA_WIDTH), (row + 0.5) * invHeight));
}

// ES 2.0: texel number → its texel.
HIGHP vec4 dataTexel(HIGHP sampler2D tex, HIGHP float index, HIGHP float invHeight) {
    HIGHP float row = floor(index / float(DATA_WIDTH));
    return dataTexelAt(tex, index - row * float(DATA_WIDTH), row, invHeight);
}
#else
ivec2 dataCoord(int index) {
    return ivec2(index & (DATA_WIDTH - 1), index / DATA_WIDTH);
}
#endif
