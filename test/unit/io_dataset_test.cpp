// Data sets (src/io/dataset/dataset.h) on small synthetic directories: frames, interpolation of
// odometry and ground truth to frame times against hand-computed values, direction labels by
// interval midpoint, every bad input as InvalidInput naming the file (and line), progress and
// cancelling, and a video standing in for images/ + frames.txt.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/test_util.h"
#include "io/dataset/dataset.h"
#include "io/dataset/frame_image.h"
#include "unit/io_test_helpers.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using io::Dataset;
using io::DatasetOptions;
using test::expect_error;
using test::expect_invalid_input;
using test::ScratchDir;
using test::write_text;
using ::testing::HasSubstr;

// Binary-exact frame times, so that interval midpoints and label boundaries are exact too.
const std::vector<double> kTimes = {1.0, 1.25, 1.5, 1.75};
constexpr int kW = 32, kH = 24;

CameraModel small_camera(int w = kW, int h = kH) {
  CameraModel c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = 0.9 * w;
  c.cx = 0.5 * w;
  c.cy = 0.5 * h;
  c.k1 = -0.1;
  return c;
}

cv::Mat noise_image(int seed, int w = kW, int h = kH) {
  cv::Mat m(h, w, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(seed) + 1);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

std::string image_name(size_t i) { return "images/" + std::to_string(1000 + i) + ".png"; }

// camera.yaml, images/*.png (random noise) and frames.txt at kTimes.
void make_dataset(const fs::path& dir) {
  fs::create_directories(dir / "images");
  io::write_camera_yaml((dir / "camera.yaml").string(), small_camera());
  std::vector<io::FrameEntry> frames;
  for (size_t i = 0; i < kTimes.size(); ++i) {
    ASSERT_TRUE(cv::imwrite((dir / image_name(i)).string(), noise_image(static_cast<int>(i))));
    frames.push_back({kTimes[i], image_name(i)});
  }
  io::write_frames((dir / "frames.txt").string(), frames);
}

TEST(IoDataset, OpensImagesAndReadsFrames) {
  ScratchDir dir;
  make_dataset(dir.path());
  Dataset ds(dir.path().string());
  EXPECT_FALSE(ds.is_video());
  ASSERT_EQ(ds.frame_count(), 4);
  EXPECT_EQ(ds.camera().width, kW);
  EXPECT_EQ(ds.camera().k1, -0.1);
  for (int64_t i = 0; i < 4; ++i) {
    EXPECT_EQ(ds.timestamp(i), kTimes[static_cast<size_t>(i)]);
    const cv::Mat f = ds.frame(i);
    ASSERT_EQ(f.type(), CV_8UC1);
    ASSERT_EQ(f.size(), cv::Size(kW, kH));
    EXPECT_EQ(cv::norm(f, noise_image(static_cast<int>(i)), cv::NORM_INF), 0.0) << i;
    EXPECT_THAT(ds.frame_source(i), HasSubstr(image_name(static_cast<size_t>(i))));
  }
  EXPECT_FALSE(ds.has_odometry());
  EXPECT_FALSE(ds.odometry_at(1).has_value());
  EXPECT_FALSE(ds.has_direction());
  EXPECT_FALSE(ds.direction_for_interval(1).has_value());
  EXPECT_FALSE(ds.groundtruth_at(1).has_value());
  EXPECT_FALSE(ds.extrinsics().has_value());
  EXPECT_FALSE(ds.extrinsics_gt().has_value());
  expect_error([&] { ds.frame(4); }, ErrorCode::InvalidArgument, "frame index 4");
  expect_error([&] { ds.timestamp(-1); }, ErrorCode::InvalidArgument, "frame index -1");

  // Movable: the C API holds it by pointer, callers by value.
  Dataset moved = std::move(ds);
  EXPECT_EQ(moved.frame_count(), 4);
}

// Image files are read ahead while frames are asked for in order: the frames are the files'
// whatever the order of the calls (in order, repeated, backwards, skipping), and an undecodable
// file's error comes when its frame is asked for, not when the one before it is.
TEST(IoDataset, ReadingAheadGivesTheFramesInAnyOrder) {
  ScratchDir dir;
  make_dataset(dir.path());
  Dataset ds(dir.path().string());
  for (const int64_t i : {0, 1, 2, 3, 3, 2, 0, 1, 3, 0, 2}) {
    const cv::Mat f = ds.frame(i);
    ASSERT_EQ(f.size(), cv::Size(kW, kH));
    EXPECT_EQ(cv::norm(f, noise_image(static_cast<int>(i)), cv::NORM_INF), 0.0) << i;
  }
  write_text(dir / image_name(2), "this is not a PNG file");
  Dataset bad(dir.path().string());
  EXPECT_NO_THROW(bad.frame(0));
  EXPECT_NO_THROW(bad.frame(1));  // frame 2's decoding fails beside it
  expect_invalid_input([&] { bad.frame(2); }, (dir / image_name(2)).string());
  EXPECT_EQ(cv::norm(bad.frame(3), noise_image(3), cv::NORM_INF), 0.0);
  // Dropped unasked: a data set destroyed with frame 2's failing read-ahead pending, and one
  // that asks for another frame instead.
  {
    Dataset dropped(dir.path().string());
    EXPECT_NO_THROW(dropped.frame(0));
    EXPECT_NO_THROW(dropped.frame(1));
  }
  Dataset skipped(dir.path().string());
  EXPECT_NO_THROW(skipped.frame(0));
  EXPECT_NO_THROW(skipped.frame(1));
  EXPECT_EQ(cv::norm(skipped.frame(3), noise_image(3), cv::NORM_INF), 0.0);
}

// Encoded images cut short (what a CompressedImage or an image file holds when its bytes stop
// early): JPEG and PNG as OpenCV writes them, whole and cut at several places.
TEST(IoImageBytes, CutJpegAndPngAreFoundWholeOnesPass) {
  cv::Mat img(48, 64, CV_8UC1);
  cv::randu(img, 0, 255);
  for (const char* ext : {".jpg", ".png"}) {
    std::vector<uchar> bytes;
    ASSERT_TRUE(cv::imencode(ext, img, bytes));
    EXPECT_EQ(io::detail::truncation_problem(bytes.data(), bytes.size()), "") << ext;
    for (double keep : {0.2, 0.5, 0.9}) {
      const size_t n = static_cast<size_t>(keep * static_cast<double>(bytes.size()));
      EXPECT_NE(io::detail::truncation_problem(bytes.data(), n), "") << ext << " cut to " << keep;
    }
    // Data after the end (a little, or a card's zero padding) is still a whole image.
    std::vector<uchar> padded = bytes;
    padded.insert(padded.end(), 16, 0x20);
    EXPECT_EQ(io::detail::truncation_problem(padded.data(), padded.size()), "") << ext;
    padded.insert(padded.end(), 2000, 0);
    EXPECT_EQ(io::detail::truncation_problem(padded.data(), padded.size()), "") << ext;
  }
  // Other formats are left to their decoders.
  const unsigned char bmp[4] = {'B', 'M', 0, 0};
  EXPECT_EQ(io::detail::truncation_problem(bmp, sizeof bmp), "");
}

TEST(IoDataset, ColourImagesAreConvertedToGrey) {
  ScratchDir dir;
  make_dataset(dir.path());
  cv::Mat colour(kH, kW, CV_8UC3);
  cv::randu(colour, 0, 256);
  ASSERT_TRUE(cv::imwrite((dir / image_name(1)).string(), colour));
  cv::Mat expected;
  cv::cvtColor(colour, expected, cv::COLOR_BGR2GRAY);
  Dataset ds(dir.path().string());
  EXPECT_EQ(cv::norm(ds.frame(1), expected, cv::NORM_INF), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Interpolation and labels

TEST(IoInterpolation, LinearInXYThetaTheShortWayRoundPi) {
  // theta goes from 3.0 to -2.9: the short way is through +-pi, by 2 pi - 5.9 = 0.3832.
  const std::vector<io::StampedPose> s = {{0.875, SE2(0, 0, 3.0)}, {1.625, SE2(3, -3, -2.9)}};
  const double step = 2 * M_PI - 5.9;
  const auto a = io::interpolate_pose(s, 1.0);  // f = 1/6
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->x, 0.5, 1e-12);
  EXPECT_NEAR(a->y, -0.5, 1e-12);
  EXPECT_NEAR(a->theta, 3.0 + step / 6, 1e-12);
  const auto b = io::interpolate_pose(s, 1.25);  // f = 1/2: past pi, so wrapped to negative
  ASSERT_TRUE(b);
  EXPECT_NEAR(b->x, 1.5, 1e-12);
  EXPECT_NEAR(b->y, -1.5, 1e-12);
  EXPECT_NEAR(b->theta, 3.0 + step / 2 - 2 * M_PI, 1e-12);
  EXPECT_LT(b->theta, -3.0);
  // The ends are the samples, exactly; outside the span there is none.
  EXPECT_EQ(io::interpolate_pose(s, 0.875)->theta, 3.0);
  EXPECT_EQ(io::interpolate_pose(s, 1.625)->x, 3.0);
  EXPECT_FALSE(io::interpolate_pose(s, 0.87499));
  EXPECT_FALSE(io::interpolate_pose(s, 1.7));
  EXPECT_FALSE(io::interpolate_pose({}, 1.0));
  EXPECT_FALSE(io::interpolate_pose(s, std::nan("")));
}

TEST(IoInterpolation, DirectionLabelCoversTheIntervalEndingAtItsTime) {
  const std::vector<io::DirectionLabel> l = {{1.0, 1}, {1.125, -1}, {1.5, 0}, {1.6, 1}};
  EXPECT_EQ(io::direction_at(l, 0.5), 1);      // the first label: everything up to its time
  EXPECT_EQ(io::direction_at(l, 1.0), 1);
  EXPECT_EQ(io::direction_at(l, 1.0001), -1);  // (1.0, 1.125]
  EXPECT_EQ(io::direction_at(l, 1.125), -1);   // the end of an interval belongs to it
  EXPECT_EQ(io::direction_at(l, 1.3), 0);
  EXPECT_EQ(io::direction_at(l, 1.6), 1);
  EXPECT_FALSE(io::direction_at(l, 1.61));     // after the last label
  EXPECT_FALSE(io::direction_at({}, 1.0));
}

TEST(IoDataset, OdometryAndGroundTruthAtFrameTimes) {
  ScratchDir dir;
  make_dataset(dir.path());
  // Odometry samples off the frame times, spanning frames 0..2 but not 3 (1.75).
  io::write_tum((dir / "odometry.txt").string(),
                {{0.875, SE2(0, 0, 3.0)}, {1.625, SE2(3, -3, -2.9)}});
  // Ground truth exactly at the frame times.
  const std::vector<io::StampedPose> gt = {
      {1.0, SE2(0.1, 0.2, 0.3)}, {1.25, SE2(-0.4, 0.5, -0.6)}, {1.5, SE2(0.7, -0.8, 3.1)}, {1.75, SE2(1, 1, -3.1)}};
  io::write_tum((dir / "groundtruth.txt").string(), gt);
  Dataset ds(dir.path().string());
  ASSERT_TRUE(ds.has_odometry());
  ASSERT_TRUE(ds.has_groundtruth());
  EXPECT_EQ(ds.odometry().size(), 2u);

  const double step = 2 * M_PI - 5.9;
  const auto o0 = ds.odometry_at(0), o1 = ds.odometry_at(1), o2 = ds.odometry_at(2);
  ASSERT_TRUE(o0 && o1 && o2);
  EXPECT_NEAR(o0->x, 0.5, 1e-12);
  EXPECT_NEAR(o0->theta, 3.0 + step / 6, 1e-12);
  EXPECT_NEAR(o1->y, -1.5, 1e-12);
  EXPECT_NEAR(o1->theta, 3.0 + step / 2 - 2 * M_PI, 1e-12);
  EXPECT_NEAR(o2->x, 2.5, 1e-12);  // f = 5/6
  EXPECT_NEAR(o2->theta, 3.0 + 5 * step / 6 - 2 * M_PI, 1e-12);
  EXPECT_FALSE(ds.odometry_at(3).has_value());  // after the odometry's last sample

  for (int64_t i = 0; i < 4; ++i) {
    const auto g = ds.groundtruth_at(i);
    ASSERT_TRUE(g);
    const auto& sample = ds.groundtruth()[static_cast<size_t>(i)].pose;
    EXPECT_EQ(g->x, sample.x);  // exact: no interpolation where the times coincide
    EXPECT_EQ(g->y, sample.y);
    EXPECT_EQ(g->theta, sample.theta);
    EXPECT_EQ(g->x, gt[static_cast<size_t>(i)].pose.x);
    EXPECT_NEAR(g->theta, gt[static_cast<size_t>(i)].pose.theta, 1e-15);
  }
}

TEST(IoDataset, DirectionForIntervalUsesTheMidpoint) {
  ScratchDir dir;
  make_dataset(dir.path());
  // Frame intervals' midpoints: 1.125, 1.375, 1.625.
  io::write_direction((dir / "direction.txt").string(), {{1.0, 1}, {1.125, -1}, {1.5, 0}, {1.6, 1}});
  Dataset ds(dir.path().string());
  ASSERT_TRUE(ds.has_direction());
  EXPECT_FALSE(ds.direction_for_interval(0).has_value());  // no interval before frame 0
  EXPECT_EQ(ds.direction_for_interval(1), -1);  // 1.125 in (1.0, 1.125]
  EXPECT_EQ(ds.direction_for_interval(2), 0);   // 1.375 in (1.125, 1.5]
  EXPECT_FALSE(ds.direction_for_interval(3).has_value());  // 1.625 after the last label
}

TEST(IoDataset, ReadsExtrinsicsFiles) {
  ScratchDir dir;
  make_dataset(dir.path());
  ExtrinsicsEstimate e;
  e.value = Extrinsics{0.2, -0.02, 0.18, 0.1, 0.2, -0.3};
  e.estimated[5] = true;  // yaw
  io::write_extrinsics_yaml((dir / "extrinsics_gt.yaml").string(), e);
  write_text(dir / "extrinsics.yaml", "%YAML:1.0\n---\nx: 0.25\ny: 0\nz: 0.2\nroll: 0\npitch: 0\nyaw: 0\n");
  Dataset ds(dir.path().string());
  ASSERT_TRUE(ds.extrinsics());
  ASSERT_TRUE(ds.extrinsics_gt());
  EXPECT_EQ(ds.extrinsics()->value.x, 0.25);
  EXPECT_EQ(ds.extrinsics_gt()->value.yaw, -0.3);
  EXPECT_EQ(ds.extrinsics_gt()->estimated, (std::array<bool, 6>{false, false, false, false, false, true}));
}

// ---------------------------------------------------------------------------------------------
// Bad input: each one InvalidInput naming the file (and line)

std::string open_error(const fs::path& dir, int line_of, const std::string& file, DatasetOptions o = {}) {
  return expect_invalid_input([&] { Dataset ds(dir.string(), o); }, file, line_of);
}

TEST(IoDatasetBadInput, DirectoryMissing) {
  ScratchDir dir;
  open_error(dir / "nowhere", 0, (dir / "nowhere").string());
}

TEST(IoDatasetBadInput, CameraYamlMissing) {
  ScratchDir dir;
  make_dataset(dir.path());
  fs::remove(dir / "camera.yaml");
  open_error(dir.path(), 0, (dir / "camera.yaml").string());
}

TEST(IoDatasetBadInput, CameraYamlLacksAKey) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "camera.yaml", "%YAML:1.0\n---\nimage_width: 32\nimage_height: 24\n"
                                  "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                                  "   data: [ 30., 0., 16., 0., 30., 12., 0., 0., 1. ]\n");
  EXPECT_THAT(open_error(dir.path(), 0, (dir / "camera.yaml").string()), HasSubstr("distortion_coefficients"));
}

TEST(IoDatasetBadInput, FramesTxtMissing) {
  ScratchDir dir;
  make_dataset(dir.path());
  fs::remove(dir / "frames.txt");
  EXPECT_THAT(open_error(dir.path(), 0, (dir / "frames.txt").string()), HasSubstr("does not exist"));
}

TEST(IoDatasetBadInput, EmptyDataSet) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "frames.txt", "# timestamp path\n\n");
  EXPECT_THAT(open_error(dir.path(), 0, (dir / "frames.txt").string()), HasSubstr("no frames"));
}

