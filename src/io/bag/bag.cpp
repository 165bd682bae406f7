#include "io/bag/bag.h"

#include <cstring>
#include <fstream>

#include "core/error.h"

namespace planarvo::io::bag {

namespace {

constexpr char kRosbagMagic[] = "#ROSBAG V2.0\n";
constexpr unsigned char kMcapMagic[] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

// Up to 16 first bytes of the file; throws InvalidInput when it cannot be read.
std::string first_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw_invalid_input(path + ": the file cannot be opened");
  char buf[16] = {};
  in.read(buf, sizeof buf);
  return std::string(buf, static_cast<size_t>(in.gcount()));
}

bool is_rosbag(const std::string& head) { return head.rfind(kRosbagMagic, 0) == 0; }
bool is_mcap(const std::string& head) {
  return head.size() >= sizeof kMcapMagic && std::memcmp(head.data(), kMcapMagic, sizeof kMcapMagic) == 0;
}

}  // namespace

bool looks_like_bag(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char buf[16] = {};
  in.read(buf, sizeof buf);
  const std::string head(buf, static_cast<size_t>(in.gcount()));
  return is_rosbag(head) || is_mcap(head);
}

std::unique_ptr<BagFile> open_bag(const std::string& path) {
  const std::string head = first_bytes(path);
  if (is_rosbag(head)) return open_rosbag1(path);
  if (is_mcap(head)) return open_mcap(path);
  if (head.rfind("#ROSBAG V", 0) == 0)
    throw_invalid_input(path + ": a ROS bag of version " + head.substr(9, 3) +
                        "; planarvo reads version 2.0 (ROS 1) and MCAP (ROS 2)");
  if (head.rfind("SQLite format 3", 0) == 0)
    throw_invalid_input(path + ": a ROS 2 bag in SQLite (.db3); planarvo reads MCAP: convert it with "
                        "`ros2 bag convert` to the mcap storage");
  throw_invalid_input(path + ": neither a ROS 1 bag (#ROSBAG V2.0) nor an MCAP file (its magic bytes)");
}

}  // namespace planarvo::io::bag
