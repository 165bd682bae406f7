// Roll and pitch from images (paper section 5.1): accuracy and time of track::RollPitchEstimator
// on simulated drives rendered in memory, against the simulator's true extrinsics.
//
//   bench_roll_pitch [key=value ...]
//     textures=a.png,b.png (shared/data/textures; "all" for every one)   default asphalt_01.png
//     config=1|2|3|random (the paper's camera configurations, or random poses, seed)  default 1
//     runs=N   random configurations when config=random                                default 4
//     init=zero|truth|offset   start at 0, at the truth, or truth + (offset_roll, offset_pitch)
//     offset_roll=DEG offset_pitch=DEG                                                  default 0
//     keyframes=N max_frames=N motion=mixed|straight|circle|spin seconds=S seed=N
//     size=WxH finest=L search=0|1 noise=GREY
// Prints one row per run: true and estimated angles, errors, reported sigmas, keyframes, frames,
// rounds, passes, time.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "sim/simulator.h"
#include "bench_args.h"
#include "ocl/runtime.h"
#include "track/roll_pitch.h"

using namespace planarvo;

namespace {

constexpr double kDeg = M_PI / 180.0;

using bench::get;
using bench::split;

}  // namespace

int main(int argc, char** argv) {
  const auto args = bench::parse_args(argc, argv, "bench_roll_pitch");
  const std::string shared = PLANARVO_SHARED_DIR;
  std::vector<std::string> textures = split(get(args, "textures", "asphalt_01.png"));
  if (textures.size() == 1 && textures[0] == "all") {
    textures.clear();
    for (const auto& e : std::filesystem::directory_iterator(shared + "/data/textures"))
      if (e.path().extension() == ".png" || e.path().extension() == ".jpg") textures.push_back(e.path().filename());
  }
  const std::string cfg = get(args, "config", "1");
  const int runs = cfg == "random" ? std::stoi(get(args, "runs", "4")) : 1;
  const std::string init = get(args, "init", "zero");
  const double off_r = std::stod(get(args, "offset_roll", "0")) * kDeg;
  const double off_p = std::stod(get(args, "offset_pitch", "0")) * kDeg;
  const std::string motion = get(args, "motion", "mixed");
  const std::string size = get(args, "size", "640x480");
  const int width = std::stoi(size.substr(0, size.find('x')));
  const int height = std::stoi(size.substr(size.find('x') + 1));

  ocl::Runtime rt;
  std::printf("%-22s %-7s %8s %8s %8s %8s | %8s %8s %7s %7s | %5s %5s %3s %5s %7s %7s %s\n", "texture", "config",
              "roll", "pitch", "init r", "init p", "err r", "err p", "sd r", "sd p", "kf/pr", "frm", "rnd", "pass",
              "trk ms", "aln ms", "status");
  for (const std::string& tex : textures)
    for (int run = 0; run < runs; ++run) {
      sim::Options so;
      so.texture = shared + "/data/textures/" + tex;
      so.camera = sim::default_camera(width, height);
      so.seconds = std::stod(get(args, "seconds", "6"));
      so.seed = static_cast<uint64_t>(std::stoll(get(args, "seed", "1"))) + static_cast<uint64_t>(run);
      so.pixel_noise = std::stod(get(args, "noise", "1"));
      so.motion = motion == "straight" ? sim::MotionProfile::Straight
                  : motion == "circle" ? sim::MotionProfile::Circle
                  : motion == "spin"   ? sim::MotionProfile::Spin
                                       : sim::MotionProfile::Mixed;
      std::string label = cfg;
      if (cfg == "random") {
        sim::Random r(sim::derive_seed(so.seed, 99));
        so.extrinsics = Extrinsics{r.uniform(-0.3, 0.3), r.uniform(-0.2, 0.2), r.uniform(0.12, 0.3),
                                   r.uniform(-30, 30) * kDeg, r.uniform(-30, 30) * kDeg, r.uniform(-180, 180) * kDeg};
        label = "rnd" + std::to_string(run);
      } else {
        so.extrinsics = sim::paper_configuration(std::stoi(cfg));
      }
      const sim::Trajectory traj = sim::generate_trajectory(so);
      const cv::Mat texture = cv::imread(so.texture, cv::IMREAD_GRAYSCALE);
      sim::Renderer renderer(rt, texture, so);
      const std::vector<sim::Exposure> exposure = sim::exposure_series(so, traj.t);

      track::RollPitchOptions o;
      if (args.count("overlap")) o.keyframe_overlap = std::stod(get(args, "overlap", "0.7"));
      if (args.count("keyframes")) o.max_keyframes = std::stoi(get(args, "keyframes", "12"));
      if (args.count("max_frames")) o.max_frames = std::stoi(get(args, "max_frames", "0"));
      if (args.count("finest")) o.align.finest_level = std::stoi(get(args, "finest", "0"));
      o.search = get(args, "search", "1") != "0";
      const Extrinsics& e = so.extrinsics;
      if (init == "truth" || init == "offset") {
        o.initial_roll = e.roll + off_r;
        o.initial_pitch = e.pitch + off_p;
      }
      track::RollPitchEstimator est(rt, so.camera, o);
      for (size_t k = 0; k < traj.t.size(); ++k) {
        const cv::Mat img = sim::apply_camera(sim::render_frame(renderer, so, traj, k), exposure[k], so.pixel_noise,
                                              sim::derive_seed(so.seed, 1000 + k));
        if (est.add_frame(img.data, img.cols, img.rows, img.step, traj.t[k])) break;
      }
      const track::RollPitchResult r = est.estimate();
      std::printf("%-22s %-7s %8.3f %8.3f %8.3f %8.3f | %8.4f %8.4f %7.4f %7.4f | %2d/%-2d %5d %3d %5d %7.0f %7.0f %s%s%s\n",
                  tex.c_str(), label.c_str(), e.roll / kDeg, e.pitch / kDeg, o.initial_roll / kDeg,
                  o.initial_pitch / kDeg, (r.roll - e.roll) / kDeg, (r.pitch - e.pitch) / kDeg,
                  std::sqrt(r.covariance(0, 0)) / kDeg, std::sqrt(r.covariance(1, 1)) / kDeg, r.keyframes, r.pairs,
                  r.frames_used, r.rounds, r.passes, r.track_ms, r.align_ms, track::status_name(r.status),
                  r.reason.empty() ? "" : ": ", r.reason.c_str());
      if (std::getenv("BENCH_VERBOSE")) {
        // The map's keyframe pairs: the tracker's first motion against the truth, the camera's
        // planar motion in units of its height: T_vs^-1 m T_vs / z with T_vs = (x, y, yaw).
        const SE2 T_vs(e.x, e.y, e.yaw);
        for (size_t k = 0; k + 1 < r.keyframe_frames.size(); ++k) {
          const auto a = static_cast<size_t>(r.keyframe_frames[k]), b = static_cast<size_t>(r.keyframe_frames[k + 1]);
          SE2 m = T_vs.inverse() * traj.pose[a].inverse() * traj.pose[b] * T_vs;
          m.x /= e.z;
          m.y /= e.z;
          std::printf("  keyframes %zu-%zu (frames %zu-%zu): true %.4f %.4f %.4f\n", k, k + 1, a, b, m.x, m.y, m.theta);
        }
        for (const auto& p : r.pair_motions)
          std::printf("  pair %d-%d estimate %.4f %.4f %.4f\n", p.reference, p.live, p.motion.x, p.motion.y, p.motion.theta);
      }
      std::fflush(stdout);
    }
  return 0;
}
