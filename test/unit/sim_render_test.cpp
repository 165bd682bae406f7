// The simulator's rendering in plain C++ (render_reference; the kernel test ties the OpenCL
// kernel to it): mip pyramid, ray tables, and the key acceptance tests: the geometry agrees
// with CameraModel::project and the true extrinsics, and the images do not alias.
#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Bilinear lookup of a grey image at a pixel position, OpenCV's pixel-centre convention.
double bilinear(const cv::Mat& img, const Eigen::Vector2d& p) {
  const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
  const double fx = p.x() - x0, fy = p.y() - y0;
  auto at = [&](int x, int y) { return static_cast<double>(img.at<float>(y, x)); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// The texture tiled over the plane by mirroring, sampled bilinearly at texture coordinates
// (u, v) (texel centres at whole numbers): an implementation independent of the renderer's,
// using OpenCV's BORDER_REFLECT (fedcba|abcdefgh|hgfedcb).
double sample_tiled(const cv::Mat& tex, double u, double v) {
  const double fu = std::floor(u), fv = std::floor(v);
  const double fx = u - fu, fy = v - fv;
  auto at = [&](double x, double y) {
    const int xi = cv::borderInterpolate(static_cast<int>(x), tex.cols, cv::BORDER_REFLECT);
    const int yi = cv::borderInterpolate(static_cast<int>(y), tex.rows, cv::BORDER_REFLECT);
    return static_cast<double>(tex.at<float>(yi, xi));
  };
  return (1 - fy) * ((1 - fx) * at(fu, fv) + fx * at(fu + 1, fv)) +
         fy * ((1 - fx) * at(fu, fv + 1) + fx * at(fu + 1, fv + 1));
}

// Where the ray through a distorted pixel meets the ground, in world coordinates: camera pose
// T_wc = T_wv T_vc, the ray's direction R_wc (x, y, 1).
Eigen::Vector3d ground_point(const CameraModel& cam, const Extrinsics& e, const SE2& pose,
                             const Eigen::Vector2d& pixel) {
  const Eigen::Matrix4d T_wc = pose.matrix3d() * e.T_vc();
  const Eigen::Vector2d n = cam.unproject(pixel);
  const Eigen::Vector3d d = T_wc.topLeftCorner<3, 3>() * Eigen::Vector3d(n.x(), n.y(), 1.0);
  const Eigen::Vector3d c = T_wc.topRightCorner<3, 1>();
  return c - (c.z() / d.z()) * d;
}

// Projects a world point into the camera at a robot pose; false when behind the camera.
bool project(const CameraModel& cam, const Extrinsics& e, const SE2& pose,
             const Eigen::Vector3d& X, Eigen::Vector2d* pixel) {
  const Eigen::Matrix4d T_cw = (pose.matrix3d() * e.T_vc()).inverse();
  const Eigen::Vector3d Xc = T_cw.topLeftCorner<3, 3>() * X + T_cw.topRightCorner<3, 1>();
  if (Xc.z() <= 0) return false;
  *pixel = cam.project(Xc);
  return true;
}

cv::Mat load_texture(const std::string& name) {
  const cv::Mat t = cv::imread(test::texture(name).string(), cv::IMREAD_GRAYSCALE);
  if (t.empty()) throw std::runtime_error("cannot read texture " + name);
  cv::Mat f;
  t.convertTo(f, CV_32F);
  return f;
}

cv::Mat noise_texture(int w, int h, uint64_t seed) {
  Random r(seed);
  cv::Mat t(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.at<float>(y, x) = static_cast<float>(255.0 * r.uniform());
  return t;
}

cv::Mat render(const cv::Mat& texture, const CameraModel& cam, const Extrinsics& e,
               double texel, const SE2& pose, int ss, bool mip) {
  const MipPyramid pyr = build_mip_pyramid(texture);
  const RayTable rays = build_ray_table(cam, ss);
  return render_reference(pyr, rays, frame_params(pose, e, Eigen::Vector2d(texel, texel), pyr, ss, mip));
}

// ---------------------------------------------------------------------------------------------

TEST(SimRender, MipPyramidLevelsAreBoxAverages) {
  const cv::Mat t = noise_texture(64, 16, 1);
  const MipPyramid m = build_mip_pyramid(t);
  ASSERT_EQ(m.num_levels(), 5);  // 64x16, 32x8, 16x4, 8x2, 4x1
  EXPECT_EQ(m.levels[3 * 4 + 1], 4);
  EXPECT_EQ(m.levels[3 * 4 + 2], 1);
  for (int l = 1; l < m.num_levels(); ++l) {
    const int po = m.levels[3 * (l - 1)], pw = m.levels[3 * (l - 1) + 1];
    const int o = m.levels[3 * l], w = m.levels[3 * l + 1], h = m.levels[3 * l + 2];
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const auto at = [&](int xx, int yy) { return static_cast<double>(m.data[static_cast<size_t>(po + yy * pw + xx)]); };
        const double box = 0.25 * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) + at(2 * x + 1, 2 * y + 1));
        ASSERT_NEAR(m.data[static_cast<size_t>(o + y * w + x)], box, 1e-3);
      }
  }
  EXPECT_NEAR(m.mean, cv::mean(t)[0], 1e-3);
  EXPECT_THROW(build_mip_pyramid(noise_texture(48, 32, 1)), Error);
}

