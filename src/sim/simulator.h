// The simulator: renders test sequences of a downward-looking camera on a differential-drive
// robot over a textured ground plane, with exact ground truth (see src/sim/SIMULATOR.md).
//
// Geometry follows docs/conventions.md: robot pose T_wv in SE(2), camera pose
// T_wc = T_wv * T_vc, ground plane z = 0. The ground texture is the photograph tiled over the
// whole plane by mirroring (period two texture sizes along each axis); world point (X, Y) is at
// texture coordinates (u, v) = (X / texel_size, Y / texel_size), integer (u, v) at texel
// centres, texel (0, 0) centred on the world origin.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/body_attitude.h"
#include "core/extrinsics.h"
#include "core/se2.h"
#include "core/camera.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::sim {

enum class MotionProfile {
  Mixed,     // forward and backward driving, turns both ways, turning in place, stops
  Straight,  // forwards and backwards along one line
  Circle,    // one constant-curvature circle
  Spin,      // turning in place
  Car,       // a car: forward driving with turns no tighter than Options::min_turn_radius, stops,
             // and slow reversing (parking); never turning in place
};

// "mixed", "straight", "circle", "spin", "car".
const char* motion_profile_name(MotionProfile profile);

// The paper's camera configuration 1: x 0.2441, y -0.0185, z 0.1787 m, roll 12.4, pitch 17.6,
// yaw -9.2 degrees.
Extrinsics default_extrinsics();
// The paper's camera configurations 1, 2 and 3 (its Tables 1-3) as numbers in docs/conventions.md's
// convention (the paper states none; these are borrowed as numbers, not as the same mounts):
// 1 = default_extrinsics(); 2 = (0.1917, -0.1078, 0.2164 m; 29.8, -4.6, 75.8 degrees);
// 3 = (0.2226, 0.0806, 0.1469 m; -26.6, 4.7, -18.6 degrees). InvalidArgument for another k.
Extrinsics paper_configuration(int k);
// width x height pixels with a horizontal field of view of fov_deg measured on the distorted
// image (the centres of the outermost pixel columns are fov_deg apart), mild barrel distortion
// k1 = -0.12, k2 = 0.03, principal point a little off the image centre as real lenses have.
CameraModel default_camera(int width = 640, int height = 480, double fov_deg = 80.0);

// How far the camera sees over the ground: the largest distance, along the ground from the
// point below the camera, of a border pixel's ray (every pixel along the four edges of the
// camera's region of interest, the whole image by default), in camera heights; +inf when a ray
// does not meet the ground (the region sees the horizon). *pixel gets that pixel. validate() refuses a camera that sees farther than kMaxGroundView heights: such
// far field is foreshortened to a few pixels per metre, no floor texture survives it, and a
// real camera there would see the horizon, walls or the car's own bumper.
double farthest_ground_view(const CameraModel& camera, const Extrinsics& extrinsics,
                            Eigen::Vector2d* pixel = nullptr);
constexpr double kMaxGroundView = 25.0;

