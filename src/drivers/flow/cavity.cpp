// flow/cavity: lid-driven square cavity ([S003] Sec. 3.2). The lid is a moving half-way
// bounce-back wall ([S003] Eq. 8); at Re = 100 the centre-line profiles are compared with
// Ghia, Ghia & Shin (1982).
#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "core/log.hpp"
#include "drivers/flow/flow_drivers.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "drivers/flow/ghia_1982.hpp"
#include "io/csv.hpp"
#include "io/plot.hpp"
#include "lbm/analysis.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {
namespace {

void declare(ParamTable& t) {
  LbmDefaults d;
  d.resolution = 128;
  d.tau = 0.7;
  d.end_time = 4000;
  d.steady_tolerance = 1e-6;
  declare_lbm_params(t, d);
  t.real("cavity.size", 0.1, "m", "side L of the square cavity").positive();
  t.real("cavity.lid_velocity", 1e-3, "m/s", "lid speed U (Re = U L / nu)").positive();
}

class CavityCase : public FlowCase {
 public:
  explicit CavityCase(const Config& cfg)
      : L_(cfg.real("cavity.size")), U_(cfg.real("cavity.lid_velocity")), nu_(cfg.real("fluid.viscosity")),
        n_(int(cfg.integer("lbm.resolution"))) {}

  double cell_size() const override { return L_ / n_; }
  int resolution() const override { return n_; }
  double characteristic_speed() const override { return U_; }
  double reynolds() const { return U_ * L_ / nu_; }

  DomainSpec domain(const lbm::Units& u) override {
    units_ = u;
    DomainSpec d;
    d.nx = d.ny = n_;
    d.faces[3].velocity = Vec3(u.to_lattice_velocity(U_), 0, 0);  // the lid, y+ (owns the top corners)
    return d;
  }

  // u along the vertical centre line x = L/2 and v along the horizontal one, cell centred.
  void centre_lines(const FlowSample& s, std::vector<double>& u, std::vector<double>& v) const {
    u.assign(std::size_t(s.ny), 0.0);
    v.assign(std::size_t(s.nx), 0.0);
    const int xa = (s.nx - 1) / 2, xb = s.nx / 2, ya = (s.ny - 1) / 2, yb = s.ny / 2;
    for (int y = 0; y < s.ny; ++y) u[y] = 0.5 * (s.velocity[s.at(xa, y)].x() + s.velocity[s.at(xb, y)].x()) / U_;
    for (int x = 0; x < s.nx; ++x) v[x] = 0.5 * (s.velocity[s.at(x, ya)].y() + s.velocity[s.at(x, yb)].y()) / U_;
  }

  // Names end in their SI unit (kinetic energy per mass, force per unit depth).
  std::vector<std::string> columns() const override {
    return {"u_centre_m_per_s", "v_centre_m_per_s", "kinetic_energy_m2_per_s2", "lid_force_N_per_m"};
  }
  void measure(const FlowSample& s, std::vector<double>& row) const override {
    const int xa = (s.nx - 1) / 2, xb = s.nx / 2, ya = (s.ny - 1) / 2, yb = s.ny / 2;
    Vec3 c = Vec3::Zero();
    for (int x : {xa, xb})
      for (int y : {ya, yb}) c += 0.25 * s.velocity[s.at(x, y)];
    double ke = 0;
    for (auto& v : s.velocity) ke += 0.5 * v.squaredNorm();
    ke /= double(s.velocity.size());
    row.insert(row.end(), {c.x(), c.y(), ke, s.face_force[3].x()});
  }
  std::optional<int> steady_column() const override { return 2; }
  std::string progress_text(const std::vector<double>& row) const override {
    return fmt::format("u(centre) = {:.4f} U", row[2] / U_);
  }

