// A band-pass of a pyramid: each level less its own Gaussian-weighted local mean, for alignments
// that a smooth brightness pattern fixed to the camera must not pull.
//
// Why. What the photometric model (photometric.h) leaves of the camera's light is a smooth
// relative error e(p) fixed to the camera. Aligning two views of a floor of mean level m and
// texture t, the error enters the Gauss-Newton step through sum J r with J ~ grad I, r ~
// I (e(w(p)) - e(p)); since I grad I = grad(I^2) / 2, integrating by parts leaves a bias of the
// motion of about m^2 sum e'' / sum |grad t|^2: the floor's mean level squared against its
// texture's gradient energy. On a faint floor under a strong lamp that pulled the joint
// alignment's roll by up to 1.5 degrees (anti_skid_tiles, 20-s drives at 640 x 480, a lamp of
// 0.8, a reflection and a shadow; src/calib/README.md). Taking out the local mean takes m out of
// that product: the texture keeps its gradients and the light's error keeps only its own
// contrast.
//
// Per level l, sigma_l = max(1.5, sigma0 / 2^l) level pixels: each level keeps the detail of its
// own resolution (the coarse levels still converge from afar). The mean is a normalised
// convolution over the valid pixels only; a pixel stays valid where it was and where its four
// gradient neighbours are valid; intensity = I - mean + 128, gradients central differences of
// it, as the pipeline's (pyramid.h).
//
// On the host (the levels are read back and written again): it runs once per joint alignment
// of a few keyframes (track/roll_pitch.h), not per frame.
#pragma once
#include <opencv2/core.hpp>

#include "image/pyramid.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo {

// sigma_l for level l (level pixels).
double band_pass_sigma(double sigma0, int level);

// One level, plain C++: `level` is CV_32FC4 laid out as pyramid.h's (I, dI/du, dI/dv, valid);
// returns the band-passed level with sigma (level pixels, > 0), in the same layout.
cv::Mat band_pass_level(const cv::Mat& level, double sigma);

// Every level of a device pyramid, in place (blocking).
void band_pass(ocl::Runtime& runtime, Pyramid& pyramid, double sigma0);

}  // namespace planarvo
