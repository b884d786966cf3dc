// flow/cylinder: a circular cylinder between two plates ([S003] Sec. 3.3): Zou-He inflow on
// x- (uniform or parabolic), Zou-He pressure outlet on x+, no-slip plates on y-/y+.
// Results: drag and lift coefficients Cd = 2 F_x / (rho U^2 D), Cl = 2 F_y / (rho U^2 D)
// (forces per unit depth), Strouhal number St = f D / U from the lift history, and the wall
// correction factor lambda = F_x / (mu u_max) of [S003] Eq. 16.
#include <fmt/format.h>

#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"
#include "drivers/flow/flow_drivers.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "io/plot.hpp"
#include "lbm/analysis.hpp"
#include "lbm/image_mask.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {
namespace {

void declare(ParamTable& t) {
  LbmDefaults d;
  d.resolution = 16;
  d.tau = 0.53;
  d.end_time = 80;
  d.steady_tolerance = 1e-7;
  d.inflow_ramp_time = -1;
  declare_lbm_params(t, d);
  t.real("channel.height", 0.16, "m", "distance H between the plates").positive();
  t.real("channel.length", 0.4, "m", "length from the inlet to the outlet").positive();
  t.string("channel.sides", "walls",
           "y boundaries: walls (no-slip plates, [S003] 3.3) or periodic (a row of cylinders H apart, which "
           "approximates a cylinder in unbounded flow when H >> D)")
      .one_of({"walls", "periodic"});
  t.real("cylinder.diameter", 0.01, "m", "cylinder diameter D (lbm.resolution cells across it)").positive();
  t.real("cylinder.x", 0.1, "m", "distance of the cylinder centre from the inlet").positive();
  t.real("cylinder.y", -1, "m", "height of the centre above the lower plate; negative: mid-channel");
  t.string("cylinder.wall", "bouzidi",
           "wall treatment: halfway (stair-wise bounce-back, [S003]), bouzidi (Bouzidi et al. 2001) or yu "
           "(Yu et al. 2003, [S002] Eq. 7)")
      .one_of({"halfway", "bouzidi", "yu"});
  t.real("cylinder.initial_perturbation", 0.05, "-",
         "transverse velocity kick behind the cylinder at t = 0, as a fraction of U (starts vortex shedding)")
      .non_negative();
  t.string("obstacles.image", "",
           "optional PGM image (P2/P5) stretched over the channel: dark pixels become extra solid cells (half-way "
           "bounce-back), e.g. grains or a rough wall");
  t.integer("obstacles.threshold", 128, "-", "grey level below which an image pixel is solid").range(0, 256);
  t.string("inlet.condition", "zou_he",
           "inflow boundary: zou_he (Zou & He 1997, velocity imposed on the first nodes) or bounce_back (moving-wall "
           "bounce-back half a cell upstream, [S003] Eq. 8)")
      .one_of({"zou_he", "bounce_back"});
  t.string("inlet.profile", "uniform", "inflow profile: uniform, or parabolic (Poiseuille)").one_of({"uniform", "parabolic"});
  t.real("inlet.velocity", 0.01, "m/s", "inflow velocity: the uniform value, or the maximum of the parabola").positive();
}

class CylinderCase : public FlowCase {
 public:
  explicit CylinderCase(const Config& cfg)
      : H_(cfg.real("channel.height")), len_(cfg.real("channel.length")), D_(cfg.real("cylinder.diameter")),
        xc_(cfg.real("cylinder.x")), yc_(cfg.real("cylinder.y") < 0 ? 0.5 * H_ : cfg.real("cylinder.y")),
        U_(cfg.real("inlet.velocity")), rho_(cfg.real("fluid.density")), nu_(cfg.real("fluid.viscosity")),
        kick_(cfg.real("cylinder.initial_perturbation")), ramp_(cfg.real("run.inflow_ramp_time") != 0),
        n_(int(cfg.integer("lbm.resolution"))),
        parabolic_(cfg.string("inlet.profile") == "parabolic"), inlet_bb_(cfg.string("inlet.condition") == "bounce_back"),
        periodic_(cfg.string("channel.sides") == "periodic"), image_(cfg.string("obstacles.image")),
        threshold_(int(cfg.integer("obstacles.threshold"))) {
    if (periodic_ && parabolic_)
      cfg.fail("inlet.profile", "a parabolic inflow needs plates: use channel.sides = \"walls\" or a uniform inflow");
    const std::string w = cfg.string("cylinder.wall");
    scheme_ = w == "halfway" ? lbm::WallScheme::HalfwayBounceBack : w == "yu" ? lbm::WallScheme::Yu : lbm::WallScheme::Bouzidi;
    if (D_ >= H_) cfg.fail("cylinder.diameter", fmt::format("the cylinder (D = {} m) must be narrower than the channel (H = {} m)", D_, H_));
    if (xc_ - D_ / 2 <= 0 || xc_ + D_ / 2 >= len_)
      cfg.fail("cylinder.x", "the cylinder must lie wholly between the inlet and the outlet");
    if (yc_ - D_ / 2 <= 0 || yc_ + D_ / 2 >= H_) cfg.fail("cylinder.y", "the cylinder must not touch the sides of the channel");
    if (!image_.empty()) {  // read here, so that `fracflow check` finds a missing or bad file too
      try {
        obstacles_ = lbm::read_pgm(image_);
      } catch (const InputError& e) {
        cfg.fail("obstacles.image", e.what());
      }
    }
  }