TEST(SimRender, PrepareTextureResizesToPowersOfTwo) {
  Eigen::Vector2d scale;
  cv::Mat t = prepare_texture(cv::Mat(300, 700, CV_8UC1, cv::Scalar(9)), &scale);
  EXPECT_EQ(t.cols, 512);
  EXPECT_EQ(t.rows, 256);
  EXPECT_EQ(t.type(), CV_32FC1);
  EXPECT_DOUBLE_EQ(scale.x(), 700.0 / 512);
  EXPECT_DOUBLE_EQ(scale.y(), 300.0 / 256);
  t = prepare_texture(cv::Mat(512, 1024, CV_8UC1, cv::Scalar(9)), &scale);
  EXPECT_EQ(t.cols, 1024);
  EXPECT_EQ(scale, Eigen::Vector2d(1, 1));
}

TEST(SimRender, RayTablesMatchTheCameraModel) {
  const CameraModel cam = default_camera(64, 48);
  const RayTable t = build_ray_table(cam, 3);
  const size_t n = 64 * 48;
  for (int r : {0, 17, 47})
    for (int c : {0, 33, 63}) {
      const size_t p = static_cast<size_t>(r * 64 + c);
      const Eigen::Vector2d ray = cam.unproject(Eigen::Vector2d(c, r));
      EXPECT_NEAR(t.pixel[p], ray.x(), 1e-6);
      EXPECT_NEAR(t.pixel[n + p], ray.y(), 1e-6);
      // Jacobian against central differences of unproject.
      const double h = 1e-3;
      const Eigen::Vector2d dx = (cam.unproject(Eigen::Vector2d(c + h, r)) - cam.unproject(Eigen::Vector2d(c - h, r))) / (2 * h);
      const Eigen::Vector2d dy = (cam.unproject(Eigen::Vector2d(c, r + h)) - cam.unproject(Eigen::Vector2d(c, r - h))) / (2 * h);
      EXPECT_NEAR(t.pixel[2 * n + p], dx.x(), 1e-6);
      EXPECT_NEAR(t.pixel[3 * n + p], dy.x(), 1e-6);
      EXPECT_NEAR(t.pixel[4 * n + p], dx.y(), 1e-6);
      EXPECT_NEAR(t.pixel[5 * n + p], dy.y(), 1e-6);
      // Subsample (i, j) = (2, 0) sits a third of a pixel right of and above the centre.
      const size_t s = 0 * 3 + 2;
      const Eigen::Vector2d rs = cam.unproject(Eigen::Vector2d(c + 1.0 / 3, r - 1.0 / 3));
      EXPECT_NEAR(t.sub[2 * s * n + p], rs.x(), 1e-6);
      EXPECT_NEAR(t.sub[(2 * s + 1) * n + p], rs.y(), 1e-6);
    }
}

TEST(SimRender, DefaultCameraHasAnEightyDegreeFieldOfView) {
  const CameraModel cam = default_camera();
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 480);
  EXPECT_LT(cam.k1, 0.0);  // barrel
  // Half the image width from the principal point is 40 degrees off the axis.
  const Eigen::Vector2d ray = cam.unproject(Eigen::Vector2d(cam.cx + 320.0, cam.cy));
  EXPECT_NEAR(std::atan(ray.x()) / kDeg, 40.0, 1e-6);
}

// The homography maps a pixel's ray to the texture coordinates of the ground point the camera
// model and the extrinsics put there, far from the origin too.
TEST(SimRender, RayToTextureHitsTheGroundPoint) {
  const CameraModel cam = default_camera();
  const Extrinsics e = default_extrinsics();
  for (const SE2& pose : {SE2(0, 0, 0), SE2(0.3, -0.2, 2.5), SE2(-4321.5, 9876.25, -1.0)}) {
    const Eigen::Vector2d texel(0.0004, 0.0005), origin(2048.0 * 3, -1024.0 * 5);
    const Eigen::Matrix3d H = ray_to_texture(pose, e, texel, origin);
    for (const Eigen::Vector2d& px : {Eigen::Vector2d(0, 0), Eigen::Vector2d(320, 240), Eigen::Vector2d(639, 100)}) {
      const Eigen::Vector3d X = ground_point(cam, e, pose, px);
      EXPECT_NEAR(X.z(), 0.0, 1e-9);
      const Eigen::Vector2d ray = cam.unproject(px);
      const Eigen::Vector3d h = H * Eigen::Vector3d(ray.x(), ray.y(), 1.0);
      EXPECT_NEAR(h.x() / h.z(), X.x() / texel.x() - origin.x(), 1e-6);
      EXPECT_NEAR(h.y() / h.z(), X.y() / texel.y() - origin.y(), 1e-6);
    }
  }
}

