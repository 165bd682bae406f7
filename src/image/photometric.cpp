// The photometric model (photometric.h): the fit from per-pixel statistics, the known and saved
// flat fields, and the plain C++ references of the correction and learning kernels. The model on
// the device (PhotometricModel) is photometric_model.cpp's.
#include "image/photometric.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/output_file.h"
#include "image/light_level.h"
#include "image/pipeline.h"

namespace planarvo {

namespace {

// Frames in motion after which a pixel's own variance over time says whether it sees the floor.
constexpr int kOwnVarianceFrames = kPhotometricSettledFrames;
// A box whose spread relative to its level exceeds this many times the median pixel's holds an
// edge of the light.
constexpr double kMaxRelativeSpread = 2.0;

// The q-quantiles (0..1) of m's values where mask is non-zero (0 when none), in qs' order.
// The maps it is used on are box-smoothed, so on large images every 4th row and column says the
// same (a sixteenth of the work of a refit's sorting).
std::vector<double> masked_quantiles(const cv::Mat& m, const cv::Mat& mask, std::initializer_list<double> qs) {
  const int step = m.total() > 100000 ? 4 : 1;
  std::vector<float> v;
  v.reserve(m.total() / static_cast<size_t>(step * step) + 1);
  for (int r = 0; r < m.rows; r += step) {
    const float* a = m.ptr<float>(r);
    const uint8_t* k = mask.ptr<uint8_t>(r);
    for (int c = 0; c < m.cols; c += step)
      if (k[c]) v.push_back(a[c]);
  }
  if (v.empty()) return std::vector<double>(qs.size(), 0.0);
  std::vector<double> out;
  for (const double q : qs) {
    auto at = v.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), at, v.end());
    out.push_back(*at);
  }
  return out;
}

// The count of valid pixels (valid01: 1 or 0) in each pixel's (2r + 1)^2 box (edges: the box
// clipped): masked_box's denominator, the same for every image boxed with one radius.
cv::Mat box_count(const cv::Mat& valid01, int r) {
  cv::Mat den;
  cv::boxFilter(valid01, den, CV_32F, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  return den;
}

// The mean of m over the valid pixels in a (2r + 1)^2 box (edges: the box clipped), 0 where
// the box holds none. den: box_count(valid01, r).
cv::Mat masked_box(const cv::Mat& m, const cv::Mat& valid01, const cv::Mat& den, int r) {
  cv::Mat num;
  const cv::Size k(2 * r + 1, 2 * r + 1);
  cv::boxFilter(m.mul(valid01), num, CV_32F, k, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::Mat out(m.size(), CV_32FC1);
  for (int y = 0; y < m.rows; ++y) {
    const float* n = num.ptr<float>(y);
    const float* d = den.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < m.cols; ++x) o[x] = d[x] > 0.5f ? n[x] / d[x] : 0.0f;
  }
  return out;
}

}  // namespace

void validate(const PhotometricOptions& o) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw_invalid_argument(std::string("photometric options: ") + what);
  };
  require(std::isfinite(o.saturation) && o.saturation > 0, "saturation must be a positive grey level");
  require(o.min_frames >= 1, "min_frames must be >= 1");
  require(o.memory_frames >= o.min_frames, "memory_frames must be >= min_frames");
  require(o.radius >= 0 && o.radius <= 256, "radius must be 0..256 pixels (0: the image's width / 40)");
  require(std::isfinite(o.min_contrast) && o.min_contrast >= 0 && o.min_contrast < 1,
          "min_contrast must be in [0, 1)");
}

PhotometricFit identity_photometric(int width, int height) {
  PhotometricFit f;
  f.scale = cv::Mat(height, width, CV_32FC1, cv::Scalar(1.0f));
  f.offset = cv::Mat(height, width, CV_32FC1, cv::Scalar(0.0f));
  f.identity = true;
  return f;
}

