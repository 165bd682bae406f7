// The tracker's keyframes (tracker_impl.h): making one from a frame, whether a frame has texture
// enough to be one, and the keyframe's subsampled pixels.
#include "track/tracker_impl.h"

namespace planarvo::track {

void Tracker::Impl::make_keyframe(const Pyramid& live) {
  if (&live == &slots[live_slot]) {
    keyframe = live;
    keyframe_is_slot = true;
    live_slot ^= 1;
    // A new photometric model is taken into use with a new keyframe: the frame (still in the
    // pipeline) is corrected again with it. Its fit was started at an earlier keyframe
    // (kSettledRefitLagFrames).
    PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
    if (photometric && refit_taken()) pipeline->reprocess(keyframe);
    if (photometric && photometric->refit_due(light_holds)) start_refit(light_holds);
    // Its frame stays on the device, so that a model made at a later frame can correct the
    // keyframe again (correct_again), or a measured twist undistort it again (take_out_shutter).
    if (photometric || camera.timed_rows()) {
      pipeline->keep();
      keyframe_kept = true;
    }
  } else {
    // Copied into the spare pyramid, which then swaps with the keyframe's: the old keyframe's
    // contents stay for residuals() until the next frame (no more copying than in place).
    if (spare.levels.size() != live.levels.size()) spare.levels.clear();
    for (size_t l = 0; l < live.levels.size(); ++l) {
      const PyramidLevel& src = live.levels[l];
      if (spare.levels.size() <= l) spare.levels.push_back(PyramidLevel());
      PyramidLevel& dst = spare.levels[l];
      const size_t bytes = static_cast<size_t>(src.width) * src.height * 16;
      if (dst.width != src.width || dst.height != src.height || !dst.data()) {
        dst.width = src.width;
        dst.height = src.height;
        dst.data = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, bytes);
      }
      rt.queue().enqueueCopyBuffer(src.data, dst.data, 0, 0, bytes);
    }
    std::swap(keyframe, spare);
    keyframe_kept = false;
    if (keyframe_is_slot) spare = Pyramid();  // a slot's buffers are the pipeline's, not spare
    keyframe_is_slot = false;
  }
  select_keyframe_pixels();
  has_keyframe = true;
  prev = Estimate();
  prev.att_ref = prev.att_live = plane.keyframe();
  prev_predicted = false;
  prev_covariance.setZero();
  prev_tilt.setZero();
  // A frame whose own twist was taken as the interval's mean velocity passes that on.
  keyframe_shear_assumed = shutter_unknown;
}

bool Tracker::Impl::has_own_texture(const Pyramid& live) {
  int coarse = std::min(opt.levels, live.num_levels()) - 1;
  while (coarse > 0 && (live.levels[static_cast<size_t>(coarse)].width < kMinLevelSide ||
                        live.levels[static_cast<size_t>(coarse)].height < kMinLevelSide))
    --coarse;
  return aligner.texture(live, coarse) >= kMinSelfTexture;
}

void Tracker::Impl::select_keyframe_pixels() {
  const AlignmentLevels levels = aligner.levels(keyframe, keyframe);
  for (int l = 0; l < keyframe.num_levels() && l < kMaxLevels; ++l) {
    const auto L = static_cast<size_t>(l);
    if (levels.select_block[L] >= 2)
      selector.run(keyframe.levels[L], l, levels.select_block[L], &selection[L]);
    else
      selection[L] = SelectedPixels();
  }
}

}  // namespace planarvo::track