struct Options {
  std::string texture;          // path of the ground photograph (any cv::imread format)
  double texel_size = 0.0004;   // metres per texture pixel
  Extrinsics extrinsics = default_extrinsics();
  CameraModel camera = default_camera();
  double seconds = 10.0;        // sequence length: round(seconds * fps) frames at t = k / fps
  double fps = 30.0;
  uint64_t seed = 1;
  MotionProfile motion = MotionProfile::Mixed;
  double max_speed = 0.8;           // peak |v|, m/s
  double max_turn_rate = 1.5;       // peak |omega|, rad/s
  double max_acceleration = 1.5;    // bound on |dv/dt|, m/s^2
  double max_angular_acceleration = 4.0;  // bound on |domega/dt|, rad/s^2
  double min_turn_radius = 0.0;     // Car: the tightest turn, |omega| <= |v| / radius (metres;
                                    // 0: limited by max_turn_rate only)
  SE2 start_pose;                   // the robot's true pose at the first frame
  double pixel_noise = 1.0;         // standard deviation of additive noise, grey levels
  double gain_variation = 0.05;     // amplitude of the slow gain change, relative
  double odometry_noise = 0.01;     // relative standard deviation of each wheel's travel
  double odometry_noise_floor = 1e-6;  // absolute floor of that standard deviation, metres
  double wheel_base = 0.33;         // distance between the wheels, metres (a Pioneer 3-DX)
  // Real-camera geometry (rolling shutter, exposure)
  double readout_time = 0.0;        // rolling shutter: seconds from reading the first row to the
                                    // last, at most 1 / fps (0: global shutter); the rendered
                                    // camera's rolling_shutter_readout, written into camera.yaml
                                    // (camera.rolling_shutter_readout is not used)
  double exposure_time = 0.0;       // seconds each row integrates the moving scene before it is
                                    // read, at most 1 / fps (0: instantaneous, no motion blur);
                                    // written into camera.yaml as exposure_time (likewise)
  bool accept_unusual_extrinsics = false;  // extrinsics outside core/extrinsics.h's plausible ranges
  int supersampling = 2;            // samples per pixel along each axis (ray tables take
                                    // 8 S^2 + 24 bytes per pixel: 17 MB at 640x480, S = 2)
  bool mipmap = true;               // prefilter the texture (off only for tests/references)
  // Real-camera light (fixed to the camera, not to the ground; see Lighting below).
  double lamp_falloff = 0.0;   // a lamp beside the lens: the darkest corner's brightness is
                               // 1 - lamp_falloff of the brightest point's; 0: even light
  double reflection = 0.0;     // the lamp's reflection on a glossy floor: peak grey levels added
                               // (saturates above about 130 on the default texture); 0: none
  double shadow = 0.0;         // the robot's own shadow over the image's bottom: the fraction of
                               // light it takes; 0: none
  // The body on its suspension (a car; the paper's section 6.4 and Figures 18-19). The camera is
  // fixed to the body, and the body rotates relative to the local ground plane about the robot
  // frame's origin: R_plane_body = Rx(roll) Ry(pitch) (see body_attitude below).
  double lean = 0.0;           // body roll per yaw rate, seconds (= degrees per degree/s); the
                               // paper's car about -0.07; 0: none
  double bumps = 0.0;          // speed bumps: peak body pitch, radians (both signs over one bump);
                               // 0: none
  double bump_spacing = 10.0;  // metres driven between bumps (the first at half of it)
  double bump_length = 2.5;    // metres driven over one bump's pitch profile
  // A knock to the camera's mounting at knock_time seconds (inf: none): from then on the
  // camera's extrinsics are roll + knock_roll, pitch + knock_pitch (radians), z + knock_z (m).
  double knock_time = HUGE_VAL;
  double knock_roll = 0.0, knock_pitch = 0.0, knock_z = 0.0;
  // Called with the fraction done and the stage; return false to cancel (Error Cancelled).
  std::function<bool(double, const char*)> progress;
};

// Throws InvalidArgument naming the first bad value.
void validate(const Options& options);

// Frame times, true poses, per-interval velocities and direction labels, wheel odometry.
struct Trajectory {
  std::vector<double> t;                   // N frame times
  std::vector<SE2> pose;                   // N true robot poses T_wv
  std::vector<Eigen::Vector2d> velocity;   // N-1: (v, omega), constant over interval k..k+1
  std::vector<int> direction;              // N-1: sign of v, 0 when v == 0
  std::vector<SE2> odometry;               // N wheel-odometry poses (odometry frame = world)
  std::vector<double> distance;            // N: distance driven up to frame k, |v| integrated, m
};

// Pure and deterministic for a seed. Velocities are held constant over each frame interval
// (a controller commanding at the frame rate), so each interval is an exact arc:
// pose[k+1] = pose[k] * SE2::exp((v dt, 0, omega dt)).
Trajectory generate_trajectory(const Options& options);

// The robot's true pose at time t: exact arcs between frames,
// pose[k] * SE2::exp((t - t_k) * (v, 0, omega)) for t in [t_k, t_k+1), exactly pose[k] at t_k;
// standing at pose[0] before t_0; after the last frame, the last interval's velocity continued.
SE2 pose_at(const Trajectory& trajectory, double t);

// ---------------------------------------------------------------------------------------------
// The body's attitude and the camera's pose relative to the local ground plane over time.