TEST(IoDatasetBadInput, NonIncreasingTimestamps) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "frames.txt", "# t path\n1.0 " + image_name(0) + "\n1.25 " + image_name(1) +
                                     "\n1.25 " + image_name(2) + "\n");
  open_error(dir.path(), 4, (dir / "frames.txt").string());
}

TEST(IoDatasetBadInput, NaNTimestamp) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "frames.txt", "1.0 " + image_name(0) + "\nnan " + image_name(1) + "\n");
  open_error(dir.path(), 2, (dir / "frames.txt").string());
}

TEST(IoDatasetBadInput, ImageMissingIsFoundAtOpen) {
  ScratchDir dir;
  make_dataset(dir.path());
  fs::remove(dir / image_name(2));
  const std::string msg = open_error(dir.path(), 0, (dir / image_name(2)).string());
  EXPECT_THAT(msg, HasSubstr("frames.txt:4"));  // the frames.txt line that names it
}

TEST(IoDatasetBadInput, ImageUnreadable) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / image_name(2), "this is not a PNG file");
  const std::string file = (dir / image_name(2)).string();
  Dataset ds(dir.path().string());  // not decoded at open...
  EXPECT_NO_THROW(ds.frame(1));
  expect_invalid_input([&] { ds.frame(2); }, file);  // ...but when read
  DatasetOptions verify;
  verify.verify_images = true;
  EXPECT_THAT(open_error(dir.path(), 0, file, verify), HasSubstr("cannot be decoded"));
}

