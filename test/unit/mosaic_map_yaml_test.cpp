// The mosaic's map YAML loads as a map (src/mosaic/mosaic.h save_mosaic): by map_server's own
// formula for the mode the YAML states (ROS 1 map_server's image_loader.cpp; nav2_map_server's
// map_io.cpp, the same in trinary mode), every seen pixel (1..255) is free and every unseen one (0)
// unknown; and the preview stretches the floor's few grey levels over the range.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "mosaic/mosaic.h"

namespace planarvo::mosaic {
namespace {

std::map<std::string, std::string> yaml_keys(const std::string& path) {
  std::ifstream in(path);
  std::map<std::string, std::string> keys;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    keys[line.substr(0, colon)] = value;
  }
  return keys;
}

// ROS 1 map_server (image_loader.cpp, loadMapFromFile) for one grey pixel: -1 unknown, 0 free, 100
// occupied; trinary and scale modes. nav2's map_io.cpp computes the same occupancy.
int map_server_value(int grey, const std::string& mode, bool negate, double occupied_thresh, double free_thresh) {
  double color_avg = grey;
  if (negate) color_avg = 255 - color_avg;
  const double occ = (255 - color_avg) / 255.0;
  if (occ > occupied_thresh) return 100;
  if (occ < free_thresh) return 0;
  if (mode == "trinary") return -1;
  const double ratio = (occ - free_thresh) / (occupied_thresh - free_thresh);
  return 1 + static_cast<int>(98 * ratio);
}

TEST(MosaicMap, EverySeenPixelIsFreeAndEveryUnseenUnknownByMapServersFormula) {
  test::ScratchDir dir;
  Mosaic m;
  m.grid.resolution = 0.001;
  m.grid.width = 256;
  m.grid.height = 3;
  m.image = cv::Mat(3, 256, CV_8UC1);
  for (int c = 0; c < 256; ++c) {
    m.image.at<uint8_t>(0, c) = static_cast<uint8_t>(c);  // every grey level
    m.image.at<uint8_t>(1, c) = 0;                        // unseen
    m.image.at<uint8_t>(2, c) = static_cast<uint8_t>(c == 0 ? 0 : 255 - c % 7);
  }
  const std::string png = (dir / "floor.png").string();
  save_mosaic(m, png);
  const auto keys = yaml_keys((dir / "floor.yaml").string());
  ASSERT_EQ(keys.count("mode"), 1u);
  ASSERT_EQ(keys.count("negate"), 1u);
  const std::string mode = keys.at("mode");
  const bool negate = std::stoi(keys.at("negate")) != 0;
  const double occupied = std::stod(keys.at("occupied_thresh")), free = std::stod(keys.at("free_thresh"));
  const cv::Mat image = cv::imread(png, cv::IMREAD_UNCHANGED);  // what map_server reads
  ASSERT_EQ(image.type(), CV_8UC1);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) {
      const int grey = image.at<uint8_t>(r, c);
      EXPECT_EQ(map_server_value(grey, mode, negate, occupied, free), grey == 0 ? -1 : 0)
          << "grey " << grey << " (row " << r << ")";
    }
}

TEST(MosaicMap, ThePreviewStretchesTheSeenGreyLevels) {
  cv::Mat image(64, 64, CV_8UC1, cv::Scalar(0));
  cv::Mat floor = image(cv::Rect(8, 8, 48, 48));
  cv::RNG rng(3);
  rng.fill(floor, cv::RNG::UNIFORM, 120, 131);  // 120..130: a floor's picture
  const cv::Mat preview = contrast_preview(image);
  double lo = 0, hi = 0;
  cv::minMaxLoc(preview(cv::Rect(8, 8, 48, 48)), &lo, &hi);
  EXPECT_LE(lo, 30);   // the darkest percent near black
  EXPECT_GE(hi, 230);  // the brightest near white
  EXPECT_GE(lo, 1);    // seen stays seen
  EXPECT_EQ(cv::countNonZero(preview), 48 * 48);  // unseen stays 0
  // Order kept: a brighter pixel of the floor is not darker in the preview.
  for (int k = 0; k < 200; ++k) {
    const int a = 8 + k % 48, b = 8 + (k * 7) % 48;
    if (image.at<uint8_t>(a, b) > image.at<uint8_t>(b, a)) {
      EXPECT_GE(preview.at<uint8_t>(a, b), preview.at<uint8_t>(b, a));
    }
  }
}

}  // namespace
}  // namespace planarvo::mosaic
