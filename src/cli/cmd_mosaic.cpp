// planarvo mosaic: the floor under a trajectory as one image, with its map_server YAML.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common.h"

namespace planarvo::cli {

namespace {

struct MosaicDeleter {
  void operator()(planarvo_mosaic* m) const { planarvo_mosaic_destroy(m); }
};

// The trajectory's poses, times made the data set's (a bag's TUM stamps are absolute).
void read_trajectory(const std::string& path, int64_t time_origin_ns, std::vector<double>* t,
                     std::vector<planarvo_se2>* poses) {
  size_t n = 0;
  check(planarvo_read_tum(path.c_str(), nullptr, nullptr, 0, &n));
  t->resize(n);
  poses->resize(n);
  if (n > 0) check(planarvo_read_tum(path.c_str(), t->data(), poses->data(), n, &n));
  const double origin = static_cast<double>(time_origin_ns) * 1e-9;
  for (double& v : *t) v -= origin;
}

}  // namespace

int cmd_mosaic(int argc, char** argv) {
  std::vector<OptionSpec> specs = {
      {"trajectory", "FILE", "the robot's poses (TUM), e.g. what planarvo track -o wrote", ""},
      {"extrinsics", "FILE", "camera extrinsics YAML", "DATASET/extrinsics.yaml"},
      {"output", "FILE", "the mosaic image (PNG) (also -o); FILE with .yaml for its extension gets the "
                         "map_server description", ""},
      {"preview", "FILE", "also write a contrast-stretched copy for an ordinary viewer (the image itself keeps the "
                          "floor's grey levels, which span only a few)", ""},
      {"resolution", "M_PER_PX", "metres per mosaic pixel", "0.001"},
      {"max-range", "M", "use no ground farther than this from the camera's foot point", "4 x the camera height"},
      {"frame-spacing", "M", "use a frame once the camera has moved this far (or turned 5 degrees) since the last "
                             "one used", "an eighth of the ground in view"},
      {"every-frame", "", "use every frame of the trajectory", ""},
      {"no-gain", "", "no per-frame brightness correction", ""},
      readout_option(),
      force_option(),
      {"quiet", "", "no progress bar", ""},
      {"help", "", "show this help", ""}};
  for (auto& b : bag_options()) specs.push_back(b);
  for (auto& d : device_options()) specs.push_back(d);
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo mosaic DATASET --trajectory traj.txt [--extrinsics FILE] [--resolution M] -o floor.png\n\n"
                "The ground under a trajectory as one image: each frame warped onto the ground plane, brightness-\n"
                "corrected and blended. Writes the image and, beside it, a ROS map_server YAML (floor.yaml) that\n"
                "places it in the trajectory's frame. Pixels no frame saw are 0. A rolling-shutter camera's frames\n"
                "are warped row by row, each row from the robot's pose when it was read.\n\n%s",
                format_options(specs).c_str());
    return kExitOk;
  }
  args.expect_positionals(1, "DATASET, the data set folder or a bag");
  const std::string dir = args.positionals()[0];
  if (!args.has("trajectory")) throw UsageError("--trajectory FILE is required (planarvo track -o writes one)");
  if (!args.has("output")) throw UsageError("-o FILE is required: where to write the mosaic image (floor.png)");
  args.expect_output_files({"output", "preview"});
  const std::string out = args.get("output");
  {
    std::string ext = std::filesystem::path(out).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".png" && ext != ".pgm" && ext != ".tif" && ext != ".tiff" && ext != ".bmp")
      throw UsageError("-o " + out + ": the mosaic is written as .png (or .pgm, .tif, .bmp: lossless formats)");
  }
  planarvo_mosaic_options o;
  planarvo_mosaic_options_init(&o);
  o.resolution = args.get_double("resolution", o.resolution);
  if (!(o.resolution > 0) || !std::isfinite(o.resolution))
    throw UsageError("--resolution must be a positive number of metres per pixel, not " + args.get("resolution"));
  o.max_range = args.get_double("max-range", 0.0);
  if (!(o.max_range >= 0) || !std::isfinite(o.max_range)) throw UsageError("--max-range must be positive");
  if (args.has("every-frame") && args.has("frame-spacing"))
    throw UsageError("--every-frame and --frame-spacing exclude each other");
  o.frame_spacing = args.has("every-frame") ? -1.0 : args.get_double("frame-spacing", 0.0);
  if (!(o.frame_spacing >= -1.0) || !std::isfinite(o.frame_spacing)) throw UsageError("--frame-spacing must be positive");
  o.estimate_gain = args.has("no-gain") ? 0 : 1;
  o.accept_unusual_extrinsics = args.has("force") ? 1 : 0;
  const std::optional<double> readout = parse_readout(args);
  const planarvo_extrinsics e = extrinsics_for(args, dir);
  ContextPtr ctx = make_context(args);
  Progress progress(!args.has("quiet"));
  DatasetPtr ds = open_dataset(dir, args, false, &progress);
  apply_readout(readout, ds.get());
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  check(planarvo_dataset_info_get(ds.get(), &info));
  std::vector<double> t;
  std::vector<planarvo_se2> poses;
  read_trajectory(args.get("trajectory"), info.time_origin_ns, &t, &poses);
  o.progress = Progress::callback;
  o.progress_user_data = &progress;
  planarvo_mosaic* raw = nullptr;
  check(planarvo_mosaic_build(ctx.get(), ds.get(), &e, t.data(), poses.data(), t.size(), &o, &raw));
  std::unique_ptr<planarvo_mosaic, MosaicDeleter> mosaic(raw);
  check(planarvo_mosaic_save(mosaic.get(), out.c_str()));
  if (args.has("preview")) check(planarvo_mosaic_save_preview(mosaic.get(), args.get("preview").c_str()));
  progress.finish();
  planarvo_mosaic_info mi{};
  mi.struct_size = sizeof mi;
  check(planarvo_mosaic_info_get(mosaic.get(), &mi));
  const std::string yaml = std::filesystem::path(out).replace_extension(".yaml").string();
  const double area = static_cast<double>(mi.covered_pixels) * mi.resolution * mi.resolution;
  std::printf("mosaic of %s on %s: %d x %d px at %g m/px, origin (%.4f, %.4f) m\n", dir.c_str(),
              device_name(ctx.get()).c_str(), mi.width, mi.height, mi.resolution, mi.origin_x, mi.origin_y);
  std::printf("frames used %lld of %lld; ground seen %.3f m^2 (%.1f%% of the image); gains %.3f .. %.3f\n",
              static_cast<long long>(mi.frames_used), static_cast<long long>(mi.frames_given), area,
              100.0 * static_cast<double>(mi.covered_pixels) / (static_cast<double>(mi.width) * mi.height), mi.gain_min,
              mi.gain_max);
  std::printf("time %.2f s: decoding %.2f s, warping %.2f s, blending %.2f s; tile memory at most %.1f MB\n",
              mi.seconds_total, mi.seconds_decode, mi.seconds_warp, mi.seconds_blend,
              static_cast<double>(mi.peak_tile_bytes) / 1e6);
  std::printf("wrote %s and %s", out.c_str(), yaml.c_str());
  if (args.has("preview")) std::printf(", and the preview %s", args.get("preview").c_str());
  std::printf("\n");
  return kExitOk;
}

}  // namespace planarvo::cli
