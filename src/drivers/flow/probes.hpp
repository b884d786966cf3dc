// Named point probes of the flow drivers (issue 14): pressure and velocity at points given in
// metres, written per sample to series.csv (p_<name>_Pa, ux_<name>_m_per_s, ...) and, between
// two named probes, the pressure difference dp_<a>_<b>_Pa (the Delta p of Schaefer & Turek 1996).
//
// Interpolation (lattice coordinates: cell (i, j, k) has its centre at ((i+1/2), (j+1/2),
// (k+1/2)) dx): bilinear (trilinear) when the 4 (8) surrounding nodes are fluid; otherwise
// (on or next to a solid surface or a domain face) a weighted least-squares fit of a
// second-order polynomial over the fluid nodes within kFitRadius cells, evaluated at the point:
// exact for quadratic fields, error O(dx^3) for smooth ones. The stencils (nodes and weights)
// are computed once from the solid mask, so a sample costs a few multiply-adds per probe.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "io/params.hpp"

namespace ff::drivers {

struct FlowSample;

inline constexpr double kFitRadius = 2.5;  // cells: nodes of the least-squares fit

struct ProbePoint {
  std::string name;
  Vec3 position = Vec3::Zero();  // m
};

struct ProbeSet {
  std::vector<ProbePoint> points;
  std::optional<std::array<int, 2>> delta_p;  // indices into points
  bool three_d = false;                      // D3Q19: uz columns
  bool empty() const { return points.empty(); }
};

void declare_probe_params(ParamTable& t);
// Reads and checks probes.* (lengths, names, delta_p); `depth` [m] of a D3Q19 lattice (z
// default: mid-depth), 0 on D2Q9. Throws InputError naming the key.
ProbeSet read_probes(const Config& cfg, bool d3q19, double depth);
// Checks the points against the lattice (nx x ny x nz cells of size dx, `solid(x, y, z)`):
// outside the domain, or in a solid more than ~1 cell from any fluid node, is an InputError
// naming the key and the probe's index.
void check_probe_positions(const Config& cfg, const ProbeSet& p, double dx, int nx, int ny, int nz,
                           const std::function<bool(int, int, int)>& solid);

// Weights of one probe: value = sum_k weight[k] * field[node[k]].
struct ProbeStencil {
  std::vector<std::size_t> node;
  std::vector<double> weight;
  std::string method;  // "bilinear", "trilinear", "quadratic least squares (N nodes)", ...
};
// The stencil at lattice point p (cell centres at integer coordinates) on an nx x ny x nz
// lattice (x fastest) whose solid cells are solid[i] != 0. Throws InputError when no fluid
// node lies within kFitRadius.
ProbeStencil probe_stencil(const Vec3& p, int nx, int ny, int nz, std::span<const std::uint8_t> solid);

class Probes {
 public:
  Probes() = default;
  Probes(ProbeSet set, double dx) : set_(std::move(set)), dx_(dx) {}
  bool empty() const { return set_.empty(); }
  const ProbeSet& set() const { return set_; }
  // Column names (appended after the case's columns).
  void columns(std::vector<std::string>& out) const;
  // Appends the probe values of a sample; the stencils are made at the first call from the
  // sample's solid mask (the geometry does not change during a run).
  void measure(const FlowSample& s, std::vector<double>& row);
  const std::vector<ProbeStencil>& stencils() const { return stencils_; }

 private:
  ProbeSet set_;
  double dx_ = 1;
  std::vector<ProbeStencil> stencils_;
};

class FlowCase;
// The columns of series.csv: "step", "time_s", the case's, then the probes'. Throws InputError
// naming probes.names when a probe column repeats one of the case's (probes "front" and "back"
// with probes.delta_p give dp_front_back_Pa, which flow/cylinder writes itself).
std::vector<std::string> series_columns(const Config& cfg, const FlowCase& fc, const Probes& probes);

}  // namespace ff::drivers
