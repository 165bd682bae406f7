// What reading a bag costs against reading the same frames from a data set folder, and against
// tracking them: per source, the time to open (index, stamps, camera), the median time to read
// and decode one frame (the mean: a compressed chunk holds several frames, and the first one
// read pays for its decompression), and the median time to track one (the tracker's own time, reading
// excluded), through the C API as `planarvo track` uses it; and the largest difference of any
// frame's tracked motion (m, rad), time after the first frame, odometry and ground-truth pose
// from the first source's (the folder). Sources are read in turn, `rounds` times; after the
// first round the files are in the page cache, as for a second run of the tool.
//
//   bench_bag DATASET EXTRINSICS.yaml SOURCE... [rounds=3] [odom=/odom] [gt=/ground_truth]
//     SOURCE: the DATASET folder itself, a .bag or an .mcap written from it
//     (test/tools/rosbag/dataset_to_rosbag.py, test/tools/mcap/dataset_to_mcap.mjs)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "planarvo/planarvo.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void check(planarvo_status s, const char* what) {
  if (s != PLANARVO_OK) {
    std::fprintf(stderr, "bench_bag: %s: %s\n", what, planarvo_last_error());
    std::exit(2);
  }
}

struct Row {
  std::string source;
  int64_t frames = 0;
  std::vector<double> open_ms, read_ms, track_ms, total_ms;
  std::vector<planarvo_frame_data> data;  // the first round's
  std::vector<planarvo_se2> motion;
};

double angle_diff(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }
double pose_diff(const planarvo_se2& a, const planarvo_se2& b) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), angle_diff(a.theta, b.theta)});
}

// The largest difference of motions, times and poses from the reference's, or -1 when the frame
// counts differ.
double max_difference(const Row& r, const Row& ref) {
  if (r.motion.size() != ref.motion.size()) return -1;
  double worst = 0;
  const double t0 = ref.data.empty() ? 0 : ref.data.front().timestamp;
  for (size_t i = 0; i < r.motion.size(); ++i) {
    const planarvo_frame_data &a = r.data[i], &b = ref.data[i];
    worst = std::max({worst, pose_diff(r.motion[i], ref.motion[i]), std::abs(a.timestamp - (b.timestamp - t0))});
    if (a.has_odometry != b.has_odometry || a.has_groundtruth != b.has_groundtruth) return -1;
    if (a.has_odometry) worst = std::max(worst, pose_diff(a.odometry, b.odometry));
    if (a.has_groundtruth) worst = std::max(worst, pose_diff(a.groundtruth, b.groundtruth));
  }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> sources;
  int rounds = 3;
  std::string odom = "/odom", gt = "/ground_truth";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("rounds=", 0) == 0) rounds = std::max(1, std::atoi(a.c_str() + 7));
    else if (a.rfind("odom=", 0) == 0) odom = a.substr(5);
    else if (a.rfind("gt=", 0) == 0) gt = a.substr(3);
    else sources.push_back(a);
  }
  if (sources.size() < 3) {
    std::fprintf(stderr, "usage: bench_bag DATASET EXTRINSICS.yaml SOURCE... [rounds=3]\n");
    return 2;
  }
  planarvo_extrinsics extrinsics{};
  check(planarvo_extrinsics_load(sources[1].c_str(), &extrinsics), "extrinsics");
  sources.erase(sources.begin(), sources.begin() + 2);

  planarvo_context* ctx = nullptr;
  check(planarvo_context_create(nullptr, &ctx), "context");
  check(planarvo_context_prepare_kernels(ctx), "kernels");
  std::vector<Row> rows(sources.size());
  for (int round = 0; round < rounds; ++round) {
    for (size_t s = 0; s < sources.size(); ++s) {
      Row& row = rows[s];
      row.source = sources[s];
      const bool bag = std::filesystem::is_regular_file(sources[s]);
      planarvo_dataset_options o;
      planarvo_dataset_options_init(&o);
      if (bag) {
        o.odometry_topic = odom.c_str();
        o.groundtruth_topic = gt.c_str();
      }
      const auto t_open = Clock::now();
      planarvo_dataset* ds = nullptr;
      check(planarvo_dataset_open(sources[s].c_str(), &o, &ds), sources[s].c_str());
      planarvo_dataset_info info{};
      info.struct_size = sizeof info;
      check(planarvo_dataset_info_get(ds, &info), "info");
      row.open_ms.push_back(ms_since(t_open));
      row.frames = info.frame_count;
      planarvo_tracker* tracker = nullptr;
      check(planarvo_tracker_create(ctx, &info.camera, &extrinsics, nullptr, &tracker), "tracker");
      const auto t_all = Clock::now();
      for (int64_t i = 0; i < info.frame_count; ++i) {
        planarvo_frame_data fd{};
        planarvo_image img{};
        const auto t_read = Clock::now();
        check(planarvo_dataset_frame_data(ds, i, &fd), "frame data");
        check(planarvo_dataset_frame(ds, i, &img), "frame");
        row.read_ms.push_back(ms_since(t_read));
        planarvo_track_result r{};
        r.struct_size = sizeof r;
        const auto t_track = Clock::now();
        check(planarvo_tracker_track(tracker, &img, fd.timestamp, &r), "track");
        row.track_ms.push_back(ms_since(t_track));
        if (round == 0) {
          row.data.push_back(fd);
          row.motion.push_back(r.motion);
        }
      }
      row.total_ms.push_back(ms_since(t_all) + row.open_ms.back());
      planarvo_tracker_destroy(tracker);
      planarvo_dataset_destroy(ds);
    }
  }
  planarvo_context_destroy(ctx);

  const Row& base = rows.front();
  std::printf("%d rounds; medians over rounds (open, total), mean over frames x rounds (read), median over frames "
              "x rounds (track)\n\n",
              rounds);
  std::printf("| source | frames | open ms | read ms/frame | track ms/frame | (open + read) / track | total s | "
              "vs %s | max difference |\n",
              std::filesystem::path(base.source).filename().c_str());
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    double rd = 0;
    for (double v : r.read_ms) rd += v / static_cast<double>(r.read_ms.size());
    const double tr = median(r.track_ms), op = median(r.open_ms);
    const double n = static_cast<double>(r.frames);
    std::printf("| %s | %lld | %.1f | %.3f | %.2f | %.1f%% | %.2f | %+.1f%% | %.1e |\n",
                std::filesystem::path(r.source).filename().c_str(), static_cast<long long>(r.frames), op, rd, tr,
                100.0 * (op + rd * n) / (tr * n), median(r.total_ms) / 1e3,
                100.0 * (median(r.total_ms) / median(base.total_ms) - 1.0), max_difference(r, base));
  }
  return 0;
}
