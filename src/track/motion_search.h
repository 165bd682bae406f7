// The search for a motion where no guess is good enough (kernels/track/motion_search.cl): the first
// frames of a robot already at speed, the frames after it was lost, a kick. The aligner converges
// from within about a pixel of its coarsest level; at 640x480 with four levels that is about 8
// pixels of the full image, while a robot camera at 0.2 m sees the floor move 40 pixels per frame
// at 0.6 m/s. The search scores a grid of planar motions around a centre (the previous frame's
// pose) on one pyramid level, all in one pass, by the zero-mean normalised cross-correlation of
// the reference and the warped live level, and returns its best separate peaks for the aligner
// to start from. The grid is even in the image: spaced grid_px pixels of the level in the shift
// of the image's centre, out to max_shift of the level's smaller side, at each of a few rotations.
#pragma once
#include <string>
#include <vector>

#include <CL/opencl.hpp>
#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/se2.h"
#include "image/pyramid.h"
#include "track/warp_reduce.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

struct MotionSearchOptions {
  double max_shift = 0.3;     // the largest shift of the image's centre searched, of the level's smaller side
  double grid_px = 1.5;       // grid spacing, pixels of the level
  double max_rotation = 0.04; // rotations searched (rad): -max_rotation, 0, +max_rotation (0: none)
  // The level's pixels scored, at most (every step-th column and row): 1500 scores the 1350
  // motions at 640x480 in about 15 ms here; 6000 took 45 ms for the same outcome on 15 drives.
  int max_pixels = 1500;
  int max_candidates = 3;     // separate peaks returned, best first
  double min_overlap = 0.5;   // a hypothesis needs this share of the best-covered one's valid pixels
  // The best peak must be distinct, as in Lowe's ratio test: its distance from a perfect match
  // (1 - correlation) at most this share of the second peak's, else the search returns none. A
  // floor that repeats within the search's reach scores its neighbouring periods alike (tiles
  // under the robot's shadow: 0.9979 against 0.9973 and 0.9967, a ratio of 0.78), where a search
  // that finds the motion scores it apart (the acquisition drives: 0.11-0.47, and 0.55 on blue
  // tiles, whose first search was right); 1 turns the test off.
  double max_ambiguity = 0.65;
};

// One hypothesis's sums (the kernel's row): valid pairs n and, over them, the sums of a = I_r -
// 128, b = I_l(w(p)) - 128, a^2, b^2 and a b.
struct SearchSums {
  double n = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  // The zero-mean normalised cross-correlation, -1..1; -2 with fewer than 16 pairs or either
  // side flat.
  double correlation() const;
};

// The kernel's plain C++ reference: the warp and the sampling's validity in float as the kernel
// computes them, the sums in double.
std::vector<SearchSums> motion_search_reference(const LevelView& ref, const LevelView& live,
                                                const std::vector<Eigen::Matrix3d>& homographies, int step);

class MotionSearch {
 public:
  explicit MotionSearch(ocl::Runtime& runtime, int work_group = 64);
  static std::string build_options(int work_group);

  // The sums per homography (reference -> live pixels of the levels) over every step-th column and
  // row of the reference level (float4 buffers of pyramid.h).
  void run(const cl::Buffer& ref, int ref_w, int ref_h, const cl::Buffer& live, int live_w, int live_h,
           const std::vector<Eigen::Matrix3d>& homographies, int step, std::vector<SearchSums>* out);

  // The best separate peaks of the grid around `centre` at `level` of the pyramids (K: level 0's
  // camera matrix), best first; at most options.max_candidates, none when no hypothesis overlaps
  // or the best is not distinct from the second (options.max_ambiguity).
  std::vector<SE2> candidates(const Pyramid& reference, const Pyramid& live, int level, const Eigen::Matrix3d& K,
                              const Extrinsics& extrinsics, const SE2& centre, const MotionSearchOptions& options);

 private:
  ocl::Runtime& runtime_;
  int wg_;
  cl::Kernel kernel_;
  cl::Buffer homographies_, sums_;
  size_t capacity_ = 0;  // hypotheses the buffers hold
  std::vector<float> h_host_, sums_host_;
};

}  // namespace planarvo::track
