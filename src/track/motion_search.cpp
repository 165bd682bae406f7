#include "track/motion_search.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/LU>

#include "core/error.h"
#include "core/tasks.h"
#include "ocl/runtime.h"
#include "track/warp_model.h"

namespace planarvo::track {
namespace {

constexpr int kSums = 6;  // a row of the kernel's output

// The default program, registered before main() so that exported kernel binaries hold it (the
// tracker searches when tracking and when calibrating).
const bool kDefaultRegistered = [] {
  ocl::Runtime::register_build_options("motion_search", MotionSearch::build_options(64),
                                       {tasks::kTrack, tasks::kCalibrate});
  return true;
}();

struct GridPoint {
  SE2 motion;
  Eigen::Vector2d shift;  // of the image's centre, pixels of the level
};

std::vector<GridPoint> make_grid(const Eigen::Matrix3d& Kl, const Extrinsics& e, const SE2& centre, int w, int h,
                                 const MotionSearchOptions& o) {
  // The centre pixel's shift per unit of the motion's x, y and theta (from the centre pose):
  // d pi(H p) = (m.x - u m.z, m.y - v m.z) with m = dH_i p, H(centre) scaled to H(2,2) = 1 and
  // the pixel p where the centre pose sees the level's middle.
  const MotionHomography mh = motion_homography(Kl, e, centre);
  const Eigen::Vector3d mid(0.5 * (w - 1), 0.5 * (h - 1), 1.0);
  const Eigen::Vector3d p = mh.H.inverse() * mid;
  if (!(std::abs(p.z()) > 1e-12)) return {};
  const Eigen::Vector3d pn = p / p.z();
  Eigen::Matrix<double, 2, 3> J;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d q = mh.H * pn, m = mh.dH[static_cast<size_t>(i)] * pn;
    const double iz = 1.0 / q.z();
    J(0, i) = iz * (m.x() - q.x() * iz * m.z());
    J(1, i) = iz * (m.y() - q.y() * iz * m.z());
  }
  const Eigen::Matrix2d Jt = J.leftCols<2>();
  if (!(std::abs(Jt.determinant()) > 1e-12) || !J.allFinite()) return {};
  const Eigen::Matrix2d Jinv = Jt.inverse();

  std::vector<double> rotations = {0.0};
  if (o.max_rotation > 0.0) rotations = {0.0, -o.max_rotation, o.max_rotation};
  const double R = o.max_shift * std::min(w, h);
  const int n = static_cast<int>(std::floor(R / o.grid_px));
  std::vector<GridPoint> grid;
  for (double theta : rotations)
    for (int j = -n; j <= n; ++j)
      for (int i = -n; i <= n; ++i) {
        const Eigen::Vector2d s(i * o.grid_px, j * o.grid_px);
        if (s.norm() > R + 1e-9) continue;
        // The translation that, with this rotation, shifts the centre by s (to first order).
        const Eigen::Vector2d t = Jinv * (s - J.col(2) * theta);
        grid.push_back({centre * SE2(t.x(), t.y(), theta), s});
      }
  return grid;
}

int level_step(int w, int h, int max_pixels) {
  int step = 1;
  while (static_cast<long long>((w + step - 1) / step) * ((h + step - 1) / step) > max_pixels) ++step;
  return step;
}

}  // namespace

double SearchSums::correlation() const {
  if (n < 16) return -2.0;
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (!(va > 1e-9 * n) || !(vb > 1e-9 * n)) return -2.0;
  return (sab - sa * sb / n) / std::sqrt(va * vb);
}

std::vector<SearchSums> motion_search_reference(const LevelView& ref, const LevelView& live,
                                                const std::vector<Eigen::Matrix3d>& homographies, int step) {
  std::vector<SearchSums> out(homographies.size());
  for (size_t k = 0; k < homographies.size(); ++k) {
    float h[9];
    for (int i = 0; i < 9; ++i) h[i] = static_cast<float>(homographies[k](i / 3, i % 3));
    SearchSums& s = out[k];
    for (int y = 0; y < ref.height; y += step)
      for (int x = 0; x < ref.width; x += step) {
        const float* R = ref.data + 4 * (static_cast<size_t>(y) * ref.stride + x);
        if (R[3] == 0.0f) continue;
        KernelSample sample;
        if (!kernel_sample(h, x, y, live, &sample)) continue;
        const double L = sample.value[0];
        const double a = R[0] - 128.0, b = L - 128.0;
        s.n += 1.0;
        s.sa += a;
        s.sb += b;
        s.saa += a * a;
        s.sbb += b * b;
        s.sab += a * b;
      }
  }
  return out;
}

std::string MotionSearch::build_options(int work_group) { return "-D WG=" + std::to_string(work_group); }

MotionSearch::MotionSearch(ocl::Runtime& runtime, int work_group) : runtime_(runtime), wg_(work_group) {
  if (work_group < 8 || work_group > 1024 || (work_group & (work_group - 1)) != 0)
    throw_invalid_argument("MotionSearch: the work-group size must be a power of two, 8..1024");
  const std::string options = build_options(work_group);
  ocl::Runtime::register_build_options("motion_search", options);
  kernel_ = cl::Kernel(runtime.program("motion_search", options), "motion_search");
}

