// `fracflow check` refuses exactly what `fracflow run` refuses (issue 12, part 5): every bad
// scenario below goes through both commands of the real program; both must exit with code 2,
// both messages must name the key (or the file), and the run must leave no results folder.
// Each of these was accepted by `check` before (and most were refused by `run` only after
// the sample or lattice was being built). A valid scenario passes both.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "../program_runner.hpp"

namespace fs = std::filesystem;

namespace {

using Result = ff::test::ProgramResult;
// A bounded wait: a scenario that slips through would start a whole run.
Result run_program(const std::string& args) { return ff::test::run_program(args, "timeout -s KILL 20 "); }

// A scratch folder per test process, removed at the end.
struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("fracflow_check_run_" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = dir / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

// Tiny valid samples: a failed check costs nothing, a missed one at most a small genesis.
// Written with dotted keys only, so that a case appends its keys without repeating a table.
const std::string kOutput = "output.vtk = false\noutput.plots = false\n";
const std::string kContact = "dem.group.rock.density = 2600\ndem.contact.rock-rock.friction = 0.5\n";
const std::string kRock = kContact + "dem.bond.rock-rock.cohesion = 5e6\n";
const std::string kUcs2d = "driver = \"ucs\"\n" + kOutput + "dem.dim = 2\n" + kRock +
                           "sample.shape = \"box\"\nsample.width = 6e-3\nsample.height = 12e-3\nsample.porosity = 0.25\n";
const std::string kUcs3d = "driver = \"ucs\"\n" + kOutput + kRock + "sample.diameter = 5e-3\nsample.height = 10e-3\n";
const std::string kTriaxial = "driver = \"triaxial\"\n" + kOutput + kRock + "sample.diameter = 5e-3\nsample.height = 10e-3\n";
const std::string kCavity = "driver = \"flow/cavity\"\n" + kOutput + "lbm.resolution = 16\n";
const std::string kCylinder = "driver = \"flow/cylinder\"\n" + kOutput;
const std::string kHydrofrac2d = "driver = \"hydrofrac\"\n" + kOutput + "dem.dim = 2\n" + kRock +
                                 "sample.shape = \"box\"\nsample.width = 6e-3\nsample.height = 6e-3\nsample.porosity = 0.25\n";
// A 12 mm block with a hole that fits it: for the checks made once the sample exists.
const std::string kHydrofracBlock2d = kHydrofrac2d.substr(0, kHydrofrac2d.find("sample.width")) +
                                      "sample.width = 12e-3\nsample.height = 12e-3\nsample.porosity = 0.25\n"
                                      "borehole.radius = 1.5e-3\n";
const std::string kSaturated2d = "driver = \"saturated_ucs\"\n" + kOutput + "dem.dim = 2\n" + kRock +
                                 "sample.shape = \"box\"\nsample.width = 6e-3\nsample.height = 12e-3\nsample.porosity = 0.25\n";

struct Bad {
  std::string name;  // also the scenario file's name
  std::string text;  // scenario (ignored when `folder`)
  std::vector<std::string> expect;  // in both messages (the key, the file, the reason); "@" = the scenario path
  bool folder = false;              // give a folder as the scenario
};

std::vector<Bad> bad_scenarios() {
  const std::string vein = "dem.group.vein.density = 2000\nsample.default_group = \"rock\"\n";
  return {
      {"empty", "", {"@", "sets no key"}},
      {"bom_only", "\xEF\xBB\xBF", {"@", "sets no key"}},
      {"comments_only", "# a scenario\n\n# to be written\n", {"@", "sets no key"}},
      {"a_folder", "", {"@", "is a folder"}, true},
      // min > max pairs, sizes, porosity
      {"radius_min_above_max", kUcs2d + "sample.radius_min = 0.7e-3\nsample.radius_max = 0.5e-3\n",
       {"sample.radius_max", "radius_min"}},
      {"window_min_above_max",
       kUcs3d + "sample.voxels.folder = \"s\"\nsample.voxels.threshold.rock.min = 200\nsample.voxels.threshold.rock.max = 100\n",
       {"sample.voxels.threshold.rock.max", "min = 200"}},
      {"box_region_hi_below_lo",
       kUcs3d + "[[sample.region]]\ngroup = \"rock\"\nshape = \"box\"\nlo = [0, 0, 0]\nhi = [1e-3, -1e-3, 1e-3]\n",
       {"sample.region.0.hi"}},
      {"porosity_below_packing_3d", kUcs3d + "sample.porosity = 0.2\n", {"sample.porosity", "0.35"}},
      {"porosity_below_packing_2d",
       "driver = \"ucs\"\n" + kOutput + "dem.dim = 2\n" + kRock +
           "sample.shape = \"box\"\nsample.width = 6e-3\nsample.height = 12e-3\nsample.porosity = 0.1\n",
       {"sample.porosity", "0.16"}},
      {"too_many_particles", kUcs3d + "sample.radius_min = 2e-6\nsample.radius_max = 3e-6\n", {"sample.radius_min", "5e7"}},
      {"sample_narrower_than_particles", kUcs3d + "sample.radius_min = 1e-3\nsample.radius_max = 2e-3\n",
       {"sample.diameter", "4 particle radii"}},
      {"2d_cylinder", "driver = \"ucs\"\n" + kOutput + "dem.dim = 2\n" + kRock, {"sample.shape", "box"}},
      {"gravity_out_of_plane_2d", kUcs2d + "dem.gravity = [0, 0, -9.81]\n", {"dem.gravity", "z component"}},
      // files
      {"missing_stl", kUcs3d + "[[sample.region]]\ngroup = \"rock\"\nshape = \"stl\"\nfile = \"no_such_vein.stl\"\n",
       {"sample.region.0.file", "no_such_vein.stl"}},
      {"missing_voxels", kUcs3d + "sample.voxels.folder = \"no_such_slices\"\nsample.voxels.threshold.rock.min = 10\n",
       {"sample.voxels.folder", "no_such_slices"}},
      {"cylinder_missing_image", kCylinder + "obstacles.image = \"no_such_grains.pgm\"\n",
       {"obstacles.image", "no_such_grains.pgm"}},
      // groups used but not declared, pair tables
      {"region_group_undeclared", kUcs3d + "[[sample.region]]\ngroup = \"ghost\"\nradius = 1e-3\n",
       {"sample.region.0.group", "ghost"}},
      {"window_group_undeclared", kUcs3d + "sample.voxels.folder = \"s\"\nsample.voxels.threshold.ghost.min = 10\n",
       {"sample.voxels.threshold.ghost.min", "ghost"}},
      {"default_group_undeclared", kUcs3d + "sample.default_group = \"ghost\"\n", {"sample.default_group", "ghost"}},
      {"bond_pair_group_undeclared", kUcs3d + "dem.bond.rock-ghost.cohesion = 1e6\n", {"dem.bond.rock-ghost", "ghost"}},
      {"contact_pair_missing", kUcs3d + vein, {"dem.contact.rock-vein"}},
      {"pair_table_twice",
       kUcs3d + vein + "dem.contact.rock-vein.friction = 0.3\ndem.contact.vein-rock.friction = 0.4\n",
       {"dem.contact.rock-vein", "dem.contact.vein-rock"}},
      {"too_many_groups",
       [] {
         std::string t = kUcs3d;
         for (int g = 0; g < 65; ++g) t += "dem.group.g" + std::to_string(g) + ".density = 2600\n";
         return t;
       }(),
       {"66 particle groups", "the limit is 64"}},
      // keys of a law that is not the active one
      {"rotational_key_with_parallel_law", kUcs3d + "dem.bond.rock-rock.youngs_modulus = 5e9\n",
       {"dem.bond.rock-rock.youngs_modulus", "rotational", "dem.bond_law"}},
      {"parallel_key_with_rotational_law",
       kUcs3d + "dem.bond_law = \"rotational\"\ndem.bond.rock-rock.friction_angle = 30\n"
                "dem.bond.rock-rock.tensile_strength = 5e6\n",
       {"dem.bond.rock-rock.tensile_strength", "parallel"}},
      {"hertz_key_with_linear_law", kUcs3d + "dem.contact.rock-rock.shear_modulus = 2e9\n",
       {"dem.contact.rock-rock.shear_modulus", "hertz_mindlin"}},
      {"bond_key_without_bonds", kUcs3d + "dem.bond_law = \"none\"\n", {"dem.bond.rock-rock.cohesion", "none"}},
      {"rotational_bond_without_friction_angle", kUcs3d + "dem.bond_law = \"rotational\"\n",
       {"dem.bond.rock-rock.friction_angle", "> 0"}},
      // triaxial
      {"triaxial_2d", kTriaxial + "dem.dim = 2\n", {"dem.dim", "3D"}},
      {"triaxial_crushing_confinement", kTriaxial + "triaxial.confining_pressure = 1e12\n",
       {"triaxial.confining_pressure", "half a radius"}},
      {"crushing_locked_in_stress", kUcs2d + "sample.locked_in_stress = 1e300\n", {"sample.locked_in_stress", "half a radius"}},
      {"triaxial_reserved_group",
       kTriaxial + "triaxial.lateral = \"particle_membrane\"\ndem.group.membrane.density = 1000\n"
                   "dem.contact.membrane-membrane.friction = 0.1\ndem.contact.membrane-rock.friction = 0.1\n"
                   "dem.bond.membrane-membrane.cohesion = 1e6\ndem.bond.membrane-rock.cohesion = 1e6\n"
                   "sample.default_group = \"rock\"\n",
       {"triaxial.lateral", "'membrane'"}},
      {"triaxial_bonded_membrane_without_bonds",
       "driver = \"triaxial\"\n" + kOutput + kContact +
           "dem.bond_law = \"none\"\nsample.diameter = 5e-3\nsample.height = 10e-3\ntriaxial.lateral = \"particle_membrane\"\n",
       {"particle_membrane.bonded", "dem.bond_law"}},
      // LBM limits
      {"lbm_mach_too_high", kCavity + "cavity.lid_velocity = 1.0\n", {"lbm.tau", "Mach number"}},
      {"lbm_tau_and_time_step", kCavity + "lbm.tau = 0.7\nlbm.time_step = 1e-3\n", {"lbm.tau", "lbm.time_step"}},
      {"lbm_time_step_too_large", kCavity + "lbm.time_step = 10\n", {"lbm.time_step", "Mach number"}},
      {"lbm_depth_without_d3q19", kCavity + "lbm.depth_cells = 4\n", {"lbm.depth_cells", "D3Q19"}},
      {"cylinder_wider_than_channel", kCylinder + "cylinder.diameter = 0.2\n", {"cylinder.diameter"}},
      // refused only once the sample exists (check builds the set-up as run does; accepted by check before)
      {"time_step_above_critical_2d", kUcs2d + "dem.time_step = 1e-3\n", {"dem.time_step", "above the stable limit"}},
      {"time_step_above_critical_triaxial", kTriaxial + "dem.time_step = 1e-3\n",
       {"dem.time_step", "above the stable limit"}},
      {"run_that_cannot_end", kUcs2d + "ucs.platen_velocity = 1e-12\n", {"ucs.platen_velocity", "time steps of"}},
      {"platen_jumping_grains", kUcs2d + "ucs.platen_velocity = 1e6\n", {"ucs.platen_velocity", "in one time step"}},
      // grains 1e300 times too dense: a step of 1e141 s, refused for the platen's speed alone (session 49: the
      // refusal now says where the step comes from)
      {"density_lengthening_the_step",
       std::regex_replace(kUcs2d, std::regex("rock.density = 2600"), "rock.density = 1e300"),
       {"ucs.platen_velocity", "a density far too high"}},
      {"lbm_end_time_overflowing", kCavity + "lbm.tau = 0.52\nrun.end_time = 1e300\n", {"run.end_time", "time steps"}},
      // with lbm.tau fixed the step is (tau - 1/2) dx^2 / (3 nu): a viscosity of 1e300 made it 2.5e-310 s and the
      // refusal named the resolution and tau only (session 49)
      {"lbm_viscosity_shrinking_the_step", kCavity + "fluid.viscosity = 1e300\n", {"time steps", "a lower fluid.viscosity"}},
      // every pair bonded: memory past 6 GB on a 3D block
      {"bond_gap_beyond_the_grains", kUcs2d + "sample.bond_gap = 1\n", {"sample.bond_gap", "largest particle radius"}},
      // 1e300 s overflowed the ramp's step count into a negative sample index: a segmentation fault
      {"inflow_ramp_outlasting_the_run", kCylinder + "run.inflow_ramp_time = 1e300\n",
       {"run.inflow_ramp_time", "does not end before run.end_time"}},
      // every pore cavitated from the start and held there: NaN grains at the first step
      {"cavitation_above_the_initial_pressure",
       kSaturated2d + "fluid.cavitation_pressure = 1e300\n",
       {"fluid.cavitation_pressure", "not below fluid.initial_pressure"}},
      {"vapour_above_the_pore_pressure",
       kHydrofrac2d + "injection.fluid = \"network\"\nnetwork.vapour_pressure = 1e6\n",
       {"network.vapour_pressure", "not below network.pore_pressure"}},
      // 2^31 generated fractures: the generator and the bond cut ran for hours (fuzzed 2026-11-30)
      {"dfn_count_past_any_block",
       kHydrofrac2d + "dfn.count = 2147483648\n",
       {"dfn.count", "out of range"}},
      // a grid spacing that never advanced x: an endless loop
      {"dfn_grid_spacing_below_round_off",
       kHydrofracBlock2d + "dfn.count = 5\ndfn.positions = \"grid\"\ndfn.spacing = 1e-12\n",
       {"dfn.spacing", "grid positions"}},
      // a buffer past the block placed no fracture of the five asked for, without a word (fuzzed 2026-11-30)
      {"dfn_buffer_past_the_block",
       kHydrofracBlock2d + "dfn.count = 5\ndfn.buffer = 1\n",
       {"dfn.buffer", "no natural fracture could be placed"}},
      // servo walls jumping 0.4 of a grain per step: 0 MPa after insitu.max_steps, blamed on too few steps
      {"servo_walls_jumping_grains",
       kHydrofracBlock2d + "insitu.servo_velocity = 1e6\n",
       {"insitu.servo_velocity", "in one time step"}},
      // a breakdown length beyond where the run stops: the breakdown pressure stayed null for ever
      {"breakdown_length_past_the_stop",
       kHydrofracBlock2d + "injection.breakdown_length = 1\n",
       {"injection.breakdown_length", "could never reach it"}},
      // a bond section that overflows (k = E A / L = NaN): the critical step skipped it, the run turned NaN at
      // step 0 and blamed the time step's safety factor (fuzzed 2026-11-30, session 47)
      {"bond_stiffness_overflowing", kUcs3d + "dem.bond.rock-rock.radius_multiplier = 1e300\n",
       {"dem.bond.*.radius_multiplier", "critical time step is 0"}},
      {"bond_stiffness_overflowing_2d", kUcs2d + "dem.bond.rock-rock.emod = 1e308\ndem.bond.rock-rock.radius_multiplier = 1e10\n",
       {"dem.bond.*.emod", "not finite"}},
      // angles of 1e300 degrees (a direction of nothing in particular) were taken
      {"dfn_angle_beyond_a_turn", kHydrofracBlock2d + "dfn.count = 2\ndfn.angle = 1e300\n", {"dfn.angle", "[-360, 360]"}},
      {"perforation_azimuth_beyond_a_turn", kHydrofracBlock2d + "borehole.perforation_azimuth = 400\n",
       {"borehole.perforation_azimuth", "[-360, 360]"}},
      // a kick 1e300 times the inflow: NaN at step 103, blamed on the resolution
      {"cylinder_kick_above_the_inflow", kCylinder + "cylinder.initial_perturbation = 2\n",
       {"cylinder.initial_perturbation", "[0, 1]"}},
      // a perforation slot 2e9 m wide (fuzzed 2026-11-30)
      {"perforation_wider_than_the_hole",
       kHydrofracBlock2d + "borehole.perforation_length = 1e-3\nborehole.perforation_width = 2147483648\n",
       {"borehole.perforation_width", "wider than the hole"}},
      // masses that underflow: the packing went NaN at step 0 with "the time step 0 s is too large"
      {"density_underflowing_the_masses",
       "driver = \"ucs\"\n" + kOutput + "dem.group.rock.density = 1e-300\n" + kRock.substr(kRock.find('\n') + 1) +
           "sample.diameter = 5e-3\nsample.height = 10e-3\n",
       {"dem.group.*.density", "genesis's time step is 0"}},
      // kn/ks = 1e-300: the shear spring's stiffness overflows; the critical step counted kn alone and the
      // sample went NaN at step 0 with the advice to lower dem.time_step_safety (fuzzed, session 48)
      {"contact_shear_spring_overflowing", kUcs2d + "dem.contact.rock-rock.kratio = 1e-300\n",
       {"dem.contact.*.kratio", "time step is 0"}},
      // gravity of 1e300 m/s^2: the genesis crushed the packing (locked-in stress 1.4 GPa, porosity 0.56 for
      // 0.18) and check accepted it with three warnings (fuzzed, session 48)
      {"gravity_pulling_grains_through_each_other", kUcs2d + "dem.gravity = [0.0, -1e300, 0.0]\n",
       {"dem.gravity", "fall through each other"}},
      // a contact modulus that overflows: the coupled DEM step skipped its NaN stiffness, took the LBM step and
      // the disks flew off at their first contact ("moves at inf m/s", blamed on gravity)
      {"sedimentation_contact_modulus_overflowing",
       "driver = \"sedimentation\"\n" + kOutput + "fluid.sound_speed = 1.0\ndem.contact_modulus = 1e300\n",
       {"dem.contact_modulus", "DEM sub-steps per LBM step"}},
      // an inflow of 1e-300 m/s at the default Mach number: tau 3.5e298, a warning, and a drag coefficient of 0/0
      // in series.csv (fuzzed, session 48)
      {"relaxation_time_past_any_flow", kCylinder + "lbm.mach = 0.1\ninlet.velocity = 1e-300\n", {"lbm.mach", "hardly relaxes"}},
      // a TRT magic parameter of 1e300: LBM unstable at step 13,152, blamed on the resolution
      {"trt_magic_above_one", kCavity + "lbm.trt_magic = 1e300\n", {"lbm.trt_magic", "(0, 1]"}},
      // Eq. B1 with h_inf above h0 opened the contact channels as they were squeezed (fuzzed 2026-11-30)
      {"b1_aperture_widening_under_stress", kSaturated2d + "fluid.aperture_hinf = 1e-3\n",
       {"fluid.aperture_hinf", "above fluid.aperture_h0"}},
      {"network_b1_aperture_widening_under_stress",
       kHydrofrac2d + "injection.fluid = \"network\"\nnetwork.aperture_hinf = 1e-3\n",
       {"network.aperture_hinf", "above network.aperture_h0"}},
      // Eq. B2's gamma is a reduction factor (seed 004): above 1 a pore-to-pore channel was wider than the gap
      // between its grains (2^31: wider than the block), taken without a word (session 48)
      // a sleeve 2^31 sample heights long: its elements collapsed to zero area in the run, with advice naming
      // no key (session 49)
      {"membrane_sleeve_degenerate", kTriaxial + "membrane.length_factor = 2147483648\n",
       {"membrane.length_factor", "[1, 10]"}},
      // channels 1e300 m wide: check passed, the run stopped at its first step (session 49)
      {"channels_without_a_flow_step", kSaturated2d + "fluid.aperture_h0 = 1e300\n",
       {"allows no time step", "fluid.aperture_h0"}},
      // Peng-Robinson water at 1e-300 Pa: the EOS's gas root, the 3D run stopped at once (session 49)
      {"water_below_its_vapour_pressure",
       "driver = \"saturated_ucs\"\n" + kOutput + kRock +
           "sample.diameter = 5e-3\nsample.height = 10e-3\nfluid.liquid_eos = \"peng_robinson\"\n"
           "fluid.initial_pressure = 1e-300\n",
       {"fluid.initial_pressure", "vapour pressure"}},
      // a hole fluid stiffer than any material (1e300 Pa): a fluid-grain spring period of 1.5e-152 s against a DEM
      // step of 3.8e-8 s, and the network run stopped at injection (CG without convergence; session 49)
      {"hole_fluid_stiffer_than_diamond", kHydrofrac2d + "injection.fluid_bulk_modulus = 1e300\n",
       {"injection.fluid_bulk_modulus", "out of range"}},
      {"liquid_stiffer_than_diamond", kSaturated2d + "fluid.liquid_bulk_modulus = 1e300\n",
       {"fluid.liquid_bulk_modulus", "out of range"}},
      // a liquid softer than its gas (1e-12 Pa): no pore pressure ever built up, without a word (session 49)
      {"liquid_softer_than_its_gas", kSaturated2d + "fluid.liquid_bulk_modulus = 2.2\n",
       {"fluid.liquid_bulk_modulus", "softer than the gas"}},
      {"b2_reduction_factor_above_one", kSaturated2d + "fluid.aperture_gamma = 2\n", {"fluid.aperture_gamma", "(0, 1]"}},
      {"network_b2_reduction_factor_above_one",
       kHydrofrac2d + "injection.fluid = \"network\"\nnetwork.b2_gamma = 2147483648\n", {"network.b2_gamma", "(0, 1]"}},
      // a vapour pressure of 1e-300 Pa: cavitated pores became a gas of ~1e-305 kg/m^3 and the pressure solve
      // stopped without converging (session 50)
      {"vapour_pressure_of_no_liquid", kSaturated2d + "fluid.cavitation_pressure = 1e-300\n",
       {"fluid.cavitation_pressure", "or 0 to switch cavitation off"}},
      // a throat conductance cap at 1e-300 x the median clipped every throat to one value, without a word (session 50)
      {"network_conductance_cap_below_the_median",
       kHydrofrac2d + "injection.fluid = \"network\"\nnetwork.max_conductance_ratio = 0.5\n",
       {"network.max_conductance_ratio", "out of range"}},
      // a pressurised snapshot at 1e300 Pa, above the run's stop: never taken, without a word (session 49)
      {"snapshot_pressure_past_the_stop", kHydrofrac2d + "measure.pressure = 1e300\n",
       {"measure.pressure", "not below injection.max_pressure"}},
      // the run started at a pressure past its stop: NaN grains, blamed on the DEM step
      {"injection_starting_past_its_stop",
       kHydrofrac2d + "injection.initial_pressure = 1e300\n",
       {"injection.initial_pressure", "not below injection.max_pressure"}},
      // 1e300 Pa s: the throats' conductances underflowed and the pressures became NaN
      {"network_viscosity_of_a_glass",
       kHydrofrac2d + "injection.fluid = \"network\"\nnetwork.viscosity = 1e300\n",
       {"network.viscosity", "out of range"}},
      // 1e300 Pa of pore water ran through to a "successful" UCS
      {"pore_pressure_past_liquid_water",
       kSaturated2d + "fluid.initial_pressure = 1e300\n",
       {"fluid.initial_pressure", "out of range"}},
      // 2^31 steps between rows: --max-steps, --max-wall and SIGTERM wait for a row, so the run could not be stopped
      {"series_interval_past_any_stop", kUcs2d + "ucs.series_interval = 2147483648\n", {"ucs.series_interval", "out of range"}},
      // a side past an int wrapped into a negative size: "cannot create std::vector larger than max_size()"
      {"lattice_side_past_an_int", kCylinder + "channel.height = 1e9\n", {"channel.height", "2^30 cells"}},
      // a lattice past the machine's memory: std::bad_alloc, or gigabytes of masks first
      {"lattice_beyond_memory", "driver = \"flow/cavity\"\n" + kOutput + "lbm.resolution = 100000\n", {"lbm.resolution", "GiB"}},
  };
}

}  // namespace

TEST(CheckEqualsRun, EveryRefusedScenarioIsRefusedByCheckAndByRunAlike) {
  const Scratch s;
  for (const Bad& b : bad_scenarios()) {
    SCOPED_TRACE(b.name);
    ASSERT_FALSE(b.expect.empty());
    fs::path file = b.folder ? s.dir / b.name : s.write(b.name + ".toml", b.text);
    if (b.folder) fs::create_directories(file);
    const fs::path out = s.dir / (b.name + "_out");
    const auto start = std::chrono::steady_clock::now();
    const Result check = run_program("check " + file.string());
    const Result run = run_program("run " + file.string() + " --out " + out.string() + " --quiet");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(check.code, 2) << check.output;
    EXPECT_EQ(run.code, 2) << run.output;
    for (std::string e : b.expect) {
      if (e == "@") e = file.string();
      EXPECT_NE(check.output.find(e), std::string::npos) << "check does not say '" << e << "':\n" << check.output;
      EXPECT_NE(run.output.find(e), std::string::npos) << "run does not say '" << e << "':\n" << run.output;
    }
    EXPECT_FALSE(fs::exists(out)) << "the refused run left " << out;
    EXPECT_LT(seconds, 5.0) << "refused before building anything";
  }
}

TEST(CheckEqualsRun, ValidScenarioPassesCheckAndRuns) {
  const Scratch s;
  const fs::path file = s.write("valid.toml", kUcs2d);
  const Result check = run_program("check " + file.string());
  EXPECT_EQ(check.code, 0) << check.output;
  const fs::path out = s.dir / "valid_out";
  const Result run = run_program("run " + file.string() + " --out " + out.string() + " --quiet --max-steps 100");
  EXPECT_EQ(run.code, 0) << run.output;
  EXPECT_TRUE(fs::exists(out / "scenario.toml")) << run.output;
}

// The examples of `--set` errors name keys a user can actually set.
TEST(CheckEqualsRun, SetErrorExamplesNameKeysThatExist) {
  for (const char* bad : {"--set dem.local_damping", "--set dem.gravity={}"}) {
    const Result r = run_program(std::string("check ") + bad);
    ASSERT_EQ(r.code, 2) << r.output;
    // Every "--set KEY=VALUE" the message gives as an example must be accepted by check.
    std::size_t examples = 0;
    for (std::size_t at = r.output.find("e.g. "); at != std::string::npos; at = r.output.find("--set ", at)) {
      at = r.output.find("--set ", at);
      if (at == std::string::npos) break;
      at += 6;
      const std::string assignment = r.output.substr(at, r.output.find_first_of(" \n", at) - at);
      ++examples;
      const Result ok = run_program("check --set '" + assignment + "'");
      EXPECT_EQ(ok.code, 0) << assignment << ":\n" << ok.output.substr(0, 400);
    }
    EXPECT_GT(examples, 0u) << r.output;
  }
}

// Scale of input (issue 12, part 7): `fracflow check` used to cost O(keys^2) (40,000 groups
// took 5 s, 40,000 regions 50 s); now a huge file is refused early with the limit that it
// breaks, and a large valid one is checked in well under the bound.
TEST(CheckScale, MillionKeysManyGroupsAndManyRegionsAreCheckedInSeconds) {
  const Scratch s;
  auto timed_check = [&](const fs::path& file) {
    const auto start = std::chrono::steady_clock::now();
    Result r = run_program("check " + file.string());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 10.0) << file;
    return r;
  };
  auto scenario = [&](const std::string& name, int n, const std::string& head, auto&& line) {
    std::string text = head;
    text.reserve(static_cast<std::size_t>(n) * 40);
    for (int i = 0; i < n; ++i) text += line(i);
    return s.write(name, text);
  };
  // A million groups (a million keys): refused before parsing, naming the limit.
  auto r = timed_check(scenario("million_groups.toml", 1'000'000, "driver = \"ucs\"\n",
                                [](int i) { return "dem.group.g" + std::to_string(i) + ".density = 2600\n"; }));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("has 1000001 keys; the limit is 200000"), std::string::npos) << r.output.substr(0, 400);
  // 150,000 groups: within the key limit, refused by the group limit.
  r = timed_check(scenario("many_groups.toml", 150'000, "driver = \"ucs\"\n",
                           [](int i) { return "dem.group.g" + std::to_string(i) + ".density = 2600\n"; }));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("declares 150000 particle groups ([dem.group.NAME]); the limit is 64"), std::string::npos)
      << r.output.substr(0, 400);
  // 60,000 regions: refused by the region limit.
  r = timed_check(scenario("many_regions.toml", 60'000, kUcs3d,
                           [](int) { return std::string("[[sample.region]]\ngroup = \"rock\"\n"); }));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("60000 [[sample.region]] entries; the limit is 10000"), std::string::npos)
      << r.output.substr(0, 400);
  // 10,000 regions and 64 groups with every pair table: valid, every key listed.
  std::string groups;
  for (int a = 0; a < 64; ++a) {
    groups += "dem.group.g" + std::to_string(a) + ".density = 2600\n";
    for (int b = a; b < 64; ++b)
      groups += "dem.contact.g" + std::to_string(a) + "-g" + std::to_string(b) + ".friction = 0.5\ndem.bond.g" +
                std::to_string(a) + "-g" + std::to_string(b) + ".cohesion = 5e6\n";
  }
  r = timed_check(scenario("largest_valid.toml", 10'000,
                           "driver = \"ucs\"\n" + groups +
                               "sample.diameter = 5e-3\nsample.height = 10e-3\nsample.default_group = \"g0\"\n",
                           [](int i) { return "[[sample.region]]\ngroup = \"g" + std::to_string(i % 64) + "\"\n"; }));
  EXPECT_EQ(r.code, 0) << r.output.substr(0, 400);
  EXPECT_NE(r.output.find("sample.region.9999.group"), std::string::npos);
  EXPECT_NE(r.output.find("dem.bond.g62-g63.truncation"), std::string::npos);
}