  double cell_size() const override { return D_ / n_; }
  int resolution() const override { return n_; }
  // The inflow speed (the maximum of a parabola) sets the Mach number, as usual for bluff bodies.
  double characteristic_speed() const override { return U_; }
  // Reference velocity of Cd, Cl, Re and St: the uniform inflow, or the mean of the parabola.
  double u_ref() const { return parabolic_ ? 2.0 / 3.0 * U_ : U_; }
  // Largest velocity of the undisturbed (developed) channel flow, for lambda ([S003] Eq. 16).
  double u_max() const { return parabolic_ ? U_ : 1.5 * U_; }
  double inflow(double y) const { return parabolic_ ? 4 * U_ * y * (H_ - y) / (H_ * H_) : U_; }

  DomainSpec domain(const lbm::Units& u) override {
    units_ = u;
    const double dx = u.dx();
    DomainSpec d;
    d.nx = int(std::lround(len_ / dx));
    d.ny = int(std::lround(H_ / dx));
    d.periodic = {false, periodic_};
    d.faces[0].kind = inlet_bb_ ? lbm::FaceCondition::Kind::Wall : lbm::FaceCondition::Kind::Velocity;
    // A plug profile is singular where it meets the no-slip plates: the two Zou-He inflow nodes
    // next to the plates get half the speed (the mean over their half cell); at full speed these
    // corner nodes drive TRT unstable at large tau.
    const int ny = d.ny;
    d.faces[0].profile = [this, dx, ny](int, int y, int) {
      const double corner = !parabolic_ && !inlet_bb_ && !periodic_ && (y == 0 || y == ny - 1) ? 0.5 : 1.0;
      return Vec3(corner * units_.to_lattice_velocity(inflow((y + 0.5) * dx)), 0, 0);
    };
    d.faces[1].kind = lbm::FaceCondition::Kind::Pressure;
    d.faces[1].density = 1;
    // Lattice coordinates: cell (i, j) has its centre at ((i + 1/2) dx, (j + 1/2) dx).
    const Vec3 c(xc_ / dx - 0.5, yc_ / dx - 0.5, 0);
    const double r = 0.5 * D_ / dx;
    DomainSpec::Object cyl;
    cyl.name = "cylinder";
    cyl.scheme = scheme_;
    cyl.center = c;
    cyl.shape = lbm::Circle{c, r};
    d.objects.push_back(cyl);
    if (!image_.empty()) {
      DomainSpec::Object img;
      img.name = "image obstacles";
      img.center = c;
      img.cells = lbm::solid_cells(obstacles_, d.nx, d.ny, threshold_);
      d.objects.push_back(img);
    }
    const double kick = kick_ * u.to_lattice_velocity(u_ref());
    d.init = [this, dx, c, r, kick](int x, int y, double&, Vec3& v) {
      v = ramp_ ? Vec3::Zero() : Vec3(units_.to_lattice_velocity(inflow((y + 0.5) * dx)), 0, 0);
      const double ex = x - (c.x() + 2 * r), ey = y - c.y();
      v.y() += kick * std::exp(-(ex * ex + ey * ey) / (r * r));
    };
    return d;
  }

  // Forces per unit depth with their unit; the coefficients are dimensionless.
  std::vector<std::string> columns() const override { return {"Fx_N_per_m", "Fy_N_per_m", "Cd", "Cl"}; }
  void measure(const FlowSample& s, std::vector<double>& row) const override {
    const Vec3 F = s.force[0];
    const double q = 0.5 * rho_ * u_ref() * u_ref() * D_;
    row.insert(row.end(), {F.x(), F.y(), F.x() / q, F.y() / q});
  }
  std::optional<int> steady_column() const override { return 2; }
  std::string progress_text(const std::vector<double>& row) const override {
    return fmt::format("Cd {:.4f}  Cl {:+.4f}", row[4], row[5]);
  }

