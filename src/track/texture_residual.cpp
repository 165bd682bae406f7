#include "track/texture_residual.h"

#include <cmath>
#include <cstddef>
#include <limits>

#include "image/pyramid.h"

namespace planarvo::track {

int texture_residual_level(int width, int levels) {
  int l = 0;
  while (l + 1 < levels && level_size(width, l) > 200) ++l;
  return l;
}

double texture_residual(const ResidualImage& im) {
  const int w = im.width, h = im.height;
  // Sums of |N*r| and |N*I_r| over the pixels whose neighbourhood is valid.
  double sr = 0.0, si = 0.0;
  size_t n = 0;
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      double nr = 0.0, ni = 0.0;
      bool valid = true;
      for (int dy = -1; dy <= 1 && valid; ++dy) {
        const size_t row = static_cast<size_t>(y + dy) * static_cast<size_t>(w);
        for (int dx = -1; dx <= 1; ++dx) {
          const size_t q = row + static_cast<size_t>(x + dx);
          if (!(im.weight[q] > 0.0f)) {
            valid = false;
            break;
          }
          // N's weights: 4 at the centre, -2 at the four sides, 1 at the four corners.
          const double c = dx == 0 && dy == 0 ? 4.0 : (dx == 0 || dy == 0 ? -2.0 : 1.0);
          nr += c * im.residual[q];
          ni += c * im.intensity[q];
        }
      }
      if (!valid) continue;
      sr += std::abs(nr);
      si += std::abs(ni);
      ++n;
    }
  }
  return texture_residual_ratio(sr, si, static_cast<double>(n));
}

double texture_residual_ratio(double sum_nr, double sum_ni, double count) {
  if (count < 16 || !(sum_ni > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return sum_nr / (std::sqrt(2.0) * sum_ni);
}

}  // namespace planarvo::track