// An image path that is a directory or a named pipe is named as such at open (issue 27: "does
// not exist", or "cannot be decoded" when read); a pipe is never opened.
TEST(IoDatasetBadInput, ImagePathsThatAreNotFilesAreNamedAsSuch) {
  for (const bool pipe : {false, true}) {
    ScratchDir dir;
    make_dataset(dir.path());
    const std::string file = (dir / image_name(2)).string();
    fs::remove(file);
    if (pipe)
      ASSERT_EQ(mkfifo(file.c_str(), 0600), 0);
    else
      fs::create_directory(file);
    EXPECT_THAT(open_error(dir.path(), 0, file), HasSubstr(pipe ? "named pipe" : "is a directory"));
    // Opened without the check, the frame itself says so when read.
    DatasetOptions lenient;
    lenient.allow_missing_images = true;
    Dataset ds(dir.path().string(), lenient);
    EXPECT_THAT(expect_invalid_input([&] { ds.frame(2); }, file), HasSubstr(pipe ? "named pipe" : "is a directory"));
  }
}

TEST(IoDatasetBadInput, ImageOfTheWrongSize) {
  ScratchDir dir;
  make_dataset(dir.path());
  ASSERT_TRUE(cv::imwrite((dir / image_name(3)).string(), noise_image(3, kW + 2, kH)));
  const std::string file = (dir / image_name(3)).string();
  Dataset ds(dir.path().string());
  const std::string msg = expect_invalid_input([&] { ds.frame(3); }, file);
  EXPECT_THAT(msg, HasSubstr("34x24"));
  EXPECT_THAT(msg, HasSubstr("camera.yaml says 32x24"));
  DatasetOptions verify;
  verify.verify_images = true;
  open_error(dir.path(), 0, file, verify);
}

