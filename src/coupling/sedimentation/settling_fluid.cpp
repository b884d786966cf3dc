// The sedimentation driver's fluid: an lbm::Solver with walls on every face and the DemLbmCoupler
// (settling_fluid.hpp).
#include "coupling/sedimentation/settling_fluid.hpp"

#include <fmt/format.h>

#include <span>

#include "core/error.hpp"
#include "coupling/dem_lbm_coupler.hpp"
#include "io/vtk.hpp"
#include "lbm/lattice_budget.hpp"

namespace ff::coupling {

double max_lattice_side() { return lbm::kMaxLatticeSide; }

void check_box_memory(const SettlingBox& box, const std::string& advice) {
  lbm::check_lattice_memory(box.cells[0], box.cells[1], box.dim == 3 ? box.cells[2] : 1, box.dim == 3 ? 19 : 9,
                            box.double_precision ? 8 : 4, advice);
}

namespace {

template <class L, class T>
class SettlingFluidOn final : public SettlingFluid {
 public:
  SettlingFluidOn(const SettlingBox& box, const FluidScales& sc, dem::DemSystem& dem) : sc_(sc), box_(box) {
    const int d = L::D;
    lbm::Grid g(d, box.cells[0], box.cells[1], d == 3 ? box.cells[2] : 1, {false, false, d == 2});
    lbm::SolverSettings s;
    s.tau = sc_.units.tau();
    s.psm_refresh = box.psm_refresh;
    fluid_ = std::make_unique<lbm::Solver<L, T>>(g, s);
    for (int f = 0; f < 2 * d; ++f) fluid_->set_face(f, lbm::FaceCondition{});
    fluid_->finalize();
    fluid_->initialize([](int, int, int, double& rho, Vec3& u) {
      rho = 1;
      u = Vec3::Zero();
    });
    CouplerSettings cs;
    cs.origin = Vec3::Constant(0.5 * sc_.units.dx());  // cell (0, 0, 0)'s centre: half a cell in from the walls
    if (d == 2) cs.origin.z() = 0;
    cpl_ = std::make_unique<DemLbmCoupler<L, T>>(dem, *fluid_, sc_, cs);
    const std::size_t cells = std::size_t(g.nx) * std::size_t(g.ny) * std::size_t(g.nz);
    vtk_p_.assign(cells, 0.0);
    vtk_eps_.assign(cells, 0.0);
    vtk_u_.assign(cells, Vec3::Zero());
  }

  void step(bool sample) override { cpl_->step(sample); }
  long time_step() const override { return fluid_->time_step(); }
  double max_speed() const override { return fluid_->max_speed(); }
  const std::vector<Vec3>& hydro_force() const override { return cpl_->hydro_force(); }
  double dem_dt() const override { return cpl_->dem_dt(); }
  long sub_steps() const override { return cpl_->sub_steps(); }
  const CouplerTimes& times() const override { return cpl_->times; }
  std::string_view velocity_set() const override { return L::name; }
  std::string lattice() const override {
    return fmt::format("{} {} {}x{}x{}", L::name, sizeof(T) == 8 ? "double" : "float", box_.cells[0], box_.cells[1],
                       box_.cells[2]);
  }

  void save(CheckpointWriter& w) const override {
    w.put_string("sed.lattice", lattice());
    const auto& f = fluid_->populations();
    w.put("lbm.populations", std::vector<T>(f.begin(), f.end()));
    // With lbm.psm_refresh the fractions come from where the particles were at the last rebuild.
    const auto* psm = fluid_->psm();
    w.put("sed.psm_positions", psm ? psm->geometry_positions() : std::vector<Vec3>{});
    w.put("sed.psm_radii", psm ? psm->geometry_radii() : std::vector<double>{});
  }

  void load(CheckpointReader& r, long time_step) override {
    if (r.get_string("sed.lattice") != lattice())
      throw InputError(fmt::format("{}: the checkpoint holds a {} lattice but the scenario builds {}", r.path().string(),
                                   r.get_string("sed.lattice"), lattice()));
    std::vector<T> f;
    r.get("lbm.populations", f);
    fluid_->restore(f, time_step);
    std::vector<Vec3> pos;
    std::vector<double> radii;
    if (r.has("sed.psm_positions")) {  // absent in checkpoints before lbm.psm_refresh (rebuilt every step)
      r.get("sed.psm_positions", pos);
      r.get("sed.psm_radii", radii);
    }
    if (!pos.empty()) fluid_->restore_psm_geometry(pos, radii);
  }

  void write_vti(const std::filesystem::path& file) override {
    const auto& g = fluid_->grid();
    const auto* psm = fluid_->psm();
    std::size_t k = 0;
    for (int z = 0; z < g.nz; ++z)
      for (int y = 0; y < g.ny; ++y)
        for (int x = 0; x < g.nx; ++x, ++k) {
          vtk_p_[k] = sc_.pressure(fluid_->density(x, y, z));
          vtk_u_[k] = fluid_->velocity(x, y, z) * sc_.units.velocity_factor();
          vtk_eps_[k] = psm ? psm->solid_fraction(g.index(x, y, z)) : 0.0;
        }
    const double dx = sc_.units.dx();
    const std::vector<VtkArray> arrays = {vtk_array("pressure_Pa", std::span<const double>(vtk_p_)),
                                          vtk_array("velocity_m_per_s", std::span<const Vec3>(vtk_u_)),
                                          vtk_array("solid_fraction", std::span<const double>(vtk_eps_))};
    ff::write_vti(file, {g.nx, g.ny, g.nz}, Vec3::Zero(), Vec3(dx, dx, L::D == 3 ? dx : 1.0), arrays);
  }

 private:
  FluidScales sc_;
  SettlingBox box_;
  std::unique_ptr<lbm::Solver<L, T>> fluid_;
  std::unique_ptr<DemLbmCoupler<L, T>> cpl_;
  std::vector<double> vtk_p_, vtk_eps_;
  std::vector<Vec3> vtk_u_;
};

}  // namespace

std::unique_ptr<SettlingFluid> make_settling_fluid(const SettlingBox& box, const FluidScales& scales,
                                                   dem::DemSystem& dem) {
  if (box.dim == 3)
    return box.double_precision ? std::unique_ptr<SettlingFluid>(new SettlingFluidOn<lbm::D3Q19, double>(box, scales, dem))
                                : std::unique_ptr<SettlingFluid>(new SettlingFluidOn<lbm::D3Q19, float>(box, scales, dem));
  return box.double_precision ? std::unique_ptr<SettlingFluid>(new SettlingFluidOn<lbm::D2Q9, double>(box, scales, dem))
                              : std::unique_ptr<SettlingFluid>(new SettlingFluidOn<lbm::D2Q9, float>(box, scales, dem));
}

}  // namespace ff::coupling