// The body's rotation relative to the local ground plane at time t, radians:
// R_plane_body = Rx(roll) Ry(pitch) (body x forward, y left, z up), rotating about the robot
// frame's origin on the ground. roll = lean * omega(t), with omega(t) the yaw rate interpolated
// linearly between the midpoints of the frame intervals (held at the ends), so the body turns
// smoothly. pitch = bumps * b(u) / max(b), b(u) = sin(2 pi u) sin^2(pi u), u the fraction of
// bump_length driven since the bump's start (bumps start at spacing (j + 1/2), j = 0, 1, ...,
// of the distance driven, forwards or backwards): smooth, nose one way then the other.
BodyAttitude body_attitude(const Options& options, const Trajectory& trajectory, double t);

// The camera's extrinsics relative to the local ground plane at time t: options.extrinsics
// (after the knock when t >= knock_time) carried by the body's attitude,
// T(t) = [R_plane_body 0; 0 1] T_vc. options.extrinsics exactly when the body does not move.
Extrinsics camera_extrinsics_at(const Options& options, const Trajectory& trajectory, double t);

// The mounting's extrinsics after the knock (options.extrinsics when there is none).
Extrinsics knocked_extrinsics(const Options& options);

// ---------------------------------------------------------------------------------------------
// Rendering. The texture is prefiltered into a float mip pyramid; every output pixel averages
// supersampling^2 subsamples, each a trilinear lookup at the level matching the subsample's
// footprint on the ground. The OpenCL kernel (kernels/sim/render.cl) and render_reference() below
// compute the same float arithmetic from the same tables.

// Float mip pyramid of a texture whose sides are powers of two: level 0 is the texture, level
// l+1 the 2x2 box average of level l, down to a side of 1. Box blocks never straddle the
// mirror lines, so each level mirror-tiles exactly like the texture.
struct MipPyramid {
  int width = 0, height = 0;     // level 0
  std::vector<float> data;       // all levels, row-major, one after another
  std::vector<int> levels;       // per level: offset into data, width, height
  float mean = 0.0f;             // of level 0
  int num_levels() const { return static_cast<int>(levels.size() / 3); }
};
// texture: CV_8UC1 or CV_32FC1 with power-of-two sides (see prepare_texture).
MipPyramid build_mip_pyramid(const cv::Mat& texture);

// A grey texture resized to the nearest power-of-two sides (unchanged when they already are),
// as CV_32FC1; texel_scale gets the factors (old size / new size) along x and y, by which the
// physical texel size grows.
cv::Mat prepare_texture(const cv::Mat& texture, Eigen::Vector2d* texel_scale);

// Per-camera ray tables, computed once in double with CameraModel::unproject, stored as float
// planes (plane-major so neighbouring work-items read neighbouring floats):
//   pixel: 6 planes of width*height: undistorted normalised ray (x, y) of the pixel centre and
//          the Jacobian d(x, y)/d(pixel) (row-major 2x2) there;
//   sub:   2 * S*S planes: the ray (x, y) of each subsample; subsample (i, j) of pixel (c, r)
//          sits at (c + (i + 0.5)/S - 0.5, r + (j + 0.5)/S - 0.5), plane pair j*S + i.
struct RayTable {
  int width = 0, height = 0, supersampling = 1;
  std::vector<float> pixel;
  std::vector<float> sub;
};
RayTable build_ray_table(const CameraModel& camera, int supersampling);

// The per-frame parameter block the kernel reads as __constant float*.
enum RenderParam {
  kParamH = 0,            // 9: homography, undistorted ray (x, y, 1) -> texture coordinates
  kParamInvS = 9,         // 1 / supersampling: a subsample's share of the pixel
  kParamLodMax = 10,      // highest mip level used (0: no mip-mapping)
  kParamFar = 11,         // value of rays that miss the ground or land absurdly far
  kParamInvCount = 12,    // 1 / supersampling^2
  kParamCount = 16
};
using FrameParams = std::array<float, kParamCount>;

