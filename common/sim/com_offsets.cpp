#include "common/sim/com_offsets.hpp"

#include <algorithm>
#include <random>

namespace masa::task {

void drawComOffsets(double size, bool per_limb, const std::vector<std::vector<int>>& body_image,
                    const std::vector<double>& spatial_map, int base_body, Rng& rng, std::vector<double>& out) {
  const int num_elements = static_cast<int>(body_image.size());
  const int nbody = num_elements > 0 ? static_cast<int>(body_image[0].size()) : 0;
  out.assign(3 * static_cast<std::size_t>(nbody), 0.0);
  std::uniform_real_distribution<double> u(-size, size);
  if (per_limb) {
    for (int b = 1; b < nbody; ++b)  // body 0 is the world
      for (int k = 0; k < 3; ++k) out[3 * b + k] = u(rng);
    return;
  }
  std::vector<char> done(static_cast<std::size_t>(nbody), 0);
  std::vector<double> sum(3 * static_cast<std::size_t>(nbody), 0.0);
  std::vector<int> count(static_cast<std::size_t>(nbody), 0);
  for (int r = 1; r < nbody; ++r) {
    if (done[r]) continue;
    bool reached = true;
    for (int i = 0; i < num_elements; ++i) reached = reached && body_image[i][r] >= 0;
    if (!reached && r != base_body) continue;  // images unknown: no offset
    const double d[3] = {u(rng), u(rng), u(rng)};
    std::vector<int> orbit;
    for (int i = 0; i < num_elements; ++i) {
      const int target = reached ? body_image[i][r] : r;  // the base: fixed by every element
      const double* s = spatial_map.data() + 9 * i;
      for (int row = 0; row < 3; ++row)
        sum[3 * target + row] += s[3 * row] * d[0] + s[3 * row + 1] * d[1] + s[3 * row + 2] * d[2];
      ++count[target];
      orbit.push_back(target);
    }
    for (int b : orbit) {
      if (done[b]) continue;
      done[b] = 1;
      for (int k = 0; k < 3; ++k) out[3 * b + k] = sum[3 * b + k] / count[b];
    }
  }
}

}  // namespace masa::task
