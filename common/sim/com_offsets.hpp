// Centre-of-mass offsets that keep a robot's symmetry (env.randomization.com_offset, issue #52).
//
// The symmetry T_i carries body b onto body T_i(b) and maps world vectors by S_i (a mirror or a
// rotation). A model stays symmetric when the offset of T_i(b) is S_i times the offset of b. So one
// offset d is drawn per orbit, at its first body r, and every body of the orbit gets the average of
// S_i d over the elements i that carry r onto it: for the orbit's other bodies that is S_j of r's
// own offset, and for r itself the average over the elements that fix r, the projection onto their
// fixed subspace. A body the symmetry maps onto itself (the robot base) can thus only move within
// the mirror's plane or along the rotation's axis: a trunk whose centre of mass is off to one side
// is not a symmetric robot. Bodies the symmetry does not reach other than the base get none (their
// images are not known). Per limb: every body its own offset.
#pragma once

#include <vector>

#include "common/core/types.hpp"

namespace masa::task {

// out: 3 per body, world frame. body_image[i][b]: T_i(b) or -1 (unknown); spatial_map: 9 per
// element, row major. base_body: the robot base (fixed by every element), -1 if none.
void drawComOffsets(double size, bool per_limb, const std::vector<std::vector<int>>& body_image,
                    const std::vector<double>& spatial_map, int base_body, Rng& rng, std::vector<double>& out);

}  // namespace masa::task
