// An image file through the data set, as the tool reads it: a fixed data set of one 32x24 frame
// whose image is the input, as PNG or JPEG (the first byte chooses), opened with verify_images
// (the truncation check, OpenCV's decoder, the size and depth checks) and read through
// planarvo_dataset_frame. A frame that opens is the camera's size and 8-bit; anything else is
// INVALID_INPUT with a message.

#include "fuzz_common.h"

namespace {

constexpr int kWidth = 32, kHeight = 24;

const std::string& dataset_dir() {
  static const std::string dir = [] {
    const std::string d = planarvo_fuzz::work_dir() + "/dataset";
    std::filesystem::create_directories(d + "/images");
    planarvo_camera camera;
    if (planarvo_sim_default_camera(kWidth, kHeight, 80.0, &camera) != PLANARVO_OK ||
        planarvo_camera_save((d + "/camera.yaml").c_str(), &camera) != PLANARVO_OK)
      planarvo_fuzz::broken("cannot write the fixture's camera.yaml");
    std::ofstream(d + "/frames_png.txt") << "0.0 images/0.png\n";
    std::ofstream(d + "/frames_jpg.txt") << "0.0 images/0.jpg\n";
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  if (size < 1) return 0;
  const std::string& d = dataset_dir();
  const bool png = (data[0] & 1) == 0;
  write_file(d + (png ? "/images/0.png" : "/images/0.jpg"), data + 1, size - 1);
  std::filesystem::copy_file(d + (png ? "/frames_png.txt" : "/frames_jpg.txt"), d + "/frames.txt",
                             std::filesystem::copy_options::overwrite_existing);
  planarvo_dataset_options o;
  planarvo_dataset_options_init(&o);
  o.verify_images = 1;
  planarvo_dataset* ds = nullptr;
  const planarvo_status st = planarvo_dataset_open(d.c_str(), &o, &ds);
  check_status(st);
  if (st != PLANARVO_OK) {
    if (st != PLANARVO_ERROR_INVALID_INPUT) broken("a bad image gave a status other than INVALID_INPUT");
    if (ds != nullptr) broken("a failed open returned a data set");
    return 0;
  }
  planarvo_image image;
  const planarvo_status read = planarvo_dataset_frame(ds, 0, &image);
  check_status(read);
  if (read != PLANARVO_OK) broken("a verified image did not read");
  if (image.width != kWidth || image.height != kHeight || image.format != PLANARVO_GRAY8 ||
      image.stride < static_cast<size_t>(kWidth) || image.data == nullptr)
    broken("a frame that is not the camera's size or not 8-bit grey");
  // Every pixel readable (ASan sees a short buffer).
  unsigned sum = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) sum += static_cast<const uint8_t*>(image.data)[static_cast<size_t>(y) * image.stride + static_cast<size_t>(x)];
  (void)sum;
  planarvo_dataset_destroy(ds);
  return 0;
}
