// C API calls that fuzzing (fuzz/fuzz_capi.cpp) found misbehaving on bad arguments, each now a
// documented status with a message.
#include <cstring>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "planarvo/planarvo.h"

namespace {

using ::testing::HasSubstr;

// What a C caller can pass: any int in the enum's place. Returning it is itself what clang's
// UBSan checks ("load of value 4294967295, which is not a valid value"): in C it is an int.
#if defined(__clang__)
__attribute__((no_sanitize("enum")))
#endif
planarvo_status status_from_int(int v) {
  planarvo_status s;
  static_assert(sizeof s == sizeof v, "planarvo_status is an int");
  std::memcpy(&s, &v, sizeof v);
  return s;
}

// planarvo_status_name switched on the enum itself: an out-of-range value is undefined behaviour in
// C++ (UBSan: "load of value 2164260352, which is not a valid value for type 'planarvo_status'").
TEST(CApiFuzzRegression, StatusNameOfAnyIntIsUnknown) {
  for (int v : {-1, 11, 16, 999, static_cast<int>(0x80FFFF00u), 0x7fffffff})
    EXPECT_STREQ(planarvo_status_name(status_from_int(v)), "PLANARVO_ERROR_UNKNOWN") << v;
  EXPECT_STREQ(planarvo_status_name(status_from_int(9)), "PLANARVO_ERROR_INTERNAL");
  EXPECT_STREQ(planarvo_status_name(status_from_int(10)), "PLANARVO_ERROR_OUT_OF_MEMORY");
  EXPECT_STREQ(planarvo_status_name(status_from_int(0)), "PLANARVO_OK");
}

// A colour (3 bytes per pixel) or float (4) image whose stride covers the width in bytes but not
// the row: planarvo_roll_pitch_add_frame and planarvo_camera_calibrator_add_frame handed it to
// OpenCV, whose assertion came back as PLANARVO_ERROR_INTERNAL ("a bug in planarvo").
TEST(CApiFuzzRegression, StrideBelowTheRowIsInvalidArgumentForEveryFrameCall) {
  planarvo_context* context = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &context), PLANARVO_OK) << planarvo_last_error();
  planarvo_camera camera;
  ASSERT_EQ(planarvo_sim_default_camera(64, 48, 80.0, &camera), PLANARVO_OK);
  const planarvo_extrinsics extrinsics{0.2, 0.0, 0.2, 0.1, 0.1, 0.0};
  planarvo_tracker* tracker = nullptr;
  ASSERT_EQ(planarvo_tracker_create(context, &camera, &extrinsics, nullptr, &tracker), PLANARVO_OK)
      << planarvo_last_error();
  planarvo_roll_pitch* roll_pitch = nullptr;
  ASSERT_EQ(planarvo_roll_pitch_create(context, &camera, nullptr, &roll_pitch), PLANARVO_OK)
      << planarvo_last_error();
  planarvo_camera_calibrator* calibrator = nullptr;
  ASSERT_EQ(planarvo_camera_calibrator_create(context, &camera, nullptr, &calibrator), PLANARVO_OK)
      << planarvo_last_error();

  // Enough memory for the stride the caller claims: 64 bytes x 48 rows.
  std::vector<unsigned char> pixels(64 * 48, 128);
  for (planarvo_pixel_format format : {PLANARVO_BGR8, PLANARVO_RGB8, PLANARVO_GRAY32F}) {
    SCOPED_TRACE(static_cast<int>(format));
    const planarvo_image image{pixels.data(), 64, 48, 64, format};
    planarvo_track_result result;
    std::memset(&result, 0, sizeof result);
    result.struct_size = sizeof result;
    EXPECT_EQ(planarvo_tracker_track(tracker, &image, 0.0, &result), PLANARVO_ERROR_INVALID_ARGUMENT);
    EXPECT_THAT(planarvo_last_error(), HasSubstr("planarvo_tracker_track: stride"));
    int32_t complete = -1;
    EXPECT_EQ(planarvo_roll_pitch_add_frame(roll_pitch, &image, 0.0, &complete), PLANARVO_ERROR_INVALID_ARGUMENT);
    EXPECT_THAT(planarvo_last_error(), HasSubstr("planarvo_roll_pitch_add_frame: stride is less than the row"));
    EXPECT_EQ(complete, -1);  // untouched on failure
    EXPECT_EQ(planarvo_camera_calibrator_add_frame(calibrator, &image, 0.0, nullptr, nullptr),
              PLANARVO_ERROR_INVALID_ARGUMENT);
    EXPECT_THAT(planarvo_last_error(),
                HasSubstr("planarvo_camera_calibrator_add_frame: stride is less than the row"));
  }
  // A float image whose rows are not whole floats apart (stride 258 >= 4 x 64): an OpenCV assertion
  // (PLANARVO_ERROR_INTERNAL) in all three before.
  std::vector<unsigned char> floats(258 * 48, 0);
  const planarvo_image odd{floats.data(), 64, 48, 258, PLANARVO_GRAY32F};
  planarvo_track_result result;
  std::memset(&result, 0, sizeof result);
  result.struct_size = sizeof result;
  EXPECT_EQ(planarvo_tracker_track(tracker, &odd, 0.0, &result), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_THAT(planarvo_last_error(), HasSubstr("must be a multiple of 4"));
  EXPECT_EQ(planarvo_roll_pitch_add_frame(roll_pitch, &odd, 0.0, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_camera_calibrator_add_frame(calibrator, &odd, 0.0, nullptr, nullptr),
            PLANARVO_ERROR_INVALID_ARGUMENT);

  // The same memory as 8-bit grey is a whole frame: accepted by all three.
  const planarvo_image grey{pixels.data(), 64, 48, 64, PLANARVO_GRAY8};
  EXPECT_EQ(planarvo_roll_pitch_add_frame(roll_pitch, &grey, 0.0, nullptr), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(planarvo_camera_calibrator_add_frame(calibrator, &grey, 0.0, nullptr, nullptr), PLANARVO_OK)
      << planarvo_last_error();

  planarvo_camera_calibrator_destroy(calibrator);
  planarvo_roll_pitch_destroy(roll_pitch);
  planarvo_tracker_destroy(tracker);
  planarvo_context_destroy(context);
}

}  // namespace
