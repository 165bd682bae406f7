// The light's level from the photometric model's statistics (photometric.h), where a box's mean
// is not good enough: README.md, "The settled level".
//
// A box's mean of the per-pixel means is off where the light is not flat: by half the box's
// variance times the level's Laplacian inside the image, by the light's slope times the valid
// pixels' offset from the box's centre along the image's border and beside holes. Such an error
// is a pattern fixed to the camera, scaled by the floor's mean level, that a faint floor's
// alignments feel (band_pass.h).
#pragma once
#include <opencv2/core.hpp>

namespace planarvo {

// The level over a box of half-width r as a plane fitted by least squares to the supported
// pixels in it (support: CV_8UC1, non-zero where a pixel takes part), evaluated at the box's
// centre: inside the image the box's mean, at the border and beside holes unbiased for a slope.
// Where the supported pixels do not span a plane (less than a tenth of the box's extent each
// way) their mean. m: CV_32FC1. Returns CV_32FC1, 0 where the box holds no supported pixel.
cv::Mat local_plane_level(const cv::Mat& m, const cv::Mat& support, int r);

// The settled level: local_plane_level P sharpened by one step of van Cittert's deconvolution,
// 2 P m - P (P m). Inside the image that is 2 B - B^2 of the box B: its response 2 H - H^2 is
// flat to fourth order at zero frequency and never above 1, so the box's second-order bias goes
// and the statistics' noise is passed at most as it is. Where the step would halve the level
// (never on a smooth light) P m is kept; 0 where P m is 0.
cv::Mat settled_light_level(const cv::Mat& m, const cv::Mat& support, int r);

}  // namespace planarvo