// Maps undistorted rays (x, y, 1) of the camera at robot pose T_wv to homogeneous texture
// coordinates relative to `origin` (texels). texel = physical size of a texel along u and v.
Eigen::Matrix3d ray_to_texture(const SE2& robot_pose, const Extrinsics& extrinsics,
                               const Eigen::Vector2d& texel, const Eigen::Vector2d& origin);

// The parameter block for one frame. The homography is taken relative to an origin shifted
// by a whole number of mirror periods (2 texture sizes) close to the camera, which leaves the
// tiling unchanged and keeps the float texture coordinates small however far the robot goes.
FrameParams frame_params(const SE2& robot_pose, const Extrinsics& extrinsics,
                         const Eigen::Vector2d& texel, const MipPyramid& pyramid,
                         int supersampling, bool mipmap);

// The kernel takes its homography per output row (a rolling shutter sees each row from its own
// pose): height x 9 floats, row y's the homography (FrameParams kParamH..kParamH+8) for row y.
// row_homographies(p, height) repeats one frame's (a global shutter); the other builds them
// from one parameter block per row.
std::vector<float> row_homographies(const FrameParams& p, int height);
std::vector<float> row_homographies(const std::vector<FrameParams>& rows);

// The plain C++ reference of the render kernel: CV_32FC1, grey levels. The first uses p's
// homography for every row; the second row y's of `rows` (height x 9 floats) and p's other
// entries (kParamInvS and after).
cv::Mat render_reference(const MipPyramid& pyramid, const RayTable& rays, const FrameParams& p);
cv::Mat render_reference(const MipPyramid& pyramid, const RayTable& rays, const FrameParams& p,
                         const std::vector<float>& rows);

