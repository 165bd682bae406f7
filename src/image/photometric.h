// The light fixed to the camera (a camera's own lamp and vignetting, the lamp's reflection on a
// glossy floor, the robot's shadow): a per-pixel affine photometric model of the undistorted
// image, learnt online from the frames themselves, and the correction the image pipeline
// applies with it before the pyramid. See README.md, "The photometric model".
//
// Why it can be learnt: the floor moves through the image and the light does not. Over frames
// in motion, a pixel sees many different patches of the same floor, so its temporal mean and
// variance are the floor's (the same at every pixel) passed through what is fixed to the camera
// at that pixel: with radiance gain(x) * albedo + add(x),
//     mean(x) = gain(x) * mean_albedo + add(x),   sd(x) = gain(x) * sd_albedo.
// The correction (raw - mean(x)) * sd_ref / sd(x) + mean_ref takes both out: every pixel then
// sees the floor with the same mean and contrast. Pixels with no contrast left (saturated, or
// static structure) have no value. The means and variances are smoothed over a window (the
// light is smooth; the estimate's noise is not), so a few seconds of driving suffice.
#pragma once
#include <memory>
#include <string>

#include <CL/opencl.hpp>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "image/rolling_shutter.h"
#include "image/undistort.h"

namespace planarvo {

namespace ocl {
class Runtime;
}

struct PhotometricOptions {
  // Correct each frame with the model and leave saturated pixels out. false: the pipeline as it
  // was without a model (the raw intensity, every pixel).
  bool enabled = true;
  // Learn the model from frames in motion (false: identity, or the flat field given).
  bool learn = true;
  // A raw grey level at or above this is saturated: the pixel has no value in that frame
  // (above 255: never).
  double saturation = 250.0;
  // Frames in motion accumulated before a learnt model replaces the identity when the tracker
  // sees the light hold its alignments (otherwise kPhotometricFirstFitFrames, and only a model
  // that differs from the identity by more than the statistics' noise: uniform_spread).
  int min_frames = 2;
  // The statistics' memory: the n-th frame has weight 1/n up to n = memory_frames, then
  // 1/memory_frames (an exponential moving average, so a lamp that changes is followed).
  int memory_frames = 300;
  // Half-width of the box over which the means and variances are smoothed, level-0 pixels; 0:
  // the image's width / 40 (16 at 640 pixels, 8 at 320): the light is smooth relative to the
  // image, not to its pixels (a 33-pixel box on a 320 x 240 camera marked a band twice as wide
  // around the shadow's edge and the reflection's rim, and the coarse levels emptied).
  int radius = 0;
  // No value where the smoothed contrast, or after 30 frames a pixel's own, is below
  // this fraction of the median contrast (saturated spots, deep shadow, static structure).
  double min_contrast = 0.3;
  // The identity is kept while the learnt mean level varies over the image by less than this
  // (10th to 90th percentile, relative to the median) and every pixel has a value: an evenly lit
  // camera tracks exactly as without the model. Before kPhotometricSettledFrames frames, n, the
  // statistics' own noise is allowed for: uniform_spread * sqrt(40 / n), pixels without a value
  // not counted.
  double uniform_spread = 0.06;
};

// Throws InvalidArgument naming the first bad value.
void validate(const PhotometricOptions& options);

// The model: per pixel of the undistorted image, corrected = raw * scale + offset, scale 0
// where the pixel has no value. CV_32FC1 each.
struct PhotometricFit {
  cv::Mat scale, offset;
  double mean_ref = 0, sd_ref = 0;  // the corrected image's mean and contrast (medians)
  int frames = 0;                   // frames in motion the fit is made from (0: identity)
  double unusable = 0;              // fraction of the valid pixels left without a value
  // The statistics found no light fixed to the camera beyond their own noise: the model is the
  // identity (fit_photometric), unless the caller needed one.
  bool uniform = false;
  // The model is the identity: nothing learnt yet, or nothing found (uniform, not needed).
  bool identity = false;
};

// The identity model (scale 1, offset 0) of a width x height image.
PhotometricFit identity_photometric(int width, int height);

// The fit from the statistics (plain C++; what PhotometricModel::refit runs on the host):
// per pixel, the mean and the mean square of its values (CV_32FC1) over `frames` frames in
// motion; valid (CV_8UC1, non-zero where the undistortion has a source) marks the pixels that
// have statistics. Mean and contrast over a box of the options' radius and the frames
// together; references the medians over valid pixels. From kPhotometricSettledFrames frames on,
// the level the scale divides by is the box's least-squares plane sharpened by one step of van
// Cittert's deconvolution, over the pixels with a value that do not reach `saturation`
// (README.md, "The settled level").
// `needed`: the caller has seen the light hold its alignments, so the model is used even where
// the statistics cannot yet tell the light from their own noise (PhotometricFit::uniform).
PhotometricFit fit_photometric(const cv::Mat& mean, const cv::Mat& square, const cv::Mat& valid,
                               int frames, const PhotometricOptions& options, bool needed = false);

// A known multiplicative flat field (CV_32FC1, the undistorted image's size, positive where
// valid): scale = max(gain) / gain, offset 0; pixels with gain <= min_contrast * max have no
// value.
PhotometricFit flat_field_photometric(const cv::Mat& gain, const cv::Mat& valid,
                                      const PhotometricOptions& options);

// Known and saved flat fields (README.md, "Known and saved flat fields"). A flat-field file is
// the camera's relative brightness per pixel of the distorted camera image, brightest 1 (DSO's
// vignette.png): any 8- or 16-bit grey image OpenCV reads (8-bit divided by 255, 16-bit by
// 65535, float as it is), then divided by its maximum.
//
// read_flat_field: CV_32FC1 of width x height in camera (distorted) pixels, maximum 1. Throws
// InvalidInput naming the file when it cannot be read as an image, is not width x height (both
// sizes named), or has a zero, negative or non-finite pixel (the pixel named).
cv::Mat read_flat_field(const std::string& path, int width, int height);
// The gain in the undistorted image: gain_distorted (CV_32FC1, the camera's size) sampled
// bilinearly at the map's source coordinates where the map is valid, 0 elsewhere (remap_bilinear).
cv::Mat flat_field_to_undistorted(const cv::Mat& gain_distorted, const UndistortMap& map);
// The inverse, for saving a model: per distorted camera pixel, the model's gain 1 / scale
// sampled bilinearly at the pixel's undistorted position (CameraModel::unproject, then K),
// normalised to maximum 1; 0 where the model has no value (scale 0, or the undistortion no
// source, at any of the four neighbours). CV_32FC1 of the camera's size. InvalidArgument when the
// model is not the camera's size.
cv::Mat flat_field_to_distorted(const PhotometricFit& fit, const CameraModel& camera);
// Each zero pixel of a gain image takes the value of the nearest non-zero pixel, so that a
// saved model (which has no value in a saturated spot, or where the undistorted image has no
// source) reads back as a flat field, which has no zeros. Failed when every pixel is zero.
cv::Mat fill_flat_field(const cv::Mat& gain);
// Writes a gain image (CV_32FC1, values 0..1) as a 16-bit grey PNG, value * 65535 rounded (a
// positive value at least 1), complete or not at all (core/output_file.h). Io naming the file
// when it cannot be written; InvalidArgument for another type.
void write_flat_field(const std::string& path, const cv::Mat& gain);

// Plain C++ reference of the `photometric` kernel (kernels/image/undistort.cl): raw level-0 intensity
// (kInvalidIntensity where not valid) -> corrected.
cv::Mat photometric_reference(const cv::Mat& raw, const PhotometricFit& fit, double saturation);
// Plain C++ reference of the `photometric_rolling` kernel: raw is undistort_rolling_reference's
// output for `warp`; the model is read at the pixel nearest p + the warp's light field
// (row_warp_at), clamped to the image (with the identity warp: photometric_reference).
cv::Mat photometric_rolling_reference(const cv::Mat& raw, const PhotometricFit& fit, const RowWarp& warp,
                                      double saturation);
// Plain C++ reference of the `photometric_learn` kernel: updates the mean and mean square
// (CV_32FC1) in place from raw with weight alpha, in the kernel's float arithmetic.
void photometric_learn_reference(const cv::Mat& raw, float alpha, cv::Mat* mean, cv::Mat* square);

// Frames in motion after which the statistics are settled: a pixel's own variance says whether
// it sees the floor, and a model is the identity unless the light spreads the mean level by
// uniform_spread or leaves a pixel without a value (before: by more than the statistics' noise).
inline constexpr int kPhotometricSettledFrames = 30;
// Frames in motion before the first fit: a lamp's falloff or a shadow is plain after 8 (a fit
// then is what keeps a shadow's edge from holding the first second of a drive), a faint
// vignetting only once the statistics settle.
inline constexpr int kPhotometricFirstFitFrames = 8;

// The model on the device: its two planes (scale, offset), the statistics' two planes (mean,
// variance), the count of frames accumulated and when to refit.
class PhotometricModel {
 public:
  // valid: CV_8UC1 of width x height, non-zero where the undistortion has a source.
  PhotometricModel(ocl::Runtime& runtime, const cv::Mat& valid, const PhotometricOptions& options);
  ~PhotometricModel();
  PhotometricModel(const PhotometricModel&) = delete;
  PhotometricModel& operator=(const PhotometricModel&) = delete;

