// The pixels of a reference level that the tracker aligns when it subsamples the level: one per
// B x B block (B = `block`; the last row and column of blocks may be cut by the level's border),
// at an offset within the block that a hash of the block's position chooses (a jittered grid:
// every pixel equally likely, no lattice for a periodic texture to alias with, the same offsets
// for every keyframe). Stratified, not chosen by gradient: a pixel picked for its large gradient
// is a peak that bilinear sampling of the live frame flattens, so it biases the residuals, their
// robust scale and the texture test, and on textures near the pixel grid's resolution (a high
// camera over fine asphalt) it tracked worse than every pixel of the half-resolution level
// (src/track/README.md, "Full resolution from subsampled pixels").
//
// Output: a grid of ceil(w / B) x ceil(h / B) float4, entry (bx, by) = (I, dI/du, dI/dv, code)
// of the block's pixel, code = 1 + ox + 256 oy for the pixel (bx B + ox, by B + oy) (decoded with
// a mask and a shift: an integer division per pixel costs the fused pass a scalar division per
// lane on CPUs, whose vector units have none), or all zero
// when that pixel is invalid or outside the level. This is the reference of warp_reduce.cl built
// with SELECT = 1 and select_block = B. One work-item per block; global size (grid_w, grid_h) rounded up to the
// work-group size. The plain C++ reference is select_pixels_reference() in
// src/track/pixel_selection.cpp, with the same hash (select_offset).

// The block's offset: a 32-bit integer hash of (bx, by) (multiply, xor-shift), its low 16 bits
// scaled to the column 0..B-1 and its high 16 bits to the row, (bits * B) >> 16: no integer
// division, which CPUs' vector units lack (three per block cost a keyframe about 1 ms on PoCL).
inline uint sp_hash(uint bx, uint by) {
  uint h = bx * 0x9E3779B1u ^ (by + 0x7F4A7C15u) * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return h;
}

__kernel void select_pixels(__global const float4* level, const int width, const int height,
                            const int block, __global float4* grid, const int grid_w,
                            const int grid_h) {
  const int bx = (int)get_global_id(0);
  const int by = (int)get_global_id(1);
  if (bx >= grid_w || by >= grid_h) return;
  const uint h = sp_hash((uint)bx, (uint)by);
  const int ox = (int)(((h & 0xFFFFu) * (uint)block) >> 16), oy = (int)(((h >> 16) * (uint)block) >> 16);
  const int x = bx * block + ox, y = by * block + oy;
  float4 out = (float4)(0.0f, 0.0f, 0.0f, 0.0f);
  if (x < width && y < height) {
    const float4 p = level[y * width + x];
    if (p.w != 0.0f) out = (float4)(p.x, p.y, p.z, (float)(1 + ox + 256 * oy));
  }
  grid[by * grid_w + bx] = out;
}
