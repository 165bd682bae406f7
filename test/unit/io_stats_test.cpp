// Reading the statistics CSV back (io/stats.h read_stats): what StatsWriter writes reads back
// exactly, whatever the values and statuses; hand-written files of both headers read as a CSV
// reader reads them; malformed files are InvalidInput naming the file and line.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/test_util.h"
#include "core/error.h"
#include "io/stats.h"
#include "unit/io_test_helpers.h"

namespace planarvo {
namespace {

using test::ScratchDir;

// Bit-exact, NaN equal to NaN.
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b)); }

void expect_same_row(const io::FrameStats& a, const io::FrameStats& b, size_t i) {
  SCOPED_TRACE("row " + std::to_string(i));
  EXPECT_TRUE(same(a.timestamp, b.timestamp)) << a.timestamp << " " << b.timestamp;
  for (auto [x, y] : {std::pair{a.vx, b.vx}, std::pair{a.vy, b.vy}, std::pair{a.omega, b.omega},
                      std::pair{a.final_cost, b.final_cost}, std::pair{a.inlier_fraction, b.inlier_fraction},
                      std::pair{a.ms, b.ms}})
    EXPECT_TRUE(same(x, y)) << x << " " << y;
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.has_attitude, b.has_attitude);
  if (a.has_attitude && b.has_attitude) {
    for (auto [x, y] : {std::pair{a.roll, b.roll}, std::pair{a.pitch, b.pitch},
                        std::pair{a.sigma_roll, b.sigma_roll}, std::pair{a.sigma_pitch, b.sigma_pitch}})
      EXPECT_TRUE(same(x, y)) << x << " " << y;
    EXPECT_EQ(a.mounting_changed, b.mounting_changed);
  }
}

TEST(IoStatsRead, WhatTheWriterWritesReadsBackExactly) {
  ScratchDir dir;
  const std::string path = (dir / "stats.csv").string();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const char* statuses[] = {"first", "ok", "degraded", "lost", "", "a, b", "say \"hi\"", "two\nlines", "cr\r\nlf"};
  std::vector<io::FrameStats> rows(500);
  {
    io::StatsWriter w(path);
    double t = 1e9;  // a bag's stamps are seconds since 1970
    for (size_t i = 0; i < rows.size(); ++i) {
      io::FrameStats& r = rows[i];
      t += 0.033 * (1 + u(rng) * 0.01);
      r.timestamp = std::round(t * 1e9) / 1e9;  // written with 9 decimals
      r.vx = u(rng);
      r.vy = i % 7 == 0 ? -0.0 : u(rng) * 1e-7;
      r.omega = i % 11 == 0 ? nan : u(rng);
      r.iterations = static_cast<int>(rng() % 200);
      r.final_cost = i % 13 == 0 ? inf : std::abs(u(rng)) * 1e3;
      r.inlier_fraction = i % 17 == 0 ? -inf : std::abs(u(rng)) / 10;
      r.ms = std::abs(u(rng));
      r.status = statuses[rng() % (sizeof statuses / sizeof statuses[0])];
      r.has_attitude = i % 3 != 0;
      if (r.has_attitude) {
        r.roll = u(rng) / 100;
        r.pitch = u(rng) / 100;
        r.sigma_roll = std::abs(u(rng)) / 1000;
        r.sigma_pitch = std::abs(u(rng)) / 1000;
        r.mounting_changed = rng() % 2 != 0;
      }
      w.add(r);
    }
    w.close();
  }
  const std::vector<io::FrameStats> back = io::read_stats(path);
  ASSERT_EQ(back.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) expect_same_row(rows[i], back[i], i);
}

TEST(IoStatsRead, HandWrittenFilesOfBothHeadersRead) {
  ScratchDir dir;
  // Before the local plane: nine columns; CRLF line ends and a blank last line, as a spreadsheet
  // writes them.
  const std::string old_file = (dir / "old.csv").string();
  test::write_text(old_file,
                   "timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status\r\n"
                   "0.000000000,0,0,0,0,0,0,3.5,first\r\n"
                   "0.033333333,0.5,-0.25,1e-3,12,4.5,0.96875,2.25,\"lost, \"\"then\"\" found\"\r\n"
                   "\r\n");
  const std::vector<io::FrameStats> a = io::read_stats(old_file);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].status, "first");
  EXPECT_EQ(a[0].ms, 3.5);
  EXPECT_EQ(a[1].timestamp, 0.033333333);
  EXPECT_EQ(a[1].vy, -0.25);
  EXPECT_EQ(a[1].omega, 1e-3);
  EXPECT_EQ(a[1].iterations, 12);
  EXPECT_EQ(a[1].inlier_fraction, 0.96875);
  EXPECT_EQ(a[1].status, "lost, \"then\" found");
  EXPECT_FALSE(a[1].has_attitude);

  const std::string new_file = (dir / "new.csv").string();
  test::write_text(new_file,
                   std::string(io::StatsWriter::kHeader) +
                       "\n5.000000000,1,2,3,4,nan,-inf,6,ok,0.125,-0.5,0.001,0.002,1\n"
                       "5.100000000,1,2,3,4,5,0.5,6,degraded,,,,,\n");
  const std::vector<io::FrameStats> b = io::read_stats(new_file);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_TRUE(std::isnan(b[0].final_cost));
  EXPECT_EQ(b[0].inlier_fraction, -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(b[0].has_attitude);
  EXPECT_EQ(b[0].roll, 0.125);
  EXPECT_EQ(b[0].pitch, -0.5);
  EXPECT_EQ(b[0].sigma_pitch, 0.002);
  EXPECT_TRUE(b[0].mounting_changed);
  EXPECT_FALSE(b[1].has_attitude);
  EXPECT_EQ(b[1].status, "degraded");
}

TEST(IoStatsRead, MalformedFilesNameFileAndLine) {
  ScratchDir dir;
  const std::string header = std::string(io::StatsWriter::kHeader) + "\n";
  const std::string good = "1.0,0,0,0,3,1,1,1,ok,,,,,\n";
  struct Case {
    std::string text;
    int line;
  };
  const Case cases[] = {
      {"", 0},                                                      // empty
      {header, 0},                                                  // no row
      {"t,vx\n" + good, 1},                                         // not the header
      {header + good + "2.0,0,0,0,3,1,1,1,ok\n", 3},                // too few fields
      {header + "2.0,0,zero,0,3,1,1,1,ok,,,,,\n", 2},               // not a number
      {header + "nan,0,0,0,3,1,1,1,ok,,,,,\n", 2},                  // the timestamp
      {header + "2.0,0,0,0,3.5,1,1,1,ok,,,,,\n", 2},                // iterations
      {header + "2.0,0,0,0,3,1,1,1,ok,0.1,,,,\n", 2},               // attitude partly empty
      {header + "2.0,0,0,0,3,1,1,1,ok,0.1,0.1,0,0,2\n", 2},         // mounting_changed
      {header + good + "3.0,0,0,0,3,1,1,1,\"open,,,,,\n", 3},       // quote not closed
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const std::string path = (dir / ("bad" + std::to_string(i) + ".csv")).string();
    test::write_text(path, cases[i].text);
    test::expect_error([&] { io::read_stats(path); }, ErrorCode::InvalidInput, path, cases[i].line);
  }
  test::expect_error([&] { io::read_stats((dir / "missing.csv").string()); }, ErrorCode::InvalidInput,
                     (dir / "missing.csv").string());
}

}  // namespace
}  // namespace planarvo