// The key acceptance test. Two noise-free renders from known robot poses; many ground points
// seen in both, projected into each with the true extrinsics and camera model in double; the
// rendered intensities there must agree, and much better than when the second pose is off by
// about one pixel's worth of motion. The texture is a real photograph blurred to low
// frequencies (Gaussian, sigma 5 texels) and stretched to a contrast of 40 grey levels (std),
// so that a one-pixel error shows while the difference between a pixel's area average and a
// point sample stays small; points where a pixel covers more than 2.5 texels, where that
// difference grows, are left out.
struct Config {
  const char* name;
  Extrinsics e;
  SE2 a, motion;
};

TEST(SimRender, GeometryAgreesWithTheCameraModelAndExtrinsics) {
  cv::Mat tex = load_texture("asphalt_01.png");
  cv::GaussianBlur(tex, tex, cv::Size(), 5.0, 5.0, cv::BORDER_REFLECT);  // consistent with mirroring
  cv::Scalar mean, sd;
  cv::meanStdDev(tex, mean, sd);
  tex = (tex - mean[0]) * (40.0 / sd[0]) + 128.0;  // a contrast of 40 grey levels (std)
  const double texel = 0.0004;
  const CameraModel cam = default_camera();
  const MipPyramid pyr = build_mip_pyramid(tex);
  const RayTable rays = build_ray_table(cam, 3);
  Extrinsics tilted = default_extrinsics();
  tilted.pitch = 30 * kDeg;
  tilted.roll = -8 * kDeg;
  tilted.yaw = 25 * kDeg;
  tilted.x = -0.1;
  tilted.z = 0.25;
  const Config configs[] = {
      {"paper configuration 1", default_extrinsics(), SE2(0.37, -0.21, 0.4), SE2(0.04, 0.0, 0.08)},
      {"pitch 30, far from the origin", tilted, SE2(1234.567, -987.654, -2.0), SE2(0.03, 0.0, -0.12)},
  };
  for (const Config& c : configs) {
    SCOPED_TRACE(c.name);
    const SE2 b = c.a * c.motion;
    const double px_motion = c.e.z / cam.fx;  // ground distance of one pixel under the camera
    auto at = [&](const SE2& pose) {
      return render_reference(pyr, rays, frame_params(pose, c.e, Eigen::Vector2d(texel, texel), pyr, 3, true));
    };
    const cv::Mat ia = at(c.a), ib = at(b);
    const cv::Mat ib_dx = at(b * SE2(px_motion, 0, 0)), ib_dy = at(b * SE2(0, px_motion, 0));
    const cv::Mat ib_dth = at(b * SE2(0, 0, 1.0 / cam.fx));
    double sum = 0, sum_dx = 0, sum_dy = 0, sum_dth = 0, sum_direct = 0, sum_direct_shift = 0;
    int count = 0;
    for (int y = 8; y < cam.height - 8; y += 6)
      for (int x = 8; x < cam.width - 8; x += 6) {
        const Eigen::Vector2d pa(x, y);
        const Eigen::Vector3d X = ground_point(cam, c.e, c.a, pa);
        Eigen::Vector2d pa2, pb;
        ASSERT_TRUE(project(cam, c.e, c.a, X, &pa2));
        ASSERT_LT((pa2 - pa).norm(), 1e-6);
        if (!project(cam, c.e, b, X, &pb) || pb.x() < 2 || pb.y() < 2 || pb.x() > cam.width - 3 ||
            pb.y() > cam.height - 3)
          continue;
        // A pixel's footprint on the ground, in texels, in both frames.
        const double foot_a = (ground_point(cam, c.e, c.a, pa + Eigen::Vector2d(1, 0)) - X).norm() / texel;
        const double foot_b = (ground_point(cam, c.e, b, pb + Eigen::Vector2d(1, 0)) - X).norm() / texel;
        if (foot_a > 2.5 || foot_b > 2.5) continue;
        const double va = ia.at<float>(y, x);
        sum += std::abs(va - bilinear(ib, pb));
        sum_dx += std::abs(va - bilinear(ib_dx, pb));
        sum_dy += std::abs(va - bilinear(ib_dy, pb));
        sum_dth += std::abs(va - bilinear(ib_dth, pb));
        // The rendered pixel against the texture sampled directly at its ground point, and at
        // a point one pixel's worth away.
        sum_direct += std::abs(va - sample_tiled(tex, X.x() / texel, X.y() / texel));
        sum_direct_shift += std::abs(va - sample_tiled(tex, (X.x() + px_motion) / texel, X.y() / texel));
        ++count;
      }
    ASSERT_GT(count, 2500);
    const double mad = sum / count, mad_dx = sum_dx / count, mad_dy = sum_dy / count;
    const double mad_dth = sum_dth / count, mad_direct = sum_direct / count;
    const double mad_direct_shift = sum_direct_shift / count;
    std::printf("%s: %d points; mean |difference| %.3f grey levels; second pose off by one pixel "
                "along x %.3f, along y %.3f, in angle %.3f; against the texture %.3f, shifted %.3f\n",
                c.name, count, mad, mad_dx, mad_dy, mad_dth, mad_direct, mad_direct_shift);
    EXPECT_LT(mad, 0.5);
    EXPECT_LT(mad, 0.25 * mad_dx);
    EXPECT_LT(mad, 0.25 * mad_dy);
    EXPECT_LT(mad, 0.5 * mad_dth);
    EXPECT_LT(mad_direct, 0.5);
    EXPECT_LT(mad_direct, 0.25 * mad_direct_shift);
  }
}

