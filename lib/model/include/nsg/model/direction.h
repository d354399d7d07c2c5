#pragma once
// LaneDirNet's label space and the paper's rule that orients an edge from it.
//
// Angles are in the map frame (x east, y north), counter-clockwise from east, in [0, 2π).
// A tile's pixel step (du, dv) (v grows southwards) has the map angle atan2(−dv, du).
#include <array>

#include "nsg/skeleton/skeleton.h"

namespace nsg::model {

constexpr int kDirectionBins = 18;                // 20° each, as in the paper
constexpr int kBackgroundClass = kDirectionBins;  // the 19th class: no lane here
constexpr int kDirectionClasses = kDirectionBins + 1;

// Map angle of a pixel-frame vector (du, dv), in [0, 2π).
double map_angle(double du, double dv);
// Bin of a map angle (any real value; wrapped into [0, 2π)).
int direction_bin(double angle_rad);
// Centre angle of a bin, in [0, 2π).
double bin_centre_rad(int bin);

// Mean predicted direction at a node as a pixel-frame vector (du, dv) from the vote
// counts of the 19 classes (background ignored): Σ votes[k] · unit(centre_k). Zero when
// only background was voted.
std::array<double, 2> mean_direction_px(const std::array<float, kDirectionClasses>& votes);

// The paper's rule that orients an anchor pair from the mean directions at its ends lives
// with the skeleton chain (graphify's directed mode uses it too).
using skeleton::orient_a_to_b;

}  // namespace nsg::model