TEST(IoDatasetBadInput, SixteenBitImagesAreRejected) {
  ScratchDir dir;
  make_dataset(dir.path());
  cv::Mat deep;
  noise_image(0).convertTo(deep, CV_16U, 256.0);
  ASSERT_TRUE(cv::imwrite((dir / image_name(0)).string(), deep));
  Dataset ds(dir.path().string());
  EXPECT_THAT(expect_invalid_input([&] { ds.frame(0); }, (dir / image_name(0)).string()),
              HasSubstr("16-bit"));
}

TEST(IoDatasetBadInput, OdometryMalformed) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "odometry.txt", "1.0 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 1\n");
  open_error(dir.path(), 2, (dir / "odometry.txt").string());
}

TEST(IoDatasetBadInput, OdometryWithoutSamples) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "odometry.txt", "# t x y z qx qy qz qw\n");
  open_error(dir.path(), 0, (dir / "odometry.txt").string());
}

TEST(IoDatasetBadInput, OdometryOnAnotherClock) {
  ScratchDir dir;
  make_dataset(dir.path());
  // Milliseconds against the frames' seconds: no frame falls in its span.
  io::write_tum((dir / "odometry.txt").string(), {{1000.0, SE2()}, {1750.0, SE2(1, 0, 0)}});
  EXPECT_THAT(open_error(dir.path(), 0, (dir / "odometry.txt").string()), HasSubstr("no frame"));
}