// With the camera looking straight down and the robot heading along x, the image top sees
// the robot's front (conventions.md) and the image's left the robot's left.
TEST(SimRender, ImageTopIsTheRobotsFront) {
  // A dark texture with a bright patch; the robot stands at the texture's centre, texel
  // (128, 128), so that the mirrored copies of the patch are far out of view.
  const double texel = 0.001;
  const SE2 pose(128 * texel, 128 * texel, 0.0);
  Extrinsics e;
  e.z = 0.1;
  const CameraModel cam = default_camera(160, 120);
  auto centroid = [&](const cv::Rect& patch) {
    cv::Mat tex(256, 256, CV_32FC1, cv::Scalar(0));
    tex(patch).setTo(255);
    const cv::Moments m = cv::moments(render(tex, cam, e, texel, pose, 2, true) > 128, true);
    EXPECT_GT(m.m00, 10);
    return Eigen::Vector2d(m.m10 / m.m00, m.m01 / m.m00);
  };
  // 2 to 4 cm ahead (u = 148..167), centred across (v = 123..132): above the image centre.
  Eigen::Vector2d c = centroid(cv::Rect(148, 123, 20, 10));
  EXPECT_LT(c.y(), cam.cy - 10);
  EXPECT_NEAR(c.x(), cam.cx, 3.0);
  // 2 to 4 cm to the robot's left (world y > 0: v = 148..167): left of the image centre.
  c = centroid(cv::Rect(123, 148, 10, 20));
  EXPECT_LT(c.x(), cam.cx - 10);
  EXPECT_NEAR(c.y(), cam.cy, 3.0);
}

// Anti-aliasing: a noise texture seen by a strongly tilted camera. The default renderer
// (3x3 subsamples, mip-mapped) must be much closer to a brute-force 16x16-subsample render
// without mip-mapping than a single-sample render without mip-mapping is.
TEST(SimRender, DoesNotAlias) {
  const cv::Mat tex = noise_texture(512, 512, 3);
  const CameraModel cam = default_camera(160, 120);
  Extrinsics e = default_extrinsics();
  e.pitch = 30 * kDeg;
  const double texel = 0.001;
  const SE2 pose(0.1, 0.2, 0.3);
  const cv::Mat brute = render(tex, cam, e, texel, pose, 16, false);
  const cv::Mat brute12 = render(tex, cam, e, texel, pose, 12, false);
  const cv::Mat def = render(tex, cam, e, texel, pose, 3, true);
  const cv::Mat naive = render(tex, cam, e, texel, pose, 1, false);
  const cv::Mat ss_only = render(tex, cam, e, texel, pose, 3, false);
  auto rms = [](const cv::Mat& a, const cv::Mat& b) {
    const cv::Mat d = a - b;
    return std::sqrt(cv::mean(d.mul(d))[0]);
  };
  const double e_def = rms(def, brute), e_naive = rms(naive, brute), e_ss = rms(ss_only, brute);
  const double e_brute = rms(brute12, brute);
  std::printf("RMS against 16x16 brute force: default %.2f, 1 sample %.2f, 3x3 without mip %.2f, "
              "12x12 without mip %.2f grey levels\n", e_def, e_naive, e_ss, e_brute);
  EXPECT_LT(e_def, 0.3 * e_naive);
  EXPECT_LT(e_def, e_ss);
}

}  // namespace
}  // namespace planarvo::sim
