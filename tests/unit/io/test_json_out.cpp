// JSON summaries: indent 2, non-finite numbers as null, written atomically.
#include <gtest/gtest.h>

#include <limits>

#include "io/json_out.hpp"
#include "scratch_dir.hpp"

using namespace ff;

TEST(io_json, NonFiniteBecomesNullAndParsesBack) {
  test::ScratchDir d;
  nlohmann::json j;
  j["ucs_Pa"] = 1.25e8;
  j["e_modulus"] = std::numeric_limits<double>::quiet_NaN();
  j["peak_strain"] = std::numeric_limits<double>::infinity();
  j["name"] = std::string("bad \xC3 utf8");
  j["list"] = {1, 2};
  const auto p = d / "out/summary.json";
  write_json_atomic(p, j);
  const std::string text = test::slurp(p);
  EXPECT_NE(text.find("\n  \"e_modulus\": null,"), std::string::npos) << text;
  EXPECT_NE(text.find("\"peak_strain\": null"), std::string::npos) << text;
  EXPECT_EQ(text.back(), '\n');
  const auto back = nlohmann::json::parse(text);
  EXPECT_EQ(back["ucs_Pa"].get<double>(), 1.25e8);
  EXPECT_TRUE(back["e_modulus"].is_null());
  EXPECT_EQ(back["list"].size(), 2u);
}
