#include "io/dataset/dataset_bag.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/bag/bag.h"
#include "io/bag/messages.h"
#include "io/dataset/frame_image.h"

namespace planarvo::io::detail {

namespace {

using bag::MessageKind;

std::string topic_list(const std::vector<bag::TopicInfo>& topics) {
  if (topics.empty()) return "it has no topics";
  std::string s = "its topics are";
  for (size_t i = 0; i < topics.size(); ++i) {
    s += (i ? ", " : " ") + topics[i].name + " (" + topics[i].type;
    if (topics[i].count >= 0) s += ", " + std::to_string(topics[i].count) + " messages";
    s += ")";
  }
  return s;
}

// A topic asked for by name ("/odom" or "odom") and its expected kinds.
uint32_t find_topic(const bag::BagFile& file, std::string name, std::initializer_list<MessageKind> kinds,
                    const char* option) {
  if (!name.empty() && name[0] != '/') name = "/" + name;
  const auto& topics = file.topics();
  for (uint32_t i = 0; i < topics.size(); ++i) {
    const std::string& n = topics[i].name;
    if (n != name && !(n[0] != '/' && "/" + n == name)) continue;
    const MessageKind k = bag::message_kind(topics[i].type);
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) {
      std::string want;
      for (MessageKind w : kinds) want += std::string(want.empty() ? "" : " or ") + bag::kind_name(w);
      throw_invalid_input(file.path() + ": " + option + " " + name + " carries " + topics[i].type + ", not " + want);
    }
    return i;
  }
  throw_invalid_input(file.path() + ": no topic " + name + " (" + option + "); " + topic_list(topics));
}

// The only topic of the given kinds, for an option left out.
std::optional<uint32_t> only_topic(const bag::BagFile& file, std::initializer_list<MessageKind> kinds,
                                   const char* option, bool required) {
  std::vector<uint32_t> found;
  const auto& topics = file.topics();
  for (uint32_t i = 0; i < topics.size(); ++i)
    if (std::find(kinds.begin(), kinds.end(), bag::message_kind(topics[i].type)) != kinds.end()) found.push_back(i);
  if (found.size() == 1) return found[0];
  if (found.empty() && !required) return std::nullopt;
  throw_invalid_input(file.path() + ": " + (found.empty() ? "no topic for " : "more than one topic could be ") +
                      option + ", name one; " + topic_list(topics));
}

// nav_msgs/Odometry's pose as a planar pose: x, y and the yaw of the quaternion (ZYX order).
// A position or orientation that is not finite, or a position beyond kMaxPositionMetres, is a
// corrupt message (InvalidInput, placed by the caller).
SE2 planar_pose(const bag::OdometryMessage& m) {
  for (int k = 0; k < 2; ++k) {
    const double p = m.position[static_cast<size_t>(k)];
    if (!std::isfinite(p) || std::abs(p) > kMaxPositionMetres)
      throw_invalid_input(std::string("the odometry's position ") + "xy"[k] + " = " + std::to_string(p) +
                          (std::isfinite(p) ? " m is beyond 1e6 m: a corrupt value or another unit"
                                            : " is not finite"));
  }
  const auto& q = m.orientation;  // x y z w
  if (!std::all_of(q.begin(), q.end(), [](double v) { return std::isfinite(v); }))
    throw_invalid_input("the odometry's orientation is not finite");
  const double yaw = std::atan2(2.0 * (q[3] * q[2] + q[0] * q[1]), 1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2]));
  return SE2(m.position[0], m.position[1], yaw);
}

double seconds_after(int64_t ns, int64_t origin_ns) {
  // Integer difference first (exact for any two stamps within ±292 years), then seconds.
  return static_cast<double>(ns - origin_ns) * 1e-9;
}