  void finish(const FlowSample& s, const std::vector<std::vector<double>>&, const fs::path& out, bool plots,
              nlohmann::json& res) const override {
    std::vector<double> u, v;
    centre_lines(s, u, v);
    const double h = 1.0 / n_;
    {
      CsvWriter a;
      a.open(out / "profile_u_vertical_centreline.csv", {"y_over_L", "u_over_U"});
      a.row({0.0, 0.0});
      for (int y = 0; y < s.ny; ++y) a.row({(y + 0.5) * h, u[y]});
      a.row({1.0, 1.0});
      CsvWriter b;
      b.open(out / "profile_v_horizontal_centreline.csv", {"x_over_L", "v_over_U"});
      b.row({0.0, 0.0});
      for (int x = 0; x < s.nx; ++x) b.row({(x + 0.5) * h, v[x]});
      b.row({1.0, 0.0});
    }
    res["reynolds"] = reynolds();
    const bool re100 = std::abs(reynolds() - 100) < 0.5;
    if (re100) {
      // Deviation from Ghia et al. at their interior points (end points are the boundary values).
      CsvWriter gu, gv;
      gu.open(out / "reference_ghia1982_u.csv", {"y_over_L", "u_over_U"});
      gv.open(out / "reference_ghia1982_v.csv", {"x_over_L", "v_over_U"});
      double eu = 0, ev = 0;
      for (std::size_t i = 0; i < ghia1982::kU.size(); ++i) {
        const auto& p = ghia1982::kU[i];
        gu.row({p.pos, p.vel});
        if (p.pos > 0 && p.pos < 1) eu = std::max(eu, std::abs(lbm::interpolate_profile(u, h, p.pos, 0, 1) - p.vel));
      }
      for (std::size_t i = 0; i < ghia1982::kV.size(); ++i) {
        const auto& p = ghia1982::kV[i];
        gv.row({p.pos, p.vel});
        if (p.pos > 0 && p.pos < 1) ev = std::max(ev, std::abs(lbm::interpolate_profile(v, h, p.pos, 0, 0) - p.vel));
      }
      res["ghia1982_max_error_u_over_U"] = eu;
      res["ghia1982_max_error_v_over_U"] = ev;
      log::info("cavity Re = {:.4g}: largest deviation from Ghia et al. (1982): u {:.4f} U, v {:.4f} U", reynolds(), eu, ev);
    } else {
      log::info("cavity Re = {:.4g} (Ghia et al. reference data here are for Re = 100 only)", reynolds());
    }
    res["u_centre_over_U"] = lbm::interpolate_profile(u, h, 0.5, 0, 1);
    if (!plots) return;
    PlotSpec pu;
    pu.title = fmt::format("Lid-driven cavity Re = {:.4g}: u on the vertical centre line", reynolds());
    pu.x = "y_over_L";
    pu.xlabel = "y / L";
    pu.y = {"u_over_U"};
    pu.ylabel = "u / U";
    PlotSpec pv = pu;
    pv.title = fmt::format("Lid-driven cavity Re = {:.4g}: v on the horizontal centre line", reynolds());
    pv.x = "x_over_L";
    pv.xlabel = "x / L";
    pv.y = {"v_over_U"};
    pv.ylabel = "v / U";
    if (re100) {
      pu.reference_csv = out / "reference_ghia1982_u.csv";
      pu.ref_x = "y_over_L";
      pu.ref_y = "u_over_U";
      pu.ref_label = "Ghia, Ghia & Shin (1982)";
      pv.reference_csv = out / "reference_ghia1982_v.csv";
      pv.ref_x = "x_over_L";
      pv.ref_y = "v_over_U";
      pv.ref_label = pu.ref_label;
    }
    PlotSpec k;
    k.title = "Lid-driven cavity: approach to steady state";
    k.x = "time_s";
    k.xlabel = "time [s]";
    k.y = {"kinetic_energy_m2_per_s2"};
    k.ylabel = "mean kinetic energy per mass [m^2/s^2]";
    const PlotJob jobs[] = {{out / "profile_u_vertical_centreline.csv", out / "plots" / "u_vertical_centreline.png", pu},
                            {out / "profile_v_horizontal_centreline.csv", out / "plots" / "v_horizontal_centreline.png", pv},
                            {out / "series.csv", out / "plots" / "kinetic_energy.png", k}};
    plot_series(jobs);
  }

 private:
  double L_, U_, nu_;
  int n_;
  lbm::Units units_;
};

void validate(const Config& cfg) {
  CavityCase c(cfg);  // its constructor checks the geometry keys
  validate_flow(cfg, c);
}

RunStatus run(const Config& cfg, const RunOptions& opt) {
  CavityCase c(cfg);
  return run_flow(cfg, opt, c, "flow/cavity");
}

}  // namespace

Driver flow_cavity_driver() {
  return Driver{"flow/cavity", "LBM lid-driven cavity against Ghia, Ghia & Shin (1982) ([S003] 3.2)", declare, run,
                validate};
}

}  // namespace ff::drivers
