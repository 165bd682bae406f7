// `planarvo simulate` and `planarvo info`: data sets in and out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

#include "common.h"
#include "drive.h"

namespace planarvo::cli {
namespace {

constexpr double kDeg = M_PI / 180.0;
namespace fs = std::filesystem;

// A bag's topics, before it is opened as a data set (which needs the right topics).
struct BagTopic {
  std::string name, type, count;  // count "" when the file does not say
  std::string described() const { return name + " (" + type + (count.empty() ? "" : ", " + count + " messages") + ")"; }
};

std::vector<BagTopic> bag_topics(const std::string& path) {
  size_t needed = 0;
  check(planarvo_bag_topics(path.c_str(), nullptr, 0, &needed));
  std::string list(needed, '\0');
  check(planarvo_bag_topics(path.c_str(), list.data(), list.size(), nullptr));
  std::vector<BagTopic> topics;
  size_t at = 0;
  for (size_t end = list.find('\n'); end != std::string::npos; at = end + 1, end = list.find('\n', at)) {
    const std::string line = list.substr(at, end - at);
    const size_t a = line.find('\t'), b = line.rfind('\t');
    const std::string count = line.substr(b + 1);
    topics.push_back({line.substr(0, a), line.substr(a + 1, b - a - 1), count == "-1" ? "" : count});
  }
  return topics;
}

void print_bag_topics(const std::string& path, const std::vector<BagTopic>& topics) {
  std::printf("topics of %s\n", path.c_str());
  for (const BagTopic& t : topics)
    std::printf("  %-32s %-32s %s\n", t.name.c_str(), t.type.c_str(),
                t.count.empty() ? "" : (t.count + " messages").c_str());
}

// For a bag, which topic each of the data set's streams comes from: the one given (--...-topic),
// else the only candidate the library picked, else the candidates and the option that picks one.
void print_bag_streams(const std::vector<BagTopic>& topics, const Args& args) {
  const auto of_type = [&](std::initializer_list<const char*> types) {
    std::vector<BagTopic> out;
    for (const BagTopic& t : topics)
      for (const char* type : types)
        if (t.type == type) {
          out.push_back(t);
          break;
        }
    return out;
  };
  const auto find = [&](const std::string& name) {
    for (const BagTopic& t : topics)
      if (t.name == name) return t.described();
    return name;
  };
  const auto line = [&](const char* label, const std::string& option, std::initializer_list<const char*> types,
                        bool picks_the_only_one, const std::string& taken = "") {
    std::vector<BagTopic> candidates = of_type(types);
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const BagTopic& t) { return t.name == taken; }),
                     candidates.end());
    std::string text;
    if (args.has(option)) {
      text = find(args.get(option));
    } else if (picks_the_only_one && candidates.size() == 1) {
      text = candidates[0].described() + (taken.empty() ? ", the only one" : ", the only one besides " + taken);
    } else if (candidates.empty()) {
      text = "none in the bag";
    } else {
      text = "not read: give --" + option + " (";
      for (size_t i = 0; i < candidates.size(); ++i) text += (i ? ", " : "") + candidates[i].described();
      text += ")";
    }
    std::printf("  %-11s %s\n", label, text.c_str());
  };
  line("images", "image-topic", {"sensor_msgs/Image", "sensor_msgs/CompressedImage", "sensor_msgs/msg/Image",
                                 "sensor_msgs/msg/CompressedImage"}, true);
  if (args.has("camera"))
    std::printf("  %-11s %s\n", "camera from", args.get("camera").c_str());
  else
    line("camera from", "camera-info-topic", {"sensor_msgs/CameraInfo", "sensor_msgs/msg/CameraInfo"}, true);
  // Odometry: the only Odometry topic besides the ground truth's (the library's rule, io/dataset/dataset_bag.cpp).
  line("odometry", "odom-topic", {"nav_msgs/Odometry", "nav_msgs/msg/Odometry"}, true, args.get("groundtruth-topic"));
  line("groundtruth", "groundtruth-topic", {"nav_msgs/Odometry", "nav_msgs/msg/Odometry"}, false);
}

