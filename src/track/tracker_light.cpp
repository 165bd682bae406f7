// The light fixed to the camera as the tracker handles it (tracker_impl.h): learning the
// photometric model from tracked frames, its refits beside the tracking, and the rescue of a frame
// the light holds.
#include "track/tracker_impl.h"

namespace planarvo::track {

void Tracker::Impl::learn_photometric(const FrameResult& r) {
  PhotometricModel* photometric = pipeline->photometric();
  if (!photometric || !photometric->learning()) return;
  if (learnt_this_frame || r.status == Status::First) {
    if (!learnt_this_frame) pipeline->learn();
    learnt_this_frame = false;
    light_gate.learnt();
    return;
  }
  if (light_gate.learn_from(r)) pipeline->learn();
}

bool Tracker::Impl::correct_again(const Pyramid& live) {
  PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
  if (!photometric || !photometric->learning() || &live != &slots[live_slot] || !keyframe_kept) return false;
  if (!learnt_this_frame) {
    pipeline->learn();
    learnt_this_frame = true;
  }
  if (!photometric->refit_due(true)) return false;
  photometric->refit(true);
  correct_with_new_model();
  return true;
}

void Tracker::Impl::start_young_refit() {
  PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
  if (!photometric || !photometric->learning() || !has_keyframe || !keyframe_kept || photometric->refit_pending())
    return;
  const PhotometricFit& fit = photometric->fit();
  if (fit.frames >= kPhotometricSettledFrames) return;
  const bool rough = !fit.identity;
  if (rough ? photometric->frames() - fit.frames < std::max(1, fit.frames / 4) : !photometric->refit_due()) return;
  start_refit(rough);
}

void Tracker::Impl::take_young_refit() {
  PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
  // A settled model's refit is taken at a keyframe (make_keyframe).
  if (!photometric || !photometric->refit_pending() || !refit_young) return;
  const bool was_identity = photometric->fit().identity;
  if (refit_taken() && !(was_identity && photometric->fit().identity) && has_keyframe && keyframe_kept)
    correct_with_new_model();
}

void Tracker::Impl::start_refit(bool needed) {
  PhotometricModel* photometric = pipeline->photometric();
  if (photometric->refit_pending()) return;
  photometric->start_refit(needed);
  refit_young = photometric->frames() < kPhotometricSettledFrames;
  refit_take_at = camera_frames + (refit_young ? kYoungRefitLagFrames : kSettledRefitLagFrames);
}

bool Tracker::Impl::refit_taken() {
  PhotometricModel* photometric = pipeline->photometric();
  return photometric->refit_pending() && camera_frames >= refit_take_at && photometric->take_refit();
}

void Tracker::Impl::correct_with_new_model() {
  pipeline->reprocess_kept(keyframe);
  pipeline->reprocess(slots[live_slot]);
  select_keyframe_pixels();
}

}  // namespace planarvo::track
