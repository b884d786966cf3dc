// injection.fluid = "sleeve": the borehole pressure p(t) acts as a normal traction on the
// particles that line the hole (the laboratory sleeve-fracturing test: a jacket presses the
// wall, no fluid enters the rock), and, with injection.penetration = true, also on the faces of
// every crack connected to the hole (each broken bond reached from the wall pushes its two
// particles apart with p times its face area: fluid that follows the crack; the
// Haimson-Fairhurst case). The pressure either rises at a set rate (injection.mode = "ramp") or
// follows a pumped rate Q through the compressibility of the fluid in the borehole
// (injection.mode = "rate"): dp/dt = K_f / V (Q - dV/dt), V the pressurised volume measured from
// the wall particles' motion (and the wetted cracks' opening). Units: 2D per metre of thickness.
#pragma once
#include <vector>

#include "coupling/hydrofrac/borehole.hpp"
#include "coupling/hydrofrac/fluid_load.hpp"

namespace ff::drivers::hydrofrac {

// The borehole geometry and the FluidLoad interface (src/coupling/hydrofrac/), which the sleeve
// implements without a second physics module.
using namespace coupling::hydrofrac;

struct SleeveSettings {
  bool rate_mode = false;
  Real ramp_rate = 0;         // [Pa/s]
  Real initial_pressure = 0;  // [Pa]
  Real flow_rate = 0;         // Q [m^3/s] (2D: per metre)
  Real bulk_modulus = 2.2e9;  // K_f [Pa]
  bool penetration = false;
  long update_interval = 20;  // steps between searches for newly connected cracks
  Real cell = 0, inflate = 0, reach = 0;  // flood fill (hole_surface)
};

class SleeveLoad final : public FluidLoad {
 public:
  explicit SleeveLoad(SleeveSettings s) : s_(s) {}
  void begin(const dem::DemSystem& sys, const BoreholeGeometry& hole, const std::vector<JointPair>& joints) override;
  void add_forces(dem::DemSystem& sys) override;
  void advance(const dem::DemSystem& sys) override;
  FluidState state() const override;
  const std::vector<Index>& wall_particles() const override { return wall_; }
  void save(CheckpointWriter& w) const override;
  void load(CheckpointReader& r, const dem::DemSystem& sys) override;
  Real effective_radius() const { return st_.effective_radius; }

 private:
  struct Wetted {  // (trivially copyable: a checkpoint section)  // a crack face under pressure
    Index a, b;
    Real area, gap0;
  };
  struct State {
    Real pressure = 0, t0 = 0, volume0 = 0, volume = 0, injected = 0, effective_radius = 0;
    long steps = 0, unused = 0;
  };
  Real volume(const dem::DemSystem& sys) const;
  void find_wetted(const dem::DemSystem& sys);

  SleeveSettings s_;
  State st_;
  std::vector<Index> wall_;
  std::vector<Vec3> area_, x0_;
  std::vector<JointPair> joints_;
  std::vector<Wetted> wetted_;
  // scratch
  std::vector<Index> id_index_;
  std::vector<std::size_t> ev_, jt_;
  std::vector<char> visited_;
};

}  // namespace ff::drivers::hydrofrac