TEST(IoDatasetBadInput, DirectionMalformed) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "direction.txt", "1.0 1\n1.2 -1\n1.3 2\n");
  open_error(dir.path(), 3, (dir / "direction.txt").string());
}

TEST(IoDatasetBadInput, GroundtruthMalformed) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "groundtruth.txt", "# header\n1.0 0 0 0 0 0 0 1\n1.5 0 inf 0 0 0 0 1\n");
  open_error(dir.path(), 3, (dir / "groundtruth.txt").string());
}

TEST(IoDatasetBadInput, ExtrinsicsMalformed) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "extrinsics.yaml", "%YAML:1.0\n---\nx: 0.25\ny: 0\nz: 0.2\nroll: 0\npitch: 0\n");
  EXPECT_THAT(open_error(dir.path(), 0, (dir / "extrinsics.yaml").string()), HasSubstr("yaw"));
}

TEST(IoDatasetBadInput, ExtrinsicsGtMalformed) {
  ScratchDir dir;
  make_dataset(dir.path());
  write_text(dir / "extrinsics_gt.yaml", "%YAML:1.0\n---\nx: .Nan\ny: 0\nz: 0.2\nroll: 0\npitch: 0\nyaw: 0\n");
  open_error(dir.path(), 0, (dir / "extrinsics_gt.yaml").string());
}

