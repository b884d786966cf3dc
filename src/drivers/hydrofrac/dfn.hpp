// Natural fractures (a discrete fracture network) as zero-strength bonds, as seed 003 s. 4.3
// does in the DLSM: "joints are represented as 2D lines, and the spring bonds which were cut by
// the lines are set to zero strength", so the two particles interact through the contact law
// only (friction, no cohesion). 2D: segments in x-y; 3D: vertical discs (normal in x-y). From a
// file or a generator: uniform random or grid positions, fixed, staggered (alternating +-angle
// by grid row, seed 003 Fig. 17b) or random angles, lengths uniform in a range, none within a
// buffer of the wellbore.
#pragma once
#include <string>
#include <vector>

#include "dem/dem_system.hpp"
#include "coupling/hydrofrac/fluid_load.hpp"
#include "io/params.hpp"

namespace ff::drivers::hydrofrac {

using coupling::hydrofrac::JointPair;  // a bond cut by a joint (the fluid loads read them too)

struct Joint {
  Vec3 centre = Vec3::Zero();
  Real angle = 0;   // [rad] direction of the trace in x-y, from x
  Real length = 0;  // 2D: segment length; 3D: disc diameter [m]
};

void declare_dfn_params(ParamTable& t);
// The joints of the scenario (file or generator; none when dfn.count = 0 and no file) in a
// block [lo, hi] around a hole of radius `hole_radius` centred at `centre`. Throws InputError
// naming the key for a bad file or settings, and for a file whose every joint is centred outside
// the block (another unit or origin); `outside`, if given, counts the file's joints centred outside
// (a DFN drawn over a larger region than the block). The generator refuses a count of which it can
// place none (naming dfn.buffer or dfn.spacing); `shortfall`, if given, says why it placed fewer.
std::vector<Joint> make_joints(const Config& cfg, const Vec3& lo, const Vec3& hi, const Vec3& centre, Real hole_radius, int dim,
                               long* outside = nullptr, std::string* shortfall = nullptr);
// Removes every intact bond whose centre-to-centre segment crosses a joint; returns the pairs
// (global ids, bond face area) for the fluid.
std::vector<JointPair> cut_bonds(dem::DemSystem& sys, const std::vector<Joint>& joints);

}  // namespace ff::drivers::hydrofrac