// topics: a bag's (bag_topics), empty for a folder.
void print_dataset(planarvo_dataset* ds, const std::string& dir, const Args& args,
                   const std::vector<BagTopic>& topics) {
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  check(planarvo_dataset_info_get(ds, &info));
  const auto& c = info.camera;
  const double span = info.last_timestamp - info.first_timestamp;
  std::printf("%s %s\n", info.is_bag ? "bag" : "data set", dir.c_str());
  std::printf("  frames      %lld over %.3f s (%.2f fps)\n", static_cast<long long>(info.frame_count), span,
              info.frame_count > 1 ? static_cast<double>(info.frame_count - 1) / span : 0.0);
  if (info.is_bag)
    std::printf("  first frame %lld.%09lld s (its stamp; times are counted from it)\n",
                static_cast<long long>(info.time_origin_ns / 1000000000),
                static_cast<long long>(info.time_origin_ns % 1000000000));
  std::printf("  camera      %dx%d, fx %.2f fy %.2f cx %.2f cy %.2f, distortion %.4g %.4g %.4g %.4g %.4g\n",
              c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3);
  if (c.roi.width > 0)
    std::printf("  region      x %d, y %d, %dx%d pixels (region of interest)\n", c.roi.x, c.roi.y, c.roi.width,
                c.roi.height);
  else
    std::printf("  region      the whole image\n");
  if (c.rolling_shutter_readout > 0)
    std::printf("  shutter     rolling, %.3f ms from the first row's read to the last's\n",
                c.rolling_shutter_readout * 1e3);
  if (c.exposure_time > 0) std::printf("  exposure    %.3f ms\n", c.exposure_time * 1e3);
  if (info.is_bag) {
    print_bag_streams(topics, args);  // which topic each stream comes from, or which could
  } else {
    std::printf("  odometry    %s\n  direction   %s\n  groundtruth %s\n", info.has_odometry ? "yes" : "no",
                info.has_direction ? "yes" : "no", info.has_groundtruth ? "yes" : "no");
  }
  auto ext = [](const char* label, int has, const planarvo_extrinsics& e) {
    if (!has) {
      std::printf("  %-11s no\n", label);
      return;
    }
    std::printf("  %-11s x %.1f mm, y %.1f mm, z %.1f mm, roll %.2f deg, pitch %.2f deg, yaw %.2f deg\n", label,
                e.x * 1e3, e.y * 1e3, e.z * 1e3, e.roll / kDeg, e.pitch / kDeg, e.yaw / kDeg);
  };
  ext("extrinsics", info.has_extrinsics, info.extrinsics);
  ext("true extr.", info.has_extrinsics_gt, info.extrinsics_gt);
  if (info.has_groundtruth) {
    const DriveSummary s = summarise(ds, info.frame_count);
    std::printf("  drive       %.2f m, peak %.2f m/s and %.2f rad/s; intervals: %d forward, %d backward, "
                "%d without linear motion\n",
                s.distance, s.peak_speed, s.peak_turn, s.forward, s.backward, s.still);
  }
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  const auto specs = simulate_options();
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo simulate --out DIR [options]\n\n"
                "Renders a downward-looking camera on a differential-drive robot over a textured ground\n"
                "plane, with exact ground truth, in the data set layout planarvo reads.\n\n%s",
                format_options(specs).c_str());
    return kExitOk;
  }
  if (!args.positionals().empty()) throw UsageError("unexpected argument " + args.positionals()[0]);
  if (!args.has("out")) throw UsageError("--out DIR is required");
  planarvo_sim_options o;
  planarvo_sim_options_init(&o);
  std::string texture;
  apply_simulate_args(args, &o, &texture);
  ContextPtr ctx = make_context(args);
  Progress progress(!args.has("quiet"));
  o.progress = &Progress::callback;
  o.progress_user_data = &progress;
  const auto t0 = std::chrono::steady_clock::now();
  check(planarvo_simulate(ctx.get(), &o, args.get("out").c_str()));
  progress.finish();
  std::printf("simulated %.1f s at %.0f fps (%dx%d) over %s into %s in %.1f s on %s\n", o.seconds, o.fps,
              o.camera.width, o.camera.height, texture.c_str(), args.get("out").c_str(), seconds_since(t0),
              device_name(ctx.get()).c_str());
  return kExitOk;
}

int cmd_info(int argc, char** argv) {
  const std::vector<OptionSpec> specs = {
      {"video", "FILE", "a video file standing in for images/ and frames.txt", ""},
      {"verify", "", "decode every image now (sizes, unreadable files)", ""},
      {"quiet", "", "no progress bar", ""},
      {"help", "", "show this help", ""}};
  std::vector<OptionSpec> all = specs;
  for (auto& b : bag_options()) all.push_back(b);
  Args args(all, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo info DATASET [--verify] [--video FILE]\n"
                "       planarvo info BAG [--image-topic T] [--camera-info-topic T | --camera FILE] [--odom-topic T]\n\n"
                "Reads a data set (docs/formats.md: camera.yaml, frames.txt, images/, optional odometry.txt,\n"
                "direction.txt, groundtruth.txt, extrinsics.yaml), checks it and prints what it holds.\n\n%s",
                format_options(all).c_str());
    return kExitOk;
  }
  args.expect_positionals(1, "DATASET, the data set folder or a bag");
  std::vector<BagTopic> topics;  // read once, for the list and the streams
  if (is_bag_path(args.positionals()[0])) {
    topics = bag_topics(args.positionals()[0]);
    print_bag_topics(args.positionals()[0], topics);
  }
  Progress progress(!args.has("quiet"));
  DatasetPtr ds = open_dataset(args.positionals()[0], args, args.has("verify"), &progress);
  progress.finish();
  print_dataset(ds.get(), args.positionals()[0], args, topics);
  if (args.has("verify")) std::printf("  every image decoded and checked\n");
  return kExitOk;
}


}  // namespace planarvo::cli