namespace {

// The floor's contrast as the pixel sees it: the spread of the values over the box and the frames
// together (the texture within the box varies from the first frame on), relative to the level.
cv::Mat relative_spread(const cv::Mat& m, const cv::Mat& q) {
  cv::Mat rel(m.size(), CV_32FC1);
  for (int y = 0; y < m.rows; ++y) {
    const float *mm = m.ptr<float>(y), *qq = q.ptr<float>(y);
    float* rr = rel.ptr<float>(y);
    for (int x = 0; x < m.cols; ++x) rr[x] = mm[x] > 0 ? std::sqrt(std::max(qq[x] - mm[x] * mm[x], 0.0f)) / mm[x] : 0.0f;
  }
  return rel;
}

// The pixels with no value (each test on smoothed statistics, so that it marks regions: the
// pyramid leaves out every coarse pixel that has one fine pixel without a value, so scattered
// holes would empty the coarse levels):
// - faint: the floor's texture shows too faintly against what the light adds (saturated spots,
//   a reflection's core, static structure), relative to the median pixel;
// - an edge of the light: the box's spread relative to its level far above the median's (a
//   shadow's edge, a reflection's rim), which a smooth model cannot follow.
// Specks smaller than 5 x 5 pixels are noise of the tests, not light. own_sd: empty, or the
// pixel's own spread over the frames.
cv::Mat unusable_pixels(const cv::Mat& valid, const cv::Mat& m, const cv::Mat& rel, const cv::Mat& own_sd,
                        double rel_ref, const PhotometricOptions& o) {
  const bool own = !own_sd.empty();
  cv::Mat bad(m.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < m.rows; ++y) {
    const uint8_t* k = valid.ptr<uint8_t>(y);
    const float* mm = m.ptr<float>(y);
    const float* rr = rel.ptr<float>(y);
    uint8_t* b = bad.ptr<uint8_t>(y);
    for (int x = 0; x < m.cols; ++x) {
      if (!k[x]) continue;
      const bool faint = rr[x] < o.min_contrast * rel_ref ||
                         (own && mm[x] > 0 && own_sd.at<float>(y, x) / mm[x] < o.min_contrast * rel_ref);
      const bool edge = rr[x] > kMaxRelativeSpread * rel_ref;
      b[x] = !(mm[x] > 0) || faint || edge ? 255 : 0;
    }
  }
  cv::morphologyEx(bad, bad, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
  return bad;
}

// The fraction of the valid pixels that have no value.
double unusable_fraction(const cv::Mat& valid, const cv::Mat& bad, const cv::Mat& m) {
  long n_valid = 0, n_unusable = 0;
  for (int y = 0; y < m.rows; ++y) {
    const uint8_t* k = valid.ptr<uint8_t>(y);
    const uint8_t* b = bad.ptr<uint8_t>(y);
    const float* mm = m.ptr<float>(y);
    for (int x = 0; x < m.cols; ++x) {
      if (!k[x]) continue;
      ++n_valid;
      if (b[x] || !(mm[x] > 0)) ++n_unusable;
    }
  }
  return n_valid > 0 ? static_cast<double>(n_unusable) / static_cast<double>(n_valid) : 0.0;
}

// The settled light level (light_level.h): fitted to the pixels that do not reach the camera's
// white level (a mean within 2.5 of its own standard deviations of it), since a saturated spot's
// clipped mean would pull its surroundings' level down (by 1-3 % over 40 pixels around the
// reflection's core), and to the pixels that have a value: a plane across a shadow's edge,
// sharpened, rings 3-8 % beside the edge's band.
cv::Mat settled_level(const cv::Mat& mean, const cv::Mat& own_var, const cv::Mat& valid, const cv::Mat& bad,
                      int radius, const PhotometricOptions& o) {
  cv::Mat support(mean.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < mean.rows; ++y) {
    const uint8_t *k = valid.ptr<uint8_t>(y), *b = bad.ptr<uint8_t>(y);
    const float *mm = mean.ptr<float>(y), *v = own_var.ptr<float>(y);
    uint8_t* s = support.ptr<uint8_t>(y);
    for (int x = 0; x < mean.cols; ++x)
      s[x] = k[x] && !b[x] && mm[x] > 0 && mm[x] + 2.5f * std::sqrt(v[x]) < o.saturation;
  }
  return settled_light_level(mean, support, radius);
}

}  // namespace

PhotometricFit fit_photometric(const cv::Mat& mean, const cv::Mat& square, const cv::Mat& valid,
                               int frames, const PhotometricOptions& o, bool needed) {
  if (mean.type() != CV_32FC1 || square.type() != CV_32FC1 || valid.type() != CV_8UC1 ||
      mean.size() != square.size() || mean.size() != valid.size())
    throw_invalid_argument("fit_photometric: mean, square (CV_32FC1) and valid (CV_8UC1) of one size");
  cv::Mat valid01;
  valid.convertTo(valid01, CV_32F);
  cv::threshold(valid01, valid01, 0.5, 1.0, cv::THRESH_BINARY);
  // The light: the pixel's mean over the frames, smoothed over a box (the light is smooth; the
  // floor's own large patches, which the frames have not yet averaged out, are not).
  // Multiplicative: its gain is the mean's ratio to the reference. (The floor's contrast is not
  // used for the gain: on a tilted camera it changes over the image with the ground's scale in
  // it, which no correction should undo.)
  const int radius = o.radius > 0 ? o.radius : std::max(1, (mean.cols + 20) / 40);
  const cv::Mat den = box_count(valid01, radius);
  const cv::Mat m = masked_box(mean, valid01, den, radius);
  const cv::Mat rel = relative_spread(m, masked_box(square, valid01, den, radius));
  const std::vector<double> m_quantiles = masked_quantiles(m, valid, {0.5, 0.1, 0.9});
  const double mean_ref = m_quantiles[0];
  const double rel_ref = masked_quantiles(rel, valid, {0.5})[0];
  // The pixel's own spread over the frames (once they are enough to say, and for the settled level).
  const bool settled = frames >= kPhotometricSettledFrames;
  cv::Mat own_var;
  if (settled || frames >= kOwnVarianceFrames) own_var = cv::max(square - mean.mul(mean), 0.0f);
  PhotometricFit f;
  f.frames = frames;
  f.mean_ref = mean_ref;
  f.sd_ref = rel_ref * mean_ref;
  f.scale = cv::Mat(mean.size(), CV_32FC1, cv::Scalar(0.0f));
  f.offset = cv::Mat(mean.size(), CV_32FC1, cv::Scalar(0.0f));
  // A pixel's own spread over the frames says "static" only once it has seen enough frames;
  // smoothed over 5 x 5 pixels, so that it marks regions, not single noisy pixels.
  const bool own = frames >= kOwnVarianceFrames;
  cv::Mat own_sd;
  if (own) cv::sqrt(masked_box(own_var, valid01, box_count(valid01, 2), 2), own_sd);
  const cv::Mat bad = unusable_pixels(valid, m, rel, own_sd, rel_ref, o);
  f.unusable = unusable_fraction(valid, bad, m);
  // Nothing fixed to the camera that the statistics can tell from their own noise: the mean
  // level varies over the image by less than uniform_spread (10th to 90th percentile, relative
  // to the median), and no pixel lacks a value. The correction would only add its own noise (a
  // faint pattern fixed to the camera); the identity is used.
  // Before kPhotometricSettledFrames frames the statistics' own noise spreads the mean level by
  // about 0.26 / sqrt(frames) (brick_floor's large bricks, the noisiest floor measured: 0.084 at
  // 10 frames, 0.032 at 29) and leaves up to 3 % of the pixels without a value (anti_skid_tiles
  // at 10-15 frames): the spread allowed grows as sqrt(40 / frames), and the pixels without a
  // value do not count. A lamp's falloff or a shadow spreads it by 0.3-0.7.
  const double m_spread = m_quantiles[2] - m_quantiles[1];
  const double allowed = o.uniform_spread * (settled ? 1.0 : std::sqrt(40.0 / std::max(frames, 1)));
  f.uniform = m_spread < allowed * mean_ref && (!settled || f.unusable < 0.005);
  if (f.uniform && !needed) {
    f.scale.setTo(1.0f, valid);
    f.offset.setTo(0.0f);
    f.identity = true;
    return f;
  }
  // Once settled: the young statistics' noise, not the box's bias, is their error (sharpened at
  // 8-10 frames, anti_skid_tiles' first model put two frames' brightness 2x off).
  const cv::Mat level = frames >= kPhotometricSettledFrames ? settled_level(mean, own_var, valid, bad, radius, o) : m;
  for (int y = 0; y < mean.rows; ++y) {
    const uint8_t* k = valid.ptr<uint8_t>(y);
    const uint8_t* b = bad.ptr<uint8_t>(y);
    const float* mm = level.ptr<float>(y);
    float* sc = f.scale.ptr<float>(y);
    for (int x = 0; x < mean.cols; ++x)
      if (k[x] && !b[x] && mm[x] > 0) sc[x] = static_cast<float>(mean_ref / mm[x]);
  }
  return f;
}

PhotometricFit flat_field_photometric(const cv::Mat& gain, const cv::Mat& valid,
                                      const PhotometricOptions& o) {
  if (gain.type() != CV_32FC1 || valid.type() != CV_8UC1 || gain.size() != valid.size())
    throw_invalid_argument("flat_field_photometric: gain (CV_32FC1) and valid (CV_8UC1) of one size");
  double top = 0.0;
  cv::minMaxLoc(gain, nullptr, &top, nullptr, nullptr, valid);
  PhotometricFit f = identity_photometric(gain.cols, gain.rows);
  f.offset.setTo(0.0f);
  f.frames = 0;
  // A known flat field is a model like a learnt one (its light moves with a rolling shutter's
  // rows; its noise varies over the image), even where it is flat.
  f.identity = false;
  long n_valid = 0, n_unusable = 0;
  for (int y = 0; y < gain.rows; ++y) {
    const float* g = gain.ptr<float>(y);
    const uint8_t* k = valid.ptr<uint8_t>(y);
    float* sc = f.scale.ptr<float>(y);
    for (int x = 0; x < gain.cols; ++x) {
      if (!k[x]) continue;
      ++n_valid;
      if (top > 0 && g[x] > o.min_contrast * top) {
        sc[x] = static_cast<float>(top / g[x]);
      } else {
        sc[x] = 0.0f;
        ++n_unusable;
      }
    }
  }
  f.unusable = n_valid > 0 ? static_cast<double>(n_unusable) / static_cast<double>(n_valid) : 0.0;
  return f;
}

cv::Mat read_flat_field(const std::string& path, int width, int height) {
  const cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
  if (img.empty()) throw_invalid_input("flat field " + path + ": cannot be read as an image");
  if (img.cols != width || img.rows != height)
    throw_invalid_input("flat field " + path + ": the image is " + std::to_string(img.cols) + "x" +
                        std::to_string(img.rows) + ", the camera " + std::to_string(width) + "x" +
                        std::to_string(height));
  double unit = 1.0;
  switch (img.depth()) {
    case CV_8U: unit = 255.0; break;
    case CV_16U: unit = 65535.0; break;
    case CV_32F:
    case CV_64F: unit = 1.0; break;
    default:
      throw_invalid_input("flat field " + path + ": not an 8-bit, 16-bit or float grey image");
  }
  cv::Mat gain;
  img.convertTo(gain, CV_32F, 1.0 / unit);
  for (int y = 0; y < gain.rows; ++y) {
    const float* g = gain.ptr<float>(y);
    for (int x = 0; x < gain.cols; ++x)
      if (!(std::isfinite(g[x]) && g[x] > 0.0f))
        throw_invalid_input("flat field " + path + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") is " + (std::isfinite(g[x]) ? std::to_string(g[x]) : std::string("not finite")) +
                            "; a flat field is positive everywhere");
  }
  double top = 0.0;
  cv::minMaxLoc(gain, nullptr, &top);
  return gain / top;
}

cv::Mat flat_field_to_undistorted(const cv::Mat& gain_distorted, const UndistortMap& map) {
  if (gain_distorted.type() != CV_32FC1)
    throw_invalid_argument("flat_field_to_undistorted: the gain must be CV_32FC1");
  return remap_bilinear(gain_distorted, map);
}

cv::Mat flat_field_to_distorted(const PhotometricFit& fit, const CameraModel& camera) {
  const UndistortMap map = compute_undistort_map(camera);
  if (fit.scale.type() != CV_32FC1 || fit.scale.cols != camera.width || fit.scale.rows != camera.height)
    throw_invalid_argument("flat_field_to_distorted: the model must be CV_32FC1 of the camera's " +
                           std::to_string(camera.width) + "x" + std::to_string(camera.height));
  const int w = camera.width, h = camera.height;
  // The gain per undistorted pixel, 0 where it has no value.
  cv::Mat g(h, w, CV_32FC1, cv::Scalar(0.0f));
  for (int y = 0; y < h; ++y) {
    const float* sc = fit.scale.ptr<float>(y);
    float* o = g.ptr<float>(y);
    for (int x = 0; x < w; ++x)
      if (map.valid[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)] && sc[x] > 0.0f)
        o[x] = 1.0f / sc[x];
  }
  cv::Mat out(h, w, CV_32FC1, cv::Scalar(0.0f));
  double top = 0.0;
  for (int v = 0; v < h; ++v) {
    float* o = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d n = camera.unproject(Eigen::Vector2d(u, v));
      const double px = camera.fx * n.x() + camera.cx, py = camera.fy * n.y() + camera.cy;
      if (!(px >= 0 && py >= 0 && px <= w - 1 && py <= h - 1)) continue;
      const int x0 = std::min(static_cast<int>(px), w - 2), y0 = std::min(static_cast<int>(py), h - 2);
      const double ax = px - x0, ay = py - y0;
      const float a = g.at<float>(y0, x0), b = g.at<float>(y0, x0 + 1);
      const float c = g.at<float>(y0 + 1, x0), d = g.at<float>(y0 + 1, x0 + 1);
      if (!(a > 0 && b > 0 && c > 0 && d > 0)) continue;
      const double s = (1 - ay) * ((1 - ax) * a + ax * b) + ay * ((1 - ax) * c + ax * d);
      o[u] = static_cast<float>(s);
      top = std::max(top, s);
    }
  }
  if (top > 0) out /= top;
  return out;
}

