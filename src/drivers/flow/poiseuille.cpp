// flow/poiseuille: laminar flow between two plates ([S003] Sec. 3.1, Eq. 14-15):
//   u(y) = G / (2 mu) y (H - y),  u_max = G H^2 / (8 mu),  u_mean = 2/3 u_max.
#include <fmt/format.h>

#include <cmath>

#include "core/log.hpp"
#include "drivers/flow/flow_drivers.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "io/csv.hpp"
#include "io/plot.hpp"
#include "lbm/lattice_budget.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {
namespace {

void declare(ParamTable& t) {
  LbmDefaults d;
  d.resolution = 20;
  d.tau = 0.8;
  d.end_time = 4.0;
  declare_lbm_params(t, d);
  t.real("channel.height", 1e-3, "m", "distance H between the plates").positive();
  t.real("channel.length", 2e-3, "m", "channel length (periodic for the body-force drive)").positive();
  t.string("channel.drive", "body_force",
           "body_force: periodic channel with a uniform force density; pressure: Zou-He pressure inlet and outlet; "
           "velocity: parabolic Zou-He inflow and a pressure outlet")
      .one_of({"body_force", "pressure", "velocity"});
  t.real("channel.pressure_gradient", 1.0, "Pa/m", "driving pressure gradient G (or force density)").positive();
}

class PoiseuilleCase : public FlowCase {
 public:
  explicit PoiseuilleCase(const Config& cfg)
      : H_(cfg.real("channel.height")),
        len_(cfg.real("channel.length")),
        G_(cfg.real("channel.pressure_gradient")),
        mu_(cfg.real("fluid.density") * cfg.real("fluid.viscosity")),
        n_(int(cfg.integer("lbm.resolution"))),
        drive_(cfg.string("channel.drive")) {}

  double cell_size() const override { return H_ / n_; }
  int resolution() const override { return n_; }
  std::string resolution_key() const override { return "lbm.resolution"; }
  double u_max() const { return G_ * H_ * H_ / (8 * mu_); }
  double characteristic_speed() const override { return u_max(); }
  double analytic(double y) const { return G_ / (2 * mu_) * y * (H_ - y); }

  DomainSpec domain(const lbm::Units& u) override {
    units_ = u;
    DomainSpec d;
    d.nx = lbm::lattice_side(std::max(1.0, len_ / u.dx()), "channel.length", "lower lbm.resolution or channel.length");
    d.ny = n_;
    d.periodic = {drive_ == "body_force", false};
    const double dx = u.dx();
    if (drive_ == "body_force") {
      d.body_force = Vec3(u.to_lattice_force_density(G_), 0, 0);
    } else if (drive_ == "pressure") {
      // G acts between the inlet and outlet nodes, (nx - 1) dx apart.
      const double drho = u.to_si_density_offset(G_ * (d.nx - 1) * dx);
      d.faces[0].kind = d.faces[1].kind = lbm::FaceCondition::Kind::Pressure;
      d.faces[0].density = 1 + drho / 2;
      d.faces[1].density = 1 - drho / 2;
      const int nx = d.nx;
      d.init = [drho, nx](int x, int, int, double& rho, Vec3&) { rho = 1 + drho / 2 - drho * x / std::max(1, nx - 1); };
    } else {
      d.faces[0].kind = lbm::FaceCondition::Kind::Velocity;
      d.faces[0].profile = [this, dx](int, int y, int) {
        return Vec3(units_.to_lattice_velocity(analytic((y + 0.5) * dx)), 0, 0);
      };
      d.faces[1].kind = lbm::FaceCondition::Kind::Pressure;
      d.init = [this, dx](int, int y, int, double&, Vec3& v) { v = Vec3(units_.to_lattice_velocity(analytic((y + 0.5) * dx)), 0, 0); };
    }
    return d;
  }

  std::vector<std::string> columns() const override {
    // Names end in their SI unit (the flow rate is per unit depth).
    return {"u_max_m_per_s", "u_max_analytic_m_per_s", "flow_rate_m2_per_s", "wall_shear_stress_Pa"};
  }
  void measure(const FlowSample& s, std::vector<double>& row) const override {
    const int x = s.nx / 2;
    double umax = 0, q = 0;
    for (int y = 0; y < s.ny; ++y) {
      const double u = s.velocity[s.at(x, y)].x();
      umax = std::max(umax, u);
      q += u * units_.dx();
    }
    const double len = s.nx * units_.dx();
    const double tau_w = (s.face_force[2].x() + s.face_force[3].x()) / (2 * len);  // drag on both plates
    row.insert(row.end(), {umax, u_max(), q, tau_w});
  }
  std::optional<int> steady_column() const override { return 0; }
  std::string progress_text(const std::vector<double>& row) const override {
    return fmt::format("u_max {:.5g} m/s ({:.3f} of analytic)", row[2], row[2] / u_max());
  }