CameraModel camera_from_info(const bag::CameraInfoMessage& m, const std::string& where) {
  CameraModel c;
  c.width = static_cast<int>(std::min<uint32_t>(m.width, 1u << 30));
  c.height = static_cast<int>(std::min<uint32_t>(m.height, 1u << 30));
  c.fx = m.k[0];
  c.cx = m.k[2];
  c.fy = m.k[4];
  c.cy = m.k[5];
  if (m.k[1] != 0.0)
    throw_invalid_input(where + ": the camera matrix has a skew (K[0][1] = " + std::to_string(m.k[1]) +
                        "), which planarvo's camera model lacks; give a camera.yaml instead");
  const std::string& model = m.distortion_model;
  const bool radtan = model == "plumb_bob" || model == "rational_polynomial";
  if (!radtan && !(model.empty() && std::all_of(m.d.begin(), m.d.end(), [](double v) { return v == 0.0; })))
    throw_invalid_input(where + ": distortion model \"" + model + "\"; planarvo reads plumb_bob (k1 k2 p1 p2 k3) "
                        "and rational_polynomial without its k4..k6; give a camera.yaml calibrated with that model");
  if (radtan) {
    for (size_t i = 5; i < m.d.size(); ++i)
      if (m.d[i] != 0.0)
        throw_invalid_input(where + ": rational_polynomial with k4..k6 not zero, which planarvo's camera model "
                            "lacks; give a camera.yaml");
    double d[5] = {0, 0, 0, 0, 0};
    for (size_t i = 0; i < std::min<size_t>(5, m.d.size()); ++i) d[i] = m.d[i];
    c.k1 = d[0], c.k2 = d[1], c.p1 = d[2], c.p2 = d[3], c.k3 = d[4];
  }
  if (m.binning_x > 1 || m.binning_y > 1 || m.roi.width != 0 || m.roi.height != 0)
    throw_invalid_input(where + ": the camera info has binning or a region of interest, which planarvo does not "
                        "apply; give a camera.yaml for the images as recorded");
  c.validate(where.c_str());
  return c;
}

bool same_camera(const bag::CameraInfoMessage& a, const bag::CameraInfoMessage& b) {
  return a.width == b.width && a.height == b.height && a.k == b.k && a.d == b.d &&
         a.distortion_model == b.distortion_model && a.binning_x == b.binning_x && a.binning_y == b.binning_y;
}

// A sensor_msgs/Image's pixels as a cv::Mat header over its data (no copy), or a throw naming
// the encoding when planarvo does not read it. cvt: the conversion to grey, -1 for none.
cv::Mat wrap_image(const bag::ImageMessage& m, const std::string& where, int& cvt) {
  struct Encoding {
    const char* name;
    int channels;
    int code;
  };
  static const Encoding kEncodings[] = {
      {"mono8", 1, -1},  {"8UC1", 1, -1}, {"bgr8", 3, cv::COLOR_BGR2GRAY}, {"8UC3", 3, cv::COLOR_BGR2GRAY},
      {"rgb8", 3, cv::COLOR_RGB2GRAY}, {"bgra8", 4, cv::COLOR_BGRA2GRAY}, {"8UC4", 4, cv::COLOR_BGRA2GRAY},
      {"rgba8", 4, cv::COLOR_RGBA2GRAY},
      // ROS names a Bayer pattern by its first row; OpenCV by the second row's middle pair
      // (cv_bridge's mapping).
      {"bayer_rggb8", 1, cv::COLOR_BayerBG2GRAY}, {"bayer_bggr8", 1, cv::COLOR_BayerRG2GRAY},
      {"bayer_gbrg8", 1, cv::COLOR_BayerGR2GRAY}, {"bayer_grbg8", 1, cv::COLOR_BayerGB2GRAY}};
  const Encoding* e = nullptr;
  for (const Encoding& k : kEncodings)
    if (m.encoding == k.name) e = &k;
  if (!e) {
    const bool deep = m.encoding.find("16") != std::string::npos || m.encoding.find("32") != std::string::npos;
    throw_invalid_input(where + ": image encoding \"" + m.encoding + "\"" +
                        (deep ? " is not 8-bit; planarvo reads 8-bit images, since the right scaling depends on "
                                "the sensor's bit depth"
                              : " is not one planarvo reads") +
                        " (mono8, bgr8, rgb8, bgra8, rgba8, bayer_rggb8/bggr8/gbrg8/grbg8, or a CompressedImage)");
  }
  const uint64_t row = uint64_t{m.width} * static_cast<uint64_t>(e->channels);
  if (m.width == 0 || m.height == 0 || m.width > (1u << 16) || m.height > (1u << 16))
    throw_invalid_input(where + ": image size " + std::to_string(m.width) + "x" + std::to_string(m.height));
  if (m.step < row)
    throw_invalid_input(where + ": step " + std::to_string(m.step) + " is less than a row of " + m.encoding + " (" +
                        std::to_string(row) + " bytes)");
  if (m.data.size() < uint64_t{m.step} * (m.height - 1) + row)
    throw_invalid_input(where + ": " + std::to_string(m.data.size()) + " bytes of data, less than " +
                        std::to_string(m.height) + " rows of step " + std::to_string(m.step));
  cvt = e->code;
  return cv::Mat(static_cast<int>(m.height), static_cast<int>(m.width), CV_8UC(e->channels),
                 const_cast<uint8_t*>(m.data.data()), m.step);
}