cv::Mat fill_flat_field(const cv::Mat& gain) {
  if (gain.type() != CV_32FC1) throw_invalid_argument("fill_flat_field: the gain must be CV_32FC1");
  cv::Mat holes(gain.size(), CV_8UC1);
  for (int y = 0; y < gain.rows; ++y)
    for (int x = 0; x < gain.cols; ++x) holes.at<uint8_t>(y, x) = gain.at<float>(y, x) > 0.0f ? 0 : 255;
  if (cv::countNonZero(holes) == 0) return gain.clone();
  if (cv::countNonZero(holes) == static_cast<int>(gain.total()))
    throw Error(ErrorCode::Failed, "the flat field has no pixel with a value");
  // Each pixel labelled with its nearest zero of `holes` (a pixel with a value).
  cv::Mat dist, labels;
  cv::distanceTransform(holes, dist, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  double max_label = 0;
  cv::minMaxLoc(labels, nullptr, &max_label);
  std::vector<float> value(static_cast<size_t>(max_label) + 1, 0.0f);
  for (int y = 0; y < gain.rows; ++y)
    for (int x = 0; x < gain.cols; ++x)
      if (!holes.at<uint8_t>(y, x)) value[static_cast<size_t>(labels.at<int>(y, x))] = gain.at<float>(y, x);
  cv::Mat out = gain.clone();
  for (int y = 0; y < gain.rows; ++y)
    for (int x = 0; x < gain.cols; ++x)
      if (holes.at<uint8_t>(y, x)) out.at<float>(y, x) = value[static_cast<size_t>(labels.at<int>(y, x))];
  return out;
}

void write_flat_field(const std::string& path, const cv::Mat& gain) {
  if (gain.type() != CV_32FC1 || gain.empty())
    throw_invalid_argument("write_flat_field: the gain must be a non-empty CV_32FC1 image");
  cv::Mat u16(gain.size(), CV_16UC1);
  for (int y = 0; y < gain.rows; ++y)
    for (int x = 0; x < gain.cols; ++x) {
      const float g = gain.at<float>(y, x);
      const double v = std::isfinite(g) ? std::clamp(static_cast<double>(g), 0.0, 1.0) : 0.0;
      long q = std::lround(v * 65535.0);
      if (v > 0 && q == 0) q = 1;
      u16.at<uint16_t>(y, x) = static_cast<uint16_t>(q);
    }
  std::vector<uchar> png;
  if (!cv::imencode(".png", u16, png)) throw Error(ErrorCode::Io, "flat field " + path + ": PNG encoding failed");
  OutputFile out(path);
  if (std::fwrite(png.data(), 1, png.size(), out.stream()) != png.size())
    throw Error(ErrorCode::Io, "flat field " + path + ": writing failed");
  out.commit();
}

cv::Mat photometric_reference(const cv::Mat& raw, const PhotometricFit& fit, double saturation) {
  if (raw.type() != CV_32FC1 || fit.scale.size() != raw.size() || fit.offset.size() != raw.size())
    throw_invalid_argument("photometric_reference: raw (CV_32FC1) and the model of one size");
  const float sat = static_cast<float>(saturation);
  cv::Mat out(raw.size(), CV_32FC1);
  for (int y = 0; y < raw.rows; ++y) {
    const float* v = raw.ptr<float>(y);
    const float* sc = fit.scale.ptr<float>(y);
    const float* of = fit.offset.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) {
      const bool use = v[x] > 0.5f * kInvalidIntensity && v[x] < sat && sc[x] > 0.0f;
      o[x] = use ? v[x] * sc[x] + of[x] : kInvalidIntensity;
    }
  }
  return out;
}