  void finish(const FlowSample& s, const std::vector<std::vector<double>>& history, const fs::path& out, bool plots,
              nlohmann::json& res) const override {
    // Profile across the channel in the middle, against Eq. 14.
    CsvWriter prof;
    prof.open(out / "profile.csv", {"y_m", "u_lbm_m_per_s", "u_analytic_m_per_s"});
    const int x = s.nx / 2;
    double err2 = 0, umean = 0;
    for (int y = 0; y < s.ny; ++y) {
      const double yy = (y + 0.5) * units_.dx();
      const double u = s.velocity[s.at(x, y)].x(), ua = analytic(yy);
      prof.row({yy, u, ua});
      err2 += (u - ua) * (u - ua);
      umean += u / s.ny;
    }
    prof.close();
    {  // the analytic curve, finely sampled wall to wall, for the plot
      CsvWriter ana;
      ana.open(out / "profile_analytic.csv", {"y_m", "u_analytic_m_per_s"});
      for (int k = 0; k <= 100; ++k) ana.row({H_ * k / 100.0, analytic(H_ * k / 100.0)});
    }
    const double l2 = std::sqrt(err2 / s.ny) / u_max();
    const auto& last = history.back();
    res["u_max_m_per_s"] = last[2];
    res["u_max_analytic_m_per_s"] = u_max();
    res["u_mean_m_per_s"] = umean;
    res["u_max_over_u_mean"] = last[2] / umean;  // 3/2 analytically ([S003] Eq. 15)
    res["profile_l2_error_rel_umax"] = l2;       // RMS deviation from Eq. 14 over u_max
    res["wall_shear_stress_Pa"] = last[5];
    res["wall_shear_stress_analytic_Pa"] = G_ * H_ / 2;
    res["drive"] = drive_;
    log::info("Poiseuille: u_max = {:.6g} m/s (analytic {:.6g}), profile L2 error {:.3e} of u_max, u_max/u_mean = {:.4f}",
               last[2], u_max(), l2, last[2] / umean);
    if (!plots) return;
    PlotSpec p;
    p.title = "Poiseuille flow: velocity profile (LBM vs [S003] Eq. 14)";
    p.x = "y_m";
    p.x_scale = 1e3;
    p.xlabel = "y [mm]";
    p.y = {"u_analytic_m_per_s"};
    p.y_scale = 1e3;
    p.ylabel = "u [mm/s]";
    p.reference_csv = out / "profile.csv";
    p.ref_x = "y_m";
    p.ref_y = "u_lbm_m_per_s";
    p.ref_label = "LBM (cell centres)";
    PlotSpec h;
    h.title = "Poiseuille flow: approach to steady state";
    h.x = "time_s";
    h.xlabel = "time [s]";
    h.y = {"u_max_m_per_s", "u_max_analytic_m_per_s"};
    h.y_scale = 1e3;
    h.ylabel = "centre-line velocity [mm/s]";
    const PlotJob jobs[] = {{out / "profile_analytic.csv", out / "plots" / "velocity_profile.png", p},
                            {out / "series.csv", out / "plots" / "u_max_history.png", h}};
    plot_series(jobs);
  }

 private:
  double H_, len_, G_, mu_;
  int n_;
  std::string drive_;
  lbm::Units units_;
};

void validate(const Config& cfg) {
  PoiseuilleCase c(cfg);  // its constructor checks the geometry keys
  validate_flow(cfg, c);
}

RunStatus run(const Config& cfg, const RunOptions& opt) {
  PoiseuilleCase c(cfg);
  return run_flow(cfg, opt, c, "flow/poiseuille");
}

}  // namespace

Driver flow_poiseuille_driver() {
  return Driver{"flow/poiseuille", "LBM channel flow between plates against the analytic profile ([S003] 3.1)", declare,
                run, validate};
}

}  // namespace ff::drivers
