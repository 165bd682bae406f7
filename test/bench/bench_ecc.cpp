// The tracker against OpenCV's findTransformECC on the same frame pairs of a simulated sequence,
// in the same run, in both methods' terms. Prints tables, asserts nothing.
//
//   bench_ecc [key=value...]
//     textures=a.png,b.png|all (asphalt_01.png)  seconds=20  w=640 h=480  seed=1
//     pairs=60 (spread evenly over the sequence)  levels=3 (ECC's pyramid)  finest=N (the tracker's)
//     select=B (the tracker's level 0 on one pixel per B x B block)  prior=0|1
//     the scene: config=1|2|3 or ext=x,y,z,roll,pitch,yaw (m, deg), fov=deg,
//     motion=mixed|straight|circle|spin|car, speed=m/s, turn=rad/s, radius=m, noise=grey levels
//
// The pairs are consecutive frames (k, k+1). ECC: MOTION_HOMOGRAPHY, coarse to fine over `levels`
// halvings from the identity, 50 iterations and eps 1e-6 per level, Gaussian 5, on the frames
// undistorted with cv::remap (bilinear), masked to the valid undistorted pixels; its time is
// findTransformECC's with its pyramid, not the undistortion. planarvo: the whole sequence tracked
// frame by frame with the default options (keyframes, prediction), the frame-to-frame motion of
// the same intervals; its time is the engine's `ms` of frame k+1 (undistortion, pyramid and
// alignment included).
//
// Errors, per pair: ECC's own terms, the mean distance in undistorted pixels between a grid of
// reference pixels (every 16th, valid and landing inside the live image) mapped by the
// estimated and by the true homography (planarvo's estimate is the ground homography of its
// motion); and the planar motion's translation error in mm (ECC's homography reduced to a
// planar motion with the true camera, an SE(2) fit of back-projected grid points).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "bench_ecc.h"
#include "bench_scene.h"
#include "core/se2.h"
#include "image/undistort.h"
#include "ocl/runtime.h"
#include "track/tracker.h"

using namespace planarvo;
using bench::now_ms;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

Eigen::Vector2d ground_point(const Eigen::Matrix3d& Kinv, const Extrinsics& e, double u, double v) {
  const Eigen::Vector3d ray = Kinv * Eigen::Vector3d(u, v, 1.0);
  const Eigen::Vector3d n = e.plane_normal_camera();
  const Eigen::Vector3d X = ray * (-e.z / n.dot(ray));
  return (e.R_vc() * X + e.t_vc()).head<2>();
}

// ECC's homography reduced to the robot's planar motion with the true camera: reference grid
// pixels and their images back-projected onto the ground in robot frames k and k+1, and the
// SE(2) motion between the point sets fitted (Procrustes).
bool homography_to_motion(const Eigen::Matrix3d& H, const Eigen::Matrix3d& K, const Extrinsics& e, int w, int h,
                          SE2* motion) {
  const Eigen::Matrix3d Kinv = K.inverse();
  std::vector<Eigen::Vector2d> pr, pl;
  for (int v = 4; v < h; v += 8)
    for (int u = 4; u < w; u += 8) {
      const Eigen::Vector3d q = H * Eigen::Vector3d(u, v, 1.0);
      if (q(2) <= 0) continue;
      const double ul = q(0) / q(2), vl = q(1) / q(2);
      if (ul < 0 || vl < 0 || ul > w - 1 || vl > h - 1) continue;
      pr.push_back(ground_point(Kinv, e, u, v));
      pl.push_back(ground_point(Kinv, e, ul, vl));
    }
  if (pr.size() < 10) return false;
  Eigen::Vector2d cr = Eigen::Vector2d::Zero(), cl = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < pr.size(); ++i) {
    cr += pr[i];
    cl += pl[i];
  }
  cr /= static_cast<double>(pr.size());
  cl /= static_cast<double>(pl.size());
  double sdot = 0, scross = 0;
  for (size_t i = 0; i < pr.size(); ++i) {
    const Eigen::Vector2d a = pl[i] - cl, b = pr[i] - cr;
    sdot += a.dot(b);
    scross += a.x() * b.y() - a.y() * b.x();
  }
  const double th = std::atan2(scross, sdot);
  const Eigen::Vector2d t = cr - Eigen::Rotation2Dd(th) * cl;
  *motion = SE2(t.x(), t.y(), th);
  return true;
}

// Mean distance (undistorted pixels) between the images of a grid of valid reference pixels
// under H and under the true homography, over those whose true image is inside the live image.
double grid_error(const Eigen::Matrix3d& H, const Eigen::Matrix3d& Htrue, const cv::Mat& mask) {
  double sum = 0;
  int n = 0;
  for (int v = 8; v < mask.rows; v += 16)
    for (int u = 8; u < mask.cols; u += 16) {
      if (!mask.at<uint8_t>(v, u)) continue;
      const Eigen::Vector3d t = Htrue * Eigen::Vector3d(u, v, 1.0), e = H * Eigen::Vector3d(u, v, 1.0);
      const Eigen::Vector2d pt = t.hnormalized(), pe = e.hnormalized();
      if (!(t.z() > 0) || pt.x() < 0 || pt.y() < 0 || pt.x() > mask.cols - 1 || pt.y() > mask.rows - 1) continue;
      sum += (e.z() > 0 ? (pe - pt).norm() : 1e6);
      ++n;
    }
  return n > 0 ? sum / n : 0.0;
}