class Renderer {
 public:
  // texture: a grey image (CV_8UC1 or CV_32FC1), any size (see prepare_texture). Uses
  // options.camera, extrinsics, texel_size, supersampling and mipmap.
  Renderer(ocl::Runtime& runtime, const cv::Mat& texture, const Options& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // The noise-free, gain-free image at a robot pose: CV_32FC1 grey levels, or rounded CV_8UC1.
  cv::Mat render_float(const SE2& robot_pose);
  cv::Mat render(const SE2& robot_pose);
  // The same with the camera at `extrinsics` relative to the ground (a leaning body).
  cv::Mat render_float(const SE2& robot_pose, const Extrinsics& extrinsics);
  // Row y seen from robot pose row_poses[y] (one per image row), CV_32FC1: one frame of a
  // rolling shutter at one instant of its exposure. Row y equals row y of
  // render_float(row_poses[y]) bit for bit.
  cv::Mat render_float_rows(const std::vector<SE2>& row_poses);
  // The same with each row's camera at its own extrinsics (one per row).
  cv::Mat render_float_rows(const std::vector<SE2>& row_poses, const std::vector<Extrinsics>& row_extrinsics);

  const MipPyramid& pyramid() const;
  const RayTable& rays() const;
  FrameParams params(const SE2& robot_pose) const;
  FrameParams params(const SE2& robot_pose, const Extrinsics& extrinsics) const;
  // Texel size along u and v in metres (texel_size times the prepare_texture scale).
  Eigen::Vector2d texel() const;
  // The OpenCL build options of the render program (registered with the Runtime).
  static std::string build_options();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// What a real camera sees of the moving ground: a rolling shutter and a finite exposure.

// How fast the image moves for a robot driving at velocity (v, omega) (m/s, rad/s): the largest
// image speed, pixels per second, of the ground points seen at a 9 x 9 grid of pixels over the
// image (corners included), for options.camera on options.extrinsics.
double image_speed(const Options& options, const Eigen::Vector2d& velocity);

// The number of sub-renders that frame k's exposure is averaged from: with E = exposure_time and
// s the largest image_speed over the trajectory's intervals during [t_k - E, t_k + readout_time]
// (standing before t_0, the last velocity after the last frame), ceil(2 s E), so that the image
// moves less than half a pixel between sub-renders, clamped to [1, 64]; 1 when E is 0.
int exposure_samples(const Options& options, const Trajectory& trajectory, size_t k);

// The ground as camera frame k sees it (before gain, noise and quantisation): each row at its
// own read time (rolling shutter), each averaged over the exposure before that time. Row r of H
// is read at t_r = t_k + r / (H - 1) * readout_time, and is the mean of N = exposure_samples()
// renders at t_r - E + (i + 0.5) E / N, i = 0 .. N-1 (the midpoints of N equal parts of
// [t_r - E, t_r]); the robot at pose_at(trajectory, time). CV_32FC1, grey levels. With neither
// readout nor exposure it is renderer.render_float(trajectory.pose[k]) bit for bit.
cv::Mat render_frame(Renderer& renderer, const Options& options, const Trajectory& trajectory, size_t k);

// ---------------------------------------------------------------------------------------------
// The camera: slow smooth gain change, additive Gaussian noise, 8-bit quantisation.

// Per frame: gain 1 + a g(t) and offset 60 a o(t) grey levels, a = gain_variation, where g and
// o are smooth random curves in [-1, 1] made of slow sinusoids (periods of 3 to 20 s) with
// random phases.
struct Exposure {
  double gain = 1.0, offset = 0.0;
};
std::vector<Exposure> exposure_series(const Options& options, const std::vector<double>& t);

// The light fixed to the camera (Options::lamp_falloff, reflection, shadow), per pixel of the
// camera image: radiance = gain * ground + add. The lamp is a point source beside the lens
// (centred at 58 % of the width, 42 % of the height): gain = (1 + rho^2)^(-3/2) (inverse square
// and Lambert's cosine over a plane), rho scaled so that the darkest image corner is at
// 1 - lamp_falloff. The reflection is a Gaussian spot (sigma 7 % of the width) at 45 % of the
// width, 62 % of the height, plus a halo a third as bright and three times as wide. The shadow
// darkens the image below a slanted line through 75 % of the height by `shadow`, with a soft
// edge 6 px wide. All 1 and 0 when the options are 0.
struct Lighting {
  cv::Mat gain, add;  // CV_32FC1, the camera image's size
  bool empty() const { return gain.empty(); }
};
Lighting camera_lighting(const Options& options);
// image = lighting.gain * image + lighting.add, in place (CV_32FC1 of the lighting's size); no
// change when the lighting is empty.
void apply_lighting(const Lighting& lighting, cv::Mat& image);
// round(clamp(gain * image + offset + noise)), noise ~ N(0, sigma^2) per pixel from a generator
// seeded with frame_seed. image: CV_32FC1; returns CV_8UC1.
cv::Mat apply_camera(const cv::Mat& image, const Exposure& exposure, double sigma,
                     uint64_t frame_seed);

// Deterministic random numbers, the same on every platform (std::mt19937_64 with explicit
// conversions; no std:: distributions).
class Random {
 public:
  explicit Random(uint64_t seed) : g_(seed) {}
  double uniform() { return static_cast<double>(g_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double normal();  // standard normal, Box-Muller
  int sign() { return uniform() < 0.5 ? -1 : 1; }

 private:
  std::mt19937_64 g_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};
// A well-mixed 64-bit seed for stream `stream` of a user seed (splitmix64).
uint64_t derive_seed(uint64_t seed, uint64_t stream);

// ---------------------------------------------------------------------------------------------
// Where simulate() spent its time, seconds. setup and render are the calling thread's wall-clock
// time; camera and write (PNG) run on worker threads beside the render and are their time summed.
struct SimulationStats {
  double setup = 0;    // trajectory, texture, mip pyramid, ray tables, kernel build
  double render = 0;   // the render kernel, including the read-back
  double camera = 0;   // lighting, gain, offset, noise, quantisation (worker threads)
  double write = 0;    // PNG encoding and writing (worker threads), text files
  int64_t frames = 0;
};

// Renders the whole data set into out_dir (created if missing): camera.yaml, images/NNNNNN.png,
// frames.txt (written last, so an interrupted run leaves no openable data set), odometry.txt,
// direction.txt, groundtruth.txt, extrinsics_gt.yaml, and simulation.yaml recording the options.
// Throws InvalidArgument for bad options, InvalidInput for an unreadable texture, Io when a
// file cannot be written, Cancelled when options.progress returns false.
void simulate(ocl::Runtime& runtime, const Options& options, const std::string& out_dir,
              SimulationStats* stats = nullptr);

}  // namespace planarvo::sim
