// The image noise's share in a level's gradient, taken out where the noise is not the same over
// the image (a camera's own light, corrected by the photometric model).
//
// Why. The pyramid's levels are smoothed (the prefilter, the downsampling), so a level's noise at
// a pixel is correlated with its central-difference gradient there: with raw noise of variance
// sigma^2(k) at level-0 pixel k, E[n(q) dn/du(q)] = c_l d sigma^2/du (first order), c_l a
// constant of the level's filter chain (gradient_noise_coefficient: 1/3 at level 0 with the
// prefilter, 0.58 at level 1; 0 for an unsmoothed level 0). Evenly lit, sigma^2 is the same
// everywhere and the correlation is 0. Corrected by the photometric model, the noise is the
// raw noise times the model's scale, so a lamp's dim corners, a shadow and a reflection's flank
// carry a camera-fixed noise variance that varies over the image. ESM's gradient,
// g = (grad I_r + grad I_l Dw) / 2, and the residual r = I_l(w(p)) - I_r(p) then have
//     E[g r] = (grad sigma^2(w(p)) Dw - grad sigma^2(p)) c_l / 2,
// a difference of the same camera-fixed field at the floor point's two image positions: the
// alignment is pulled towards zero image motion by an amount that grows with the motion and with
// the noise's share of the gradients (the texture's, a faint floor's, blurred along the motion by
// the exposure). Measured on anti_skid_tiles, configuration 1, lamp + reflection + shadow,
// 25 ms readout, 4 ms exposure: velocity slope 0.9973 with 1 grey level of noise, 1.0003 with
// none; a forward motion turned the heading by 0.011 rad per metre.
//
// What. The part of the gradient's noise that the intensity's noise predicts is removed: per
// level pixel, grad' = grad - beta (I - mean), beta = E[n grad n] / E[n^2] = c_l grad log
// sigma^2 (in level-0 pixels). The noise's level cancels in beta: only its shape over the image
// is needed, taken as the model's scale squared (a read-noise-limited camera, as under a chassis;
// a shot-noise-limited one has the scale's first power, which this corrects by half). The
// texture's own term, beta (T - mean), is about 1 % of its gradient under a strong lamp and
// changes only the Jacobian, not where the alignment converges.
#pragma once
#include <vector>

#include <opencv2/core.hpp>

namespace planarvo {

// c_l for pyramid level `level` (0 ..): E[n grad_u n] per unit of d sigma^2/du (level-0 pixels)
// over E[n^2] per unit sigma^2, for the pipeline's filter chain (the 3-tap binomial prefilter
// when `prefilter`, then the [1 5 10 10 5 1] / 32 downsampling per level) and central
// differences in level pixels. Computed from the chain's kernel, exactly.
double gradient_noise_coefficient(int level, bool prefilter);

// beta per pyramid level (CV_32FC2 of the level's size, level_size of width and height), from
// the noise variance's shape over level 0 (CV_32FC1, > 0 where known; 0 where not, which takes
// its nearest known value). InvalidArgument for another type or no positive pixel.
std::vector<cv::Mat> gradient_noise_beta(const cv::Mat& variance_shape, int levels, bool prefilter);

// The noise variance's shape of a photometric model's corrected image: scale^2 (scale CV_32FC1,
// 0 where the model has no value).
cv::Mat corrected_noise_shape(const cv::Mat& scale);

// Plain C++ reference of the `gradient_decorrelated` kernel (kernels/image/pyramid.cl): as
// gradient_reference (pipeline.h), the gradients less beta (I - mean) where valid.
cv::Mat decorrelated_gradient_reference(const cv::Mat& level, const cv::Mat& beta, float mean);

}  // namespace planarvo