// ---------------------------------------------------------------------------------------------
// Progress and cancelling

TEST(IoDataset, ReportsProgressAndCanBeCancelled) {
  ScratchDir dir;
  make_dataset(dir.path());
  std::vector<double> fractions;
  DatasetOptions o;
  o.verify_images = true;
  o.progress = [&](double f, const char* stage) {
    EXPECT_NE(stage, nullptr);
    fractions.push_back(f);
    return true;
  };
  Dataset ds(dir.path().string(), o);
  ASSERT_GE(fractions.size(), 2u + kTimes.size());  // start, each image, end
  EXPECT_EQ(fractions.front(), 0.0);
  EXPECT_EQ(fractions.back(), 1.0);
  for (size_t i = 1; i < fractions.size(); ++i) EXPECT_GE(fractions[i], fractions[i - 1]);

  int calls = 0;
  o.progress = [&](double, const char* stage) {
    ++calls;
    return std::string(stage) != "verifying images";
  };
  expect_error([&] { Dataset d2(dir.path().string(), o); }, ErrorCode::Cancelled, "verifying images");
  EXPECT_EQ(calls, 2);  // stopped at the first image
}

// The size an encoded image declares, read before decoding: as OpenCV decodes it, for JPEG
// (baseline, progressive, with extra bytes before a marker) and PNG; a declared size that is not
// the camera's is refused before the decoder allocates it (fuzz_image: a 296-byte JPEG that
// declared 18756x16724 pixels made it allocate 1.9 GB).
TEST(IoImageBytes, TheDeclaredSizeIsReadBeforeDecoding) {
  cv::Mat img(37, 53, CV_8UC1);
  cv::randu(img, 0, 255);
  for (const auto& [ext, params] : {std::pair<const char*, std::vector<int>>{".jpg", {}},
                                    {".jpg", {cv::IMWRITE_JPEG_PROGRESSIVE, 1}},
                                    {".png", {}}}) {
    std::vector<uchar> bytes;
    ASSERT_TRUE(cv::imencode(ext, img, bytes, params));
    const cv::Mat decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
    EXPECT_EQ(io::detail::declared_size(bytes.data(), bytes.size()), decoded.size()) << ext;
  }
  std::vector<uchar> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", img, jpeg));
  // Bytes before a marker (libjpeg skips them with a warning) do not hide the frame header.
  std::vector<uchar> extraneous(jpeg.begin(), jpeg.begin() + 2);
  extraneous.insert(extraneous.end(), {0x12, 0x34, 0x56});
  extraneous.insert(extraneous.end(), jpeg.begin() + 2, jpeg.end());
  EXPECT_EQ(io::detail::declared_size(extraneous.data(), extraneous.size()), cv::Size(53, 37));
  EXPECT_EQ(io::detail::declared_size(jpeg.data(), 2), cv::Size(0, 0));  // not within the bytes given

  // The data set refuses a file that declares another size, naming both, before decoding it.
  ScratchDir dir;
  make_dataset(dir.path());
  std::vector<uchar> big;
  cv::Mat frame(kH, kW, CV_8UC1, cv::Scalar(90));
  ASSERT_TRUE(cv::imencode(".jpg", frame, big));
  for (size_t at = 2; at + 9 < big.size(); ++at)
    if (big[at] == 0xFF && big[at + 1] == 0xC0) {  // SOF0: FF C0, length, precision, height, width
      big[at + 5] = 0x49, big[at + 6] = 0x44, big[at + 7] = 0x41, big[at + 8] = 0x54;
      break;
    }
  EXPECT_EQ(io::detail::declared_size(big.data(), big.size()), cv::Size(0x4154, 0x4944));
  const fs::path file = dir.path() / "images" / "000002.jpg";
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(big.data()),
                                              static_cast<std::streamsize>(big.size()));
  write_text(dir.path() / "frames.txt", "0.0 " + image_name(0) + "\n0.1 " + image_name(1) + "\n0.2 images/000002.jpg\n");
  DatasetOptions verify;
  verify.verify_images = true;
  EXPECT_THAT(open_error(dir.path(), 0, file.string(), verify), HasSubstr("declares 16724x18756 pixels"));
}

