// flow/cylinder: a circular cylinder between two plates ([S003] Sec. 3.3): Zou-He inflow on
// x- (uniform or parabolic), an outlet on x+ (Zou-He pressure, zero-gradient or convective),
// no-slip plates on y-/y+; with channel.depth > 0 a D3Q19 duct with walls on z-/z+ too, the
// cylinder spanning it (the DFG 3D-1Z geometry of Schaefer & Turek 1996, Fig. 3).
// Results: drag and lift coefficients Cd = 2 F_x / (rho U^2 D), Cl = 2 F_y / (rho U^2 D)
// (forces per unit depth; in the duct total forces over rho U^2 D W / 2, W the depth), Strouhal
// number St = f D / U from the lift history, the wall correction factor lambda = F_x / (mu u_max)
// of [S003] Eq. 16, and the DFG benchmark quantities (Schaefer & Turek 1996, Sec. 2): pressure
// difference between the front and back points of the cylinder, recirculation length L_a, and
// for vortex shedding the extremes of Cd and Cl and Delta p half a period after the maximum lift.
#include <fmt/format.h>

#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"
#include "drivers/flow/flow_drivers.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "drivers/flow/probes.hpp"
#include "io/plot.hpp"
#include "lbm/analysis.hpp"
#include "lbm/image_mask.hpp"
#include "lbm/lattice_budget.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {
namespace {

void declare(ParamTable& t) {
  LbmDefaults d;
  d.resolution = 16;
  d.tau = 0.53;
  d.end_time = 80;
  d.steady_tolerance = 1e-5;  // drift of window means (steady.hpp); 1e-7 is below the acoustic noise
  d.inflow_ramp_time = -1;
  declare_lbm_params(t, d);
  t.real("channel.height", 0.16, "m", "distance H between the plates").positive();
  t.real("channel.length", 0.4, "m", "length from the inlet to the outlet").positive();
  t.real("channel.depth", 0.0, "m",
         "0: a 2D channel (D3Q19 extrudes it along a periodic z axis of lbm.depth_cells cells); > 0: a D3Q19 duct "
         "this deep with no-slip walls on z-/z+, the cylinder spanning it (DFG 3D-1Z)")
      .non_negative();
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
      .range(0, 1);
  t.string("obstacles.image", "",
           "optional PGM image (P2/P5) stretched over the channel: dark pixels become extra solid cells (half-way "
           "bounce-back), e.g. grains or a rough wall");
  t.integer("obstacles.threshold", 128, "-", "grey level below which an image pixel is solid").range(0, 256);
  t.string("inlet.condition", "zou_he",
           "inflow boundary: zou_he (Zou & He 1997, velocity imposed on the first nodes) or bounce_back (moving-wall "
           "bounce-back half a cell upstream, [S003] Eq. 8)")
      .one_of({"zou_he", "bounce_back"});
  t.string("inlet.profile", "uniform",
           "inflow profile: uniform, or parabolic (Poiseuille; in a duct 16 U y z (H - y)(W - z) / (H W)^2)")
      .one_of({"uniform", "parabolic"});
  t.string("outlet.condition", "pressure",
           "outflow boundary: pressure (Zou-He, p = 0 on the last nodes), zero_gradient (populations extrapolated "
           "from the interior) or convective (convected out with the mean outflow velocity)")
      .one_of({"pressure", "zero_gradient", "convective"});
  t.real("inlet.velocity", 0.01, "m/s", "inflow velocity: the uniform value, or the maximum of the parabola").positive();
}

class CylinderCase : public FlowCase {
 public:
  explicit CylinderCase(const Config& cfg)
      : H_(cfg.real("channel.height")), len_(cfg.real("channel.length")), W_(cfg.real("channel.depth")),
        D_(cfg.real("cylinder.diameter")),
        xc_(cfg.real("cylinder.x")), yc_(cfg.real("cylinder.y") < 0 ? 0.5 * H_ : cfg.real("cylinder.y")),
        U_(cfg.real("inlet.velocity")), rho_(cfg.real("fluid.density")), nu_(cfg.real("fluid.viscosity")),
        kick_(cfg.real("cylinder.initial_perturbation")), ramp_(cfg.real("run.inflow_ramp_time") != 0),
        n_(int(cfg.integer("lbm.resolution"))),
        parabolic_(cfg.string("inlet.profile") == "parabolic"), inlet_bb_(cfg.string("inlet.condition") == "bounce_back"),
        periodic_(cfg.string("channel.sides") == "periodic"), image_(cfg.string("obstacles.image")),
        threshold_(int(cfg.integer("obstacles.threshold"))), outlet_(cfg.string("outlet.condition")) {
    if (W_ > 0 && cfg.string("lbm.lattice") != "D3Q19")
      cfg.fail("channel.depth", "a duct with walls in z (channel.depth > 0) needs lbm.lattice = \"D3Q19\"; 0 gives a 2D channel");
    if (W_ > 0 && cfg.has("lbm.depth_cells"))
      cfg.fail("lbm.depth_cells", "the duct's depth comes from channel.depth; remove lbm.depth_cells");
    if (W_ > 0 && periodic_)
      cfg.fail("channel.sides", "a duct (channel.depth > 0) has walls on all four sides; use channel.sides = \"walls\"");
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
  bool duct() const { return W_ > 0; }
  // The lattice rounds each side to whole cells; a side that moves by more than 0.1% changes
  // the benchmark (the DFG channel of 0.41 m needs a resolution that is a multiple of 10).
  std::vector<std::string> warnings() const override {
    std::vector<std::string> out;
    const double dx = cell_size();
    auto side = [&](const char* key, double len) {
      if (len <= 0) return;
      const double n = len / dx, rounded = std::max(1.0, std::round(n));
      if (std::abs(rounded - n) > 1e-3 * n)
        out.push_back(fmt::format("{} = {} m is {:.4g} cells of {:.4g} m: the lattice uses {} cells ({:.6g} m, {:+.2f}%); "
                                  "choose lbm.resolution so that it is a whole number of cells",
                                  key, len, n, dx, rounded, rounded * dx, 100 * (rounded / n - 1)));
    };
    side("channel.height", H_);
    side("channel.length", len_);
    if (duct()) side("channel.depth", W_);
    return out;
  }
  // Reference velocity of Cd, Cl, Re and St: the uniform inflow, or the mean of the parabola
  // (2/3 U across plates, 4/9 U over the duct's cross-section).
  double u_ref() const { return parabolic_ ? (duct() ? 4.0 / 9.0 : 2.0 / 3.0) * U_ : U_; }
  // Largest velocity of the undisturbed (developed) channel flow, for lambda ([S003] Eq. 16).
  double u_max() const { return parabolic_ ? U_ : 1.5 * U_; }
  // Inflow profile; z only in the duct (Schaefer & Turek 1996: U(0, y, z) = 16 Um y z (H-y)(H-z)/H^4).
  double inflow(double y, double z = -1) const {
    if (!parabolic_) return U_;
    const double a = 4 * U_ * y * (H_ - y) / (H_ * H_);
    return duct() && z >= 0 ? 4 * a * z * (W_ - z) / (W_ * W_) : a;
  }
  // A cylinder sheds vortices above Re ~ 47 (Williamson 1996, Annu. Rev. Fluid Mech. 28:477;
  // confinement raises the onset somewhat): the error model of a vortex street applies.
  bool unsteady() const override { return u_ref() * D_ / nu_ > 47.0; }
  // Length the forces are divided by in Cd, Cl: 1 m of depth in 2D (forces per unit depth),
  // the span W of the cylinder in the duct (total forces).
  double span() const { return duct() ? W_ : 1.0; }

  DomainSpec domain(const lbm::Units& u) override {
    units_ = u;
    const double dx = u.dx();
    DomainSpec d;
    const char* hint = "lower lbm.resolution or the channel's size";
    d.nx = lbm::lattice_side(len_ / dx, "channel.length", hint);
    d.ny = lbm::lattice_side(H_ / dx, "channel.height", hint);
    d.nz = duct() ? lbm::lattice_side(std::max(1.0, W_ / dx), "channel.depth", hint) : 0;
    // Before the masks below (a byte per cell): the least any lattice of this size needs (D2Q9 in
    // single precision); the runner checks the lattice actually chosen.
    lbm::check_lattice_memory(d.nx, d.ny, std::max(1, d.nz), 9, 4, hint);
    d.periodic = {false, periodic_, false};
    d.faces[0].kind = inlet_bb_ ? lbm::FaceCondition::Kind::Wall : lbm::FaceCondition::Kind::Velocity;
    // A plug profile is singular where it meets the no-slip walls: the Zou-He inflow nodes next
    // to a wall get half the speed (the mean over their half cell); at full speed these corner
    // nodes drive TRT unstable at large tau.
    const int ny = d.ny, nz = d.nz;
    const bool box = duct();
    d.faces[0].profile = [this, dx, ny, nz, box](int, int y, int z) {
      double corner = 1.0;
      if (!parabolic_ && !inlet_bb_) {
        if (!periodic_ && (y == 0 || y == ny - 1)) corner *= 0.5;
        if (box && (z == 0 || z == nz - 1)) corner *= 0.5;
      }
      return Vec3(corner * units_.to_lattice_velocity(inflow((y + 0.5) * dx, box ? (z + 0.5) * dx : -1)), 0, 0);
    };
    using K = lbm::FaceCondition;
    if (outlet_ == "pressure") {
      d.faces[1].kind = K::Kind::Pressure;
      d.faces[1].density = 1;
    } else {  // the solver implements the open outflow faces (lbm/solver.hpp)
      d.faces[1].kind = K::Kind::Outflow;
      d.faces[1].outflow = outlet_ == "convective" ? K::Outflow::Convective : K::Outflow::ZeroGradient;
      d.faces[1].convective_velocity = 0;  // the face's mean normal velocity
    }
    // z faces of the duct keep the default: no-slip walls.
    // Lattice coordinates: cell (i, j) has its centre at ((i + 1/2) dx, (j + 1/2) dx).
    const Vec3 c(xc_ / dx - 0.5, yc_ / dx - 0.5, box ? 0.5 * nz - 0.5 : 0.0);
    const double r = 0.5 * D_ / dx;
    DomainSpec::Object cyl;
    cyl.name = "cylinder";
    cyl.scheme = scheme_;
    cyl.center = c;
    cyl.shape = lbm::Circle{c, r};
    d.objects.push_back(cyl);
    std::vector<std::uint8_t> image_solid;
    if (!image_.empty()) {
      DomainSpec::Object img;
      img.name = "image obstacles";
      img.center = c;
      img.cells = lbm::solid_cells(obstacles_, d.nx, d.ny, threshold_);
      image_solid.assign(std::size_t(d.nx) * d.ny, 0);
      for (auto& k : img.cells) image_solid[std::size_t(k[0]) + std::size_t(d.nx) * k[1]] = 1;
      d.objects.push_back(img);
    }
    // Delta p probes on the front and back points of the cylinder (the mid-plane of the duct).
    auto solid = [&](int x, int y) {
      return lbm::inside(*cyl.shape, Vec3(x, y, 0)) ||
             (!image_solid.empty() && image_solid[std::size_t(x) + std::size_t(d.nx) * y]);
    };
    // The same stencils as the probes.* keys (probes.cpp: a weighted least-squares quadratic
    // over the fluid nodes near the surface point), set up once.
    const double zc = box ? 0.5 * nz - 0.5 : 0.0;  // lattice z of the mid-plane
    const int planes = box ? nz : 1;
    std::vector<std::uint8_t> mask(std::size_t(d.nx) * std::size_t(d.ny) * std::size_t(planes));
    for (int z = 0; z < planes; ++z)
      for (int y = 0; y < d.ny; ++y)
        for (int x = 0; x < d.nx; ++x)
          mask[std::size_t(x) + std::size_t(d.nx) * (std::size_t(y) + std::size_t(d.ny) * z)] = solid(x, y) ? 1 : 0;
    try {
      front_ = probe_stencil(Vec3(c.x() - r, c.y(), zc), d.nx, d.ny, planes, mask);
      back_ = probe_stencil(Vec3(c.x() + r, c.y(), zc), d.nx, d.ny, planes, mask);
    } catch (const InputError& e) {
      // Only solid around the cylinder's front or back point: the obstacles image covers it.
      throw InputError(fmt::format("the pressure-difference probes at the cylinder's front and back points: {}{}",
                                   e.what(),
                                   image_solid.empty()
                                       ? std::string()
                                       : fmt::format("; obstacles.image '{}' (dark pixels below obstacles.threshold) "
                                                     "covers the cylinder's surroundings: lighten that part of the "
                                                     "image or lower obstacles.threshold",
                                                     image_)));
    }
    const double kick = kick_ * u.to_lattice_velocity(u_ref());
    d.init = [this, dx, c, r, kick, box](int x, int y, int z, double&, Vec3& v) {
      v = ramp_ ? Vec3::Zero() : Vec3(units_.to_lattice_velocity(inflow((y + 0.5) * dx, box ? (z + 0.5) * dx : -1)), 0, 0);
      const double ex = x - (c.x() + 2 * r), ey = y - c.y();
      v.y() += kick * std::exp(-(ex * ex + ey * ey) / (r * r));
    };
    return d;
  }

  static double probe_value(const ProbeStencil& pr, std::span<const double> f) {
    if (pr.node.empty()) return NAN;
    double v = 0;
    for (std::size_t k = 0; k < pr.node.size(); ++k) v += pr.weight[k] * f[pr.node[k]];
    return v;
  }

  // Recirculation length L_a = x_r - (x_c + D/2) from the last sample: x_r is where u_x on the
  // line y = y_c (mid-plane of the duct) behind the cylinder changes from negative to positive
  // (linear interpolation in y between rows, in x between nodes). 0 without a recirculation zone.
  double recirculation_length(const FlowSample& s) const {
    const double dx = units_.dx();
    const double yl = yc_ / dx - 0.5;
    const int y0 = std::clamp(int(std::floor(yl)), 0, s.ny - 2);
    const double ay = yl - y0;
    const int za = duct() ? (s.nz - 1) / 2 : 0, zb = duct() ? s.nz / 2 : 0;
    auto ux = [&](int x) {
      double v = 0;
      for (int z : {za, zb})
        v += 0.5 * ((1 - ay) * s.velocity[s.at(x, y0, z)].x() + ay * s.velocity[s.at(x, y0 + 1, z)].x());
      return v;
    };
    auto solid = [&](int x) { return s.solid[s.at(x, y0, za)] || s.solid[s.at(x, y0 + 1, za)]; };
    const double x_back = xc_ + 0.5 * D_;
    int x = int(std::floor(x_back / dx - 0.5));
    while (x < s.nx && solid(x)) ++x;
    if (x >= s.nx - 1 || ux(x) >= 0) return 0.0;
    for (; x + 1 < s.nx; ++x) {
      const double a = ux(x), b = ux(x + 1);
      if (a < 0 && b >= 0) {
        const double xr = (x + 0.5 + a / (a - b)) * dx;
        return xr - x_back;
      }
    }
    return 0.0;
  }

  // Forces per unit depth (2D) or total forces (duct) with their unit; the coefficients are
  // dimensionless; Delta p = p(front) - p(back) of the cylinder.
  std::vector<std::string> columns() const override {
    if (duct()) return {"Fx_N", "Fy_N", "Cd", "Cl", "dp_front_back_Pa"};
    return {"Fx_N_per_m", "Fy_N_per_m", "Cd", "Cl", "dp_front_back_Pa"};
  }
  void measure(const FlowSample& s, std::vector<double>& row) const override {
    const Vec3 F = s.force[0];
    const double q = 0.5 * rho_ * u_ref() * u_ref() * D_ * span();
    const double dp = probe_value(front_, s.pressure) - probe_value(back_, s.pressure);
    row.insert(row.end(), {F.x(), F.y(), F.x() / q, F.y() / q, dp});
  }
  std::optional<int> steady_column() const override { return 2; }
  std::string progress_text(const std::vector<double>& row) const override {
    return fmt::format("Cd {:.4f}  Cl {:+.4f}  dp {:.4g} Pa", row[4], row[5], row[6]);
  }

  void finish(const FlowSample& last, const std::vector<std::vector<double>>& hist, const fs::path& out, bool plots,
              nlohmann::json& res) const override {
    std::vector<double> t, cd, cl, fx, dp;
    for (auto& r : hist) {
      t.push_back(r[1]);
      fx.push_back(r[2]);
      cd.push_back(r[4]);
      cl.push_back(r[5]);
      dp.push_back(r[6]);
    }
    // Statistics over the second half of the time after the inflow reached full speed (the
    // first half of it is the start-up of the wake).
    const double t_from = last.ramp_end_time + 0.5 * (t.back() - last.ramp_end_time);
    const auto lift = lbm::analyse_oscillation(t, cl, t_from);
    const auto drag = lbm::analyse_oscillation(t, cd, t_from);
    const bool shedding = lift.cycles >= 2 && (lift.max - lift.min) > 1e-3;
    const double cd_mean = shedding ? lbm::time_average(t, cd, lift.first_up, lift.last_up) : cd.back();
    const double re = u_ref() * D_ / nu_;
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    res["reynolds"] = re;
    res["blockage_D_over_H"] = D_ / H_;
    res["reference_velocity_m_per_s"] = u_ref();
    res["geometry"] = duct() ? "duct" : "2d";
    res["depth_m"] = W_;  // 0: 2D, forces per unit depth
    res["force_unit"] = duct() ? "N" : "N/m";
    res["coefficient_area_m2_per_m"] = D_ * span();  // D (per unit depth) or D W (duct), in Cd = 2 F / (rho U^2 A)
    res["outlet_condition"] = outlet_;
    res["cd_mean"] = cd_mean;
    res["averaging_from_s"] = t_from;
    res["cd_final"] = cd.back();
    res["cl_final"] = cl.back();
    res["dp_final_Pa"] = num(dp.back());
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
    // The DFG benchmark quantities (Schaefer & Turek 1996): steady flow: the final values and
    // the recirculation length; vortex shedding: extremes and means over the whole periods
    // between the first and last upward crossings of the mean lift, and Delta p at t0 + 1/(2f),
    // t0 the time of the (last) maximum lift in those periods.
    if (shedding) {
      const auto cdx = lbm::extremes(t, cd, lift.first_up, lift.last_up);
      const auto clx = lbm::extremes(t, cl, lift.first_up, lift.last_up);
      const double t_dp = clx.t_max + 0.5 / lift.frequency;
      res["cd_max_periods"] = cdx.max;
      res["cd_min_periods"] = cdx.min;
      res["cl_max_periods"] = clx.max;
      res["cl_min_periods"] = clx.min;
      res["cl_mean_periods"] = lbm::time_average(t, cl, lift.first_up, lift.last_up);
      res["period_s"] = 1.0 / lift.frequency;
      res["cl_max_time_s"] = clx.t_max;
      res["dp_half_period_after_cl_max_time_s"] = t_dp;
      res["dp_half_period_after_cl_max_Pa"] =
          t_dp <= t.back() ? num(lbm::interpolate_series(t, dp, t_dp)) : nlohmann::json(nullptr);
      res["recirculation_length_m"] = nullptr;
      res["recirculation_length_reason"] = "vortex shedding: no steady recirculation zone";
    } else {
      res["recirculation_length_m"] = recirculation_length(last);
    }
    // [S003] Eq. 16 is the wall factor of a cylinder between plates (per unit depth); a duct's
    // cylinder has walls at its ends too and no such factor.
    if (duct()) {
      res["lambda_wall_factor"] = nullptr;
      res["lambda_wall_factor_reason"] = "defined for a cylinder between two plates ([S003] Eq. 16), not in a duct";
    } else {
      res["lambda_wall_factor"] = fx.back() / (rho_ * nu_ * u_max());
    }
    res["wall_scheme"] = scheme_ == lbm::WallScheme::Bouzidi ? "bouzidi" : scheme_ == lbm::WallScheme::Yu ? "yu" : "halfway";
    if (shedding)
      log::info("cylinder Re = {:.4g}: mean Cd = {:.4f}, Cd max = {:.4f}, Cl max = {:.4f}, St = {:.4f} (over {} shedding "
                "periods), Delta p(t0 + T/2) = {:.4g} Pa",
                re, cd_mean, double(res["cd_max_periods"]), double(res["cl_max_periods"]), lift.frequency * D_ / u_ref(),
                lift.cycles, res["dp_half_period_after_cl_max_Pa"].is_null() ? NAN : double(res["dp_half_period_after_cl_max_Pa"]));
    else
      log::info("cylinder Re = {:.4g}: Cd = {:.4f}, Cl = {:.5f}, Delta p = {:.4g} Pa, L_a = {:.4g} m, lambda = {:.4f} "
                "(steady, no shedding)",
                re, cd.back(), cl.back(), dp.back(), double(res["recirculation_length_m"]),
                duct() ? NAN : double(res["lambda_wall_factor"]));
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
    f.title = duct() ? "Cylinder in a duct: force" : "Cylinder in a channel: force per unit depth";
    f.x = "time_s";
    f.xlabel = "time [s]";
    f.y = duct() ? std::vector<std::string>{"Fx_N", "Fy_N"} : std::vector<std::string>{"Fx_N_per_m", "Fy_N_per_m"};
    f.ylabel = duct() ? "force [N]" : "force [N/m]";
    const PlotJob jobs[] = {{out / "series.csv", out / "plots" / "force_coefficients.png", p},
                            {out / "series.csv", out / "plots" / "forces.png", f}};
    plot_series(jobs);
  }

 private:
  double H_, len_, W_, D_, xc_, yc_, U_, rho_, nu_, kick_;
  bool ramp_;  // the inflow is ramped up: start from rest
  int n_;
  bool parabolic_, inlet_bb_, periodic_;
  std::string image_;
  lbm::GreyImage obstacles_;  // of image_, when set
  int threshold_;
  std::string outlet_;
  ProbeStencil front_, back_;  // Delta p probes (set by domain())
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