// The topics a data set reads: what was asked for, or the only candidate.
struct Topics {
  uint32_t image = 0;
  std::optional<uint32_t> info, odom, gt;
  std::vector<uint32_t> all() const {
    std::vector<uint32_t> v{image};
    for (const auto& t : {info, odom, gt})
      if (t && std::find(v.begin(), v.end(), *t) == v.end()) v.push_back(*t);
    return v;
  }
};

Topics select_topics(const bag::BagFile& file, const BagDatasetOptions& o) {
  Topics t;
  const auto image_kinds = {MessageKind::Image, MessageKind::CompressedImage};
  t.image = o.image_topic.empty() ? *only_topic(file, image_kinds, "the images (--image-topic)", true)
                                  : find_topic(file, o.image_topic, image_kinds, "--image-topic");
  if (!o.camera_info_topic.empty() && !o.camera_yaml.empty())
    throw_invalid_input(file.path() + ": both a camera info topic and a camera.yaml were given; give one");
  if (!o.camera_info_topic.empty())
    t.info = find_topic(file, o.camera_info_topic, {MessageKind::CameraInfo}, "--camera-info-topic");
  else if (o.camera_yaml.empty())
    t.info = only_topic(file, {MessageKind::CameraInfo}, "the camera (--camera-info-topic, or --camera FILE)", true);
  if (!o.groundtruth_topic.empty())
    t.gt = find_topic(file, o.groundtruth_topic, {MessageKind::Odometry}, "--groundtruth-topic");
  if (!o.odometry_topic.empty()) {
    t.odom = find_topic(file, o.odometry_topic, {MessageKind::Odometry}, "--odom-topic");
  } else {
    // The bag's only Odometry topic besides the ground truth's; none when there are several (a
    // simulator's /odom and /ground_truth: which is which is the user's to say).
    std::vector<uint32_t> odometry;
    for (uint32_t i = 0; i < file.topics().size(); ++i)
      if (bag::message_kind(file.topics()[i].type) == MessageKind::Odometry && t.gt != i) odometry.push_back(i);
    if (odometry.size() == 1) t.odom = odometry[0];
  }
  return t;
}

// What one pass over the indexed messages gives: each image's time (header stamp or receive
// time; only the header is decoded) and its index in refs, the odometry and ground-truth poses
// with their times, and the camera info.
struct Stamped {
  int64_t ns;
  size_t ref;
};
struct Scanned {
  std::vector<Stamped> images;
  std::vector<std::pair<int64_t, SE2>> odom, gt;
  std::optional<bag::CameraInfoMessage> info;
};

std::string message_place(const bag::BagFile& file, const bag::MessageRef& m) {
  return file.path() + ": " + file.topics()[m.topic].name + " message at receive time " +
         std::to_string(m.receive_time_ns) + " ns";
}

