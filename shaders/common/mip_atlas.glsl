// A mip chain packed into one 2D image (depth.hiz, color.pyramid; read by ssr.hiz): level 0 at the origin,
// levels 1.. side by side in a row below it. Level k is max(1, floor(size0 / 2^k)) texels, so a texel's
// footprint in the level below is 2x2, or 3 wide/high in the last column/row of an odd-sized level. One image
// rather than Vulkan mips because a node's storage bindings see a whole image, and so one descriptor serves
// every level.
#ifndef COMMON_MIP_ATLAS_GLSL
#define COMMON_MIP_ATLAS_GLSL

ivec2 mipSize(ivec2 size0, int level) { return max(size0 >> level, ivec2(1)); }

// Top-left texel of `level` in the atlas.
ivec2 mipOffset(ivec2 size0, int level) {
    if (level == 0) return ivec2(0);
    int x = 0;
    for (int j = 1; j < level; ++j) x += mipSize(size0, j).x;
    return ivec2(x, size0.y);
}

// Levels down to 1x1 of a level-0 image of size0 (mipAtlasLevels() on the C++ side).
int mipLevels(ivec2 size0) {
    int levels = 1;
    while ((max(size0.x, size0.y) >> levels) > 0) ++levels;
    return levels;
}

// Whether atlas texel p belongs to some level. The rest (right of level 0 when the row of levels is wider, right
// of the row, below the smaller levels) is padding that the reductions fill with zeros: a bilinear lookup at a
// level's edge touches it with a weight of (about) zero, and NaN garbage there would not vanish (NaN * 0 = NaN).
bool mipAtlasInLevel(ivec2 size0, ivec2 p) {
    if (p.y < size0.y) return p.x < size0.x;
    int y = p.y - size0.y, x = 0, levels = mipLevels(size0);
    for (int k = 1; k < levels; ++k) {
        ivec2 s = mipSize(size0, k);
        if (p.x < x + s.x) return p.x >= x && y < s.y;
        x += s.x;
    }
    return false;
}

// The texels [lo, hi] of level `source` that texel c of level `target` (>= source) covers.
void mipFootprint(ivec2 size0, int source, int target, ivec2 c, out ivec2 lo, out ivec2 hi) {
    lo = c;
    hi = c;
    for (int j = target; j > source; --j) {
        ivec2 below = mipSize(size0, j - 1);
        bvec2 last = equal(hi, mipSize(size0, j) - 1);
        lo = min(lo * 2, below - 1);
        hi = mix(hi * 2 + 1, below - 1, last);
    }
}

// Level-0 pixels [lo, hi) that texel c of `level` covers (the last texel of a row/column reaches the edge).
void mipCellBounds(ivec2 size0, int level, ivec2 c, out vec2 lo, out vec2 hi) {
    ivec2 last = mipSize(size0, level) - 1;
    lo = vec2(c << level);
    hi = mix(vec2((c + 1) << level), vec2(size0), equal(c, last));
}

// Bilinear fetch of `level` at uv (0..1 over the image) from a sampled atlas, clamped inside the level so
// that its neighbours in the atlas never bleed in.
vec4 mipSampleLevel(sampler2D atlas, ivec2 size0, int level, vec2 uv) {
    vec2 size = vec2(mipSize(size0, level));
    vec2 texel = clamp(uv * size, vec2(0.5), size - 0.5) + vec2(mipOffset(size0, level));
    return textureLod(atlas, texel / vec2(textureSize(atlas, 0)), 0.0);
}

// Trilinear: between the two levels around lod (clamped to [0, levels - 1]).
vec4 mipSample(sampler2D atlas, ivec2 size0, int levels, vec2 uv, float lod) {
    // A NaN uv or lod (a degenerate ray) reads nothing: clamp() of NaN is undefined, and the level and texel it
    // gives can lie outside every level, in the atlas's unwritten corner (whatever memory the transient heap left
    // there: the images then differ from run to run).
    if (any(isnan(uv)) || isnan(lod)) return vec4(0.0);
    lod = clamp(lod, 0.0, float(levels - 1));
    int l0 = int(floor(lod));
    int l1 = min(l0 + 1, levels - 1);
    return mix(mipSampleLevel(atlas, size0, l0, uv), mipSampleLevel(atlas, size0, l1, uv), lod - float(l0));
}

#endif