void MotionSearch::run(const cl::Buffer& ref, int ref_w, int ref_h, const cl::Buffer& live, int live_w, int live_h,
                       const std::vector<Eigen::Matrix3d>& homographies, int step, std::vector<SearchSums>* out) {
  if (ref_w < 1 || ref_h < 1 || live_w < 2 || live_h < 2)
    throw_invalid_argument("MotionSearch::run: levels must be at least 1x1 (reference) and 2x2 (live)");
  if (step < 1) throw_invalid_argument("MotionSearch::run: step must be at least 1");
  out->assign(homographies.size(), SearchSums());
  if (homographies.empty()) return;
  const size_t n = homographies.size();
  if (n > capacity_) {
    homographies_ = cl::Buffer(runtime_.context(), CL_MEM_READ_ONLY, n * 9 * sizeof(float));
    sums_ = cl::Buffer(runtime_.context(), CL_MEM_WRITE_ONLY, n * kSums * sizeof(float));
    capacity_ = n;
  }
  h_host_.resize(n * 9);
  sums_host_.resize(n * kSums);
  for (size_t k = 0; k < n; ++k)
    for (int i = 0; i < 9; ++i) h_host_[9 * k + static_cast<size_t>(i)] = static_cast<float>(homographies[k](i / 3, i % 3));
  cl::CommandQueue& q = runtime_.queue();
  q.enqueueWriteBuffer(homographies_, CL_FALSE, 0, h_host_.size() * sizeof(float), h_host_.data());
  int a = 0;
  kernel_.setArg(a++, ref);
  kernel_.setArg(a++, ref_w);
  kernel_.setArg(a++, ref_h);
  kernel_.setArg(a++, live);
  kernel_.setArg(a++, live_w);
  kernel_.setArg(a++, live_h);
  kernel_.setArg(a++, homographies_);
  kernel_.setArg(a++, step);
  kernel_.setArg(a++, sums_);
  q.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(static_cast<size_t>(wg_), n),
                         cl::NDRange(static_cast<size_t>(wg_), 1));
  q.enqueueReadBuffer(sums_, CL_TRUE, 0, sums_host_.size() * sizeof(float), sums_host_.data());
  for (size_t k = 0; k < n; ++k) {
    const float* r = &sums_host_[kSums * k];
    (*out)[k] = {r[0], r[1], r[2], r[3], r[4], r[5]};
  }
}

std::vector<SE2> MotionSearch::candidates(const Pyramid& reference, const Pyramid& live, int level,
                                          const Eigen::Matrix3d& K, const Extrinsics& extrinsics, const SE2& centre,
                                          const MotionSearchOptions& o) {
  if (level < 0 || level >= reference.num_levels() || level >= live.num_levels()) return {};
  const PyramidLevel& r = reference.levels[static_cast<size_t>(level)];
  const PyramidLevel& l = live.levels[static_cast<size_t>(level)];
  const Eigen::Matrix3d Kl = level_camera_matrix(K, level);
  const std::vector<GridPoint> grid = make_grid(Kl, extrinsics, centre, r.width, r.height, o);
  if (grid.empty()) return {};
  std::vector<Eigen::Matrix3d> H;
  H.reserve(grid.size());
  for (const GridPoint& g : grid) H.push_back(ground_homography(Kl, extrinsics, g.motion.matrix3d()));
  std::vector<SearchSums> sums;
  run(r.data, r.width, r.height, l.data, l.width, l.height, H, level_step(r.width, r.height, o.max_pixels), &sums);

  double most = 0.0;
  for (const SearchSums& s : sums) most = std::max(most, s.n);
  std::vector<double> score(sums.size());
  for (size_t k = 0; k < sums.size(); ++k) score[k] = sums[k].n >= o.min_overlap * most ? sums[k].correlation() : -2.0;
  std::vector<size_t> order(sums.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return score[a] > score[b]; });
  // Peaks at least three grid steps apart in the image's shift.
  std::vector<SE2> out;
  std::vector<double> scores;
  std::vector<Eigen::Vector2d> taken;
  const double apart = 3.0 * o.grid_px;
  for (size_t k : order) {
    // (Two at least, for the ambiguity test.)
    if (static_cast<int>(out.size()) >= std::max(o.max_candidates, 2) || !(score[k] > -1.0)) break;
    bool near = false;
    for (const Eigen::Vector2d& t : taken) near = near || (t - grid[k].shift).norm() < apart;
    if (near) continue;
    taken.push_back(grid[k].shift);
    out.push_back(grid[k].motion);
    scores.push_back(score[k]);
  }
  if (scores.size() >= 2 && 1.0 - scores[0] > o.max_ambiguity * (1.0 - scores[1])) return {};
  if (static_cast<int>(out.size()) > o.max_candidates) out.resize(static_cast<size_t>(o.max_candidates));
  return out;
}

}  // namespace planarvo::track