// ---------------------------------------------------------------------------------------------
// Video

constexpr int kVideoFrames = 12;
constexpr double kFps = 25.0;
constexpr int kVW = 64, kVH = 48;

cv::Mat video_frame(int i) {
  // Smooth content that JPEG keeps well: a gradient and a bright square that moves.
  cv::Mat m(kVH, kVW, CV_8UC1);
  for (int y = 0; y < kVH; ++y)
    for (int x = 0; x < kVW; ++x) m.at<uint8_t>(y, x) = static_cast<uint8_t>(40 + 2 * x + y);
  cv::rectangle(m, cv::Rect(4 + 3 * i, 12, 16, 16), cv::Scalar(230), cv::FILLED);
  return m;
}

std::string make_video_dataset(const fs::path& dir) {
  fs::create_directories(dir);
  io::write_camera_yaml((dir / "camera.yaml").string(), small_camera(kVW, kVH));
  const std::string video = (dir / "drive.avi").string();
  cv::VideoWriter w(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), kFps, cv::Size(kVW, kVH), false);
  EXPECT_TRUE(w.isOpened());
  for (int i = 0; i < kVideoFrames; ++i) w.write(video_frame(i));
  w.release();
  return video;
}

TEST(IoDatasetVideo, FramesTimesAndContent) {
  ScratchDir dir;
  DatasetOptions o;
  o.video = make_video_dataset(dir.path());
  Dataset ds(dir.path().string(), o);
  EXPECT_TRUE(ds.is_video());
  ASSERT_EQ(ds.frame_count(), kVideoFrames);
  for (int64_t i = 1; i < ds.frame_count(); ++i) {
    EXPECT_GT(ds.timestamp(i), ds.timestamp(i - 1));
    EXPECT_NEAR(ds.timestamp(i) - ds.timestamp(i - 1), 1.0 / kFps, 1e-3);
  }
  EXPECT_NEAR(ds.timestamp(0), 0.0, 1e-6);  // the first frame starts the container's clock
  std::vector<cv::Mat> sequential;
  for (int i = 0; i < kVideoFrames; ++i) {
    const cv::Mat f = ds.frame(i);
    ASSERT_EQ(f.type(), CV_8UC1);
    ASSERT_EQ(f.size(), cv::Size(kVW, kVH));
    // JPEG is lossy: the mean error is small, and the square is where it was written.
    EXPECT_LT(cv::norm(f, video_frame(i), cv::NORM_L1) / f.total(), 3.0) << i;
    EXPECT_GT(f.at<uint8_t>(20, 12 + 3 * i), 200) << i;
    sequential.push_back(f.clone());
  }
  // Out of order (reopening, skipping, the cache) gives the same frames.
  for (int i : {7, 2, 3, 11, 0, 10, 9}) EXPECT_EQ(cv::norm(ds.frame(i), sequential[static_cast<size_t>(i)], cv::NORM_INF), 0.0) << i;
  EXPECT_THAT(ds.frame_source(5), HasSubstr("drive.avi frame 5"));
}

TEST(IoDatasetVideo, VerifyDecodesEverythingAtOpen) {
  ScratchDir dir;
  DatasetOptions o;
  o.video = make_video_dataset(dir.path());
  o.verify_images = true;
  int calls = 0;
  o.progress = [&](double, const char*) { return ++calls < 5; };
  expect_error([&] { Dataset ds(dir.path().string(), o); }, ErrorCode::Cancelled, "video");
  o.progress = nullptr;
  Dataset ds(dir.path().string(), o);
  EXPECT_EQ(ds.frame_count(), kVideoFrames);
}