struct Method {
  std::vector<double> px, mm, deg, ms;
  int failed = 0;
  void add(double p, const SE2& est, const SE2& truth, double t) {
    px.push_back(p);
    mm.push_back(1e3 * std::hypot(est.x - truth.x, est.y - truth.y));
    deg.push_back(std::abs(wrap_angle(est.theta - truth.theta)) * 180 / M_PI);
    ms.push_back(t);
  }
  static double mean(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  }
  static double rms(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x * x;
    return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
  }
  static double max(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }
  void print(const char* texture, const char* name) const {
    std::printf("%-24s %-28s %5zu %5d %9.2f %9.4f %9.4f %9.4f %9.4f %9.5f\n", texture, name, px.size(), failed,
                median(ms), mean(px), max(px), rms(mm), max(mm), rms(deg));
  }
};

}  // namespace

int main(int argc, char** argv) {
  bench::Scene scene;
  std::vector<std::string> textures = {"asphalt_01.png"};
  double seconds = 20.0;
  int w = 640, h = 480, pairs = 60, levels = 3;
  uint64_t seed = 1;
  track::TrackerOptions topt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const size_t eq = a.find('=');
    const std::string k = a.substr(0, eq), v = eq == std::string::npos ? "" : a.substr(eq + 1);
    if (scene.parse(k, v)) continue;
    if (k == "textures") textures = v == "all" ? bench::all_textures() : bench::split(v);
    else if (k == "seconds") seconds = std::atof(v.c_str());
    else if (k == "w") w = std::atoi(v.c_str());
    else if (k == "h") h = std::atoi(v.c_str());
    else if (k == "seed") seed = std::strtoull(v.c_str(), nullptr, 10);
    else if (k == "pairs") pairs = std::max(1, std::atoi(v.c_str()));
    else if (k == "levels") levels = std::max(1, std::atoi(v.c_str()));
    else if (k == "finest") topt.finest_level = std::atoi(v.c_str());
    else if (k == "select") topt.select_blocks[0] = std::atoi(v.c_str());  // level 0 at 1 / select^2
    else if (k == "prior") topt.subsample_prior = std::atoi(v.c_str()) != 0;
    else {
      std::fprintf(stderr, "unknown option %s (see the comment at the top of bench_ecc.cpp)\n", a.c_str());
      return 2;
    }
  }
  ocl::Runtime rt;
  std::printf("device: %s; OpenCV %s, %d threads\n", rt.device_info().device_name.c_str(), CV_VERSION,
              cv::getNumThreads());
  std::printf("%dx%d, %.0f s at 30 Hz, seed %llu; %s\n", w, h, seconds, static_cast<unsigned long long>(seed),
              scene.summary().c_str());
  std::printf("%d pairs (k, k+1) spread over each sequence; ECC: homography, %d levels from the identity, on "
              "undistorted frames; planarvo: the sequence tracked with the default options, finest level %d (-1: auto)\n",
              pairs, levels, topt.finest_level);
  std::printf("%-24s %-28s %5s %5s %9s %9s %9s %9s %9s %9s\n", "texture", "method", "pairs", "fail", "med_ms",
              "mean_px", "max_px", "rms_mm", "max_mm", "rms_deg");
  for (const std::string& tex : textures) {
    const sim::Options so = scene.options(tex, seconds, w, h, seed);
    const sim::Trajectory traj = sim::generate_trajectory(so);
    const std::vector<cv::Mat> frames = bench::render_sequence(rt, so, traj);
    const size_t n = frames.size();
    std::vector<track::FrameResult> res;
    {
      track::Tracker tracker(rt, so.camera, so.extrinsics, topt);
      for (size_t k = 0; k < n; ++k) res.push_back(tracker.track(frames[k].data, w, h, frames[k].step, traj.t[k]));
    }
    const Eigen::Matrix3d K = so.camera.K();
    const bench::EccFrames ecc_frames(so.camera);
    const cv::Mat& mask = ecc_frames.mask;
    auto undistort = [&](const cv::Mat& g) { return ecc_frames.undistort(g); };
    Method ecc, vo;
    for (int i = 0; i < pairs; ++i) {
      const size_t k = 1 + static_cast<size_t>(i) * (n - 3) / static_cast<size_t>(std::max(1, pairs - 1));
      const SE2 truth = traj.pose[k].inverse() * traj.pose[k + 1];
      const Eigen::Matrix3d Htrue = ground_homography(K, so.extrinsics, truth.matrix3d());
      const cv::Mat a = undistort(frames[k]), b = undistort(frames[k + 1]);
      cv::Mat H32;
      const double t0 = now_ms();
      const bool ok = bench::ecc_pair(a, b, mask, levels, &H32);
      const double ms = now_ms() - t0;
      Eigen::Matrix3d H;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) H(r, c) = H32.at<float>(r, c);
      SE2 m;
      if (!homography_to_motion(H, K, so.extrinsics, w, h, &m)) m = SE2();
      ecc.failed += !ok;  // counted; its estimate still counts
      ecc.add(grid_error(H, Htrue, mask), m, truth, ms);
      const track::FrameResult& r = res[k + 1];
      vo.failed += r.status == track::FrameResult::Status::Lost;  // counted; the prediction counts too
      vo.add(grid_error(ground_homography(K, so.extrinsics, r.motion.value.matrix3d()), Htrue, mask), r.motion.value, truth, r.ms);
    }
    ecc.print(tex.c_str(), "ECC homography");
    vo.print(tex.c_str(), "planarvo (sequence)");
    std::printf("%-24s %-28s px error %.3fx ECC's; %.0fx faster per pair (median)\n", tex.c_str(), "planarvo / ECC",
                Method::mean(vo.px) / std::max(1e-12, Method::mean(ecc.px)), median(ecc.ms) / std::max(1e-9, median(vo.ms)));
    std::fflush(stdout);
  }
  return 0;
}