Scanned read_stamps(bag::BagFile& file, const std::vector<bag::MessageRef>& refs, const Topics& topics,
                    bool receive_time, std::vector<uint8_t>& buf,
                    const std::function<void(double, const char*)>& report) {
  const bag::Serialization ser = file.serialization();
  Scanned s;
  for (size_t r = 0; r < refs.size(); ++r) {
    if (r % 64 == 0) report(0.8 + 0.2 * static_cast<double>(r) / static_cast<double>(refs.size()), "reading stamps");
    const bag::MessageRef& m = refs[r];
    file.read(m, buf);
    try {
      if (m.topic == topics.image)
        s.images.push_back({receive_time ? m.receive_time_ns : bag::decode_header(ser, buf.data(), buf.size()).stamp_ns, r});
      if (topics.info && m.topic == *topics.info) {
        bag::CameraInfoMessage ci = bag::decode_camera_info(ser, buf.data(), buf.size());
        if (!s.info) {
          camera_from_info(ci, "the camera info");  // a bad first one is named as bad, not as different
          s.info = std::move(ci);
        }
        else if (!same_camera(*s.info, ci))
          throw_invalid_input("the camera info differs from the first one; planarvo uses one camera for a run");
      }
      for (auto [topic, out] : {std::pair{topics.odom, &s.odom}, std::pair{topics.gt, &s.gt}}) {
        if (!topic || m.topic != *topic) continue;
        const bag::OdometryMessage od = bag::decode_odometry(ser, buf.data(), buf.size());
        out->emplace_back(receive_time ? m.receive_time_ns : od.header.stamp_ns, planar_pose(od));
      }
    } catch (const Error& e) {
      if (e.code() != ErrorCode::InvalidInput) throw;
      throw_invalid_input(message_place(file, m) + ": " + e.what());
    }
  }
  return s;
}

}  // namespace

}  // namespace planarvo::io::detail

namespace planarvo::io {

std::optional<std::string> bag_file_for(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(path, ec))
    return bag::looks_like_bag(path) ? std::optional<std::string>(path) : std::nullopt;
  if (!fs::is_directory(path, ec) || !fs::exists(fs::path(path) / "metadata.yaml", ec)) return std::nullopt;
  std::vector<std::string> mcap, db3;
  for (const auto& entry : fs::directory_iterator(path, ec)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".mcap") mcap.push_back(entry.path().string());
    if (ext == ".db3") db3.push_back(entry.path().string());
  }
  std::sort(mcap.begin(), mcap.end());
  if (mcap.size() == 1) return mcap.front();
  if (mcap.size() > 1)
    throw_invalid_input(path + ": a ROS 2 bag split into " + std::to_string(mcap.size()) + " MCAP files (" +
                        mcap.front() + ", ...); planarvo reads one file: join them with `ros2 bag convert` "
                        "(max_bagfile_size 0), or give one of the files");
  if (!db3.empty())
    throw_invalid_input(path + ": a ROS 2 bag stored in SQLite (" + db3.front() + "); planarvo reads MCAP: convert it "
                        "with `ros2 bag convert` to the mcap storage");
  throw_invalid_input(path + ": has a ROS 2 bag's metadata.yaml but no .mcap file");
}

}  // namespace planarvo::io

namespace planarvo::io::detail {

struct BagSource::Impl {
  std::unique_ptr<bag::BagFile> file;
  uint32_t image_topic = 0;
  bool compressed = false;
  std::vector<bag::MessageRef> frame_refs;  // in frame order
  std::vector<uint8_t> buffer;
};

BagSource::BagSource(const std::string& path, const BagDatasetOptions& o, bool verify,
                     const std::function<void(double, const char*)>& report)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.file = bag::open_bag(path);
  bag::BagFile& file = *d.file;
  const Topics topics = select_topics(file, o);
  d.image_topic = topics.image;
  d.compressed = bag::message_kind(file.topics()[topics.image].type) == MessageKind::CompressedImage;
  const std::vector<bag::MessageRef> refs = file.index(topics.all(), [&](double f) {
    report(0.8 * f, "indexing the bag");
    return true;
  });
  Scanned s = read_stamps(file, refs, topics, o.use_receive_time, d.buffer, report);
  if (s.images.empty())
    throw_invalid_input(path + ": the image topic " + file.topics()[topics.image].name + " has no messages");