// An MJPEG video (an AVI as OpenCV's FFmpeg writer makes it) whose frame `cut` keeps only the
// first half of its image data, as a camera that delivered part of a frame leaves it: the frame's
// chunk is shortened, its index entry too, and the rest of its bytes become a JUNK chunk, which
// readers skip.
void cut_jpeg_frame(const std::string& video, int cut) {
  std::string bytes = test::read_file(video);
  const auto le32 = [&](size_t at) {
    uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(bytes[at + static_cast<size_t>(k)]);
    return v;
  };
  const auto put32 = [&](size_t at, uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes[at + static_cast<size_t>(k)] = static_cast<char>(v >> (8 * k) & 0xFF);
  };
  // Frame chunks: "00dc", a 4-byte little-endian size, the JPEG data (SOI, FF D8 FF).
  size_t at = 0;
  for (int seen = -1; seen < cut; at += 4) {
    at = bytes.find("00dc", at);
    ASSERT_NE(at, std::string::npos) << "frame " << seen + 1;
    if (bytes.compare(at + 8, 3, "\xFF\xD8\xFF") == 0 && ++seen == cut) break;  // not the index's
  }
  const uint32_t size = le32(at + 4);
  ASSERT_GT(size, 100u);
  ASSERT_EQ(bytes.compare(at + 8 + size - 2, 2, "\xFF\xD9"), 0);  // the frame's end-of-image marker
  // Its headers and the first half of its entropy-coded data, after the start of scan (FF DA).
  const size_t scan = bytes.find("\xFF\xDA", at + 8);
  ASSERT_LT(scan, at + 8 + size);
  const uint32_t kept = static_cast<uint32_t>(scan - (at + 8) + (at + 8 + size - scan) / 2) & ~1u;
  ASSERT_GE(size - kept, 16u);
  put32(at + 4, kept);
  bytes.replace(at + 8 + kept, 4, "JUNK");
  put32(at + 12 + kept, size - kept - 8);
  // The index (idx1): 16 bytes per chunk, "00dc", flags, offset, size; the frame's is its cut-th.
  size_t index = bytes.find("idx1");
  ASSERT_NE(index, std::string::npos);
  int entry = -1;
  for (size_t e = index + 8; e + 16 <= bytes.size(); e += 16)
    if (bytes.compare(e, 4, "00dc") == 0 && ++entry == cut) {
      ASSERT_EQ(le32(e + 12), size);
      put32(e + 12, kept);
      break;
    }
  ASSERT_EQ(entry, cut);
  std::ofstream(video, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(IoDatasetVideo, AJpegFrameCutShortIsNamed) {
  ScratchDir dir;
  DatasetOptions o;
  o.video = make_video_dataset(dir.path());
  cut_jpeg_frame(o.video, 5);
  // The decoder itself takes the frame (with a warning on stderr): all 12 frames decode.
  cv::VideoCapture plain(o.video);
  int decoded = 0;
  for (cv::Mat f; plain.read(f);) ++decoded;
  EXPECT_EQ(decoded, kVideoFrames);
  // Read in order, the frames before it are as written; the cut one is InvalidInput naming it.
  Dataset ds(dir.path().string(), o);
  ASSERT_EQ(ds.frame_count(), kVideoFrames);
  for (int i = 0; i < 5; ++i)
    EXPECT_LT(cv::norm(ds.frame(i), video_frame(i), cv::NORM_L1) / (kVW * kVH), 3.0) << i;
  const std::string msg = expect_invalid_input([&] { ds.frame(5); }, o.video);
  EXPECT_THAT(msg, HasSubstr("frame 5 of the video"));
  EXPECT_THAT(msg, HasSubstr("cut short"));
  EXPECT_LT(cv::norm(ds.frame(6), video_frame(6), cv::NORM_L1) / (kVW * kVH), 3.0);
  // Verified at open, it is found there.
  o.verify_images = true;
  EXPECT_THAT(open_error(dir.path(), 0, o.video, o), HasSubstr("frame 5 of the video"));
}

TEST(IoDatasetVideo, BadVideos) {
  ScratchDir dir;
  DatasetOptions o;
  o.video = make_video_dataset(dir.path());
  // Frames of another size than camera.yaml's: found at open (the first frame is decoded).
  io::write_camera_yaml((dir / "camera.yaml").string(), small_camera(kVW + 16, kVH));
  EXPECT_THAT(open_error(dir.path(), 0, o.video, o), HasSubstr("camera.yaml says 80x48"));
  io::write_camera_yaml((dir / "camera.yaml").string(), small_camera(kVW, kVH));

  DatasetOptions missing;
  missing.video = (dir / "none.avi").string();
  open_error(dir.path(), 0, missing.video, missing);

  DatasetOptions garbage;
  garbage.video = (dir / "garbage.avi").string();
  write_text(garbage.video, std::string(4096, 'x'));
  open_error(dir.path(), 0, garbage.video, garbage);
}

}  // namespace
}  // namespace planarvo