cv::Mat photometric_rolling_reference(const cv::Mat& raw, const PhotometricFit& fit, const RowWarp& warp,
                                      double saturation) {
  if (raw.type() != CV_32FC1 || fit.scale.size() != raw.size() || fit.offset.size() != raw.size() ||
      raw.cols < 2 || raw.rows < 2)
    throw_invalid_argument("photometric_rolling_reference: raw (CV_32FC1) and the model of one size");
  if (warp.width != raw.cols || warp.height != raw.rows || warp.nodes_x < 2 || warp.nodes_y < 2 ||
      warp.light.size() != 2 * static_cast<size_t>(warp.nodes_x) * static_cast<size_t>(warp.nodes_y))
    throw_invalid_argument("photometric_rolling_reference: the row warp is not for this image's size");
  const float sat = static_cast<float>(saturation);
  const int w = raw.cols, h = raw.rows;
  cv::Mat out(raw.size(), CV_32FC1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2f d = row_warp_at(warp, warp.light, x, y);
      const float qx = std::clamp(static_cast<float>(x) + d[0], 0.0f, static_cast<float>(w - 1));
      const float qy = std::clamp(static_cast<float>(y) + d[1], 0.0f, static_cast<float>(h - 1));
      const int mx = static_cast<int>(qx + 0.5f), my = static_cast<int>(qy + 0.5f);
      const float scale = fit.scale.at<float>(my, mx), offset = fit.offset.at<float>(my, mx);
      const float v = raw.at<float>(y, x);
      const bool use = v > 0.5f * kInvalidIntensity && v < sat && scale > 0.0f;
      out.at<float>(y, x) = use ? v * scale + offset : kInvalidIntensity;
    }
  }
  return out;
}

void photometric_learn_reference(const cv::Mat& raw, float alpha, cv::Mat* mean, cv::Mat* square) {
  if (raw.type() != CV_32FC1 || !mean || !square || mean->size() != raw.size() ||
      square->size() != raw.size() || mean->type() != CV_32FC1 || square->type() != CV_32FC1)
    throw_invalid_argument("photometric_learn_reference: raw, mean and square CV_32FC1 of one size");
  for (int y = 0; y < raw.rows; ++y) {
    const float* v = raw.ptr<float>(y);
    float* mu = mean->ptr<float>(y);
    float* var = square->ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) {
      if (!(v[x] > 0.5f * kInvalidIntensity)) continue;
      mu[x] += alpha * (v[x] - mu[x]);
      var[x] += alpha * (v[x] * v[x] - var[x]);
    }
  }
}

}  // namespace planarvo