  // Frames in time order; the same time twice is two frames that cannot both be right.
  std::stable_sort(s.images.begin(), s.images.end(), [](const Stamped& a, const Stamped& b) { return a.ns < b.ns; });
  for (size_t i = 1; i < s.images.size(); ++i)
    if (s.images[i].ns == s.images[i - 1].ns)
      throw_invalid_input(message_place(file, refs[s.images[i].ref]) + ": has the same " +
                          (o.use_receive_time ? "receive time" : "header stamp") + " as " +
                          message_place(file, refs[s.images[i - 1].ref]) + " (" + std::to_string(s.images[i].ns) +
                          " ns)");
  origin_ns_ = s.images.front().ns;
  for (const Stamped& st : s.images) {
    frames_.push_back({seconds_after(st.ns, origin_ns_), std::string(), 0});
    d.frame_refs.push_back(refs[st.ref]);
  }
  for (auto [raw, out] : {std::pair{&s.odom, &odometry_}, std::pair{&s.gt, &groundtruth_}}) {
    std::stable_sort(raw->begin(), raw->end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [ns, pose] : *raw) out->push_back({seconds_after(ns, origin_ns_), pose});
  }
  for (auto [topic, out] : {std::pair{topics.odom, &odometry_}, std::pair{topics.gt, &groundtruth_}})
    if (topic && out->empty()) throw_invalid_input(path + ": the topic " + file.topics()[*topic].name + " has no messages");

  if (s.info) {
    camera_source_ = "the camera info on " + file.topics()[*topics.info].name;
    camera_ = camera_from_info(*s.info, path + ": " + camera_source_);
  } else {
    camera_source_ = o.camera_yaml;
    camera_ = read_camera_yaml(o.camera_yaml, &readout_given_);
  }
  // The first frame is decoded now, so that a size that disagrees with the camera is found at
  // open; every frame with verify.
  const int64_t n = verify ? static_cast<int64_t>(frames_.size()) : 1;
  for (int64_t i = 0; i < n; ++i) frame(i);
  report(1.0, "done");
}

BagSource::~BagSource() = default;

std::string BagSource::name(int64_t i) const {
  return impl_->file->path() + ": " + impl_->file->topics()[impl_->image_topic].name + " message " +
         std::to_string(i + 1) + " of " + std::to_string(frames_.size());
}

cv::Mat BagSource::frame(int64_t i) {
  Impl& d = *impl_;
  const bag::Serialization ser = d.file->serialization();
  d.file->read(d.frame_refs[static_cast<size_t>(i)], d.buffer);
  const std::string where = name(i);
  try {
    if (d.compressed) {
      const bag::CompressedImageMessage m = bag::decode_compressed_image(ser, d.buffer.data(), d.buffer.size());
      if (const std::string problem = detail::encoded_image_problem(m.data.data(), m.data.size(), camera_, camera_source_);
          !problem.empty())
        throw_invalid_input("the \"" + m.format + "\" image: " + problem);
      cv::Mat img;
      try {
        img = cv::imdecode(m.data, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
      } catch (const cv::Exception& e) {
        throw_invalid_input("the \"" + m.format + "\" image cannot be decoded: " + e.err);
      }
      if (img.empty()) throw_invalid_input("the \"" + m.format + "\" image cannot be decoded");
      return to_grey_checked(img, camera_, where, "a CompressedImage", camera_source_);
    }
    const bag::ImageMessage m = bag::decode_image(ser, d.buffer.data(), d.buffer.size());
    int cvt = -1;
    const cv::Mat raw = wrap_image(m, where, cvt);
    if (raw.cols != camera_.width || raw.rows != camera_.height)
      return to_grey_checked(raw, camera_, where, m.encoding, camera_source_);  // throws, naming the sizes
    cv::Mat grey;
    if (cvt < 0)
      grey = raw.clone();  // raw points into the message, which goes away
    else
      cv::cvtColor(raw, grey, cvt);
    return grey;
  } catch (const Error& e) {
    if (e.code() != ErrorCode::InvalidInput || std::string(e.what()).rfind(where, 0) == 0) throw;
    throw_invalid_input(where + ": " + e.what());
  }
}

}  // namespace planarvo::io::detail
