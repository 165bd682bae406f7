// The C API's readers of the files its writers write (planarvo.h, dataset.h): extrinsics.yaml with
// everything it holds, plane.txt, the statistics CSV. Each reads back exactly what was written,
// sizes its buffers, and refuses what it cannot hold.
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "planarvo/planarvo.h"
#include "common/test_util.h"

namespace {

using planarvo::test::ScratchDir;

TEST(CApiFiles, ExtrinsicsFileLoadReadsEverythingTheWritersWrite) {
  ScratchDir dir;
  const std::string path = (dir / "extrinsics.yaml").string();
  const planarvo_extrinsics e{0.25, -0.02, 0.18, 0.2, 0.3, -0.1};
  double cov[36];
  for (int i = 0; i < 36; ++i) cov[i] = 1e-6 * (1 + i % 7) * ((i / 6 == i % 6) ? 10 : 0.1);
  const std::string notes = "calibrated on \"drive 3\", 2026-11-29: 41 s\nsecond line";
  ASSERT_EQ(planarvo_extrinsics_save(path.c_str(), &e, cov, "x,yaw,z", "odometry (section 5.2)", notes.c_str()),
            PLANARVO_OK)
      << planarvo_last_error();
  planarvo_extrinsics_file f;
  std::memset(&f, 0x5a, sizeof f);  // every byte is written
  ASSERT_EQ(planarvo_extrinsics_file_load(path.c_str(), &f), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(std::memcmp(&f.value, &e, sizeof e), 0);
  for (int i = 0; i < 36; ++i) EXPECT_EQ(f.covariance[i], cov[i]) << i;
  const int32_t estimated[6] = {1, 0, 1, 0, 0, 1};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(f.estimated[i], estimated[i]) << i;
  EXPECT_STREQ(f.method, "odometry (section 5.2)");
  EXPECT_EQ(std::string(f.notes), notes);

  // The values alone, and strings absent: zeros and "".
  const std::string bare = (dir / "bare.yaml").string();
  std::ofstream(bare) << "%YAML:1.0\n---\nx: 1.\ny: 0.\nz: 0.5\nroll: 0.\npitch: 0.\nyaw: 0.\n";
  ASSERT_EQ(planarvo_extrinsics_file_load(bare.c_str(), &f), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(f.value.x, 1.0);
  EXPECT_EQ(f.value.z, 0.5);
  for (int i = 0; i < 36; ++i) EXPECT_EQ(f.covariance[i], 0.0);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(f.estimated[i], 0);
  EXPECT_STREQ(f.method, "");
  EXPECT_STREQ(f.notes, "");

  // Notes longer than the struct holds (no planarvo writer writes them): refused, not cut.
  const std::string long_notes = (dir / "long.yaml").string();
  std::ofstream(long_notes) << "%YAML:1.0\n---\nx: 1.\ny: 0.\nz: 0.5\nroll: 0.\npitch: 0.\nyaw: 0.\nnotes: "
                            << std::string(PLANARVO_EXTRINSICS_TEXT_MAX + 1, 'n') << "\n";
  EXPECT_EQ(planarvo_extrinsics_file_load(long_notes.c_str(), &f), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_NE(std::string(planarvo_last_error()).find(long_notes), std::string::npos);
  EXPECT_EQ(planarvo_extrinsics_file_load(nullptr, &f), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_extrinsics_file_load(path.c_str(), nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
}

TEST(CApiFiles, PlaneReadsBackWhatWasWrittenAndSizesItsArray) {
  ScratchDir dir;
  const std::string path = (dir / "plane.txt").string();
  std::vector<planarvo_plane_attitude> rows;
  for (int i = 0; i < 50; ++i)
    rows.push_back({0.1 * i, 0.01 * std::sin(i), -0.02 * std::cos(i), 1e-4 * i, 2e-4});
  ASSERT_EQ(planarvo_write_plane(path.c_str(), rows.data(), rows.size()), PLANARVO_OK) << planarvo_last_error();
  size_t count = 0;
  ASSERT_EQ(planarvo_read_plane(path.c_str(), nullptr, 0, &count), PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(count, rows.size());
  std::vector<planarvo_plane_attitude> back(count);
  EXPECT_EQ(planarvo_read_plane(path.c_str(), back.data(), count - 1, &count), PLANARVO_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(planarvo_read_plane(path.c_str(), back.data(), back.size(), &count), PLANARVO_OK) << planarvo_last_error();
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, rows[i].timestamp, 1e-9);  // written with 9 decimals
    EXPECT_EQ(back[i].roll, rows[i].roll);
    EXPECT_EQ(back[i].pitch, rows[i].pitch);
    EXPECT_EQ(back[i].sigma_roll, rows[i].sigma_roll);
    EXPECT_EQ(back[i].sigma_pitch, rows[i].sigma_pitch);
  }
  const std::string degrees = (dir / "degrees.txt").string();
  std::ofstream(degrees) << "0.0 12.4 0 0 0\n";
  EXPECT_EQ(planarvo_read_plane(degrees.c_str(), nullptr, 0, &count), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_NE(std::string(planarvo_last_error()).find(degrees + ":1:"), std::string::npos) << planarvo_last_error();
}

TEST(CApiFiles, StatsTableHoldsEveryRowTheWriterWrote) {
  ScratchDir dir;
  const std::string path = (dir / "stats.csv").string();
  planarvo_stats_writer* w = nullptr;
  ASSERT_EQ(planarvo_stats_writer_open(path.c_str(), &w), PLANARVO_OK) << planarvo_last_error();
  const char* statuses[3] = {"first", "ok", "lost, \"badly\""};
  for (int i = 0; i < 3; ++i) {
    planarvo_frame_stats r{};
    r.timestamp = 1.5 + i;
    r.vx = 0.25 * i;
    r.omega = i == 2 ? NAN : -0.5;
    r.iterations = 10 + i;
    r.final_cost = 3.0;
    r.inlier_fraction = 0.75;
    r.ms = 2.0;
    r.status = statuses[i];
    r.has_attitude = i == 1;
    r.roll = 0.125;
    r.pitch = -0.0625;
    r.sigma_roll = 0.001;
    r.sigma_pitch = 0.002;
    r.mounting_changed = 1;
    ASSERT_EQ(planarvo_stats_writer_add(w, &r), PLANARVO_OK) << planarvo_last_error();
  }
  ASSERT_EQ(planarvo_stats_writer_close(w), PLANARVO_OK) << planarvo_last_error();

  planarvo_stats_table* table = nullptr;
  ASSERT_EQ(planarvo_stats_read(path.c_str(), &table), PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(planarvo_stats_table_size(table), 3u);
  for (size_t i = 0; i < 3; ++i) {
    planarvo_frame_stats r{};
    ASSERT_EQ(planarvo_stats_table_row(table, i, &r), PLANARVO_OK) << planarvo_last_error();
    EXPECT_EQ(r.timestamp, 1.5 + static_cast<double>(i));
    EXPECT_EQ(r.vx, 0.25 * static_cast<double>(i));
    EXPECT_EQ(std::isnan(r.omega), i == 2);
    EXPECT_EQ(r.iterations, 10 + static_cast<int>(i));
    EXPECT_STREQ(r.status, statuses[i]);
    EXPECT_EQ(r.has_attitude, i == 1 ? 1 : 0);
    if (i == 1) {
      EXPECT_EQ(r.roll, 0.125);
      EXPECT_EQ(r.sigma_pitch, 0.002);
      EXPECT_EQ(r.mounting_changed, 1);
    }
  }
  planarvo_frame_stats r{};
  EXPECT_EQ(planarvo_stats_table_row(table, 3, &r), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_stats_table_free(table);
  planarvo_stats_table_free(nullptr);
  EXPECT_EQ(planarvo_stats_table_size(nullptr), 0u);

  std::ofstream(path) << "not,a,stats,file\n";
  table = reinterpret_cast<planarvo_stats_table*>(&r);  // set to NULL on failure
  EXPECT_EQ(planarvo_stats_read(path.c_str(), &table), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_EQ(table, nullptr);
}

}  // namespace