  const PhotometricOptions& options() const;
  const cl::Buffer& model() const;  // 2 planes: scale, offset
  cl::Buffer& statistics();         // 2 planes: mean, mean square
  // Whether it learns (options().learn and no known model given).
  bool learning() const;
  // The weight of the next frame's statistics update, 1/(n + 1) capped at 1/memory_frames; the
  // frame is counted. 0 when not learning.
  float next_alpha();
  int frames() const;
  // A refit is due: learning, at least kPhotometricFirstFitFrames frames and a quarter more (at
  // least 4) since the last fit; or, when the model is `needed` (the caller sees the light hold
  // its alignments), at least min_frames frames and one more since the last fit.
  bool refit_due(bool needed = false) const;
  // Reads the statistics back (blocking), fits (fit_photometric) and uploads the model. A refit
  // started in the background is dropped first.
  void refit(bool needed = false);
  // A refit off the caller's thread: the statistics as learnt so far are read back (enqueued on
  // the queue now, so later learning does not enter them) and fitted on a worker thread, while
  // the caller goes on with its frames; the model in use does not change until take_refit(). A
  // refit started counts as the last fit for refit_due(). Does nothing while one is pending.
  void start_refit(bool needed = false);
  // A refit started and not yet taken.
  bool refit_pending() const;
  // Waits for the started refit (rethrowing its error) and uploads its model. False (nothing
  // changed) when none was pending. The caller decides when, by its own frame count, so that
  // tracking is the same however fast the worker thread was.
  bool take_refit();
  // Uses a known model (and stops learning); its size must be the image's.
  void set(const PhotometricFit& fit);
  // The model in use.
  const PhotometricFit& fit() const;
  // Counts the models put in use (each refit, set and reset): what was made from fit() is stale
  // when it changed.
  long revision() const;
  // Forgets the statistics (and a pending refit); back to the identity (or the known model given
  // with set()).
  void reset();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace planarvo