  void finish(const FlowSample& last, const std::vector<std::vector<double>>& hist, const fs::path& out, bool plots,
              nlohmann::json& res) const override {
    std::vector<double> t, cd, cl, fx;
    for (auto& r : hist) {
      t.push_back(r[1]);
      fx.push_back(r[2]);
      cd.push_back(r[4]);
      cl.push_back(r[5]);
    }
    // Statistics over the second half of the time after the inflow reached full speed (the
    // first half of it is the start-up of the wake).
    const double t_from = last.ramp_end_time + 0.5 * (t.back() - last.ramp_end_time);
    const auto lift = lbm::analyse_oscillation(t, cl, t_from);
    const auto drag = lbm::analyse_oscillation(t, cd, t_from);
    const bool shedding = lift.cycles >= 2 && (lift.max - lift.min) > 1e-3;
    const double cd_mean = shedding ? lbm::time_average(t, cd, lift.first_up, lift.last_up) : cd.back();
    const double re = u_ref() * D_ / nu_;
    res["reynolds"] = re;
    res["blockage_D_over_H"] = D_ / H_;
    res["reference_velocity_m_per_s"] = u_ref();
    res["cd_mean"] = cd_mean;
    res["averaging_from_s"] = t_from;
    res["cd_final"] = cd.back();
    res["cd_min"] = drag.min;
    res["cd_max"] = drag.max;
    res["cl_amplitude"] = 0.5 * (lift.max - lift.min);
    res["cl_mean"] = lift.mean;
    res["shedding"] = shedding;
    // No shedding, no frequency: null with the reason rather than a Strouhal number of 0.
    res["strouhal"] = shedding ? nlohmann::json(lift.frequency * D_ / u_ref()) : nlohmann::json(nullptr);
    if (!shedding)
      res["strouhal_reason"] = fmt::format("no vortex shedding: {} lift cycles between {:.4g} s and the end at {:.4g} s "
                                           "(2 needed), Cl amplitude {:.3g}",
                                           lift.cycles, t_from, t.back(), 0.5 * (lift.max - lift.min));
    res["shedding_periods_averaged"] = shedding ? lift.cycles : 0;
    res["lambda_wall_factor"] = fx.back() / (rho_ * nu_ * u_max());  // [S003] Eq. 16
    res["wall_scheme"] = scheme_ == lbm::WallScheme::Bouzidi ? "bouzidi" : scheme_ == lbm::WallScheme::Yu ? "yu" : "halfway";
    if (shedding)
      log::info("cylinder Re = {:.4g}: mean Cd = {:.4f}, Cl amplitude = {:.4f}, St = {:.4f} (over {} shedding periods)", re,
                cd_mean, 0.5 * (lift.max - lift.min), lift.frequency * D_ / u_ref(), lift.cycles);
    else
      log::info("cylinder Re = {:.4g}: Cd = {:.4f}, lambda = F/(mu u_max) = {:.4f} (steady, no shedding)", re, cd.back(),
                fx.back() / (rho_ * nu_ * u_max()));
    if (!plots) return;
    PlotSpec p;
    p.title = fmt::format("Cylinder in a channel, Re = {:.4g}: force coefficients", re);
    p.x = "time_s";
    p.xlabel = "time [s]";
    p.y = {"Cd"};
    p.ylabel = "drag coefficient Cd";
    p.y2 = {"Cl"};
    p.y2label = "lift coefficient Cl";
    PlotSpec f;
    f.title = "Cylinder in a channel: force per unit depth";
    f.x = "time_s";
    f.xlabel = "time [s]";
    f.y = {"Fx_N_per_m", "Fy_N_per_m"};
    f.ylabel = "force [N/m]";
    const PlotJob jobs[] = {{out / "series.csv", out / "plots" / "force_coefficients.png", p},
                            {out / "series.csv", out / "plots" / "forces.png", f}};
    plot_series(jobs);
  }

 private:
  double H_, len_, D_, xc_, yc_, U_, rho_, nu_, kick_;
  bool ramp_;  // the inflow is ramped up: start from rest
  int n_;
  bool parabolic_, inlet_bb_, periodic_;
  std::string image_;
  lbm::GreyImage obstacles_;  // of image_, when set
  int threshold_;
  lbm::WallScheme scheme_ = lbm::WallScheme::Bouzidi;
  lbm::Units units_;
};

void validate(const Config& cfg) {
  CylinderCase c(cfg);  // its constructor checks the geometry keys
  validate_flow(cfg, c);
}

RunStatus run(const Config& cfg, const RunOptions& opt) {
  CylinderCase c(cfg);
  return run_flow(cfg, opt, c, "flow/cylinder");
}

}  // namespace

Driver flow_cylinder_driver() {
  return Driver{"flow/cylinder", "LBM cylinder between plates: drag, lift, Strouhal number ([S003] 3.3)", declare, run,
                validate};
}

}  // namespace ff::drivers
