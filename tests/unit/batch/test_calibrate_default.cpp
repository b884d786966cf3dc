// Long (label long): `fracflow calibrate` on the built-in default sample (1,727 spheres) to the
// seed 000 Table 5 averages, E = 2.37 GPa, nu = 0.35, UCS = 14.97 MPa; 2 UCS runs of ~13 s each.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace fs = std::filesystem;

TEST(CalibrateDefault, ReachesTable5WithinTolerances) {
  const auto out = fs::temp_directory_path() / "fracflow_test_calibrate_default";
  fs::remove_all(out);
  const std::string cmd = std::string(FRACFLOW_BIN) +
                          " calibrate --target-E 2.37e9 --target-nu 0.35 --target-ucs 14.97e6 --max-iter 12 "
                          "--threads-per-run 1 --out " + out.string();
  const int st = std::system(cmd.c_str());
  std::ifstream f(out / "calibration.json");
  ASSERT_TRUE(f) << "no calibration.json; exit status " << st;
  const auto j = nlohmann::json::parse(f);
  EXPECT_TRUE(j["converged"].get<bool>()) << j.dump(2);
  const auto& m = j["final_measured"];
  EXPECT_LT(std::abs(m["youngs_modulus_Pa"].get<double>() / 2.37e9 - 1), 0.05);
  EXPECT_LT(std::abs(m["poisson_ratio"].get<double>() - 0.35), 0.03);
  EXPECT_LT(std::abs(m["ucs_Pa"].get<double>() / 14.97e6 - 1), 0.05);
  EXPECT_TRUE(fs::exists(out / "calibrated.toml"));
  EXPECT_TRUE(fs::exists(out / "calibration.csv"));
}
