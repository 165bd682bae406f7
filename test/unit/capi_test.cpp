// The C API's contract: statuses and messages instead of exceptions, NULL safety, struct_size
// checks, thread-local error messages, buffer sizing.
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "planarvo/planarvo.h"
#include "common/test_util.h"

namespace {

TEST(CApi, VersionMatchesHeader) {
  EXPECT_EQ(planarvo_version_number(), PLANARVO_VERSION_NUMBER);
  EXPECT_STREQ(planarvo_version_string(), "0.2.0");
}

TEST(CApi, NullArgumentsAreStatusesNotCrashes) {
  EXPECT_EQ(planarvo_context_create(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("context"), std::string::npos);
  EXPECT_EQ(planarvo_list_devices(nullptr, 0, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_camera_load(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_extrinsics_matrix(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_context_destroy(nullptr);
  planarvo_dataset_destroy(nullptr);
}

TEST(CApi, StructSizeIsChecked) {
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  EXPECT_EQ(o.struct_size, sizeof o);
  o.struct_size = 4;
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(&o, &c), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(c, nullptr);
  EXPECT_NE(std::string(planarvo_last_error()).find("struct_size"), std::string::npos);
}

TEST(CApi, ListDevicesSizesItsBuffer) {
  size_t n = 0;
  ASSERT_EQ(planarvo_list_devices(nullptr, 0, &n), PLANARVO_OK);
  ASSERT_GE(n, 1u) << "the test machine has PoCL";
  planarvo_device_info one{};
  one.struct_size = sizeof one;
  size_t m = 0;
  if (n > 1) {
    EXPECT_EQ(planarvo_list_devices(&one, 1, &m), PLANARVO_ERROR_BUFFER_TOO_SMALL);
  }
  std::vector<planarvo_device_info> all(n);
  for (auto& d : all) d.struct_size = sizeof d;
  ASSERT_EQ(planarvo_list_devices(all.data(), n, &m), PLANARVO_OK);
  EXPECT_EQ(m, n);
  EXPECT_GT(std::strlen(all[0].device_name), 0u);
  EXPECT_GT(all[0].max_work_group_size, 0u);
  EXPECT_EQ(all[0].index, 0);
}

TEST(CApi, UnknownDeviceIsNoDevice) {
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  o.device = "no-such-device-xyz";
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(&o, &c), PLANARVO_ERROR_NO_DEVICE);
  EXPECT_EQ(c, nullptr);
  EXPECT_NE(std::string(planarvo_last_error()).find("no-such-device-xyz"), std::string::npos);
}

TEST(CApi, ContextOnDefaultDevice) {
  planarvo_context* c = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &c), PLANARVO_OK) << planarvo_last_error();
  planarvo_device_info info{};
  info.struct_size = sizeof info;
  EXPECT_EQ(planarvo_context_device(c, &info), PLANARVO_OK);
  EXPECT_GT(std::strlen(info.device_name), 0u);
  planarvo_context_destroy(c);
}

// Where the program cache is: the option when given, "" when the cache is off or the context
// is NULL. (The default location and its fallbacks are OclCache's tests.)
TEST(CApi, ContextCacheDir) {
  planarvo::test::ScratchDir d;
  const std::string dir = (d / "cache").string();
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  o.cache_dir = dir.c_str();
  planarvo_context* c = nullptr;
  ASSERT_EQ(planarvo_context_create(&o, &c), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(std::string(planarvo_context_cache_dir(c)), dir);
  planarvo_context_destroy(c);
  o.disable_cache = 1;
  ASSERT_EQ(planarvo_context_create(&o, &c), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(std::string(planarvo_context_cache_dir(c)), "");
  planarvo_context_destroy(c);
  EXPECT_EQ(std::string(planarvo_context_cache_dir(nullptr)), "");
}

// The FPGA path's export: by use, with the count written, and names that are not uses refused.
TEST(CApi, ExportKernelsForAUse) {
  planarvo_context* c = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &c), PLANARVO_OK) << planarvo_last_error();
  planarvo::test::ScratchDir d;
  const std::string dir = (d / "bins").string();
  size_t n = 0;
  ASSERT_EQ(planarvo_context_export_kernels_for(c, dir.c_str(), "simulate", &n), PLANARVO_OK)
      << planarvo_last_error();
  EXPECT_EQ(n, 1u);  // the renderer
  EXPECT_EQ(planarvo_context_export_kernels_for(c, dir.c_str(), " simulate ,simulate", nullptr), PLANARVO_OK)
      << planarvo_last_error();
  EXPECT_EQ(planarvo_context_export_kernels_for(c, dir.c_str(), "track,no-such-use", &n),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("no-such-use"), std::string::npos);
  EXPECT_EQ(planarvo_context_export_kernels_for(c, dir.c_str(), "track,,simulate", &n),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_context_export_kernels_for(nullptr, dir.c_str(), nullptr, &n), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_context_export_kernels_for(c, nullptr, nullptr, &n), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_context_destroy(c);
}

// Preparing by use builds what the export for the same use writes, into the context's cache.
TEST(CApi, PrepareKernelsForAUseBuildsWhatItsExportWrites) {
  planarvo::test::ScratchDir d;
  const std::string cache = (d / "cache").string();
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  o.cache_dir = cache.c_str();
  planarvo_context* c = nullptr;
  ASSERT_EQ(planarvo_context_create(&o, &c), PLANARVO_OK) << planarvo_last_error();
  const auto entries = [&] {
    size_t n = 0;
    if (std::filesystem::exists(cache))
      for (const auto& e : std::filesystem::recursive_directory_iterator(cache)) n += e.is_regular_file();
    return n;
  };
  size_t simulate = 0, track = 0;
  ASSERT_EQ(planarvo_context_export_kernels_for(c, (d / "sim").string().c_str(), "simulate", &simulate), PLANARVO_OK);
  ASSERT_EQ(planarvo_context_export_kernels_for(c, (d / "track").string().c_str(), "track", &track), PLANARVO_OK);
  ASSERT_GT(track, 1u);
  planarvo_context_destroy(c);  // the exports built into the cache too: start again from an empty one
  std::filesystem::remove_all(cache);
  ASSERT_EQ(planarvo_context_create(&o, &c), PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(planarvo_context_prepare_kernels_for(c, "simulate"), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(entries(), simulate);
  ASSERT_EQ(planarvo_context_prepare_kernels_for(c, "track, simulate"), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(entries(), simulate + track);
  EXPECT_EQ(planarvo_context_prepare_kernels_for(c, "tracking"), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("tracking"), std::string::npos);
  EXPECT_EQ(planarvo_context_prepare_kernels_for(nullptr, "track"), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_context_destroy(c);
}

TEST(CApi, LastErrorIsPerThread) {
  EXPECT_EQ(planarvo_context_create(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  const std::string here = planarvo_last_error();
  std::string there = "unset";
  std::thread t([&] {
    there = planarvo_last_error();  // nothing failed on this thread yet
    EXPECT_EQ(planarvo_camera_load("/nonexistent/camera.yaml", nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  });
  t.join();
  EXPECT_EQ(there, "");
  EXPECT_EQ(std::string(planarvo_last_error()), here);
}

TEST(CApi, StatusNamesAreDistinct) {
  EXPECT_STREQ(planarvo_status_name(PLANARVO_OK), "PLANARVO_OK");
  EXPECT_STREQ(planarvo_status_name(PLANARVO_ERROR_NO_DEVICE), "PLANARVO_ERROR_NO_DEVICE");
  EXPECT_STREQ(planarvo_status_name(PLANARVO_ERROR_OUT_OF_MEMORY), "PLANARVO_ERROR_OUT_OF_MEMORY");
  EXPECT_STREQ(planarvo_status_name(static_cast<planarvo_status>(999)), "PLANARVO_ERROR_UNKNOWN");
  std::set<std::string> names;
  for (int s = PLANARVO_OK; s <= PLANARVO_ERROR_OUT_OF_MEMORY; ++s) {
    const std::string name = planarvo_status_name(static_cast<planarvo_status>(s));
    EXPECT_NE(name, "PLANARVO_ERROR_UNKNOWN") << s;
    names.insert(name);
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(PLANARVO_ERROR_OUT_OF_MEMORY + 1));
}

// The message reaches a C caller whole: a NUL byte from a file is written \x00 rather than cutting
// the message there, and a path of megabytes is shortened in its middle, keeping how the message
// ends (issue 27: the message stopped mid-word; a 5 MB path was echoed whole).
TEST(CApi, MessagesCarryEveryByteAndStayShort) {
  planarvo::test::ScratchDir dir;
  const std::string tum = (dir / "nul.txt").string();
  {
    std::ofstream f(tum, std::ios::binary);
    f << "# t x y z qx qy qz qw\n0.0 0";
    f.put('\0');
    f << "abc 0 0 0 0 0 1\n";
  }
  double t[1];
  planarvo_se2 p[1];
  size_t n = 0;
  EXPECT_EQ(planarvo_read_tum(tum.c_str(), t, p, 1, &n), PLANARVO_ERROR_INVALID_INPUT);
  const std::string nul = planarvo_last_error();
  EXPECT_NE(nul.find(tum + ":2:"), std::string::npos) << nul;
  EXPECT_NE(nul.find("'0\\x00abc' is not a number"), std::string::npos) << nul;

  const std::string long_path = "/nonexistent-planarvo/" + std::string(5u << 20, 'a') + "/camera.yaml";
  planarvo_camera camera;
  EXPECT_EQ(planarvo_camera_load(long_path.c_str(), &camera), PLANARVO_ERROR_INVALID_INPUT);
  const std::string msg = planarvo_last_error();
  EXPECT_LE(msg.size(), 4096u + 64u);
  EXPECT_EQ(msg.substr(0, 22), long_path.substr(0, 22));
  const std::string end = "a/camera.yaml: cannot be read (File name too long)";
  ASSERT_GE(msg.size(), end.size());
  EXPECT_EQ(msg.substr(msg.size() - end.size()), end);
}

TEST(CApi, ExtrinsicsMatrixFollowsConventions) {
  const planarvo_extrinsics e{0.1, -0.2, 0.3, 0, 0, 0};
  double m[16];
  ASSERT_EQ(planarvo_extrinsics_matrix(&e, m), PLANARVO_OK);
  // Straight down, image top forward: camera z -> robot -z, camera y (image down) -> robot -x.
  EXPECT_DOUBLE_EQ(m[2 * 4 + 2], -1.0);
  EXPECT_DOUBLE_EQ(m[0 * 4 + 1], -1.0);
  EXPECT_DOUBLE_EQ(m[0 * 4 + 3], 0.1);
  EXPECT_DOUBLE_EQ(m[2 * 4 + 3], 0.3);
  EXPECT_DOUBLE_EQ(m[15], 1.0);
}

}  // namespace

namespace {

using planarvo::test::ScratchDir;

planarvo_context* make_context() {
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(nullptr, &c), PLANARVO_OK) << planarvo_last_error();
  return c;
}

planarvo_sim_options tiny_sim(const std::string& texture) {
  planarvo_sim_options o;
  planarvo_sim_options_init(&o);
  static std::string tex;
  tex = texture;
  o.texture = tex.c_str();
  o.seconds = 0.2;
  EXPECT_EQ(planarvo_sim_default_camera(96, 64, 80.0, &o.camera), PLANARVO_OK);
  return o;
}

TEST(CApiData, MissingDatasetIsInvalidInputNamingIt) {
  planarvo_dataset* d = nullptr;
  EXPECT_EQ(planarvo_dataset_open("/nonexistent/planarvo-ds", nullptr, &d), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_EQ(d, nullptr);
  EXPECT_NE(std::string(planarvo_last_error()).find("/nonexistent/planarvo-ds"), std::string::npos);
}

TEST(CApiData, SimOptionsDefaultToThePapersConfigurationOne) {
  planarvo_sim_options o;
  planarvo_sim_options_init(&o);
  EXPECT_EQ(o.struct_size, sizeof o);
  EXPECT_DOUBLE_EQ(o.extrinsics.x, 0.2441);
  EXPECT_NEAR(o.extrinsics.pitch, 17.6 * M_PI / 180, 1e-12);
  EXPECT_EQ(o.camera.width, 640);
  EXPECT_DOUBLE_EQ(o.fps, 30.0);
}

TEST(CApiData, SimulateValidatesItsOptions) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options o;
  planarvo_sim_options_init(&o);
  EXPECT_EQ(planarvo_simulate(c, &o, dir.path().c_str()), PLANARVO_ERROR_INVALID_ARGUMENT);  // no texture
  o = tiny_sim("/nonexistent/texture.png");
  EXPECT_EQ(planarvo_simulate(c, &o, (dir / "a").c_str()), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_NE(std::string(planarvo_last_error()).find("/nonexistent/texture.png"), std::string::npos);
  o = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  o.fps = -1;
  EXPECT_EQ(planarvo_simulate(c, &o, (dir / "b").c_str()), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_context_destroy(c);
}

TEST(CApiData, ProgressCallbackCancels) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options o = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  int calls = 0;
  o.progress = [](void* user, double, const char*) { return ++*static_cast<int*>(user) >= 2 ? 1 : 0; };
  o.progress_user_data = &calls;
  EXPECT_EQ(planarvo_simulate(c, &o, dir.path().c_str()), PLANARVO_ERROR_CANCELLED);
  EXPECT_GE(calls, 2);
  planarvo_context_destroy(c);
}

TEST(CApiData, SimulatedDatasetReadsBackThroughTheApi) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options o = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  ASSERT_EQ(planarvo_simulate(c, &o, dir.path().c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset* d = nullptr;
  ASSERT_EQ(planarvo_dataset_open(dir.path().c_str(), nullptr, &d), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK);
  EXPECT_EQ(info.frame_count, 6);
  EXPECT_EQ(info.camera.width, 96);
  EXPECT_DOUBLE_EQ(info.camera.fx, o.camera.fx);
  EXPECT_TRUE(info.has_groundtruth && info.has_odometry && info.has_direction && info.has_extrinsics_gt);
  EXPECT_NEAR(info.extrinsics_gt.yaw, o.extrinsics.yaw, 1e-12);
  planarvo_image img{};
  ASSERT_EQ(planarvo_dataset_frame(d, 5, &img), PLANARVO_OK);
  EXPECT_EQ(img.width, 96);
  EXPECT_EQ(img.height, 64);
  EXPECT_EQ(img.format, PLANARVO_GRAY8);
  EXPECT_GE(img.stride, 96u);
  planarvo_frame_data f{};
  ASSERT_EQ(planarvo_dataset_frame_data(d, 0, &f), PLANARVO_OK);
  EXPECT_TRUE(f.has_groundtruth && f.has_odometry);
  EXPECT_FALSE(f.has_direction);  // frame 0 has no interval before it
  EXPECT_DOUBLE_EQ(f.groundtruth.x, 0.0);
  EXPECT_EQ(planarvo_dataset_frame(d, 6, &img), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_dataset_destroy(d);
  planarvo_context_destroy(c);
}

// The region of interest through the C API: the simulator writes it into camera.yaml, the data
// set and planarvo_camera_load read it back, planarvo_dataset_set_roi replaces it (and refuses,
// changing nothing, a region outside the image).
TEST(CApiData, RegionOfInterestTravelsWithTheCamera) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options o = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  o.camera.roi = planarvo_region{4, 8, 80, 40};
  ASSERT_EQ(planarvo_simulate(c, &o, dir.path().c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_camera cam{};
  ASSERT_EQ(planarvo_camera_load((dir.path() / "camera.yaml").c_str(), &cam), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(cam.roi.x, 4);
  EXPECT_EQ(cam.roi.y, 8);
  EXPECT_EQ(cam.roi.width, 80);
  EXPECT_EQ(cam.roi.height, 40);
  planarvo_dataset* d = nullptr;
  ASSERT_EQ(planarvo_dataset_open(dir.path().c_str(), nullptr, &d), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK);
  EXPECT_EQ(info.camera.roi.width, 80);
  const planarvo_region outside{50, 8, 80, 40};  // 96 pixels wide: 50 + 80 > 96
  EXPECT_EQ(planarvo_dataset_set_roi(d, &outside), PLANARVO_ERROR_INVALID_INPUT);
  ASSERT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK);
  EXPECT_EQ(info.camera.roi.x, 4);
  const planarvo_region other{0, 0, 96, 32};
  ASSERT_EQ(planarvo_dataset_set_roi(d, &other), PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK);
  EXPECT_EQ(info.camera.roi.height, 32);
  ASSERT_EQ(planarvo_dataset_set_roi(d, nullptr), PLANARVO_OK);
  ASSERT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK);
  EXPECT_EQ(info.camera.roi.width, 0);
  EXPECT_EQ(planarvo_dataset_set_roi(nullptr, &other), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_dataset_destroy(d);
  planarvo_context_destroy(c);
}

// The rolling shutter's readout through the C API: planarvo_camera <-> camera.yaml both ways
// (exactly), the simulator's readout_time written into its camera.yaml and read back by the data
// set, exposure_time and readout_time checked, and neither read from a struct_size that ends
// before them.
TEST(CApiData, RollingShutterTravelsWithTheCamera) {
  ScratchDir dir;
  planarvo_camera cam{};
  ASSERT_EQ(planarvo_sim_default_camera(96, 64, 80.0, &cam), PLANARVO_OK);
  EXPECT_EQ(cam.rolling_shutter_readout, 0.0);
  EXPECT_EQ(cam.exposure_time, 0.0);
  cam.rolling_shutter_readout = 0.0123456789012345;
  cam.exposure_time = 0.00398765432109876;
  const std::string path = (dir / "camera.yaml").string();
  ASSERT_EQ(planarvo_camera_save(path.c_str(), &cam), PLANARVO_OK) << planarvo_last_error();
  planarvo_camera back{};
  ASSERT_EQ(planarvo_camera_load(path.c_str(), &back), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(back.rolling_shutter_readout, cam.rolling_shutter_readout);
  EXPECT_EQ(back.exposure_time, cam.exposure_time);
  EXPECT_EQ(back.fx, cam.fx);
  EXPECT_EQ(back.width, cam.width);
  cam.rolling_shutter_readout = -0.01;
  EXPECT_NE(planarvo_camera_save((dir / "bad.yaml").c_str(), &cam), PLANARVO_OK);
  EXPECT_NE(std::string(planarvo_last_error()).find("rolling_shutter_readout"), std::string::npos);
  cam.rolling_shutter_readout = 0.0;
  cam.exposure_time = std::nan("");
  EXPECT_NE(planarvo_camera_save((dir / "bad.yaml").c_str(), &cam), PLANARVO_OK);
  EXPECT_NE(std::string(planarvo_last_error()).find("exposure_time"), std::string::npos);

  planarvo_context* c = make_context();
  planarvo_sim_options o = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  EXPECT_EQ(o.readout_time, 0.0);
  EXPECT_EQ(o.exposure_time, 0.0);
  o.readout_time = 0.02;
  o.exposure_time = 0.003;
  ASSERT_EQ(planarvo_simulate(c, &o, (dir / "rs").c_str()), PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(planarvo_camera_load((dir / "rs" / "camera.yaml").c_str(), &back), PLANARVO_OK);
  EXPECT_EQ(back.rolling_shutter_readout, 0.02);
  EXPECT_EQ(back.exposure_time, 0.003);
  planarvo_dataset* d = nullptr;
  ASSERT_EQ(planarvo_dataset_open((dir / "rs").c_str(), nullptr, &d), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK);
  EXPECT_EQ(info.camera.rolling_shutter_readout, 0.02);
  EXPECT_EQ(info.camera.exposure_time, 0.003);
  planarvo_dataset_destroy(d);

  const auto refused = [&](double readout, double exposure, const char* says) {
    planarvo_sim_options b = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
    b.readout_time = readout;
    b.exposure_time = exposure;
    EXPECT_EQ(planarvo_simulate(c, &b, (dir / "refused").c_str()), PLANARVO_ERROR_INVALID_ARGUMENT) << says;
    EXPECT_NE(std::string(planarvo_last_error()).find(says), std::string::npos) << planarvo_last_error();
  };
  refused(-1, 0, "readout_time");
  refused(0.05, 0, "readout_time");  // longer than the frame period at 30 fps
  refused(0, -1, "exposure_time");
  refused(0, 0.05, "exposure_time");
  // An older caller's struct ends before the new fields: they are not read.
  planarvo_sim_options old = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  old.readout_time = -1;
  old.exposure_time = -1;
  old.struct_size = offsetof(planarvo_sim_options, readout_time);
  EXPECT_EQ(planarvo_simulate(c, &old, (dir / "old").c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_context_destroy(c);
}

TEST(CApiData, ExtrinsicsAndTumRoundTrip) {
  ScratchDir dir;
  const planarvo_extrinsics e{0.25, -0.02, 0.18, 0.2, 0.3, -0.1};
  double cov[36] = {};
  cov[0] = 1e-6;
  cov[35] = 4e-4;
  const std::string path = (dir / "extrinsics.yaml").string();
  ASSERT_EQ(planarvo_extrinsics_save(path.c_str(), &e, cov, "x,yaw", "test", "a note"), PLANARVO_OK)
      << planarvo_last_error();
  planarvo_extrinsics r{};
  ASSERT_EQ(planarvo_extrinsics_load(path.c_str(), &r), PLANARVO_OK) << planarvo_last_error();
  EXPECT_DOUBLE_EQ(r.yaw, e.yaw);
  EXPECT_DOUBLE_EQ(r.z, e.z);
  const planarvo_extrinsics bad{0, 0, NAN, 0, 0, 0};
  EXPECT_EQ(planarvo_extrinsics_save(path.c_str(), &bad, nullptr, nullptr, nullptr, nullptr),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  const double t[2] = {0.0, 0.1};
  const planarvo_se2 p[2] = {{0, 0, 0}, {0.1, 0.02, 0.3}};
  const std::string tum = (dir / "traj.txt").string();
  ASSERT_EQ(planarvo_write_tum(tum.c_str(), t, p, 2), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(planarvo_write_tum("/nonexistent/dir/traj.txt", t, p, 2), PLANARVO_ERROR_IO);
}

}  // namespace

namespace {

TEST(CApiTracker, TracksFramesWithStatusesNotErrors) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options o = tiny_sim(planarvo::test::texture("asphalt_01.png").string());
  ASSERT_EQ(planarvo_sim_default_camera(320, 240, 80.0, &o.camera), PLANARVO_OK);
  o.seconds = 0.3;
  ASSERT_EQ(planarvo_simulate(c, &o, dir.path().c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset* d = nullptr;
  ASSERT_EQ(planarvo_dataset_open(dir.path().c_str(), nullptr, &d), PLANARVO_OK);

  planarvo_tracker* t = nullptr;
  EXPECT_EQ(planarvo_tracker_create(c, nullptr, &o.extrinsics, nullptr, &t), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_extrinsics below = o.extrinsics;
  below.z = -0.1;
  EXPECT_EQ(planarvo_tracker_create(c, &o.camera, &below, nullptr, &t), PLANARVO_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(planarvo_tracker_create(c, &o.camera, &o.extrinsics, nullptr, &t), PLANARVO_OK) << planarvo_last_error();

  planarvo_track_result r{};
  r.struct_size = sizeof r;
  planarvo_image img{};
  planarvo_frame_data f{};
  for (int64_t i = 0; i < 9; ++i) {
    ASSERT_EQ(planarvo_dataset_frame(d, i, &img), PLANARVO_OK);
    ASSERT_EQ(planarvo_dataset_frame_data(d, i, &f), PLANARVO_OK);
    ASSERT_EQ(planarvo_tracker_track(t, &img, f.timestamp, &r), PLANARVO_OK) << planarvo_last_error();
    EXPECT_EQ(r.status, i == 0 ? PLANARVO_TRACK_FIRST : PLANARVO_TRACK_OK) << i << " " << r.reason;
  }
  // The accumulated pose against ground truth (relative to frame 0, which is the origin).
  EXPECT_NEAR(r.pose.x, f.groundtruth.x, 1e-4);
  EXPECT_NEAR(r.pose.y, f.groundtruth.y, 1e-4);
  EXPECT_NEAR(r.pose.theta, f.groundtruth.theta, 1e-3);

  // A frame of another size: LOST with a reason, not an error; the pose stays finite.
  std::vector<uint8_t> small(100 * 80, 128);
  planarvo_image wrong{small.data(), 100, 80, 100, PLANARVO_GRAY8};
  ASSERT_EQ(planarvo_tracker_track(t, &wrong, f.timestamp + 0.033, &r), PLANARVO_OK);
  EXPECT_EQ(r.status, PLANARVO_TRACK_LOST);
  EXPECT_GT(std::strlen(r.reason), 0u);
  EXPECT_TRUE(std::isfinite(r.pose.x) && std::isfinite(r.pose.theta));

  // Caller errors are statuses.
  planarvo_image empty{nullptr, 320, 240, 320, PLANARVO_GRAY8};
  EXPECT_EQ(planarvo_tracker_track(t, &empty, 1.0, &r), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_image short_stride = img;
  short_stride.stride = 10;
  EXPECT_EQ(planarvo_tracker_track(t, &short_stride, 1.0, &r), PLANARVO_ERROR_INVALID_ARGUMENT);

  // Reset: the next frame is FIRST again; colour input is converted.
  ASSERT_EQ(planarvo_tracker_reset(t), PLANARVO_OK);
  ASSERT_EQ(planarvo_dataset_frame(d, 0, &img), PLANARVO_OK);
  std::vector<uint8_t> bgr(static_cast<size_t>(img.width * img.height * 3));
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int k = 0; k < 3; ++k)
        bgr[static_cast<size_t>((y * img.width + x) * 3 + k)] =
            static_cast<const uint8_t*>(img.data)[static_cast<size_t>(y) * img.stride + static_cast<size_t>(x)];
  planarvo_image colour{bgr.data(), img.width, img.height, static_cast<size_t>(img.width * 3), PLANARVO_BGR8};
  ASSERT_EQ(planarvo_tracker_track(t, &colour, 5.0, &r), PLANARVO_OK);
  EXPECT_EQ(r.status, PLANARVO_TRACK_FIRST);
  EXPECT_DOUBLE_EQ(r.pose.x, 0.0);

  planarvo_tracker_destroy(t);
  planarvo_dataset_destroy(d);
  planarvo_context_destroy(c);
}

// level0_subsample: checked when struct_size covers it, not read when it does not (a caller
// built against 0.1's struct), and a subsampling tracker tracks.
TEST(CApiTracker, Level0SubsampleIsCheckedOnlyWhenTheStructHasIt) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options so = tiny_sim(planarvo::test::texture("skimage_gravel.png").string());
  ASSERT_EQ(planarvo_simulate(c, &so, dir.path().c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_tracker_options o;
  planarvo_tracker_options_init(&o);
  EXPECT_EQ(o.level0_subsample, 0);
  o.finest_level = 0;
  o.level0_subsample = 9;
  planarvo_tracker* t = nullptr;
  EXPECT_EQ(planarvo_tracker_create(c, &so.camera, &so.extrinsics, &o, &t), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(t, nullptr);
  o.struct_size = offsetof(planarvo_tracker_options, level0_subsample);
  ASSERT_EQ(planarvo_tracker_create(c, &so.camera, &so.extrinsics, &o, &t), PLANARVO_OK) << planarvo_last_error();
  planarvo_tracker_destroy(t);
  t = nullptr;
  o.struct_size = sizeof o;
  o.level0_subsample = 2;
  ASSERT_EQ(planarvo_tracker_create(c, &so.camera, &so.extrinsics, &o, &t), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset* d = nullptr;
  ASSERT_EQ(planarvo_dataset_open(dir.path().c_str(), nullptr, &d), PLANARVO_OK);
  planarvo_track_result r{};
  r.struct_size = sizeof r;
  planarvo_image img{};
  planarvo_frame_data f{};
  for (int64_t i = 0; i < 6; ++i) {
    ASSERT_EQ(planarvo_dataset_frame(d, i, &img), PLANARVO_OK);
    ASSERT_EQ(planarvo_dataset_frame_data(d, i, &f), PLANARVO_OK);
    ASSERT_EQ(planarvo_tracker_track(t, &img, f.timestamp, &r), PLANARVO_OK) << planarvo_last_error();
    EXPECT_EQ(r.status, i == 0 ? PLANARVO_TRACK_FIRST : PLANARVO_TRACK_OK) << i << " " << r.reason;
  }
  EXPECT_NEAR(r.pose.x, f.groundtruth.x, 1e-4);
  EXPECT_NEAR(r.pose.y, f.groundtruth.y, 1e-4);
  planarvo_dataset_destroy(d);
  planarvo_tracker_destroy(t);
  planarvo_context_destroy(c);
}

// level0_subsample's meaning at 640x480, where the automatic finest level is level 0 after
// level 1: 0 with finest_level -1 is the same tracking as 3 (one pixel per 3x3 block), and close
// to finest_level 0 with 3 (which aligns level 1 on every pixel, where the automatic choice takes
// one per 2x2 block); 1 with -1 the same as finest_level 0 on every pixel; finest_level 1 never
// reaches level 0.
TEST(CApiTracker, Level0SubsampleWithTheAutomaticFinestLevel) {
  planarvo_context* c = make_context();
  ScratchDir dir;
  planarvo_sim_options so;
  planarvo_sim_options_init(&so);
  const std::string tex = planarvo::test::texture("asphalt_01.png").string();
  so.texture = tex.c_str();
  so.seconds = 0.2;
  ASSERT_EQ(planarvo_sim_default_camera(640, 480, 80.0, &so.camera), PLANARVO_OK);
  ASSERT_EQ(planarvo_simulate(c, &so, dir.path().c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_dataset* d = nullptr;
  ASSERT_EQ(planarvo_dataset_open(dir.path().c_str(), nullptr, &d), PLANARVO_OK);
  struct Run {
    int32_t finest, block;
    std::vector<planarvo_se2> motions;
    std::vector<int32_t> level0_steps;
  };
  std::vector<Run> runs = {{-1, 0, {}, {}}, {0, 3, {}, {}}, {-1, 1, {}, {}},
                           {0, 0, {}, {}},  {1, 0, {}, {}}, {-1, 3, {}, {}}};
  for (Run& run : runs) {
    planarvo_tracker_options o;
    planarvo_tracker_options_init(&o);
    o.finest_level = run.finest;
    o.level0_subsample = run.block;
    planarvo_tracker* t = nullptr;
    ASSERT_EQ(planarvo_tracker_create(c, &so.camera, &so.extrinsics, &o, &t), PLANARVO_OK) << planarvo_last_error();
    planarvo_image img{};
    planarvo_frame_data f{};
    planarvo_track_result r{};
    r.struct_size = sizeof r;
    for (int64_t i = 0; i < 6; ++i) {
      ASSERT_EQ(planarvo_dataset_frame(d, i, &img), PLANARVO_OK);
      ASSERT_EQ(planarvo_dataset_frame_data(d, i, &f), PLANARVO_OK);
      ASSERT_EQ(planarvo_tracker_track(t, &img, f.timestamp, &r), PLANARVO_OK) << planarvo_last_error();
      if (i == 0) continue;
      EXPECT_EQ(r.status, PLANARVO_TRACK_OK) << i << " " << r.reason;
      run.motions.push_back(r.motion);
      run.level0_steps.push_back(r.iterations[0]);
    }
    planarvo_tracker_destroy(t);
  }
  auto same = [](const Run& a, const Run& b) {
    ASSERT_EQ(a.motions.size(), b.motions.size());
    for (size_t i = 0; i < a.motions.size(); ++i) {
      EXPECT_EQ(a.motions[i].x, b.motions[i].x) << i;
      EXPECT_EQ(a.motions[i].y, b.motions[i].y) << i;
      EXPECT_EQ(a.motions[i].theta, b.motions[i].theta) << i;
    }
  };
  same(runs[0], runs[5]);
  same(runs[2], runs[3]);
  ASSERT_EQ(runs[0].motions.size(), runs[1].motions.size());
  for (size_t i = 0; i < runs[0].motions.size(); ++i) {
    EXPECT_NEAR(runs[0].motions[i].x, runs[1].motions[i].x, 1e-5) << i;
    EXPECT_NEAR(runs[0].motions[i].y, runs[1].motions[i].y, 1e-5) << i;
    EXPECT_NEAR(runs[0].motions[i].theta, runs[1].motions[i].theta, 1e-5) << i;
  }
  EXPECT_NE(runs[0].motions[2].x, runs[2].motions[2].x) << "1/9 and every pixel differ";
  for (size_t i = 0; i < runs[0].level0_steps.size(); ++i) {
    EXPECT_GT(runs[0].level0_steps[i], 0) << i;
    EXPECT_GT(runs[2].level0_steps[i], 0) << i;
    EXPECT_EQ(runs[4].level0_steps[i], 0) << i;
  }
  planarvo_dataset_destroy(d);
  planarvo_context_destroy(c);
}

TEST(CApiTracker, EvaluateMotionsChecksItsArguments) {
  planarvo_motion_accuracy a{};
  const planarvo_se2 m[2] = {{0.01, 0, 0}, {0.01, 0, 0.01}};
  const double dt[2] = {0.1, 0.1};
  EXPECT_EQ(planarvo_evaluate_motions(m, m, dt, nullptr, 2, 1e-3, &a), PLANARVO_ERROR_INVALID_ARGUMENT);  // no struct_size
  a.struct_size = sizeof a;
  ASSERT_EQ(planarvo_evaluate_motions(m, m, dt, nullptr, 2, 1e-3, &a), PLANARVO_OK);
  EXPECT_EQ(a.intervals, 2);
  EXPECT_DOUBLE_EQ(a.rms_translation, 0.0);
  EXPECT_NEAR(a.distance, 0.02, 1e-15);
}

}  // namespace
