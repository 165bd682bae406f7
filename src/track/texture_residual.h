// The honest-status check's measure (src/track/README.md, "Honest status under the camera's own
// light"): how much of the two images' texture the residual at an alignment still holds.
//
// Immerkaer's noise operator N = [1 -2 1; -2 4 -2; 1 -2 1] (Immerkaer, "Fast noise variance
// estimation", CVIU 1996) is blind to what is smooth (a lamp's falloff, a brightness offset) and
// answers to texture and noise. With r = g I_l(w) + b - I_r the residual image of an alignment
// (residual_image.h):
//
//   texture_residual = mean |N*r| / (sqrt(2) mean |N*I_r|)
//
// over the pixels whose 3 x 3 neighbourhood is valid. Texture that the alignment matched cancels
// in r, so an aligned pair leaves only the two frames' noise and the interpolation's error
// (0.36-0.6 at 160 x 120 pixels on the simulator); two unrelated images of like texture give
// about 1 (their N responses add in quadrature). A pattern fixed to the camera that holds an
// alignment while the floor moves cancels in r, but the floor's texture does not: 0.85-1.1
// measured on such frames. The keyframe alone scales it (the warped live frame's N response is
// lowered by the bilinear interpolation, by how much depends on the shift's fraction); a brightness
// fit that drove the live frame out (r = b - I_r) gives 0.71, and is Lost for its gain anyway.
// The images' noise counts less at a coarse level (the tracker measures at a level of about
// 160 x 120 pixels; TrackerOptions::max_texture_residual).
#pragma once
#include "track/residual_image.h"

namespace planarvo::track {

// The pyramid level to measure it on for an image `width` pixels wide with `levels` levels: the
// finest of about 160 x 120 pixels (at most 200 wide), where the images' noise counts little
// against the floor's texture; the coarsest there is, when none is that small.
int texture_residual_level(int width, int levels);

// The measure above; NaN when fewer than 16 pixels have a valid 3 x 3 neighbourhood or the images
// have no texture at all.
double texture_residual(const ResidualImage& image);
// The measure from its sums: sum |N*r|, sum |N*I_r| and the count of pixels (NaN as above); the
// device's reduction (ResidualImager::texture_residual, residual_image.h) ends with it.
double texture_residual_ratio(double sum_nr, double sum_ni, double count);

}  // namespace planarvo::track
